#include "delineo/project/project.hpp"

#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <type_traits>
#include <unistd.h>

#include "delineo/core/error.hpp"
#include "delineo/io/output_file.hpp"
#include "delineo/project/pipeline.hpp"

namespace delineo::project {

namespace fs = std::filesystem;
using core::Error;
using core::ErrorCode;
using nlohmann::json;

std::string toString(BuildingStatus status) {
  switch (status) {
    case BuildingStatus::Pending: return "pending";
    case BuildingStatus::Automatic: return "automatic";
    case BuildingStatus::Corrected: return "corrected";
    case BuildingStatus::Accepted: return "accepted";
    case BuildingStatus::Rejected: return "rejected";
  }
  return "pending";
}

BuildingStatus statusFromString(const std::string& name) {
  for (auto s : {BuildingStatus::Pending, BuildingStatus::Automatic, BuildingStatus::Corrected,
                 BuildingStatus::Accepted, BuildingStatus::Rejected}) {
    if (toString(s) == name) return s;
  }
  throw Error(ErrorCode::UnreadableFile, "unknown building status '" + name + "'");
}

bool isOutlineMethod(const std::string& name) { return name == kActivePolygon || name == kBoxFitting; }

std::string currentUtcTime() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm utc{};
  gmtime_r(&now, &utc);
  char buffer[32];
  std::strftime(buffer, sizeof buffer, "%Y-%m-%dT%H:%M:%SZ", &utc);
  return buffer;
}

void Building::addHistory(const std::string& action, const std::string& detail) {
  history.push_back({action, currentUtcTime(), detail});
}

Building* Project::find(int id) {
  auto it = std::find_if(buildings.begin(), buildings.end(), [&](const Building& b) { return b.id == id; });
  return it == buildings.end() ? nullptr : &*it;
}

const Building* Project::find(int id) const { return const_cast<Project*>(this)->find(id); }

int Project::nextBuildingId() const {
  int next = 1;
  for (const auto& b : buildings) next = std::max(next, b.id + 1);
  return next;
}

std::vector<int> Project::pendingBuildings() const {
  std::vector<int> ids;
  for (const auto& b : buildings) {
    if (b.status == BuildingStatus::Pending) ids.push_back(b.id);
  }
  return ids;
}

const std::string& Project::methodOf(const Building& building) const {
  return building.method.empty() ? method : building.method;
}

std::vector<std::string> Project::missingFiles() const {
  std::vector<std::string> missing;
  for (const std::string* p : {&left, &right, &disparity, &dem, &labels, &exclude}) {
    std::error_code ec;
    if (!p->empty() && !fs::exists(*p, ec)) missing.push_back(*p);
  }
  return missing;
}

