// Matches hidden in the right view by a nearer match to their right (see ordering.hpp).
#include "ordering.hpp"

#include <limits>
#include <vector>

#include "workers.hpp"

namespace delineo::stereo::detail {

int rejectOrderingViolations(cv::Mat& disparity, cv::Mat& score, const OrderingSettings& settings) {
  CV_Assert(disparity.type() == CV_32F && (score.empty() || score.size() == disparity.size()));
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  std::vector<int> rejectedIn(static_cast<size_t>(disparity.rows), 0);
  forRowBands(disparity.rows, settings.threads, [&](int rowStart, int rowEnd) {
    for (int y = rowStart; y < rowEnd; ++y) {
      float* d = disparity.ptr<float>(y);
      float* s = score.empty() ? nullptr : score.ptr<float>(y);
      // From the right: the leftmost right-view position of the kept matches so far, and its
      // disparity. A rejected match hides nothing.
      float leftmost = std::numeric_limits<float>::infinity(), itsDisparity = 0;
      int rejected = 0;
      for (int x = disparity.cols - 1; x >= 0; --x) {
        if (!(d[x] == d[x])) continue;
        const float mapped = static_cast<float>(x) - d[x];
        if (hides(leftmost, itsDisparity, mapped, d[x], settings)) {
          d[x] = kNaN;
          if (s != nullptr) s[x] = kNaN;
          ++rejected;
          continue;
        }
        if (mapped < leftmost) {
          leftmost = mapped;
          itsDisparity = d[x];
        }
      }
      rejectedIn[static_cast<size_t>(y)] = rejected;
    }
  });
  int rejected = 0;
  for (const int n : rejectedIn) rejected += n;
  return rejected;
}

}  // namespace delineo::stereo::detail
