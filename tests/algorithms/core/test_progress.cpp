#include <gtest/gtest.h>

#include <set>
#include <string>
#include <thread>
#include <vector>

#include "delineo/core/progress.hpp"

using delineo::core::Progress;
using delineo::core::Stage;
using delineo::core::StageId;

TEST(Progress, ReportsAreClampedAndMonotone) {
  Progress p;
  p.report(0.4);
  p.report(0.2);  // never goes backwards
  EXPECT_DOUBLE_EQ(p.fraction(), 0.4);
  p.report(7.0);
  EXPECT_DOUBLE_EQ(p.fraction(), 1.0);
}

TEST(Progress, RangeMapsIntoParent) {
  Progress root;
  Progress::Range second(&root, 0.5, 0.75);
  second.report(0.5);
  EXPECT_DOUBLE_EQ(root.fraction(), 0.625);
  Progress::Range nested(&second, 0.0, 0.5);
  nested.report(1.0);
  EXPECT_DOUBLE_EQ(second.fraction(), 0.5);
  EXPECT_DOUBLE_EQ(root.fraction(), 0.625);
}

TEST(Progress, CancelPropagatesBothWays) {
  Progress root;
  Progress::Range sub(&root, 0.0, 1.0);
  EXPECT_FALSE(sub.canceled());
  root.cancel();
  EXPECT_TRUE(sub.canceled());
  Progress root2;
  Progress::Range sub2(&root2, 0.0, 1.0);
  sub2.cancel();
  EXPECT_TRUE(root2.canceled());
}

TEST(Progress, CancelAfterReportsIsDeterministic) {
  Progress p;
  p.cancelAfterReports(3);
  p.report(0.1);
  p.report(0.2);
  EXPECT_FALSE(p.canceled());
  p.report(0.3);
  EXPECT_TRUE(p.canceled());
}

TEST(Progress, ListenerSeesStage) {
  std::string seen;
  double last = -1;
  Progress p([&](double f, const std::string& stage) {
    seen = stage;
    last = f;
  });
  p.setStage("matching");
  p.report(0.5);
  EXPECT_EQ(seen, "matching");
  EXPECT_DOUBLE_EQ(last, 0.5);
}

TEST(Progress, AStageIsAnIdentifierWithItsNumbersWordedInEnglishForTheCli) {
  Progress root;
  Progress::Range half(&root, 0.0, 0.5);
  half.setStage(StageId::MatchingLevelRightView, 2, 4);
  // The range passes the identifier and its numbers on, not only the English text.
  EXPECT_EQ(root.stageInfo(), Stage::of(StageId::MatchingLevelRightView, 2, 4));
  EXPECT_EQ(root.stage(), "matching level 2/4, right view");
  half.setStage(StageId::DelineatingBuilding, 17);
  EXPECT_EQ(root.stage(), "building 17");
  root.setStage("reading");
  EXPECT_EQ(root.stageInfo().id, StageId::Text);
  EXPECT_EQ(root.stage(), "reading");
  // Every identifier has its own wording.
  std::set<std::string> words;
  for (int id = static_cast<int>(StageId::PreparingPyramids);
       id <= static_cast<int>(delineo::core::kLastEnglishStageId); ++id) {
    const std::string text = Stage::of(static_cast<StageId>(id), 1, 2).english();
    EXPECT_FALSE(text.empty()) << id;
    EXPECT_TRUE(words.insert(text).second) << text;
  }
}

TEST(Progress, ConcurrentReportsAndCancel) {
  Progress p;
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&p, t] {
      for (int i = 0; i <= 1000; ++i) p.report((i + t) / 1003.0);
    });
  }
  threads.emplace_back([&p] { p.cancel(); });
  for (auto& th : threads) th.join();
  EXPECT_TRUE(p.canceled());
  EXPECT_DOUBLE_EQ(p.fraction(), 1.0);
  EXPECT_EQ(p.reportCount(), 4 * 1001);
}

TEST(Progress, NullHelpersAreSafe) {
  EXPECT_FALSE(delineo::core::isCanceled(nullptr));
  delineo::core::report(nullptr, 0.5);  // no crash
}
