#include <QElapsedTimer>
#include <QLabel>
#include <QSignalSpy>
#include <QThread>
#include <QToolButton>
#include <map>
#include <stdexcept>
#include <atomic>
#include <gtest/gtest.h>

#include "delineo/core/error.hpp"
#include "delineo/widgets/job_runner.hpp"
#include "delineo/widgets/stage_text.hpp"
#include "gui_test_support.hpp"

using delineo::core::Progress;
using namespace delineo::widgets;

namespace {
// Work that reports progress until canceled (or `maxSteps` steps).
int spin(Progress& p, int maxSteps) {
  for (int i = 0; i < maxSteps; ++i) {
    if (p.canceled()) return -1;
    p.report(static_cast<double>(i) / maxSteps);
    QThread::msleep(1);
  }
  return maxSteps;
}
}  // namespace

TEST(JobRunner, FinishedDeliversTheResultOnTheGuiThread) {
  JobRunner runner;
  QSignalSpy finished(&runner, &JobRunner::finished);
  QSignalSpy progress(&runner, &JobRunner::progressChanged);
  int result = 0;
  QThread* deliveredOn = nullptr;
  const JobId id = runner.run<int>(
      QStringLiteral("sum"),
      [](Progress& p) {
        p.setStage("adding");
        return spin(p, 150) + 1;
      },
      [&](int r) {
        result = r;
        deliveredOn = QThread::currentThread();
      });
  EXPECT_TRUE(runner.isActive(id));
  ASSERT_TRUE(runner.waitForIdle(10000));
  EXPECT_EQ(result, 151);
  EXPECT_EQ(deliveredOn, QThread::currentThread());
  ASSERT_EQ(finished.count(), 1);
  EXPECT_EQ(finished.at(0).at(0).value<JobId>(), id);
  ASSERT_GE(progress.count(), 2);
  EXPECT_DOUBLE_EQ(progress.last().at(1).toDouble(), 1.0);
  // ~150 ms of work reporting 150 times is forwarded at ~20 Hz, not 150 times.
  EXPECT_LT(progress.count(), 30);
  EXPECT_EQ(progress.at(0).at(2).toString(), QStringLiteral("adding"));
}

TEST(JobRunner, CancelIsAnOutcomeAndDropsTheResult) {
  JobRunner runner;
  QSignalSpy canceled(&runner, &JobRunner::canceled);
  QSignalSpy finished(&runner, &JobRunner::finished);
  bool delivered = false;
  const JobId id = runner.run<int>(QStringLiteral("long"), [](Progress& p) { return spin(p, 100000); },
                                   [&](int) { delivered = true; });
  QThread::msleep(20);
  runner.cancel(id);
  ASSERT_TRUE(runner.waitForIdle(5000));
  EXPECT_EQ(canceled.count(), 1);
  EXPECT_EQ(finished.count(), 0);
  EXPECT_FALSE(delivered);
}

TEST(JobRunner, ErrorsKeepTheirCode) {
  JobRunner runner;
  QSignalSpy failed(&runner, &JobRunner::failed);
  runner.run<int>(QStringLiteral("bad"), [](Progress&) -> int {
    throw delineo::core::Error(delineo::core::ErrorCode::InvalidParameter, "window must be odd");
  });
  runner.run<void>(QStringLiteral("worse"), [](Progress&) { throw std::runtime_error("boom"); });
  ASSERT_TRUE(runner.waitForIdle(5000));
  ASSERT_EQ(failed.count(), 2);
  bool sawInvalid = false;
  bool sawOther = false;
  for (const auto& args : failed) {
    const auto code = args.at(1).value<delineo::core::ErrorCode>();
    const QString message = args.at(2).toString();
    // The code is not repeated in the message: the GUI says it in its own sentence.
    if (code == delineo::core::ErrorCode::InvalidParameter && message == QStringLiteral("window must be odd")) sawInvalid = true;
    if (code == delineo::core::ErrorCode::ProcessingFailed && message.contains("boom")) sawOther = true;
  }
  EXPECT_TRUE(sawInvalid);
  EXPECT_TRUE(sawOther);
}

