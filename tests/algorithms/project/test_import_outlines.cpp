// Outlines of another source imported as pending buildings (project::importOutlines).
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "delineo/core/error.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/io/vector.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/project/project.hpp"
#include "temp_dir.hpp"

using namespace delineo;

namespace {
const cv::Size kImage(200, 100);

core::Feature square(double x, double y, double side) {
  core::Feature f;
  f.polygon.outer = {{x, y}, {x + side, y}, {x + side, y + side}, {x, y + side}};
  return f;
}

core::Feature withAttribute(core::Feature f, const std::string& name, core::AttributeValue value) {
  f.attributes[name] = std::move(value);
  return f;
}
}  // namespace

TEST(ImportOutlines, InsideOutlinesBecomePendingBuildingsWithTheirSourceId) {
  project::Project p;
  const auto a = withAttribute(square(10, 10, 30), "osm_id", 4711LL);
  const auto b = withAttribute(square(60, 10, 30), "osm_id", std::string("w12"));
  project::ImportOptions options{"osm_id", "map.geojson", "test"};
  const project::ImportSummary summary = project::importOutlines(p, {a, b}, kImage, options);
  ASSERT_EQ(summary.added, (std::vector<int>{1, 2}));
  EXPECT_EQ(summary.read, 2);
  EXPECT_EQ(summary.clipped + summary.alreadyThere + summary.outsideImage, 0);
  const project::Building& first = p.buildings.front();
  EXPECT_EQ(first.status, project::BuildingStatus::Pending);
  EXPECT_EQ(first.initial.outer, a.polygon.outer);
  EXPECT_FALSE(first.roofInterval.has_value());
  EXPECT_EQ(first.sourceId, "4711");
  EXPECT_EQ(p.buildings.back().sourceId, "w12");
  ASSERT_EQ(first.history.size(), 1u);
  EXPECT_EQ(first.history.front().action, "imported");
  EXPECT_EQ(first.history.front().detail, "test: polygon 1 of map.geojson, osm_id 4711");
}

TEST(ImportOutlines, ImportingTheSameFileTwiceAddsNothingTheSecondTime) {
  project::Project p;
  const std::vector<core::Feature> features = {square(10, 10, 30), square(60, 10, 30)};
  EXPECT_EQ(project::importOutlines(p, features, kImage, {}).added.size(), 2u);
  const project::ImportSummary again = project::importOutlines(p, features, kImage, {});
  EXPECT_TRUE(again.added.empty());
  EXPECT_EQ(again.alreadyThere, 2);
  EXPECT_EQ(p.buildings.size(), 2u);
}

TEST(ImportOutlines, AnOutlineAcrossTheBorderIsCutThereAndOneOutsideIsLeftOut) {
  project::Project p;
  const auto across = square(180, 40, 40);   // half of it right of the image
  const auto outside = square(300, 10, 30);  // wholly outside
  const auto sliver = square(199, 10, 10);   // 1 x 10 px on the image: too little
  const project::ImportSummary summary = project::importOutlines(p, {across, outside, sliver}, kImage, {});
  ASSERT_EQ(summary.added.size(), 1u);
  EXPECT_EQ(summary.clipped, 1);
  EXPECT_EQ(summary.outsideImage, 2);
  const core::Polygon& kept = p.buildings.front().initial;
  EXPECT_NEAR(core::area(kept), 20.0 * 40.0, 1e-6);
  EXPECT_LE(core::boundingBox(kept.outer).br().x, 200.0);
  EXPECT_NE(p.buildings.front().history.front().detail.find("cut at the image border"), std::string::npos);
}

TEST(ImportOutlines, DetectProposalsKeepTheirRoofInterval) {
  project::Project p;
  auto f = withAttribute(square(10, 10, 30), "roof_disparity_min", 40LL);
  f.attributes["roof_disparity_max"] = 44LL;
  project::importOutlines(p, {f}, kImage, {});
  ASSERT_TRUE(p.buildings.front().roofInterval.has_value());
  EXPECT_EQ(*p.buildings.front().roofInterval, (project::DisparityInterval{40, 44}));
}