namespace {

bool sameNumber(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

bool samePolygon(const core::Polygon& a, const core::Polygon& b) {
  return a.outer == b.outer && a.holes == b.holes;
}

bool sameBuilding(const Building& a, const Building& b) {
  return a.id == b.id && samePolygon(a.initial, b.initial) && samePolygon(a.outline, b.outline) &&
         a.status == b.status && a.roofInterval == b.roofInterval &&
         sameNumber(a.roofHeight, b.roofHeight) && sameNumber(a.energy, b.energy) &&
         a.energyTerms == b.energyTerms && a.method == b.method && a.sourceId == b.sourceId &&
         a.history == b.history;
}

// ---- paths ---------------------------------------------------------------------------------

std::string relativeTo(const std::string& path, const std::string& baseDir) {
  if (path.empty() || baseDir.empty()) return path;
  const fs::path abs = fs::path(path).lexically_normal();
  const fs::path base = fs::path(baseDir).lexically_normal();
  const fs::path rel = abs.lexically_relative(base);
  // Only paths under the project folder become relative: "../../x" is harder to read than /x.
  if (rel.empty() || *rel.begin() == "..") return abs.generic_string();
  return rel.generic_string();
}

std::string resolveAgainst(const std::string& path, const std::string& baseDir) {
  if (path.empty()) return path;
  fs::path p(path);
  if (p.is_relative() && !baseDir.empty()) p = fs::path(baseDir) / p;
  return p.lexically_normal().string();
}

// ---- geometry ------------------------------------------------------------------------------

json ringToJson(const core::Ring& ring) {
  json out = json::array();
  for (const auto& p : ring) out.push_back({p.x, p.y});
  return out;
}

json polygonToJson(const core::Polygon& polygon) {
  json out = json::array();
  if (polygon.outer.empty()) return out;
  out.push_back(ringToJson(polygon.outer));
  for (const auto& hole : polygon.holes) out.push_back(ringToJson(hole));
  return out;
}

[[noreturn]] void badField(const std::string& field, const std::string& problem) {
  throw Error(ErrorCode::UnreadableFile, "field '" + field + "': " + problem);
}

// Bounds of the numbers a project may hold: beyond them a value is a typo or a corrupt file.
constexpr double kMaxCoordinate = 1e7;    // px
constexpr int kMaxDisparity = 100000;     // px
constexpr double kMaxMetresPerPixel = 1e4;
constexpr double kMaxElevation = 1e4;     // m, of the ground level above the vertical datum

// [low, high] integers within +-kMaxDisparity with low <= high.
DisparityInterval intervalFromJson(const json& in, const std::string& field) {
  if (!in.is_array() || in.size() != 2 || !in[0].is_number_integer() || !in[1].is_number_integer()) {
    badField(field, "must be [low, high] integers, or null");
  }
  const auto low = in[0].get<long long>(), high = in[1].get<long long>();
  if (low > high || std::abs(low) > kMaxDisparity || std::abs(high) > kMaxDisparity) {
    badField(field, "must be [low, high] with low <= high, within +-" + std::to_string(kMaxDisparity) + " px");
  }
  return {static_cast<int>(low), static_cast<int>(high)};
}

// The keys of `object` outside `known`: kept as they are and written back on save.
json unknownKeys(const json& object, std::initializer_list<const char*> known) {
  json out = json::object();
  for (auto it = object.begin(); it != object.end(); ++it) {
    if (std::none_of(known.begin(), known.end(), [&](const char* k) { return it.key() == k; })) {
      out[it.key()] = it.value();
    }
  }
  return out;
}

core::Ring ringFromJson(const json& in, const std::string& field) {
  if (!in.is_array()) badField(field, "a ring must be an array of [x, y] pairs");
  core::Ring ring;
  for (const auto& point : in) {
    if (!point.is_array() || point.size() != 2 || !point[0].is_number() || !point[1].is_number()) {
      badField(field, "a vertex must be [x, y] with two numbers");
    }
    const double x = point[0].get<double>(), y = point[1].get<double>();
    if (!(std::abs(x) <= kMaxCoordinate && std::abs(y) <= kMaxCoordinate)) {
      badField(field, "a vertex lies beyond " + std::to_string(static_cast<long long>(kMaxCoordinate)) + " px");
    }
    ring.emplace_back(x, y);
  }
  if (ring.size() < 3) badField(field, "a ring needs at least 3 vertices");
  return ring;
}

// A polygon is [outer, hole, hole, ...] like GeoJSON (without the repeated closing vertex);
// an empty array is an empty polygon.
core::Polygon polygonFromJson(const json& in, const std::string& field) {
  if (!in.is_array()) badField(field, "a polygon must be an array of rings");
  core::Polygon polygon;
  for (size_t i = 0; i < in.size(); ++i) {
    core::Ring ring = ringFromJson(in[i], field + "[" + std::to_string(i) + "]");
    if (i == 0) polygon.outer = std::move(ring);
    else polygon.holes.push_back(std::move(ring));
  }
  return polygon;
}

std::string methodProblem(const std::string& name) {
  return "unknown method '" + name + "' (\"" + kActivePolygon + "\" or \"" + kBoxFitting + "\")";
}

json numberOrNull(double v) { return std::isnan(v) ? json(nullptr) : json(v); }

template <class T>
T get(const json& object, const char* key, const T& fallback, const std::string& where) {
  auto it = object.find(key);
  if (it == object.end() || it->is_null()) return fallback;
  if constexpr (std::is_integral_v<T> && !std::is_same_v<T, bool>) {
    // json's get<int>() of a float outside int's range is undefined behaviour (found by
    // fuzz_project: "id": 1e128); in range, a float still truncates as get<int>() does.
    if (it->is_number_float()) {
      const double value = it->get<double>();
      if (!(value >= static_cast<double>(std::numeric_limits<T>::min()) &&
            value <= static_cast<double>(std::numeric_limits<T>::max()))) {
        badField(where + key, "number out of range");
      }
      return static_cast<T>(value);
    }
  }
  try {
    return it->get<T>();
  } catch (const json::exception&) {
    badField(where + key, "wrong type");
  }
}

}  // namespace

bool Project::operator==(const Project& other) const {
  if (!(name == other.name && left == other.left && right == other.right &&
        disparity == other.disparity && dem == other.dem && labels == other.labels &&
        exclude == other.exclude && outputDir == other.outputDir &&
        disparityRange == other.disparityRange &&
        height == other.height && method == other.method && parameters == other.parameters &&
        buildings.size() == other.buildings.size())) {
    return false;
  }
  for (size_t i = 0; i < buildings.size(); ++i) {
    if (!sameBuilding(buildings[i], other.buildings[i])) return false;
  }
  return true;
}

json toJson(const Project& project, const std::string& baseDir) {
  json out;
  out["format"] = "delineo-project";
  out["version"] = kFormatVersion;
  out["name"] = project.name;
  out["images"] = {{"left", relativeTo(project.left, baseDir)},
                   {"right", relativeTo(project.right, baseDir)},
                   {"disparity", relativeTo(project.disparity, baseDir)},
                   {"dem", relativeTo(project.dem, baseDir)},
                   {"labels", relativeTo(project.labels, baseDir)},
                   {"exclude", relativeTo(project.exclude, baseDir)}};
  out["outputDir"] = fs::path(project.outputDir).is_absolute() ? relativeTo(project.outputDir, baseDir)
                                                               : project.outputDir;
  out["disparityRange"] = project.disparityRange
                              ? json{project.disparityRange->low, project.disparityRange->high}
                              : json(nullptr);
  out["heightModel"] = {{"groundDisparity", project.height.groundDisparity},
                        {"metresPerPixel", project.height.metresPerPixel},
                        {"gsd", project.height.gsd},
                        {"groundElevation", project.height.groundElevation}};
  out["method"] = project.method;
  out["parameters"] = project.parameters.is_null() ? json::object() : project.parameters;
  json buildings = json::array();
  for (const auto& b : project.buildings) {
    json jb;
    jb["id"] = b.id;
    jb["status"] = toString(b.status);
    jb["initial"] = polygonToJson(b.initial);
    jb["outline"] = polygonToJson(b.outline);
    jb["roofInterval"] = b.roofInterval ? json{b.roofInterval->low, b.roofInterval->high} : json(nullptr);
    jb["roofHeight"] = numberOrNull(b.roofHeight);
    jb["energy"] = numberOrNull(b.energy);
    if (b.energyTerms) {
      json terms = json::object();
      for (size_t t = 0; t < kEnergyTermNames.size(); ++t) terms[kEnergyTermNames[t]] = (*b.energyTerms)[t];
      jb["energyTerms"] = std::move(terms);
    }
    if (!b.method.empty()) jb["method"] = b.method;
    if (!b.sourceId.empty()) jb["sourceId"] = b.sourceId;
    json history = json::array();
    for (const auto& h : b.history) {
      history.push_back({{"action", h.action}, {"time", h.time}, {"detail", h.detail}});
    }
    jb["history"] = std::move(history);
    for (auto it = b.unknownKeys.begin(); it != b.unknownKeys.end(); ++it) jb.emplace(it.key(), it.value());
    buildings.push_back(std::move(jb));
  }
  out["buildings"] = std::move(buildings);
  // Keys this version does not know (a newer version's, a user's own) are written back as read.
  for (auto it = project.unknownKeys.begin(); it != project.unknownKeys.end(); ++it) {
    if (it.key() == "images" && it->is_object()) {
      for (auto image = it->begin(); image != it->end(); ++image) out["images"].emplace(image.key(), image.value());
    } else {
      out.emplace(it.key(), it.value());
    }
  }
  return out;
}

namespace {

// The root is a Delineo project of a version this program reads.
void checkFormat(const json& in) {
  if (!in.is_object()) badField("(root)", "a project must be a JSON object");
  // (find, not value(): value() throws json's type_error when "format" is not a string.)
  if (const auto format = in.find("format");
      format == in.end() || !format->is_string() || *format != "delineo-project") {
    badField("format", "not a Delineo project (expected \"delineo-project\")");
  }
  const int version = get<int>(in, "version", 0, "");
  if (version < 1) badField("version", "missing or invalid");
  if (version > kFormatVersion) {
    badField("version", "format version " + std::to_string(version) +
                            " is newer than this program supports (" +
                            std::to_string(kFormatVersion) + ")");
  }
}

// The image paths of `images`, resolved against the project's folder.
void readImages(const json& images, const std::string& baseDir, Project& p) {
  if (!images.is_object()) badField("images", "must be an object");
  p.left = resolveAgainst(get<std::string>(images, "left", "", "images."), baseDir);
  p.right = resolveAgainst(get<std::string>(images, "right", "", "images."), baseDir);
  p.disparity = resolveAgainst(get<std::string>(images, "disparity", "", "images."), baseDir);
  p.dem = resolveAgainst(get<std::string>(images, "dem", "", "images."), baseDir);
  p.labels = resolveAgainst(get<std::string>(images, "labels", "", "images."), baseDir);
  p.exclude = resolveAgainst(get<std::string>(images, "exclude", "", "images."), baseDir);
  if (p.left.empty() || p.right.empty()) badField("images", "left and right images are required");
}

// The "heightModel" object, each value within its bounds.
void readHeightModel(const json& model, HeightModel& height) {
  height.groundDisparity = get<double>(model, "groundDisparity", 0.0, "heightModel.");
  height.metresPerPixel = get<double>(model, "metresPerPixel", 0.0, "heightModel.");
  height.gsd = get<double>(model, "gsd", 1.0, "heightModel.");
  height.groundElevation = get<double>(model, "groundElevation", 0.0, "heightModel.");
  if (!(height.gsd > 0 && height.gsd <= kMaxMetresPerPixel)) {
    badField("heightModel.gsd", "must be positive, at most " + std::to_string(kMaxMetresPerPixel) + " m");
  }
  if (!(std::abs(height.metresPerPixel) <= kMaxMetresPerPixel)) {
    badField("heightModel.metresPerPixel", "must be within +-" + std::to_string(kMaxMetresPerPixel));
  }
  if (!(std::abs(height.groundDisparity) <= kMaxDisparity)) {
    badField("heightModel.groundDisparity", "must be within +-" + std::to_string(kMaxDisparity) + " px");
  }
  if (!(std::abs(height.groundElevation) <= kMaxElevation)) {
    badField("heightModel.groundElevation", "must be within +-" + std::to_string(static_cast<int>(kMaxElevation)) + " m");
  }
}

// The parameter groups, each an object; an older file's search range moved to disparityRange.
void readParameters(const json& in, Project& p) {
  p.parameters = in.value("parameters", json::object());
  if (!p.parameters.is_object()) badField("parameters", "must be an object of groups");
  for (auto it = p.parameters.begin(); it != p.parameters.end(); ++it) {
    if (!it->is_object()) badField("parameters." + it.key(), "must be an object");
  }
  // Older files also kept the search range among the matcher's parameters: it is the pair's
  // disparityRange now (one range drives every computation).
  if (auto matching = p.parameters.find("matching"); matching != p.parameters.end()) {
    const bool hasMin = matching->contains("dmin"), hasMax = matching->contains("dmax");
    if (hasMin && hasMax && !p.disparityRange) {
      const json& lo = (*matching)["dmin"];
      const json& hi = (*matching)["dmax"];
      if (!lo.is_number_integer() || !hi.is_number_integer() || lo.get<int>() > hi.get<int>()) {
        badField("parameters.matching.dmin", "dmin and dmax must be integers with dmin <= dmax");
      }
      p.disparityRange = DisparityInterval{lo.get<int>(), hi.get<int>()};
    }
    matching->erase("dmin");
    matching->erase("dmax");
  }
}

// One building (`where`: "buildings[i]."), its id new to the buildings read before it (`p`).
Building buildingFromJson(const json& jb, const std::string& where, const Project& p) {
  if (!jb.is_object()) badField(where, "must be an object");
  Building b;
  b.id = get<int>(jb, "id", 0, where);
  if (b.id <= 0) badField(where + "id", "must be a positive integer");
  if (p.find(b.id) != nullptr) badField(where + "id", "duplicate id " + std::to_string(b.id));
  b.status = statusFromString(get<std::string>(jb, "status", "pending", where));
  b.initial = polygonFromJson(jb.value("initial", json::array()), where + "initial");
  b.outline = polygonFromJson(jb.value("outline", json::array()), where + "outline");
  if (b.initial.outer.empty()) badField(where + "initial", "a building needs an initial polygon");
  if (auto it = jb.find("roofInterval"); it != jb.end() && !it->is_null()) {
    b.roofInterval = intervalFromJson(*it, where + "roofInterval");
  }
  b.roofHeight = get<double>(jb, "roofHeight", std::nan(""), where);
  b.energy = get<double>(jb, "energy", std::nan(""), where);
  if (auto it = jb.find("energyTerms"); it != jb.end() && !it->is_null()) {
    if (!it->is_object()) badField(where + "energyTerms", "must be an object of numbers");
    EnergyTerms terms{};
    for (size_t t = 0; t < kEnergyTermNames.size(); ++t) {
      terms[t] = get<double>(*it, kEnergyTermNames[t], std::nan(""), where + "energyTerms.");
    }
    b.energyTerms = terms;
  }
  b.method = get<std::string>(jb, "method", "", where);
  if (!b.method.empty() && !isOutlineMethod(b.method)) badField(where + "method", methodProblem(b.method));
  b.sourceId = get<std::string>(jb, "sourceId", "", where);
  const json history = jb.value("history", json::array());
  if (!history.is_array()) badField(where + "history", "must be an array");
  for (const auto& h : history) {
    if (!h.is_object()) badField(where + "history", "entries must be objects");
    b.history.push_back({get<std::string>(h, "action", "", where + "history."),
                         get<std::string>(h, "time", "", where + "history."),
                         get<std::string>(h, "detail", "", where + "history.")});
  }
  b.unknownKeys = unknownKeys(jb, {"id", "status", "method", "initial", "outline", "roofInterval", "roofHeight",
                                   "energy", "energyTerms", "sourceId", "history"});
  return b;
}

}  // namespace

Project fromJson(const json& in, const std::string& baseDir) {
  checkFormat(in);
  Project p;
  p.name = get<std::string>(in, "name", "", "");
  const json images = in.value("images", json::object());
  readImages(images, baseDir, p);
  // Relative output folders stay relative (to wherever the project file is saved next).
  p.outputDir = get<std::string>(in, "outputDir", "output", "");
  if (p.outputDir.empty()) badField("outputDir", "must not be empty (the default is \"output\")");
  if (auto it = in.find("disparityRange"); it != in.end() && !it->is_null()) {
    p.disparityRange = intervalFromJson(*it, "disparityRange");
  }
  if (auto it = in.find("heightModel"); it != in.end() && it->is_object()) readHeightModel(*it, p.height);
  // Files written before outlines had a method name none: the active polygon, the only one then.
  p.method = get<std::string>(in, "method", kActivePolygon, "");
  if (!isOutlineMethod(p.method)) badField("method", methodProblem(p.method));
  readParameters(in, p);
  const json buildings = in.value("buildings", json::array());
  if (!buildings.is_array()) badField("buildings", "must be an array");
  for (size_t i = 0; i < buildings.size(); ++i) {
    p.buildings.push_back(buildingFromJson(buildings[i], "buildings[" + std::to_string(i) + "].", p));
  }
  p.unknownKeys = unknownKeys(in, {"format", "version", "name", "method", "images", "outputDir", "disparityRange",
                                   "heightModel", "parameters", "buildings"});
  if (json imageExtras = unknownKeys(images, {"left", "right", "disparity", "dem", "labels", "exclude"});
      !imageExtras.empty()) {
    p.unknownKeys["images"] = std::move(imageExtras);
  }
  return p;
}

Project loadProject(const std::string& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw Error(ErrorCode::FileNotFound, "project file does not exist", path);
  std::ifstream in(path);
  if (!in) throw Error(ErrorCode::UnreadableFile, "cannot open the project file", path);
  json document;
  try {
    in >> document;
  } catch (const json::parse_error& e) {
    throw Error(ErrorCode::UnreadableFile, std::string("invalid JSON: ") + e.what(), path);
  }
  const std::string baseDir = fs::absolute(path).parent_path().lexically_normal().string();
  try {
    Project project = fromJson(document, baseDir);
    validateParameters(project);
    return project;
  } catch (const Error& e) {
    throw Error(e.code(), e.detail(), path);
  }
}

std::vector<std::string> inputFiles(const Project& project) {
  return {project.left, project.right, project.disparity, project.dem, project.labels, project.exclude};
}

void saveProject(const Project& project, const std::string& path) {
  const fs::path target = fs::absolute(path).lexically_normal();
  std::error_code ec;
  fs::create_directories(target.parent_path(), ec);
  // The output policy: never over an image of the project, never over a read-only file; a
  // symlinked project is saved into the file it names, with that file's permissions.
  io::checkOutputs({{path, io::OutputFormat::Text}}, inputFiles(project));
  io::writeTextFile(path, toJson(project, target.parent_path().string()).dump(2) + "\n");
}

std::string outputDirectory(const Project& project, const std::string& projectPath) {
  const fs::path dir(project.outputDir.empty() ? std::string("output") : project.outputDir);
  if (dir.is_absolute()) return dir.lexically_normal().string();
  if (projectPath.empty()) {
    throw Error(ErrorCode::InvalidParameter,
                "the output folder '" + dir.string() +
                    "' is relative to the project file, and the project has not been saved yet");
  }
  return (fs::absolute(projectPath).parent_path() / dir).lexically_normal().string();
}

std::string autosavePath(const std::string& projectPath) {
  const fs::path p(projectPath);
  std::string name(".");
  name.append(p.filename().string()).append(".autosave");
  return (p.parent_path() / name).string();
}

bool hasNewerAutosave(const std::string& projectPath) {
  std::error_code ec;
  const std::string autosave = autosavePath(projectPath);
  if (!fs::exists(autosave, ec)) return false;
  if (!fs::exists(projectPath, ec)) return true;
  return fs::last_write_time(autosave, ec) > fs::last_write_time(projectPath, ec);
}

}  // namespace delineo::project
