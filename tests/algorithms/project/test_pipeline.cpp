// Project processing steps: the active polygon's live contour, roof heights, output folders.
#include <gtest/gtest.h>

#include "delineo/core/error.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/sim/scene.hpp"

using namespace delineo;

namespace {

// A small simulated scene whose first building lies well away from the image origin, so that
// ROI and image coordinates differ.
struct SceneProject {
  sim::Scene scene;
  project::Project project;
  project::StereoPair pair;
  project::Building building;
};

SceneProject makeSceneProject() {
  SceneProject s;
  sim::SceneParams params;
  params.seed = 11;
  params.width = 320;
  params.height = 240;
  params.buildings = 3;
  params.trees = 0;
  s.scene = sim::simulateScene(params);
  s.pair.left = s.scene.left.clone();
  s.pair.right = s.scene.right.clone();
  s.pair.left.convertTo(s.pair.left, CV_32F);
  s.pair.right.convertTo(s.pair.right, CV_32F);
  s.project.disparityRange = project::DisparityInterval{s.scene.disparityMin, s.scene.disparityMax};
  // The building farthest from the origin.
  const core::Feature* far = nullptr;
  double best = -1;
  for (const auto& f : s.scene.footprints) {
    const cv::Rect2d box = core::boundingBox(f.polygon.outer);
    if (box.x + box.y > best) best = box.x + box.y, far = &f;
  }
  const cv::Rect2d box = core::boundingBox(far->polygon.outer);
  s.building.id = 1;
  s.building.initial.outer = {{box.x - 8, box.y - 8},
                              {box.x + box.width + 8, box.y - 8},
                              {box.x + box.width + 8, box.y + box.height + 8},
                              {box.x - 8, box.y + box.height + 8}};
  s.building.roofInterval = project::suggestRoofInterval(s.scene.disparity, far->polygon);
  return s;
}

}  // namespace

TEST(Pipeline, TheLiveContourIsInLeftImagePixelsAroundTheBuilding) {
  SceneProject s = makeSceneProject();
  ASSERT_TRUE(s.building.roofInterval.has_value());
  const cv::Rect2d init = core::boundingBox(s.building.initial.outer);
  int contours = 0;
  double worst = 0;  // largest distance of a live vertex outside the initial box grown by 30 px
  const auto outcome = project::delineateBuilding(
      s.project, s.building, s.pair, nullptr, [&](const core::Polygon& contour) {
        ++contours;
        for (const auto& v : contour.outer) {
          const double dx = std::max({init.x - 30 - v.x, v.x - (init.x + init.width + 30), 0.0});
          const double dy = std::max({init.y - 30 - v.y, v.y - (init.y + init.height + 30), 0.0});
          worst = std::max(worst, std::hypot(dx, dy));
        }
      });
  ASSERT_EQ(outcome.status, core::RunStatus::Completed);
  EXPECT_GT(contours, 0);
  EXPECT_EQ(worst, 0.0) << "a live contour vertex lies " << worst
                        << " px outside the picked region";
  const cv::Rect2d result = core::boundingBox(outcome.outline.outer);
  EXPECT_LT(std::abs(result.x - init.x), 30.0);
  EXPECT_LT(std::abs(result.y - init.y), 30.0);
}

TEST(Pipeline, MatchingWithoutADisparityRangeIsRefused) {
  SceneProject s = makeSceneProject();
  s.project.disparityRange.reset();
  try {
    (void)project::computeDisparity(s.project, s.pair.left, s.pair.right, nullptr);
    FAIL() << "matching must not guess a range silently";
  } catch (const core::Error& e) {
    EXPECT_EQ(e.code(), core::ErrorCode::InvalidParameter);
  }
}

TEST(Pipeline, AnEditedOutlineIsScoredLikeTheActivePolygonScoresItsOwn) {
  SceneProject s = makeSceneProject();
  const auto outcome = project::delineateBuilding(s.project, s.building, s.pair, nullptr);
  ASSERT_EQ(outcome.status, core::RunStatus::Completed);
  double sum = 0;
  for (double t : outcome.terms) sum += t;
  EXPECT_NEAR(sum, outcome.energy, 1e-6 * std::abs(outcome.energy) + 1e-6);
  const auto same = project::outlineEnergy(s.project, s.building, s.pair, outcome.outline, nullptr);
  EXPECT_NEAR(same.energy, outcome.energy, 1e-6 * std::abs(outcome.energy) + 1e-6);
  // The outline moved 6 px off the roof explains the images worse.
  core::Polygon shifted = outcome.outline;
  for (auto& v : shifted.outer) v += cv::Point2d(6, 4);
  const auto worse = project::outlineEnergy(s.project, s.building, s.pair, shifted, nullptr);
  EXPECT_GT(worse.energy, outcome.energy + 0.01 * std::abs(outcome.energy));
}

TEST(Pipeline, RegularizingTheRawOutlineGivesWhatTheDelineationGave) {
  SceneProject s = makeSceneProject();
  const auto outcome = project::delineateBuilding(s.project, s.building, s.pair, nullptr);
  ASSERT_EQ(outcome.status, core::RunStatus::Completed);
  ASSERT_FALSE(outcome.rawOutline.outer.empty());
  const auto again =
      project::regularizeOutline(s.project, s.building, s.pair, outcome.rawOutline, nullptr);
  EXPECT_EQ(again.regularization, outcome.regularization);
  EXPECT_EQ(again.outline.outer, outcome.outline.outer);
  size_t rawVertices = outcome.rawOutline.outer.size();
  for (const auto& hole : outcome.rawOutline.holes) rawVertices += hole.size();
  EXPECT_EQ(again.verticesBefore, static_cast<int>(rawVertices));
  // With regularization off the outline comes back as it is.
  s.project.parameters["delineation"] = nlohmann::json{{"regularize", "none"}};
  const auto off =
      project::regularizeOutline(s.project, s.building, s.pair, outcome.rawOutline, nullptr);
  EXPECT_EQ(off.regularization, "off");
  EXPECT_EQ(off.outline.outer, outcome.rawOutline.outer);
}

TEST(Pipeline, TheProjectsRangeIsTheRangeTheMatcherSearches) {
  SceneProject s = makeSceneProject();
  // Share of the roof pixels (true disparity above 16 px) matched within 1 px of the truth.
  const auto roofsFound = [&](const cv::Mat& d) {
    int roof = 0, right = 0;
    for (int y = 0; y < d.rows; ++y) {
      for (int x = 0; x < d.cols; ++x) {
        const float truth = s.scene.disparity.at<float>(y, x);
        if (!(truth > 16.0f)) continue;
        ++roof;
        right += std::abs(d.at<float>(y, x) - truth) <= 1.0f;
      }
    }
    return roof > 0 ? static_cast<double>(right) / roof : 0.0;
  };
  s.project.disparityRange = project::DisparityInterval{s.scene.disparityMin, 12};
  const double narrow = roofsFound(project::computeDisparity(s.project, s.pair.left, s.pair.right, nullptr).disparity);
  s.project.disparityRange = project::DisparityInterval{s.scene.disparityMin, s.scene.disparityMax};
  const double full = roofsFound(project::computeDisparity(s.project, s.pair.left, s.pair.right, nullptr).disparity);
  EXPECT_LT(narrow, 0.05);
  EXPECT_GT(full, 0.6);
}