TEST(ImportOutlines, AnIdFieldNoOutlineHasIsRefusedAndOneSomeLackIsSaid) {
  project::Project p;
  const auto a = withAttribute(square(10, 10, 30), "ref", 1LL);
  const auto b = withAttribute(square(60, 10, 30), "name", std::string("x"));
  project::ImportOptions wrong;
  wrong.idField = "osm_id";
  try {
    project::importOutlines(p, {a, b}, kImage, wrong);
    FAIL() << "an id field no outline has must be refused";
  } catch (const core::Error& e) {
    EXPECT_EQ(e.code(), core::ErrorCode::InvalidParameter);
    EXPECT_NE(e.detail().find("they have: ref"), std::string::npos) << e.detail();
  }
  EXPECT_TRUE(p.buildings.empty());
  project::ImportOptions ref;
  ref.idField = "ref";
  const project::ImportSummary summary = project::importOutlines(p, {a, b}, kImage, ref);
  EXPECT_EQ(summary.added.size(), 2u);
  ASSERT_EQ(summary.problems.size(), 1u);
  EXPECT_EQ(summary.problems.front(), "polygon 2: no ref");
}

TEST(ImportOutlines, TheSourceIdIsSavedAndExported) {
  project::testing::TempDir dir;
  project::Project p;
  p.name = "import";
  p.left = dir.file("l.tif");
  p.right = dir.file("r.tif");
  project::importOutlines(p, {withAttribute(square(10, 10, 30), "ref", std::string("B-7"))}, kImage,
                          {"ref", "", ""});
  p.buildings.front().outline = p.buildings.front().initial;
  p.buildings.front().status = project::BuildingStatus::Accepted;
  project::saveProject(p, dir.file("p.delineo.json"));
  const project::Project back = project::loadProject(dir.file("p.delineo.json"));
  EXPECT_EQ(back.buildings.front().sourceId, "B-7");
  const auto features = project::buildingFeatures(back, {project::BuildingStatus::Accepted});
  ASSERT_EQ(features.size(), 1u);
  EXPECT_EQ(std::get<std::string>(features.front().attributes.at("source_id")), "B-7");
}

TEST(ImportOutlines, AFileInMapCoordinatesLandsOnTheGeoreferencedImage) {
  project::testing::TempDir dir;
  io::GeoReference geo;
  geo.geoTransform = {500000.0, 0.5, 0.0, 4000000.0, 0.0, -0.5};  // 0.5 m pixels, north up
  geo.hasTransform = true;
  io::writeGeoTiff(dir.file("left.tif"), cv::Mat(kImage, CV_8UC1, cv::Scalar(100)), geo);
  core::Feature map;
  map.polygon.outer = {{500005.0, 3999995.0}, {500020.0, 3999995.0}, {500020.0, 3999980.0}, {500005.0, 3999980.0}};
  io::writeFeatures(dir.file("map.geojson"), {map});  // map coordinates as they are
  project::Project p;
  p.left = dir.file("left.tif");
  const project::ImportSummary summary = project::importOutlinesFile(p, dir.file("map.geojson"), {});
  ASSERT_EQ(summary.added.size(), 1u);
  const core::Ring expected = {{10, 10}, {40, 10}, {40, 40}, {10, 40}};
  const core::Ring& ring = p.buildings.front().initial.outer;
  ASSERT_EQ(ring.size(), expected.size());
  for (size_t i = 0; i < ring.size(); ++i) {
    EXPECT_NEAR(ring[i].x, expected[i].x, 1e-9);
    EXPECT_NEAR(ring[i].y, expected[i].y, 1e-9);
  }
  EXPECT_NE(p.buildings.front().history.front().detail.find("of map.geojson"), std::string::npos);
}
