// Georeferenced round trip on real data: the SpaceNet Atlanta image (UTM 16N, 0.5 m) and its 43
// building footprints (map coordinates) become a project's accepted buildings in the image's
// pixels, are exported as GeoJSON, GeoPackage and CityJSON the way the GUI and `delineo-cli
// export` write them, and are read back in map coordinates. Prints, per format, the buildings
// written and the largest distance between a footprint's vertex and the exported one (m); exits 1
// when a format loses a building or moves a vertex by more than its precision (CityJSON's 1 mm
// grid). Then the footprints converted by GDAL into WGS 84 (GeoJSON), Web Mercator (Shapefile)
// and UTM 16N are imported into a project on the image (project::importOutlinesFile): prints the
// buildings added and the largest distance (px) between an imported vertex and the one read in the
// image's CRS; exits 1 when a building is not added or a vertex moves by more than the file's
// precision (GeoJSON may hold 7 decimals of degrees, about 1 cm: 0.05 px here; the others 1e-6 px). Skips without the data folder.
//
// bench_georef [--data DIR]
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gdal_utils.h>
#include <nlohmann/json.hpp>

#include "delineo/io/raster.hpp"
#include "delineo/io/vector.hpp"
#include "delineo/project/pipeline.hpp"
#include "shared_data.hpp"

namespace fs = std::filesystem;
using namespace delineo;

namespace {

constexpr double kCityJsonPrecision = 0.001 * 0.75;  // m: half the 1 mm grid's diagonal, rounded up

// The largest distance from a vertex of `truth` to the nearest of `vertices` (map units).
double largestVertexError(const std::vector<core::Feature>& truth, const std::vector<cv::Point2d>& vertices) {
  double largest = 0.0;
  for (const auto& f : truth) {
    for (const auto& p : f.polygon.outer) {
      double nearest = INFINITY;
      for (const auto& v : vertices) nearest = std::min(nearest, std::hypot(v.x - p.x, v.y - p.y));
      largest = std::max(largest, nearest);
    }
  }
  return largest;
}

std::vector<cv::Point2d> outlineVertices(const std::vector<core::Feature>& features) {
  std::vector<cv::Point2d> out;
  for (const auto& f : features) out.insert(out.end(), f.polygon.outer.begin(), f.polygon.outer.end());
  return out;
}

// The x, y of every vertex of a CityJSON file ("transform" applied), and its reference system.
std::vector<cv::Point2d> cityJsonVertices(const std::string& path, std::string& referenceSystem) {
  std::ifstream in(path);
  const nlohmann::json city = nlohmann::json::parse(in);
  referenceSystem = city["metadata"].value("referenceSystem", "");
  const auto& scale = city["transform"]["scale"];
  const auto& translate = city["transform"]["translate"];
  std::vector<cv::Point2d> out;
  for (const auto& v : city["vertices"]) {
    out.emplace_back(v[0].get<double>() * scale[0].get<double>() + translate[0].get<double>(),
                     v[1].get<double>() * scale[1].get<double>() + translate[1].get<double>());
  }
  return out;
}

// The footprints as a project's accepted buildings, in the image's pixels, each 9 m high.
project::Project atlantaProject(const std::string& image, const std::vector<core::Feature>& inPixels) {
  project::Project p;
  p.name = "atlanta";
  p.left = p.right = image;
  p.height = {0.0, 1.0, 0.5};
  int id = 0;
  for (const auto& f : inPixels) {
    project::Building b;
    b.id = ++id;
    b.status = project::BuildingStatus::Accepted;
    b.initial = b.outline = f.polygon;
    b.roofHeight = 9.0;
    p.buildings.push_back(b);
  }
  return p;
}

// `source` written to `target` in `crs` by GDAL's vector translation (ogr2ogr).
void convertVector(const std::string& source, const std::string& target, const char* crs, const char* format) {
  GDALDatasetH input = GDALOpenEx(source.c_str(), GDAL_OF_VECTOR, nullptr, nullptr, nullptr);
  if (input == nullptr) throw std::runtime_error("cannot open " + source);
  const char* argv[] = {"-t_srs", crs, "-f", format, nullptr};
  GDALVectorTranslateOptions* options = GDALVectorTranslateOptionsNew(const_cast<char**>(argv), nullptr);
  GDALDatasetH output = GDALVectorTranslate(target.c_str(), nullptr, 1, &input, options, nullptr);
  GDALVectorTranslateOptionsFree(options);
  GDALClose(input);
  if (output == nullptr) throw std::runtime_error("cannot write " + target);
  GDALClose(output);
}

// The largest distance (px) from a vertex of `expected` to the nearest vertex of the same
// building's initial polygon in `imported` (same order; a footprint across the image border is
// cut there, which adds vertices); infinite when the building counts differ.
double largestImportError(const std::vector<core::Feature>& expected, const project::Project& imported) {
  if (imported.buildings.size() != expected.size()) return INFINITY;
  double largest = 0.0;
  for (size_t i = 0; i < expected.size(); ++i) {
    for (const auto& a : expected[i].polygon.outer) {
      double nearest = INFINITY;
      for (const auto& b : imported.buildings[i].initial.outer) nearest = std::min(nearest, std::hypot(a.x - b.x, a.y - b.y));
      largest = std::max(largest, nearest);
    }
  }
  return largest;
}

// The labels imported in other CRSs land where they lie in the image's: true when every one does.
bool importsInOtherCrs(const std::string& image, const std::string& labels, const std::vector<core::Feature>& inPixels,
                       const fs::path& out) {
  std::printf("\n%-28s %9s %16s\n", "import (CRS, format)", "added", "max error (px)");
  bool ok = true;
  const struct {
    const char* crs;
    const char* format;
    const char* name;
    double precision;  // px
  } conversions[] = {{"EPSG:4326", "GeoJSON", "wgs84.geojson", 0.05},
                     {"EPSG:3857", "ESRI Shapefile", "mercator.shp", 1e-6},
                     {"EPSG:32616", "GPKG", "utm.gpkg", 1e-6}};
  for (const auto& c : conversions) {
    const std::string path = (out / c.name).string();
    convertVector(labels, path, c.crs, c.format);
    project::Project p;
    p.left = p.right = image;
    const size_t added = project::importOutlinesFile(p, path, {}).added.size();
    const double error = largestImportError(inPixels, p);
    std::printf("%-12s %-15s %9zu %16.2e\n", c.crs, c.name, added, error);
    ok = ok && added == inPixels.size() && error <= c.precision;
  }
  return ok;
}

}  // namespace

