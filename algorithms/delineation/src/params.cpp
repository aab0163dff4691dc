#include "delineo/delineation/params.hpp"

#include "delineo/core/error.hpp"

namespace delineo::delineation {

void DelineationParams::validate() const {
  core::checkDeclaredRanges(*this);
  regularization.validate();
  if (refinedSpacing > initialSpacing) {
    throw core::Error(core::ErrorCode::InvalidParameter,
                      "refined-spacing (" + std::to_string(refinedSpacing) +
                          " px) must not exceed initial-spacing (" +
                          std::to_string(initialSpacing) + " px)");
  }
  if (costAggregation % 2 == 0) {
    throw core::Error(core::ErrorCode::InvalidParameter,
                      "cost-aggregation must be odd, got " + std::to_string(costAggregation));
  }
  if (costWindow % 2 == 0) {
    throw core::Error(core::ErrorCode::InvalidParameter,
                      "cost-window must be odd, got " + std::to_string(costWindow));
  }
}

}  // namespace delineo::delineation
