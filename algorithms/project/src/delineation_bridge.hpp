#pragma once
// Internal: the calls into delineo::delineation, compiled only when that library is built.
#include "delineo/project/pipeline.hpp"

namespace delineo::project {

DelineationOutcome runActivePolygon(const Project& project, const Building& building,
                                    const StereoPair& pair, core::Progress* progress,
                                    const ContourListener& onContour);

EnergyOutcome evaluateBuildingOutline(const Project& project, const Building& building,
                                      const StereoPair& pair, const core::Polygon& outline,
                                      core::Progress* progress);

RegularizationOutcome regularizeBuilding(const Project& project, const Building& building,
                                         const StereoPair& pair, const core::Polygon& outline,
                                         core::Progress* progress);

}  // namespace delineo::project