int main(int argc, char** argv) {
  std::string dataRoot = bench::defaultDataRoot();
  for (int i = 1; i + 1 < argc; ++i) {
    if (std::string(argv[i]) == "--data") dataRoot = argv[++i];
  }
  const fs::path folder = fs::path(dataRoot) / "spacenet-atlanta";
  const std::string image = (folder / "sample_geotiff.tif").string();
  const std::string labels = (folder / "geotiff_labels.geojson").string();
  if (!fs::exists(image) || !fs::exists(labels)) {
    std::printf("skipped: no %s\n", folder.string().c_str());
    return 0;
  }
  const io::GeoReference geo = io::readRaster(image).geo;
  const std::vector<core::Feature> truth = io::readFeatures(labels);
  const std::vector<core::Feature> inPixels = io::readFeatures(labels, geo);
  const project::Project project = atlantaProject(image, inPixels);
  const fs::path out = fs::temp_directory_path() / "delineo_bench_georef";
  fs::create_directories(out);

  std::printf("%-10s %9s %9s %16s\n", "format", "written", "read", "max error (m)");
  bool ok = true;
  for (const char* name : {"b.geojson", "b.gpkg"}) {
    const std::string path = (out / name).string();
    const int written = project::exportBuildings(project, path).written;
    const std::vector<core::Feature> back = io::readFeatures(path);
    const double error = largestVertexError(truth, outlineVertices(back));
    std::printf("%-10s %9d %9zu %16.2e\n", fs::path(name).extension().c_str(), written, back.size(), error);
    ok = ok && written == static_cast<int>(truth.size()) && back.size() == truth.size() && error < 1e-6;
  }
  const std::string cityPath = (out / "b.city.json").string();
  const int blocks = project::exportBuildings(project, cityPath).written;
  std::string referenceSystem;
  const double error = largestVertexError(truth, cityJsonVertices(cityPath, referenceSystem));
  std::printf("%-10s %9d %9s %16.2e  %s\n", ".city.json", blocks, "-", error, referenceSystem.c_str());
  ok = ok && blocks == static_cast<int>(truth.size()) && error <= kCityJsonPrecision &&
       referenceSystem.ends_with("/EPSG/0/32616");
  const bool imports = importsInOtherCrs(image, labels, inPixels, out);
  fs::remove_all(out);
  std::printf("%s\n", ok ? "round trip: every building, every vertex within the format's precision"
                         : "round trip FAILED");
  std::printf("%s\n", imports ? "imports: every building, where it lies in the image's CRS" : "imports FAILED");
  ok = ok && imports;
  return ok ? 0 : 1;
}
