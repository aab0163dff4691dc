// delineo-cli simulate: a synthetic urban epipolar pair with exact ground truth
// (docs/simulator.md), written as GeoTIFFs, a GeoJSON of roof outlines and scene.json.
#include <filesystem>
#include <functional>
#include <iostream>
#include <string>

#include "cli_support.hpp"
#include "delineo/core/error.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/io/vector.hpp"
#include "delineo/sim/scene.hpp"

namespace {
using namespace delineo;

int run(const std::vector<std::string>& args) {
  cli::Options opts("simulate",
                    "Generates a synthetic urban stereo scene with ground truth (disparity, "
                    "occlusion, DEM, labels, roof outlines), deterministic from --seed.");
  opts.required("out", "DIR", "output directory (created when missing)")
      .params(sim::SceneParams{});
  if (!opts.parse(args)) return cli::kExitOk;
  sim::SceneParams params;
  opts.apply(params);  // invalid values: core::Error(InvalidParameter), exit code 3

  const std::filesystem::path dir(opts.get("out"));
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec || !std::filesystem::is_directory(dir)) {
    throw core::Error(core::ErrorCode::WriteFailed, "cannot create the output directory", dir.string());
  }

  auto& progress = cli::commandProgress();
  core::Progress::Range simulation(&progress, 0.0, 0.9);
  const sim::Scene scene = sim::simulateScene(params, &simulation);
  if (scene.status == core::RunStatus::Canceled) throw cli::Canceled();

  progress.setStage("writing");
  auto path = [&](const char* name) { return (dir / name).string(); };
  // Ctrl-C is honoured between files: each one is whole, the old or the new.
  const std::vector<std::function<void()>> writes{
      [&] { io::writeGeoTiff(path(sim::SceneFiles::left), scene.left); },
      [&] { io::writeGeoTiff(path(sim::SceneFiles::right), scene.right); },
      [&] { io::writeFloatGeoTiff(path(sim::SceneFiles::disparity), scene.disparity); },
      [&] { io::writeFloatGeoTiff(path(sim::SceneFiles::disparityRight), scene.disparityRight); },
      [&] { io::writeGeoTiff(path(sim::SceneFiles::occlusion), scene.occlusion); },
      [&] { io::writeFloatGeoTiff(path(sim::SceneFiles::dem), scene.dem); },
      [&] { io::writeGeoTiff(path(sim::SceneFiles::labels), scene.labels); },
      [&] { io::writeFeatures(path(sim::SceneFiles::footprints), scene.footprints, {}, "buildings"); },
      [&] { sim::writeSceneJson(path(sim::SceneFiles::description), scene, params); }};
  for (const auto& write : writes) {
    cli::throwIfCanceled(progress);
    write();
  }
  progress.report(1.0);

  std::cout << "simulated " << params.width << "x" << params.height << " scene (seed "
            << params.seed << "): " << scene.buildingsPlaced << " buildings, "
            << scene.treesPlaced << " trees, disparity range " << scene.disparityMin << ":"
            << scene.disparityMax << " -> " << dir.string() << "\n";
  return cli::kExitOk;
}

const bool registered = cli::registerCommand(
    {"simulate", "synthetic urban stereo scene with exact ground truth", run});

}  // namespace
