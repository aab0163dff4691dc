// writeElevationRasters: the files of the layers there are, georeferenced, values as given; the
// empty layers left out; a cancel or a failure leaving the folder as it was; the project's own
// disparity or DEM file not replaced by itself.
#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "delineo/core/error.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/io/vector.hpp"
#include "delineo/project/pipeline.hpp"
#include "temp_dir.hpp"

namespace {
using namespace delineo;
namespace fs = std::filesystem;
using project::ElevationLayer;
using project::ElevationLayers;

using project::testing::TempDir;

io::GeoReference lambertLikeGeo() {
  io::GeoReference geo;
  geo.geoTransform = {574000.0, 0.5, 0.0, 6280000.0, 0.0, -0.5};
  geo.hasTransform = true;
  geo.crsWkt =
      "GEOGCS[\"WGS 84\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],PRIMEM[\"Greenwich\",0],"
      "UNIT[\"degree\",0.0174532925199433],AUTHORITY[\"EPSG\",\"4326\"]]";
  return geo;
}

cv::Mat floatLayer(float offset, int seed) {
  cv::Mat m(30, 40, CV_32F);
  cv::RNG rng(static_cast<uint64_t>(seed));
  rng.fill(m, cv::RNG::UNIFORM, 0.0, 20.0);
  m += offset;
  m.at<float>(3, 4) = std::nanf("");  // no data stays no data
  return m;
}

// Equal values, NaN where NaN.
bool sameValues(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return false;
  cv::Mat fa, fb;
  a.convertTo(fa, CV_32F);
  b.convertTo(fb, CV_32F);
  for (int y = 0; y < fa.rows; ++y) {
    for (int x = 0; x < fa.cols; ++x) {
      const float u = fa.at<float>(y, x), v = fb.at<float>(y, x);
      if (std::isnan(u) != std::isnan(v) || (!std::isnan(u) && u != v)) return false;
    }
  }
  return true;
}

ElevationLayers allButEnhanced() {
  ElevationLayers layers;
  layers.disparity = floatLayer(30.0f, 1);
  layers.dem = floatLayer(140.0f, 2);
  layers.dtm = floatLayer(130.0f, 3);
  layers.ndsm = floatLayer(0.0f, 4);
  layers.labels = cv::Mat(30, 40, CV_8U, cv::Scalar(0));
  layers.labels(cv::Rect(5, 5, 10, 8)).setTo(1);
  layers.labels(cv::Rect(20, 15, 6, 6)).setTo(2);
  core::Feature object;
  object.polygon.outer = {{5, 5}, {15, 5}, {15, 13}, {5, 13}};
  object.attributes["class"] = std::string("building");
  layers.objects = std::vector<core::Feature>{object};
  return layers;
}

std::string contents(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

TEST(ElevationRasters, WritesTheLayersThereAreGeoreferenced) {
  TempDir dir;
  const ElevationLayers layers = allButEnhanced();
  const io::GeoReference geo = lambertLikeGeo();
  const project::ElevationRastersWritten written = project::writeElevationRasters(dir.dir(), geo, layers);
  EXPECT_EQ(written.status, core::RunStatus::Completed);
  EXPECT_EQ(written.rasters, 5);
  EXPECT_TRUE(written.objects);
  ASSERT_EQ(written.files.size(), 6u);
  // The enhanced DEM is empty: no file, and nothing else (no temporary) left in the folder.
  EXPECT_EQ(dir.names(), (std::vector<std::string>{"dem.tif", "disparity.tif", "dtm.tif", "labels.tif", "ndsm.tif",
                                                   "objects.geojson"}));
  const std::pair<const char*, const cv::Mat*> rasters[] = {{"disparity.tif", &layers.disparity},
                                                            {"dem.tif", &layers.dem},
                                                            {"dtm.tif", &layers.dtm},
                                                            {"ndsm.tif", &layers.ndsm},
                                                            {"labels.tif", &layers.labels}};
  for (const auto& [name, expected] : rasters) {
    const io::Raster back = io::readRaster(dir.file(name), io::ReadOptions{io::PixelType::Keep});
    EXPECT_TRUE(sameValues(back.data, *expected)) << name;
    ASSERT_TRUE(back.geo.valid()) << name;
    for (size_t i = 0; i < 6; ++i) EXPECT_DOUBLE_EQ(back.geo.geoTransform[i], geo.geoTransform[i]) << name;
    EXPECT_NE(back.geo.crsWkt.find("WGS"), std::string::npos) << name;
  }
  EXPECT_EQ(io::readRaster(dir.file("labels.tif")).data.type(), CV_8U);
  // The objects in map coordinates: read back through the same georeference, the same pixels.
  const std::vector<core::Feature> objects = io::readFeatures(dir.file("objects.geojson"), geo);
  ASSERT_EQ(objects.size(), 1u);
  EXPECT_NEAR(objects[0].polygon.outer[1].x, 15.0, 1e-6);
  EXPECT_NEAR(objects[0].polygon.outer[2].y, 13.0, 1e-6);
  EXPECT_NE(contents(dir.file("objects.geojson")).find("574007.5"), std::string::npos);  // 574000 + 15 × 0.5
}

TEST(ElevationRasters, EmptyLayersAreLeftOut) {
  TempDir dir;
  ElevationLayers layers;
  layers.dem = floatLayer(100.0f, 5);
  EXPECT_EQ(layers.present(), std::vector<ElevationLayer>{ElevationLayer::Dem});
  const auto written = project::writeElevationRasters(dir.dir(), {}, layers);
  EXPECT_EQ(written.rasters, 1);
  EXPECT_FALSE(written.objects);
  EXPECT_EQ(dir.names(), std::vector<std::string>{"dem.tif"});
  EXPECT_FALSE(io::readRaster(dir.file("dem.tif")).geo.valid());  // no georeference given, none written
  // Objects are a layer even when there are none: an empty collection says "analysed, nothing found".
  ElevationLayers none;
  none.objects.emplace();
  EXPECT_TRUE(project::writeElevationRasters(dir.dir(), {}, none).objects);
  EXPECT_TRUE(io::readFeatures(dir.file("objects.geojson")).empty());
  EXPECT_TRUE(project::writeElevationRasters(dir.dir(), {}, ElevationLayers{}).files.empty());
}

TEST(ElevationRasters, CancelLeavesTheFolderAsItWas) {
  TempDir dir;
  std::ofstream(dir.file("dem.tif")) << "previous";
  for (int reports : {0, 1, 3, 6}) {  // before the first layer, between layers, after the last one
    core::Progress progress;
    if (reports == 0) progress.cancel();
    else progress.cancelAfterReports(reports);
    const auto written = project::writeElevationRasters(dir.dir(), lambertLikeGeo(), allButEnhanced(), &progress);
    EXPECT_EQ(written.status, core::RunStatus::Canceled) << reports;
    EXPECT_TRUE(written.files.empty()) << reports;
    EXPECT_EQ(dir.names(), std::vector<std::string>{"dem.tif"}) << reports;
    EXPECT_EQ(contents(dir.file("dem.tif")), "previous") << reports;
  }
}

TEST(ElevationRasters, AFailedLayerWritesNothing) {
  TempDir dir;
  std::ofstream(dir.file("dem.tif")) << "previous";
  ElevationLayers layers = allButEnhanced();
  layers.labels = cv::Mat(30, 40, CV_64F, cv::Scalar(1.0));  // a type GeoTIFF writing refuses
  EXPECT_THROW(project::writeElevationRasters(dir.dir(), lambertLikeGeo(), layers), core::Error);
  EXPECT_EQ(dir.names(), std::vector<std::string>{"dem.tif"});
  EXPECT_EQ(contents(dir.file("dem.tif")), "previous");
  // An output that is an input of the run is refused before anything is written.
  try {
    project::writeElevationRasters(dir.dir(), {}, allButEnhanced(), nullptr, {dir.file("ndsm.tif")});
    ADD_FAILURE() << "an input was about to be replaced";
  } catch (const core::Error& e) {
    EXPECT_EQ(e.code(), core::ErrorCode::UnusableOutput);
  }
  EXPECT_EQ(dir.names(), std::vector<std::string>{"dem.tif"});
}

TEST(ElevationRasters, TheProjectsOwnDisparityIsNotReplacedByItself) {
  TempDir dir;
  project::Project p;
  p.disparity = dir.file("disparity.tif");
  p.dem = dir.file("../elsewhere/dem.tif");
  ElevationLayers layers = allButEnhanced();
  EXPECT_EQ(project::leaveOutProjectSources(p, dir.dir(), layers), std::vector<std::string>{"disparity.tif"});
  EXPECT_TRUE(layers.disparity.empty());
  EXPECT_FALSE(layers.dem.empty());
  const auto files = project::elevationFiles(dir.dir(), layers.present());
  ASSERT_EQ(files.size(), 5u);
  EXPECT_EQ(fs::path(files.front().path).filename(), "dem.tif");
  EXPECT_EQ(files.back().format, io::OutputFormat::Vector);
}
