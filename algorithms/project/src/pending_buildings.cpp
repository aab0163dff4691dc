// Buildings that come from elsewhere than the operator's pick: the scene analysis's proposals and
// outlines imported from a vector layer (a cadastre, OpenStreetMap, another project's export).
// Both become Pending buildings that the active polygon or box-fitting then outlines.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "delineo/core/error.hpp"
#include "delineo/delineation/feature_request.hpp"
#include "delineo/io/polygon_sets.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/io/vector.hpp"
#include "delineo/project/pipeline.hpp"
#include "history_detail.hpp"

namespace delineo::project {

using detail::withOrigin;

using core::Error;
using core::ErrorCode;

namespace {
core::Polygon shifted(core::Polygon polygon, cv::Point2d by) {
  for (auto& p : polygon.outer) p += by;
  for (auto& hole : polygon.holes) {
    for (auto& p : hole) p += by;
  }
  return polygon;
}

// Share of `polygon`'s pixels that lie inside `other`, both rasterized on their common box.
double coveredShare(const core::Polygon& polygon, const core::Polygon& other) {
  if (polygon.outer.size() < 3 || other.outer.size() < 3) return 0.0;
  const cv::Rect2d a = core::boundingBox(polygon.outer), b = core::boundingBox(other.outer);
  if ((a & b).area() <= 0.0) return 0.0;
  const cv::Rect box = cv::Rect(a | b) + cv::Size(2, 2);
  const cv::Point2d by(-box.x, -box.y);
  const cv::Mat ma = core::rasterize(shifted(polygon, by), box.size());
  const cv::Mat mb = core::rasterize(shifted(other, by), box.size());
  const int inside = cv::countNonZero(ma);
  return inside > 0 ? static_cast<double>(cv::countNonZero(ma & mb)) / inside : 0.0;
}

// A building the operator already has (any status) covers, or is covered by, the polygon.
bool isAlreadyABuilding(const Project& project, const core::Polygon& polygon) {
  return std::any_of(project.buildings.begin(), project.buildings.end(), [&](const Building& b) {
    return coveredShare(polygon, b.currentPolygon()) > kProposalOverlap ||
           coveredShare(b.currentPolygon(), polygon) > kProposalOverlap;
  });
}

// The feature's roof interval (detect's roof_disparity_min/max), read as every feature's is;
// none when it carries none. A malformed one is left out too, with the reason in `problem`: the
// operator then sets the interval, as for a drawn building.
std::optional<DisparityInterval> roofInterval(const core::Feature& feature, std::string& problem) {
  try {
    const auto roof = delineation::readFeatureIntervals(feature).roof;
    if (!roof) return std::nullopt;
    return DisparityInterval{roof->min, roof->max};
  } catch (const core::Error& e) {
    problem = "roof interval not read: " + e.detail();
    return std::nullopt;
  }
}

// A new Pending building on `polygon` with the feature's roof interval; a malformed interval is
// said in `problem`.
Building pendingBuilding(const Project& project, const core::Feature& feature, core::Polygon polygon,
                         std::string& problem) {
  Building b;
  b.id = project.nextBuildingId();
  b.initial = std::move(polygon);
  b.roofInterval = roofInterval(feature, problem);
  return b;
}

}  // namespace

std::vector<int> addProposedBuildings(Project& project, const std::vector<core::Feature>& proposals,
                                      const std::string& origin, std::vector<std::string>* problems) {
  std::vector<int> added;
  for (const core::Feature& proposal : proposals) {
    if (proposal.polygon.outer.size() < 3) continue;
    if (isAlreadyABuilding(project, proposal.polygon)) continue;
    std::string problem;
    Building b = pendingBuilding(project, proposal, proposal.polygon, problem);
    std::string detail = withOrigin(origin, "building proposal");
    if (!problem.empty()) {
      detail += ", " + problem;
      if (problems != nullptr) problems->push_back("building " + std::to_string(b.id) + ": " + problem);
    }
    b.addHistory("detected", detail);
    project.buildings.push_back(std::move(b));
    added.push_back(project.buildings.back().id);
  }
  return added;
}

// ---- imported outlines ----

namespace {
// The attribute as text (an id: integers as written, reals without trailing zeros); nullopt when
// absent or null.
std::optional<std::string> attributeText(const core::Feature& feature, const std::string& name) {
  const auto it = feature.attributes.find(name);
  if (it == feature.attributes.end()) return std::nullopt;
  if (const auto* text = std::get_if<std::string>(&it->second)) return *text;
  if (const auto* whole = std::get_if<long long>(&it->second)) return std::to_string(*whole);
  if (const auto* real = std::get_if<double>(&it->second)) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.15g", *real);
    return std::string(buffer);
  }
  return std::nullopt;  // null
}

// An imported polygon placed on the left image (`imageSize`): as it is when inside, else its
// largest part on the image (`clipped`); an empty polygon when less than kMinImportedArea is left.
struct ImportedPolygon {
  core::Polygon polygon;
  bool clipped = false;
};

ImportedPolygon placeOnImage(const core::Polygon& polygon, cv::Size imageSize) {
  ImportedPolygon placed;
  const core::Ring frame = {{0.0, 0.0},
                            {static_cast<double>(imageSize.width), 0.0},
                            {static_cast<double>(imageSize.width), static_cast<double>(imageSize.height)},
                            {0.0, static_cast<double>(imageSize.height)}};
  const cv::Rect2d box = core::boundingBox(polygon.outer);
  if (box.x >= 0.0 && box.y >= 0.0 && box.br().x <= imageSize.width && box.br().y <= imageSize.height) {
    placed.polygon = polygon;
  } else {
    // Partly outside: the largest part on the image (a border can cut a building in two).
    const io::PolygonSet parts = io::intersectionOf({polygon}, {core::Polygon{frame, {}}});
    const auto largest = std::max_element(parts.begin(), parts.end(), [](const auto& a, const auto& b) {
      return core::area(a) < core::area(b);
    });
    if (largest == parts.end()) return placed;
    placed.polygon = *largest;
    placed.clipped = true;
  }
  if (core::area(placed.polygon) < kMinImportedArea) placed.polygon = {};
  return placed;
}

}  // namespace

