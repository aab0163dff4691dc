#pragma once
// Deterministic optimiser of the statistical active polygon on prepared energy images.
#include <functional>
#include <string>

#include "delineo/core/progress.hpp"
#include "delineo/delineation/energy.hpp"
#include "delineo/delineation/params.hpp"

namespace delineo::delineation {

// One report per optimisation sweep: the polygon so far (ROI coordinates) and its energy.
struct IterationReport {
  int iteration = 0;
  std::string stage;  // "moves", "edge moves", "deletions", "insertion", "courtyard"
  IntPolygon polygon;
  EnergyTerms terms;
};
using IterationObserver = std::function<void(const IterationReport&)>;

enum class EnergyMode {
  Incremental,  // pre-integrated rows, only the changed edges re-evaluated (the product)
  Reference,    // rasterise and sum the whole ROI for every candidate (tests, benchmark)
};

struct ActivePolygonResult {
  IntPolygon polygon;  // ROI coordinates
  EnergyTerms terms;
  int iterations = 0;
  core::RunStatus status = core::RunStatus::Completed;
  long long evaluations = 0;  // candidate energies computed
};

// Resamples a ring so that consecutive vertices are at most `spacing` px apart (original vertices
// kept), rounds to integer pixel corners inside [0, W] x [0, H] and drops repeated vertices.
IntRing polygonise(const core::Ring& ring, int spacing, cv::Size bounds);

// Runs the optimisation (moves, edge moves, deletions; insertion at the refined spacing; then
// courtyards) from `init` (ROI coordinates, integer vertices). Never returns a self-intersecting
// polygon. On cancel, returns the polygon reached so far (energy never increases) with status
// Canceled. Throws core::Error(InvalidParameter) for a degenerate initial polygon.
ActivePolygonResult optimiseActivePolygon(const EnergyImages& images, const IntPolygon& init,
                                          const DelineationParams& params,
                                          const IterationObserver& observer = {},
                                          core::Progress* progress = nullptr,
                                          EnergyMode mode = EnergyMode::Incremental);

}  // namespace delineo::delineation
