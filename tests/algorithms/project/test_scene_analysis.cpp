// The project's scene analysis step: the chain with the project's groups on a simulated scene,
// and proposals turned into pending buildings without doubling known ones.
#include <gtest/gtest.h>

#include <string>
#include <vector>

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

// A proposal's malformed roof interval is no crash and no silent loss: the building comes without
// one (the operator sets it), and its history and the caller's problems say why.
TEST(SceneAnalysisStep, AMalformedRoofIntervalIsLeftOutAndSaid) {
  project::Project p;
  core::Feature inverted = proposal(10, 10, 30, 40, 30);  // min above max
  core::Feature text = proposal(100, 100, 30, 30, 33);
  text.attributes["roof_disparity_max"] = std::string("high");
  core::Feature plain = proposal(200, 200, 30, 30, 33);
  plain.attributes.erase("roof_disparity_min");  // none given: nothing to say
  std::vector<std::string> problems;
  const std::vector<int> added = project::addProposedBuildings(p, {inverted, text, plain}, "test", &problems);
  ASSERT_EQ(added.size(), 3u);
  for (int id : added) EXPECT_FALSE(p.find(id)->roofInterval.has_value()) << id;
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0].rfind("building " + std::to_string(added[0]) + ": roof interval not read: ", 0), 0u)
      << problems[0];
  EXPECT_NE(problems[0].find("roof_disparity_min is above roof_disparity_max"), std::string::npos) << problems[0];
  EXPECT_NE(problems[1].find("roof_disparity_max"), std::string::npos) << problems[1];
  EXPECT_NE(p.find(added[0])->history.back().detail.find("roof interval not read"), std::string::npos);
  EXPECT_EQ(p.find(added[2])->history.back().detail, "test: building proposal");
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
