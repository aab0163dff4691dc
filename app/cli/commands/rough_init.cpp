// delineo-cli rough-init: makes operator-like rough initial polygons from reference outlines.
// Used by the default pipeline and the benchmarks to stand in for the operator's rough input:
// either each outline's bounding rectangle grown by --grow px, or the outline with every vertex
// moved by up to --jitter px (deterministic from --seed). Attributes (id, roof and ground
// disparities) are kept, so `delineate` reads the roof interval from each feature.
#include <cmath>
#include <random>

#include "cli_support.hpp"
#include "delineo/core/error.hpp"
#include "delineo/io/vector.hpp"

namespace {
using namespace delineo;

int run(const std::vector<std::string>& args) {
  cli::Options opts("rough-init",
                    "Makes rough initial polygons (grown bounding rectangles or jittered outlines) "
                    "from reference footprints, keeping their attributes.");
  opts.required("truth", "FILE", "reference footprints (GeoJSON, GeoPackage or Shapefile)")
      .required("out", "FILE", "output polygons")
      .value("grow", "PX", "rectangle mode: grow each bounding rectangle by PX pixels", "8")
      .value("jitter", "PX", "jitter mode: move every vertex by up to PX pixels (0 = off)", "0")
      .value("seed", "N", "random seed of the jitter", "1");
  if (!opts.parse(args)) return cli::kExitOk;
  const double grow = opts.getDouble("grow");
  const double jitter = opts.getDouble("jitter");
  if (grow < 0 || jitter < 0) throw cli::UsageError("--grow and --jitter must be >= 0");

  cli::checkOutputs(opts, {{"out", io::OutputFormat::Vector}}, {"truth"});
  auto features = io::readFeatures(opts.get("truth"));
  std::mt19937 rng(static_cast<unsigned>(opts.getInt("seed")));
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (auto& f : features) {
    if (jitter > 0) {
      for (auto& p : f.polygon.outer) {
        p.x += jitter * unit(rng);
        p.y += jitter * unit(rng);
      }
      for (auto& hole : f.polygon.holes) {
        for (auto& p : hole) {
          p.x += jitter * unit(rng);
          p.y += jitter * unit(rng);
        }
      }
    } else {
      const cv::Rect2d box = core::boundingBox(f.polygon.outer);
      const double x0 = box.x - grow, y0 = box.y - grow;
      const double x1 = box.x + box.width + grow, y1 = box.y + box.height + grow;
      f.polygon.outer = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
      f.polygon.holes.clear();
    }
  }
  io::writeFeatures(opts.get("out"), features);
  std::fprintf(stderr, "rough-init: wrote %zu polygons to %s\n", features.size(),
               opts.get("out").c_str());
  return cli::kExitOk;
}

const bool registered = cli::registerCommand(
    {"rough-init", "make rough initial polygons from reference footprints (benchmarks, demo)", run});
}  // namespace