ImportSummary importOutlines(Project& project, const std::vector<core::Feature>& features, cv::Size imageSize,
                             const ImportOptions& options) {
  if (!options.idField.empty() && !features.empty() &&
      std::none_of(features.begin(), features.end(),
                   [&](const core::Feature& f) { return f.attributes.count(options.idField) > 0; })) {
    std::string names;
    for (const auto& [name, value] : features.front().attributes) names += (names.empty() ? "" : ", ") + name;
    throw Error(ErrorCode::InvalidParameter, "no outline has the attribute \"" + options.idField + "\" (" +
                                                 (names.empty() ? "they have none" : "they have: " + names) + ")");
  }
  ImportSummary summary;
  summary.read = static_cast<int>(features.size());
  for (size_t i = 0; i < features.size(); ++i) {
    const std::string name = "polygon " + std::to_string(i + 1);
    const ImportedPolygon placed = placeOnImage(features[i].polygon, imageSize);
    if (placed.polygon.outer.size() < 3) {
      ++summary.outsideImage;
      continue;
    }
    if (isAlreadyABuilding(project, placed.polygon)) {
      ++summary.alreadyThere;
      continue;
    }
    std::string problem;
    Building b = pendingBuilding(project, features[i], placed.polygon, problem);
    std::string detail = withOrigin(options.origin, name + (options.source.empty() ? "" : " of " + options.source));
    if (!options.idField.empty()) {
      if (const auto id = attributeText(features[i], options.idField)) {
        b.sourceId = *id;
        detail += ", " + options.idField + " " + *id;
      } else {
        summary.problems.push_back(name + ": no " + options.idField);
      }
    }
    if (placed.clipped) {
      ++summary.clipped;
      detail += ", cut at the image border";
    }
    if (!problem.empty()) {
      detail += ", " + problem;
      summary.problems.push_back(name + ": " + problem);
    }
    b.addHistory("imported", detail);
    project.buildings.push_back(std::move(b));
    summary.added.push_back(project.buildings.back().id);
  }
  return summary;
}

ImportSummary importOutlinesFile(Project& project, const std::string& path, ImportOptions options) {
  if (project.left.empty()) throw Error(ErrorCode::InvalidParameter, "the project has no left image");
  const io::RasterInfo left = io::readRasterInfo(project.left);
  const std::vector<core::Feature> features = io::readFeatures(path, left.geo);
  if (options.source.empty()) options.source = std::filesystem::path(path).filename().string();
  return importOutlines(project, features, left.size, options);
}

}  // namespace delineo::project
