#include "delineo/core/nan_mask.hpp"

namespace delineo::core {

cv::Mat numberMask(const cv::Mat& m) {
  cv::Mat out;
  cv::compare(m, m, out, cv::CMP_EQ);  // false only for NaN, in the scalar and vector paths
  return out;
}

cv::Mat nanMask(const cv::Mat& m) {
  cv::Mat out;
  cv::bitwise_not(numberMask(m), out);
  return out;
}

}  // namespace delineo::core
