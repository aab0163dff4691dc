// The project's elevation data written as files of one folder (declared in pipeline.hpp): the
// disparity, the DEM, the enhanced DEM and the scene analysis's DTM, nDSM, labels and objects,
// written all together or not at all.
#include <unistd.h>

#include <atomic>
#include <filesystem>

#include "delineo/core/error.hpp"
#include "delineo/io/output_file.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/io/vector.hpp"
#include "delineo/project/pipeline.hpp"

namespace delineo::project {

namespace fs = std::filesystem;
using core::Error;
using core::ErrorCode;

namespace {

constexpr ElevationLayer kAllLayers[] = {ElevationLayer::Disparity, ElevationLayer::Dem, ElevationLayer::EnhancedDem,
                                         ElevationLayer::Dtm,       ElevationLayer::Ndsm, ElevationLayer::Labels,
                                         ElevationLayer::Objects};

const char* fileName(ElevationLayer layer) {
  switch (layer) {
    case ElevationLayer::Disparity: return "disparity.tif";
    case ElevationLayer::Dem: return "dem.tif";
    case ElevationLayer::EnhancedDem: return "enhanced_dem.tif";
    case ElevationLayer::Dtm: return "dtm.tif";
    case ElevationLayer::Ndsm: return "ndsm.tif";
    case ElevationLayer::Labels: return "labels.tif";
    case ElevationLayer::Objects: return "objects.geojson";
  }
  return "";
}

// The raster of a layer (empty for the objects).
const cv::Mat& rasterOf(const ElevationLayers& layers, ElevationLayer layer) {
  static const cv::Mat none;
  switch (layer) {
    case ElevationLayer::Disparity: return layers.disparity;
    case ElevationLayer::Dem: return layers.dem;
    case ElevationLayer::EnhancedDem: return layers.enhancedDem;
    case ElevationLayer::Dtm: return layers.dtm;
    case ElevationLayer::Ndsm: return layers.ndsm;
    case ElevationLayer::Labels: return layers.labels;
    case ElevationLayer::Objects: return none;
  }
  return none;
}

// A hidden file beside `target` with its extension (GDAL picks the driver by it).
std::string stagingPath(const fs::path& target) {
  static std::atomic<unsigned> counter{0};
  std::string name(".");
  name.append(target.stem().string())
      .append(".staged-")
      .append(std::to_string(::getpid()))
      .append("-")
      .append(std::to_string(counter++))
      .append(target.extension().string());
  return (target.parent_path() / name).string();
}

void writeLayer(const std::string& path, const ElevationLayers& layers, ElevationLayer layer,
                const io::GeoReference& geo) {
  if (layer == ElevationLayer::Objects) {
    io::writeFeatures(path, *layers.objects, geo, "objects");
  } else if (layer == ElevationLayer::Labels) {
    io::writeGeoTiff(path, layers.labels, geo);
  } else {
    io::writeFloatGeoTiff(path, rasterOf(layers, layer), geo);
  }
}

void removeAll(const std::vector<std::string>& paths) {
  std::error_code ec;
  for (const std::string& path : paths) fs::remove(path, ec);
}

// Moves each staged file over its target (io::writeAtomically keeps the target's permissions and
// follows a symlink); the staged files not moved are removed if one move fails.
void moveIntoPlace(const std::vector<std::string>& staged, const std::vector<io::OutputFile>& targets) {
  for (size_t i = 0; i < staged.size(); ++i) {
    try {
      io::writeAtomically(targets[i].path, [&](const std::string& temp) {
        std::error_code ec;
        fs::rename(staged[i], temp, ec);
        if (ec) throw Error(ErrorCode::WriteFailed, "cannot move the written file into place: " + ec.message(), targets[i].path);
      });
    } catch (...) {
      removeAll({staged.begin() + static_cast<std::ptrdiff_t>(i), staged.end()});
      throw;
    }
  }
}

}  // namespace

std::vector<ElevationLayer> ElevationLayers::present() const {
  std::vector<ElevationLayer> layers;
  for (ElevationLayer layer : kAllLayers) {
    const bool there = layer == ElevationLayer::Objects ? objects.has_value() : !rasterOf(*this, layer).empty();
    if (there) layers.push_back(layer);
  }
  return layers;
}

void ElevationLayers::leaveOut(ElevationLayer layer) {
  switch (layer) {
    case ElevationLayer::Disparity: disparity = cv::Mat(); break;
    case ElevationLayer::Dem: dem = cv::Mat(); break;
    case ElevationLayer::EnhancedDem: enhancedDem = cv::Mat(); break;
    case ElevationLayer::Dtm: dtm = cv::Mat(); break;
    case ElevationLayer::Ndsm: ndsm = cv::Mat(); break;
    case ElevationLayer::Labels: labels = cv::Mat(); break;
    case ElevationLayer::Objects: objects.reset(); break;
  }
}

void ElevationLayers::setSceneAnalysis(const SceneAnalysisOutcome& analysis) {
  dtm = analysis.dtm;
  ndsm = analysis.ndsm;
  labels = analysis.classes;
  objects = analysis.objects;
}

ElevationLayers sceneAnalysisLayers(const SceneAnalysisOutcome& analysis) {
  ElevationLayers layers;
  layers.setSceneAnalysis(analysis);
  return layers;
}

std::vector<io::OutputFile> elevationFiles(const std::string& dir, const std::vector<ElevationLayer>& layers) {
  std::vector<io::OutputFile> files;
  for (ElevationLayer layer : layers) {
    files.push_back({(fs::path(dir) / fileName(layer)).string(),
                     layer == ElevationLayer::Objects ? io::OutputFormat::Vector : io::OutputFormat::GeoTiff});
  }
  return files;
}

std::vector<std::string> leaveOutProjectSources(const Project& project, const std::string& dir,
                                                ElevationLayers& layers) {
  std::vector<std::string> leftOut;
  for (const auto& [layer, source] : {std::pair{ElevationLayer::Disparity, &project.disparity},
                                      std::pair{ElevationLayer::Dem, &project.dem}}) {
    if (rasterOf(layers, layer).empty()) continue;
    if (io::sameFile((fs::path(dir) / fileName(layer)).string(), *source)) {
      layers.leaveOut(layer);
      leftOut.push_back(fileName(layer));
    }
  }
  return leftOut;
}

ElevationRastersWritten writeElevationRasters(const std::string& dir, const io::GeoReference& geo,
                                              const ElevationLayers& layers, core::Progress* progress,
                                              const std::vector<std::string>& inputs) {
  const std::vector<ElevationLayer> present = layers.present();
  const std::vector<io::OutputFile> targets = elevationFiles(dir, present);
  io::checkOutputs(targets, inputs);
  ElevationRastersWritten written;
  std::vector<std::string> staged;
  try {
    for (size_t i = 0; i < present.size(); ++i) {
      if (core::isCanceled(progress)) break;
      staged.push_back(stagingPath(fs::path(io::resolvedPath(targets[i].path))));
      writeLayer(staged.back(), layers, present[i], geo);
      core::report(progress, static_cast<double>(i + 1) / static_cast<double>(present.size() + 1));
    }
  } catch (...) {
    removeAll(staged);
    throw;
  }
  if (core::isCanceled(progress)) {
    removeAll(staged);
    written.status = core::RunStatus::Canceled;
    return written;
  }
  moveIntoPlace(staged, targets);
  for (size_t i = 0; i < present.size(); ++i) {
    written.files.push_back(targets[i].path);
    if (present[i] == ElevationLayer::Objects) written.objects = true;
    else ++written.rasters;
  }
  core::report(progress, 1.0);
  return written;
}

}  // namespace delineo::project
