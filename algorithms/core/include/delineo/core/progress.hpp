#pragma once
// Progress and cancellation for long work, free of Qt and threads.
//
// An algorithm receives a `Progress*` (may be null), reports fractions of its own work and polls
// `canceled()` once per band of rows. A caller splits its range among sub-steps with
// `Progress::Range`, so each step reports 0..1 of itself and the root sees one monotone value.
// All members are safe to call from any thread: the GUI's job runner cancels from the GUI
// thread while the algorithm reports from workers.
#include <atomic>
#include <functional>
#include <mutex>
#include <string>

namespace delineo::core {

class Progress {
 public:
  // Called on the reporting thread with the overall fraction in [0, 1] and the current stage.
  using Listener = std::function<void(double fraction, const std::string& stage)>;

  Progress() = default;
  explicit Progress(Listener listener) : listener_(std::move(listener)) {}
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  virtual ~Progress() = default;

  // Reports the overall fraction done; values are clamped to [0, 1] and never go backwards.
  virtual void report(double fraction);
  virtual void setStage(const std::string& stage);
  std::string stage() const;
  double fraction() const noexcept { return fraction_.load(); }

  virtual void cancel() noexcept { canceled_.store(true); }
  virtual bool canceled() const noexcept { return canceled_.load(); }

  // Deterministic cancellation for tests: cancel on the n-th call to report().
  void cancelAfterReports(int n) noexcept { cancelAfter_.store(n); }
  int reportCount() const noexcept { return reports_.load(); }

  // A view of [begin, end] of a parent's range. Reports map into the parent; cancellation is
  // shared with it.
  class Range;

 private:
  Listener listener_;
  std::atomic<double> fraction_{0.0};
  std::atomic<bool> canceled_{false};
  std::atomic<int> reports_{0};
  std::atomic<int> cancelAfter_{-1};
  mutable std::mutex stageMutex_;
  std::string stage_;
};

class Progress::Range : public Progress {
 public:
  // `parent` may be null: the range then only tracks its own cancel flag.
  Range(Progress* parent, double begin, double end);
  void report(double fraction) override;
  void setStage(const std::string& stage) override;
  void cancel() noexcept override;
  bool canceled() const noexcept override;

 private:
  Progress* parent_;
  double begin_;
  double end_;
};

// Helpers that accept a null progress.
inline bool isCanceled(const Progress* p) { return p != nullptr && p->canceled(); }
inline void report(Progress* p, double fraction) {
  if (p != nullptr) p->report(fraction);
}
inline void setStage(Progress* p, const std::string& stage) {
  if (p != nullptr) p->setStage(stage);
}

// Outcome of a long operation that can be canceled. Cancel is not an error.
enum class RunStatus { Completed, Canceled };

}  // namespace delineo::core
