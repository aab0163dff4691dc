#pragma once
// Internal: the call into delineo::delineation, compiled only when that library is built.
#include "delineo/project/pipeline.hpp"

namespace delineo::project {

DelineationOutcome runActivePolygon(const Project& project, const Building& building,
                                    const StereoPair& pair, core::Progress* progress,
                                    const ContourListener& onContour);

}  // namespace delineo::project
