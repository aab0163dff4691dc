// The 3D view's blocks kept between refreshes (gui::BuildingBlocks): after every change they
// depend on (an outline, a roof height, the DEM, a parameter) they are those made afresh.
#include <gtest/gtest.h>

#include "building_blocks.hpp"
#include "delineo/project/roof_parts.hpp"

using namespace delineo;

namespace {

core::Polygon rectangle(double x0, double y0, double x1, double y1) { return {{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, {}}; }

// A 200 x 200 px scene at ground 0: a ring roof 18 m high around an inner roof at 15 m, and a
// flat 9 m roof beside it.
cv::Mat ringScene() {
  cv::Mat heights(200, 200, CV_32F, cv::Scalar(0.0f));
  heights(cv::Rect(20, 20, 100, 100)).setTo(18.0f);
  heights(cv::Rect(45, 45, 50, 50)).setTo(15.0f);
  heights(cv::Rect(140, 40, 40, 60)).setTo(9.0f);
  return heights;
}

project::Project ringProject() {
  project::Project p;
  p.height = {0.0, 0.25, 0.1};
  for (const auto& [id, outline, roof] : {std::tuple{1, rectangle(20, 20, 120, 120), 18.0}, std::tuple{2, rectangle(140, 40, 180, 100), 9.0}}) {
    project::Building b;
    b.id = id;
    b.status = project::BuildingStatus::Accepted;
    b.initial = outline;
    b.outline = outline;
    b.roofHeight = roof;
    p.buildings.push_back(b);
  }
  return p;
}

void expectSameBlocks(const std::vector<widgets::BuildingOutline>& a, const std::vector<widgets::BuildingOutline>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].polygon.outer, b[i].polygon.outer) << "block " << i;
    EXPECT_EQ(a[i].baseHeight, b[i].baseHeight) << "block " << i;
    EXPECT_EQ(a[i].topHeight, b[i].topHeight) << "block " << i;
  }
}

TEST(BuildingBlocks, AfterEachChangeTheKeptBlocksAreThoseMadeAfresh) {
  project::Project p = ringProject();
  cv::Mat dem = ringScene();
  gui::BuildingBlocks kept;
  // The ring roof gives two blocks (inner roof and ring), the flat roof one.
  ASSERT_EQ(kept.of(p, dem).size(), 3u);
  expectSameBlocks(kept.of(p, dem), gui::BuildingBlocks().of(p, dem));

  p.buildings[1].outline = rectangle(140, 40, 180, 110);  // an edit
  expectSameBlocks(kept.of(p, dem), gui::BuildingBlocks().of(p, dem));
  EXPECT_EQ(kept.of(p, dem).back().polygon.outer[2].y, 110.0);

  p.buildings[1].roofHeight = 9.5;  // a new roof height
  EXPECT_EQ(kept.of(p, dem).back().topHeight, 9.5);

  p.buildings[0].status = project::BuildingStatus::Rejected;  // not drawn
  EXPECT_EQ(kept.of(p, dem).size(), 1u);
  p.buildings[0].status = project::BuildingStatus::Accepted;

  segmentation::RoofLevelParams off;
  off.mode = "off";
  project::setParameters(p, project::kRoofLevelsGroup, off);  // one block per building
  EXPECT_EQ(kept.of(p, dem).size(), 2u);
  expectSameBlocks(kept.of(p, dem), gui::BuildingBlocks().of(p, dem));
  p.parameters.erase(project::kRoofLevelsGroup);

  cv::Mat raised = dem + 2.0f;  // a new DEM: every block stands 2 m higher
  const auto before = kept.of(p, dem);
  const auto after = kept.of(p, raised);
  expectSameBlocks(after, gui::BuildingBlocks().of(p, raised));
  ASSERT_EQ(after.size(), before.size());
  EXPECT_NEAR(after[0].baseHeight, before[0].baseHeight + 2.0, 1e-4);
}

}  // namespace
