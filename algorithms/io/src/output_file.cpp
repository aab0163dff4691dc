#include "delineo/io/output_file.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <filesystem>
#include <fstream>
#include <string_view>
#include <utility>

#include "delineo/core/error.hpp"
#include "gdal_support.hpp"

namespace delineo::io {
namespace fs = std::filesystem;
using core::Error;
using core::ErrorCode;

namespace {

// Symlinks are followed this many times at most (a loop gives up, as the system does).
constexpr int kMaxSymlinkHops = 40;

// The file name's stem and extension, ".city.json" whole (in its case), so that a temporary
// CityJSON file is one for the writers that choose the format by the name.
std::pair<std::string, std::string> stemAndExtension(const fs::path& target) {
  const std::string name = target.filename().string();
  constexpr std::string_view kCityJson = ".city.json";
  std::string lower = name;
  std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower.size() > kCityJson.size() && lower.ends_with(kCityJson)) {
    const size_t cut = name.size() - kCityJson.size();
    return {name.substr(0, cut), name.substr(cut)};
  }
  return {target.stem().string(), target.extension().string()};
}

const std::vector<std::string>& extensionsOf(OutputFormat format) {
  static const std::vector<std::string> geotiff{".tif", ".tiff"};
  static const std::vector<std::string> vector{".geojson", ".json", ".gpkg"};
  static const std::vector<std::string> json{".json"};
  static const std::vector<std::string> cityJson{".json", ".cityjson"};
  static const std::vector<std::string> any;
  switch (format) {
    case OutputFormat::GeoTiff: return geotiff;
    case OutputFormat::Vector: return vector;
    case OutputFormat::Json: return json;
    case OutputFormat::CityJson: return cityJson;
    case OutputFormat::Text: return any;
  }
  return json;
}

std::string formatName(OutputFormat format) {
  switch (format) {
    case OutputFormat::GeoTiff: return "a GeoTIFF";
    case OutputFormat::Vector: return "a vector file";
    case OutputFormat::Json: return "a JSON file";
    case OutputFormat::CityJson: return "a CityJSON file";
    case OutputFormat::Text: return "a text file";
  }
  return "a file";
}

std::string joined(const std::vector<std::string>& items) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) out += (i == 0 ? "" : i + 1 == items.size() ? " or " : ", ") + items[i];
  return out;
}

void checkOne(const OutputFile& output) {
  const std::string& path = output.path;
  if (path.empty()) throw Error(ErrorCode::UnusableOutput, "no output file name given");
  if (detail::isVirtualPath(path)) return;
  const auto& allowed = extensionsOf(output.format);
  const std::string ext = detail::lowerExtension(path);
  if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), ext) == allowed.end()) {
    throw Error(ErrorCode::UnusableOutput,
                (ext.empty() ? std::string("no extension") : "extension '" + ext + "'") + " for " +
                    formatName(output.format) + ": use " + joined(allowed),
                path);
  }
  const fs::path target(resolvedPath(path));
  std::error_code ec;
  if (fs::is_directory(target, ec)) throw Error(ErrorCode::UnusableOutput, "is a folder, not a file", path);
  const fs::path folder = target.parent_path();
  if (!fs::is_directory(folder, ec)) {
    throw Error(ErrorCode::UnusableOutput, "the folder " + folder.string() + " does not exist", path);
  }
  if (::access(folder.c_str(), W_OK | X_OK) != 0) {
    throw Error(ErrorCode::UnusableOutput, "the folder " + folder.string() + " cannot be written", path);
  }
  // Read-only by its mode bits too: a superuser may write anything, yet a file its owner made
  // read-only is meant to stay as it is.
  struct stat existing {};
  if (::stat(target.c_str(), &existing) == 0 &&
      ((existing.st_mode & 0222) == 0 || ::access(target.c_str(), W_OK) != 0)) {
    throw Error(ErrorCode::UnusableOutput, "the file is read-only: it is not replaced", path);
  }
}

}  // namespace

std::string resolvedPath(const std::string& path) {
  if (path.empty() || detail::isVirtualPath(path)) return path;
  std::error_code ec;
  fs::path p = fs::absolute(path, ec).lexically_normal();
  for (int hop = 0; hop < kMaxSymlinkHops && fs::is_symlink(fs::symlink_status(p, ec)); ++hop) {
    const fs::path link = fs::read_symlink(p, ec);
    if (ec) break;
    p = (link.is_absolute() ? link : p.parent_path() / link).lexically_normal();
  }
  const fs::path canonical = fs::weakly_canonical(p, ec);
  return (ec ? p : canonical).string();
}

bool sameFile(const std::string& a, const std::string& b) {
  if (a.empty() || b.empty()) return false;
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec) && fs::equivalent(a, b, ec)) return true;
  return resolvedPath(a) == resolvedPath(b);
}

void checkOutputs(const std::vector<OutputFile>& outputs, const std::vector<std::string>& inputs) {
  for (size_t i = 0; i < outputs.size(); ++i) {
    checkOne(outputs[i]);
    const std::string& path = outputs[i].path;
    for (const std::string& input : inputs) {
      if (sameFile(path, input)) {
        throw Error(ErrorCode::UnusableOutput,
                    "is an input of this run (" + input + "): it would be overwritten; choose another output",
                    path);
      }
    }
    for (size_t j = 0; j < i; ++j) {
      if (sameFile(path, outputs[j].path)) {
        throw Error(ErrorCode::UnusableOutput, "is given for two outputs of this run", path);
      }
    }
  }
}

void writeAtomically(const std::string& path, const std::function<void(const std::string&)>& write) {
  if (detail::isVirtualPath(path)) {
    write(path);
    return;
  }
  const fs::path target(resolvedPath(path));
  std::error_code ec;
  if (fs::is_directory(target, ec)) throw Error(ErrorCode::WriteFailed, "is a folder, not a file", path);
  static std::atomic<unsigned> counter{0};
  const auto [stem, extension] = stemAndExtension(target);
  std::string name(".");
  name.append(stem)
      .append(".partial-")
      .append(std::to_string(::getpid()))
      .append("-")
      .append(std::to_string(counter++))
      .append(extension);
  const fs::path temp = target.parent_path() / name;
  try {
    write(temp.string());
  } catch (const Error& e) {
    fs::remove(temp, ec);
    // The error names the file the caller asked for, not the temporary one.
    throw Error(e.code(), e.detail(), e.path() == temp.string() ? path : e.path());
  } catch (...) {
    fs::remove(temp, ec);
    throw;
  }
  struct stat existing {};
  if (::stat(target.c_str(), &existing) == 0) {
    fs::permissions(temp, static_cast<fs::perms>(existing.st_mode & 07777), ec);
  }
  fs::rename(temp, target, ec);
  if (ec) {
    const std::string reason = ec.message();
    fs::remove(temp, ec);
    throw Error(ErrorCode::WriteFailed, "cannot replace the file: " + reason, path);
  }
}

void writeTextFile(const std::string& path, const std::string& text) {
  writeAtomically(path, [&](const std::string& temp) {
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out) throw Error(ErrorCode::WriteFailed, "cannot create a file in its folder", path);
    out << text;
    out.flush();
    if (!out) throw Error(ErrorCode::WriteFailed, "writing failed (disk full?)", path);
  });
}

}  // namespace delineo::io
