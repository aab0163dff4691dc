#pragma once
// Runs long algorithm calls off the GUI thread. This is the only place of the GUI that knows
// threads: work gets a core::Progress, the runner forwards its reports to the GUI thread
// (throttled to ~20 Hz) and delivers the result there.
//
//   runner.run<cv::Mat>(tr("Disparity"),
//       [left, right, params](core::Progress& p) { return stereo::computeDisparity(left, right, params, &p); },
//       [this](cv::Mat disparity) { showDisparity(disparity); },
//       QStringLiteral("disparity"));   // a new "disparity" job cancels the previous one
//
// Outcomes: finished (result delivered), canceled (cancel() was called or the progress was
// canceled by the time the work returned; the result is dropped), failed (the work threw:
// core::Error keeps its code, any other exception is ProcessingFailed).
#include <QHash>
#include <QObject>
#include <QString>
#include <QTimer>
#include <QWidget>
#include <functional>
#include <memory>
#include <optional>

#include "delineo/core/error.hpp"
#include "delineo/core/progress.hpp"

class QLabel;
class QProgressBar;
class QToolButton;

namespace delineo::widgets {

using JobId = quint64;

enum class JobOutcome { Finished, Canceled, Failed };

// Type of the result callback: void(R), or void() for jobs without a result.
template <class R>
struct JobResultCallback {
  using type = std::function<void(R)>;
};
template <>
struct JobResultCallback<void> {
  using type = std::function<void()>;
};

class JobRunner : public QObject {
  Q_OBJECT
 public:
  explicit JobRunner(QObject* parent = nullptr);
  // Cancels every job and waits for the workers to return (their results are dropped).
  ~JobRunner() override;

  // Starts `work` on the thread pool. `onResult` runs on the GUI thread when the job finishes
  // successfully (before finished() is emitted). A non-empty `key` cancels any active job with the
  // same key first. Returns the job id (never 0).
  template <class R>
  JobId run(const QString& name, std::function<R(core::Progress&)> work,
            typename JobResultCallback<R>::type onResult = {}, const QString& key = {}) {
    if constexpr (std::is_void_v<R>) {
      return start(name, key, std::move(work), std::move(onResult));
    } else {
      auto slot = std::make_shared<std::optional<R>>();
      return start(
          name, key, [slot, w = std::move(work)](core::Progress& p) { slot->emplace(w(p)); },
          [slot, cb = std::move(onResult)]() {
            if (cb && slot->has_value()) cb(std::move(**slot));
          });
    }
  }

  void cancel(JobId id);
  void cancelAll();
  bool isActive(JobId id) const;
  int activeCount() const { return static_cast<int>(jobs_.size()); }
  QString jobName(JobId id) const;
  // Latest forwarded progress of an active job (0 when unknown).
  double jobFraction(JobId id) const;
  QString jobStage(JobId id) const;
  // Blocks (processing events) until no job is active or `msec` elapse; true when idle. For
  // tests and application shutdown.
  bool waitForIdle(int msec);

 signals:
  void started(delineo::widgets::JobId id, const QString& name);
  void progressChanged(delineo::widgets::JobId id, double fraction, const QString& stage);
  void finished(delineo::widgets::JobId id);
  void canceled(delineo::widgets::JobId id);
  // `message`: a core::Error's detail, after the file it names ("path: detail"), without the
  // code's words (the caller says the code in its own sentence); what() of other exceptions.
  void failed(delineo::widgets::JobId id, delineo::core::ErrorCode code, const QString& message);
  // Any outcome; emitted after the specific signal.
  void ended(delineo::widgets::JobId id, delineo::widgets::JobOutcome outcome);
  void activeCountChanged(int count);

 private:
  struct Job;
  JobId start(const QString& name, const QString& key, std::function<void(core::Progress&)> work,
              std::function<void()> deliver);
  void onWorkerDone(JobId id);
  void pollProgress();

  QHash<JobId, std::shared_ptr<Job>> jobs_;
  JobId nextId_ = 1;
  QTimer pollTimer_;
};

// A progress bar, a stage label and a cancel button following one job of a runner (by default
// the most recently started active job). Hidden-text "idle" state when nothing runs.
class JobProgressWidget : public QWidget {
  Q_OBJECT
 public:
  explicit JobProgressWidget(JobRunner* runner, QWidget* parent = nullptr);
  // Follows a specific job (0 = follow the latest started job).
  void setJob(JobId id);
  JobId job() const { return job_; }

 private:
  void showIdle();
  JobRunner* runner_;
  JobId job_ = 0;
  bool followLatest_ = true;
  QProgressBar* bar_;
  QLabel* stage_;
  QToolButton* cancel_;
};

}  // namespace delineo::widgets

Q_DECLARE_METATYPE(delineo::core::ErrorCode)
Q_DECLARE_METATYPE(delineo::widgets::JobOutcome)
