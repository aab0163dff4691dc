// delineo-cli detect: building proposals for a whole tile (segmentation::analyseScene,
// docs/dem.md): one polygon per building object with id, roof_disparity_min/max and
// ground_disparity, the initial polygons `delineate --init` takes unchanged.
#include <cstdio>
#include <string>

#include "cli_support.hpp"
#include "delineo/core/error.hpp"
#include "delineo/io/output_file.hpp"
#include "delineo/io/vector.hpp"
#include "scene_support.hpp"

namespace {
using namespace delineo;

int run(const std::vector<std::string>& args) {
  cli::Options opts("detect",
                    "Proposes the buildings of a tile: ground and above-ground objects of the DEM "
                    "(as `segment`), the building objects as initial polygons with their roof "
                    "and ground disparity, ready for `delineate --init`.");
  cli::addSceneInputs(opts, true);
  opts.required("out", "FILE", "proposals (GeoJSON/GeoPackage), in the DEM's georeferencing when it has one")
      .value("objects", "FILE", "also write every above-ground object with its class and measures")
      .params(segmentation::DetectParams{});
  if (!opts.parse(args)) return cli::kExitOk;
  segmentation::SceneParams params;
  opts.apply(params.ground);
  opts.apply(params.classify);
  opts.apply(params.objects);
  opts.apply(params.detect);

  std::vector<std::pair<std::string, io::OutputFormat>> outputs{{"out", io::OutputFormat::Vector}};
  if (opts.has("objects")) outputs.push_back({"objects", io::OutputFormat::Vector});
  cli::checkOutputs(opts, outputs, {"dem", "image", "disparity", "scene"});
  const auto [inputs, analysis] = cli::runSceneAnalysis(opts, params);
  const auto& proposals = analysis.detection.proposals;
  io::writeFeatures(opts.get("out"), proposals, inputs.dem.geo);
  const auto& objects = analysis.detection.objects.objects;
  if (opts.has("objects")) io::writeFeatures(opts.get("objects"), segmentation::objectFeatures(objects), inputs.dem.geo, "objects");
  cli::commandProgress().report(1.0);
  cli::commandProgress().finish();
  int buildings = 0;
  for (const auto& object : objects) buildings += object.cls == segmentation::kClassBuilding ? 1 : 0;
  std::printf("detect: %zu building(s) proposed from %d building object(s) (%zu objects in all) -> %s\n",
              proposals.size(), buildings, objects.size(), opts.get("out").c_str());
  return cli::kExitOk;
}

const bool registered = cli::registerCommand(
    {"detect", "building proposals of a tile (initial polygons and intervals for delineate --init)", run});
}  // namespace