TEST(JobRunner, ANewJobWithTheSameKeyCancelsTheOldOne) {
  JobRunner runner;
  QSignalSpy ended(&runner, &JobRunner::ended);
  int first = 0;
  int second = 0;
  const JobId a = runner.run<int>(QStringLiteral("building 1"), [](Progress& p) { return spin(p, 100000); },
                                  [&](int r) { first = r; }, QStringLiteral("building"));
  const JobId other = runner.run<int>(QStringLiteral("other"), [](Progress& p) { return spin(p, 30); }, {},
                                      QStringLiteral("unrelated"));
  QThread::msleep(10);
  const JobId b = runner.run<int>(QStringLiteral("building 1 again"), [](Progress& p) { return spin(p, 20); },
                                  [&](int r) { second = r; }, QStringLiteral("building"));
  ASSERT_TRUE(runner.waitForIdle(10000));
  EXPECT_EQ(first, 0);
  EXPECT_EQ(second, 20);
  std::map<JobId, JobOutcome> outcomes;
  for (const auto& args : ended) outcomes[args.at(0).value<JobId>()] = args.at(1).value<JobOutcome>();
  EXPECT_EQ(outcomes[a], JobOutcome::Canceled);
  EXPECT_EQ(outcomes[b], JobOutcome::Finished);
  EXPECT_EQ(outcomes[other], JobOutcome::Finished);
}

TEST(JobRunner, DestructorCancelsAndWaits) {
  std::atomic<bool> sawCancel{false};
  QElapsedTimer timer;
  {
    JobRunner runner;
    runner.run<int>(QStringLiteral("long"), [&](Progress& p) {
      const int r = spin(p, 100000);
      sawCancel = r < 0;
      return r;
    });
    QThread::msleep(20);
    timer.start();
  }
  EXPECT_TRUE(sawCancel.load());  // the worker returned before the destructor did
  EXPECT_LT(timer.elapsed(), 2000);
}

TEST(JobRunner, ProgressWidgetWordsTheAlgorithmsStage) {
  JobRunner runner;
  JobProgressWidget widget(&runner);
  const JobId id = runner.run<int>(QStringLiteral("Disparity"), [](Progress& p) {
    p.setStage(delineo::core::StageId::MatchingLevelRightView, 2, 3);
    return spin(p, 100000);
  });
  QElapsedTimer t;
  t.start();
  while (runner.jobFraction(id) <= 0.0 && t.elapsed() < 3000) QCoreApplication::processEvents(QEventLoop::AllEvents, 20);
  auto* label = widget.findChild<QLabel*>();
  ASSERT_NE(label, nullptr);
  // The widget words the identifier itself (through tr(), here without a translator).
  EXPECT_EQ(label->text(), QStringLiteral("Disparity: matching level 2/3, right view"));
  EXPECT_EQ(stageText(delineo::core::Stage::of(delineo::core::StageId::DelineatingBuilding, 7)),
            QStringLiteral("delineating building 7"));
  runner.cancel(id);
  ASSERT_TRUE(runner.waitForIdle(5000));
}

TEST(JobRunner, ProgressWidgetFollowsAndCancels) {
  JobRunner runner;
  JobProgressWidget widget(&runner);
  widget.resize(420, 32);
  QSignalSpy canceled(&runner, &JobRunner::canceled);
  const JobId id = runner.run<int>(QStringLiteral("Disparity"), [](Progress& p) {
    p.setStage("matching");
    return spin(p, 100000);
  });
  EXPECT_EQ(widget.job(), id);
  QElapsedTimer t;
  t.start();
  while (runner.jobFraction(id) <= 0.0 && t.elapsed() < 3000) QCoreApplication::processEvents(QEventLoop::AllEvents, 20);
  test::saveScreenshot(widget, QStringLiteral("job_progress"));
  auto* cancel = widget.findChild<QToolButton*>();
  ASSERT_NE(cancel, nullptr);
  EXPECT_TRUE(cancel->isEnabled());
  cancel->click();
  ASSERT_TRUE(runner.waitForIdle(5000));
  EXPECT_EQ(canceled.count(), 1);
  EXPECT_EQ(widget.job(), 0u);
  EXPECT_FALSE(cancel->isEnabled());
}
