// The project's scene analysis step: the chain with the project's groups on a simulated scene,
// and proposals turned into pending buildings without doubling known ones.
#include <gtest/gtest.h>

#include "delineo/core/error.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/sim/scene.hpp"

using namespace delineo;

namespace {

core::Feature proposal(double x, double y, double side, long long roofLow, long long roofHigh) {
  core::Feature f;
  f.polygon.outer = {{x, y}, {x + side, y}, {x + side, y + side}, {x, y + side}};
  f.attributes["id"] = 1LL;
  f.attributes["roof_disparity_min"] = roofLow;
  f.attributes["roof_disparity_max"] = roofHigh;
  return f;
}

}  // namespace

TEST(SceneAnalysisStep, ProposalsBecomePendingBuildingsOnce) {
  project::Project p;
  project::Building known;
  known.id = 1;
  known.initial.outer = {{10, 10}, {50, 10}, {50, 50}, {10, 50}};
  p.buildings.push_back(known);
  const std::vector<core::Feature> proposals{proposal(12, 12, 36, 20, 24),   // the known building
                                             proposal(100, 100, 30, 30, 33)};  // a new one
  const std::vector<int> added = project::addProposedBuildings(p, proposals, "test");
  ASSERT_EQ(added.size(), 1u);
  const project::Building* b = p.find(added[0]);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(b->status, project::BuildingStatus::Pending);
  ASSERT_TRUE(b->roofInterval.has_value());
  EXPECT_EQ(b->roofInterval->low, 30);
  EXPECT_EQ(b->roofInterval->high, 33);
  ASSERT_FALSE(b->history.empty());
  EXPECT_EQ(b->history.back().action, "detected");
  // Asked again, nothing is added.
  EXPECT_TRUE(project::addProposedBuildings(p, proposals).empty());
  EXPECT_EQ(p.buildings.size(), 2u);
}

TEST(SceneAnalysisStep, TheChainRunsWithTheProjectsParametersAndGsd) {
  sim::SceneParams sp;
  sp.width = 320;
  sp.height = 240;
  sp.buildings = 3;
  sp.trees = 2;
  sp.slope = 10.0;
  sp.seed = 4;
  const sim::Scene scene = sim::simulateScene(sp);
  project::Project p;
  p.height.gsd = scene.gsd;
  const project::SceneAnalysisOutcome a = project::analyseScene(p, scene.dem, scene.left, scene.disparity, nullptr);
  ASSERT_EQ(a.status, core::RunStatus::Completed);
  EXPECT_EQ(a.classes.size(), scene.dem.size());
  EXPECT_GT(cv::countNonZero(a.classes == 1), 0);
  EXPECT_EQ(a.proposals.size(), scene.footprints.size());
  // A project parameter reaches the chain: a minimum building area over the whole image
  // leaves no proposal.
  p.parameters[project::kDetectGroup] = {{"min-building-area", 1e6}};
  EXPECT_TRUE(project::analyseScene(p, scene.dem, scene.left, scene.disparity, nullptr).proposals.empty());
  // No heights, or no gsd: clear errors.
  EXPECT_THROW(project::analyseScene(p, cv::Mat(), scene.left, scene.disparity, nullptr), core::Error);
  p.height.gsd = 0.0;
  EXPECT_THROW(project::analyseScene(p, scene.dem, scene.left, scene.disparity, nullptr), core::Error);
}
