// Project processing steps: the active polygon's live contour, roof heights, output folders.
#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

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
  core::Polygon truth;  // the building's true footprint
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
  s.truth = far->polygon;
  return s;
}

double iou(const core::Polygon& a, const core::Polygon& b, cv::Size size) {
  const cv::Mat ma = core::rasterize(a, size), mb = core::rasterize(b, size);
  const double inter = cv::countNonZero(ma & mb), uni = cv::countNonZero(ma | mb);
  return uni > 0 ? inter / uni : 0.0;
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

TEST(Pipeline, HeightsComeFromTheDemFileOrTheDisparityThroughTheHeightModel) {
  project::Project p;
  cv::Mat disparity(4, 5, CV_32F, cv::Scalar(12.0f));
  disparity.at<float>(1, 1) = std::nanf("");
  EXPECT_TRUE(project::projectHeights(p, disparity).empty());  // no height model
  p.height = {8.0, 0.5, 0.25};
  const cv::Mat heights = project::projectHeights(p, disparity);
  ASSERT_EQ(heights.size(), disparity.size());
  EXPECT_FLOAT_EQ(heights.at<float>(0, 0), 2.0f);
  EXPECT_TRUE(std::isnan(heights.at<float>(1, 1)));
  EXPECT_TRUE(project::projectHeights(p, cv::Mat()).empty());
}

TEST(Pipeline, BoxFittingOutlinesTheBuildingAndRecordsItsMethod) {
  SceneProject s = makeSceneProject();
  s.project.height = {s.scene.groundDisparity, s.scene.metresPerDisparity, 0.25};
  const cv::Mat heights = project::projectHeights(s.project, s.scene.disparity);
  const auto outcome = project::fitBuildingBoxes(s.project, s.building, heights, s.pair.left, nullptr);
  ASSERT_EQ(outcome.status, core::RunStatus::Completed);
  ASSERT_TRUE(outcome.hasOutline()) << outcome.message;
  EXPECT_FALSE(outcome.boxes.empty());
  for (const auto& box : outcome.boxes) EXPECT_EQ(box.corners.size(), 4u);
  EXPECT_TRUE(std::isfinite(outcome.energy));
  const double overlap = iou(outcome.outline, s.truth, s.pair.left.size());
  EXPECT_GT(overlap, 0.8);
  const project::Building after =
      project::withBoxFitOutline(s.project, s.building, outcome, s.scene.disparity, "test");
  EXPECT_EQ(after.method, project::kBoxFitting);
  EXPECT_EQ(after.status, project::BuildingStatus::Automatic);
  EXPECT_TRUE(after.outline.outer == outcome.outline.outer);
  EXPECT_TRUE(std::isnan(after.energy));  // F(C) is the active polygon's energy: unknown here
  EXPECT_GT(after.roofHeight, 2.0);
  ASSERT_FALSE(after.history.empty());
  EXPECT_EQ(after.history.back().action, "delineated");
  EXPECT_EQ(after.history.back().detail.rfind("test, box-fitting, ", 0), 0u) << after.history.back().detail;
  // The project's "boxfit" parameters are used: a minimum height above every roof finds nothing.
  s.project.parameters["boxfit"] = nlohmann::json{{"min-height", 200.0}};
  const auto none = project::fitBuildingBoxes(s.project, s.building, heights, s.pair.left, nullptr);
  EXPECT_FALSE(none.hasOutline());
  EXPECT_FALSE(none.message.empty());
  // Without heights box-fitting is refused with a reason.
  EXPECT_THROW(project::fitBuildingBoxes(s.project, s.building, cv::Mat(), s.pair.left, nullptr), core::Error);
}

TEST(Pipeline, EnhancedHeightsFollowTheOutlinesAndLeaveTheGroundAlone) {
  SceneProject s = makeSceneProject();
  s.project.height = {s.scene.groundDisparity, s.scene.metresPerDisparity, 0.25};
  const cv::Mat heights = project::projectHeights(s.project, s.scene.disparity);
  // Without an outline nothing changes.
  s.project.buildings.push_back(s.building);  // pending: no outline yet
  const auto plain = project::enhanceHeights(s.project, heights, nullptr);
  EXPECT_EQ(plain.footprints, 0);
  EXPECT_EQ(plain.dem.data, heights.data);
  // With the true outline the heights change near it, and not far from it.
  s.project.buildings.back().outline = s.truth;
  s.project.buildings.back().status = project::BuildingStatus::Automatic;
  const auto enhanced = project::enhanceHeights(s.project, heights, nullptr);
  ASSERT_EQ(enhanced.status, core::RunStatus::Completed);
  EXPECT_EQ(enhanced.footprints, 1);
  ASSERT_EQ(enhanced.dem.size(), heights.size());
  cv::Mat near = core::rasterize(s.truth, heights.size());
  cv::dilate(near, near, cv::getStructuringElement(cv::MORPH_RECT, {31, 31}));
  cv::Mat changed = (enhanced.dem != heights) & (heights == heights);
  EXPECT_GT(cv::countNonZero(changed & near), 0);
  EXPECT_EQ(cv::countNonZero(changed & ~near), 0);
  // A rejected building's outline is no footprint.
  s.project.buildings.back().status = project::BuildingStatus::Rejected;
  EXPECT_EQ(project::enhanceHeights(s.project, heights, nullptr).footprints, 0);
}

TEST(Pipeline, APendingBuildingIsOutlinedWithItsMethod) {
  SceneProject s = makeSceneProject();
  s.project.height = {s.scene.groundDisparity, s.scene.metresPerDisparity, 0.25};
  s.pair.disparity = s.scene.disparity;
  cv::Mat heights;
  const auto polygon = project::outlinePendingBuilding(s.project, s.building, s.pair, heights, nullptr, "test");
  ASSERT_TRUE(polygon.has_value());
  EXPECT_EQ(polygon->status, project::BuildingStatus::Automatic);
  EXPECT_EQ(polygon->method, project::kActivePolygon);
  EXPECT_TRUE(std::isfinite(polygon->energy));
  EXPECT_GT(polygon->roofHeight, 2.0);
  EXPECT_GT(iou(polygon->outline, s.truth, s.pair.left.size()), 0.85);
  EXPECT_EQ(polygon->history.back().detail.rfind("test, ", 0), 0u) << polygon->history.back().detail;
  EXPECT_TRUE(heights.empty()) << "the active polygon reads no heights";
  // Without a roof interval the disparity map gives one.
  project::Building open = s.building;
  open.roofInterval.reset();
  const auto suggested = project::outlinePendingBuilding(s.project, open, s.pair, heights, nullptr, "test");
  ASSERT_TRUE(suggested.has_value());
  EXPECT_TRUE(suggested->roofInterval.has_value());
  EXPECT_GT(iou(suggested->outline, s.truth, s.pair.left.size()), 0.85);
  // A canceled progress outlines nothing.
  core::Progress canceled;
  canceled.cancel();
  EXPECT_FALSE(project::outlinePendingBuilding(s.project, s.building, s.pair, heights, &canceled, "test"));

  // Box-fitting reads the heights.
  s.building.method = project::kBoxFitting;
  const auto boxes = project::outlinePendingBuilding(s.project, s.building, s.pair, heights, nullptr, "test");
  ASSERT_TRUE(boxes.has_value());
  EXPECT_EQ(boxes->method, project::kBoxFitting);
  EXPECT_FALSE(heights.empty()) << "the heights are read once and handed back for the next building";
  EXPECT_GT(iou(boxes->outline, s.truth, s.pair.left.size()), 0.8);
  // Without a height model there are no heights: box-fitting is refused with a reason.
  cv::Mat none;
  s.project.height = {};
  EXPECT_THROW(project::outlinePendingBuilding(s.project, s.building, s.pair, none, nullptr, "test"), core::Error);
}

TEST(Pipeline, APendingPolygonOnTheGroundIsNotOutlinedWithoutARoofInterval) {
  SceneProject s = makeSceneProject();
  s.pair.disparity = s.scene.disparity;
  // A 24 x 24 square on the ground: its centre 20 px from anything else and 40 px from the border.
  cv::Mat ground = s.scene.labels == sim::kLabelGround;
  cv::erode(ground, ground, cv::Mat(), cv::Point(-1, -1), 20);
  cv::Point at(-1, -1);
  for (int y = 40; y < ground.rows - 40 && at.x < 0; y += 4) {
    for (int x = 40; x < ground.cols - 40; x += 4) {
      if (ground.at<uchar>(y, x) != 0) {
        at = {x, y};
        break;
      }
    }
  }
  ASSERT_GE(at.x, 0) << "the scene has no open ground";
  project::Building onGround;
  onGround.id = 2;
  onGround.initial.outer = {{at.x - 12.0, at.y - 12.0}, {at.x + 12.0, at.y - 12.0}, {at.x + 12.0, at.y + 12.0},
                            {at.x - 12.0, at.y + 12.0}};
  cv::Mat heights;
  try {
    project::outlinePendingBuilding(s.project, onGround, s.pair, heights, nullptr, "test");
    FAIL() << "a polygon on the ground must not be outlined as a building";
  } catch (const core::Error& e) {
    EXPECT_EQ(e.code(), core::ErrorCode::ProcessingFailed);
    EXPECT_NE(e.detail().find("nothing stands above the ground"), std::string::npos) << e.detail();
  }
  // The operator's own interval is taken as it is.
  onGround.roofInterval = project::DisparityInterval{s.scene.disparityMin, s.scene.disparityMin + 4};
  EXPECT_TRUE(project::outlinePendingBuilding(s.project, onGround, s.pair, heights, nullptr, "test").has_value());
}
