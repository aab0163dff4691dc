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

// What a long operation is doing: an identifier and its numbers rather than a sentence, so that
// each front end words it in its own language (the CLI prints english(), the GUI translates the
// identifier). Front ends' own stages are free text (StageId::Text), already in their language.
enum class StageId {
  Text,
  // Dense matching (number/count: the pyramid level, 1 = coarsest).
  PreparingPyramids,
  MatchingLevel,
  MatchingLevelRightView,
  ValidatingLevel,
  RefiningDepthSteps,
  FillingFlatRegions,
  RemovingSpeckles,
  SnappingDepthSteps,
  RemovingSnappingSpeckles,
  FittingRoofPlanes,
  MatchingSgbm,
  // Scene simulation.
  SimulatingLayout,
  SimulatingRendering,
  SimulatingRadiometry,
  // Delineation (the active polygon's sweeps: moves, deletions, insertion, notch, courtyard).
  CorrelationCosts,
  ActivePolygon,
  PolygonMoves,
  PolygonDeletions,
  PolygonInsertion,
  PolygonNotch,
  PolygonCourtyard,
  // Project pipeline (number: the building's id).
  DenseMatching,
  DelineatingBuilding,
  // Box-fitting (number/count: the building of a whole-image run; BoxFittingBuilding: the
  // project building's id).
  BoxFitSegment,
  BoxFitBoxes,
  BoxFitOutline,
  BoxFittingBuilding,
  // DEM enhancement from the buildings' outlines.
  EnhancingDem,
  // Scene analysis: ground / above-ground and DTM, then classes, objects and proposals.
  SegmentingGround,
  DetectingObjects,  // kLastStageId
};
// The last identifier; the GUI words every one up to it (its table is checked against it).
constexpr StageId kLastStageId = StageId::DetectingObjects;
constexpr StageId kLastEnglishStageId = kLastStageId;

struct Stage {
  StageId id = StageId::Text;
  int number = 0;
  int count = 0;
  std::string text;  // StageId::Text only

  static Stage of(StageId id, int number = 0, int count = 0) { return {id, number, count, {}}; }
  // The stage in English (the CLI's wording).
  std::string english() const;
  bool operator==(const Stage&) const = default;
};

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
  virtual void setStage(const Stage& stage);
  void setStage(const std::string& text) { setStage(Stage{StageId::Text, 0, 0, text}); }
  void setStage(StageId id, int number = 0, int count = 0) { setStage(Stage::of(id, number, count)); }
  std::string stage() const { return stageInfo().english(); }
  Stage stageInfo() const;
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
  Stage stage_;
};

class Progress::Range : public Progress {
 public:
  // `parent` may be null: the range then only tracks its own cancel flag.
  Range(Progress* parent, double begin, double end);
  void report(double fraction) override;
  using Progress::setStage;
  void setStage(const Stage& stage) override;
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
inline void setStage(Progress* p, StageId id, int number = 0, int count = 0) {
  if (p != nullptr) p->setStage(id, number, count);
}

// Outcome of a long operation that can be canceled. Cancel is not an error.
enum class RunStatus { Completed, Canceled };

}  // namespace delineo::core
