#include "delineo/boxfit/params.hpp"

#include "delineo/core/error.hpp"

namespace delineo::boxfit {

void BoxFitParams::validate() const {
  core::checkDeclaredRanges(*this);
  if (groundWindow % 2 == 0) {
    throw core::Error(core::ErrorCode::InvalidParameter,
                      "ground-window must be odd, got " + std::to_string(groundWindow));
  }
  if (roiMargin < leash + snapOutward + 1) {
    throw core::Error(core::ErrorCode::InvalidParameter,
                      "roi-margin (" + std::to_string(roiMargin) + " px) must exceed leash + snap-outward (" +
                          std::to_string(leash + snapOutward) + " px)");
  }
}

}  // namespace delineo::boxfit
