// Image noise and the grey-level map between the two views (see radiometry.hpp).
#include "radiometry.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "workers.hpp"

namespace delineo::stereo::detail {

// Noise sigma of an image from its response to the difference of two Laplacians, which cancels
// locally linear intensity (the kernel of Immerkaer 1996, "Fast noise variance estimation"; under
// pure noise the response has variance 36 sigma^2). Texture adds to the response, so the level
// is read in the flattest places: the first quartile of the response's mean square over 7x7
// blocks (on a fully textured image this overestimates sigma, which only weakens the
// brightness term).
double noiseSigma(const cv::Mat& image) {
  if (image.rows < 9 || image.cols < 9) return 1.0;
  cv::Mat grey;
  if (image.depth() == CV_32F) {
    grey = image;
  } else {
    image.convertTo(grey, CV_32F);
  }
  // The response's mean square over the 7x7 blocks of the image without its 1-px border, each
  // summed directly (one pass; no full-size response and block filter: this runs on every match).
  // A row's squared responses first, element by element (vectorised; the same values), then
  // summed block by block in the same order as ever.
  const int blocksX = (grey.cols - 9) / 7 + 1, blocksY = (grey.rows - 9) / 7 + 1;
  std::vector<double> values(static_cast<size_t>(blocksX) * static_cast<size_t>(blocksY), 0.0);
  const int last = 7 * blocksX;  // the rightmost column of the last block
  std::vector<double> squares(static_cast<size_t>(last) + 1);
  for (int j = 0; j < blocksY; ++j) {
    double* energy = &values[static_cast<size_t>(j) * static_cast<size_t>(blocksX)];
    for (int y = 7 * j + 1; y <= 7 * j + 7; ++y) {
      const float* up = grey.ptr<float>(y - 1);
      const float* mid = grey.ptr<float>(y);
      const float* down = grey.ptr<float>(y + 1);
      for (int x = 1; x <= last; ++x) {
        const double corners =
            static_cast<double>(up[x - 1]) + up[x + 1] + down[x - 1] + down[x + 1];
        const double sides = static_cast<double>(up[x]) + down[x] + mid[x - 1] + mid[x + 1];
        const double r = corners - 2.0 * sides + 4.0 * static_cast<double>(mid[x]);
        squares[static_cast<size_t>(x)] = r * r;
      }
      for (int i = 0; i < blocksX; ++i) {
        double sum = 0;
        for (int x = 7 * i + 1; x <= 7 * i + 7; ++x) sum += squares[static_cast<size_t>(x)];
        energy[i] += sum;
      }
    }
    for (int i = 0; i < blocksX; ++i) energy[i] /= 49.0;
  }
  const auto q = values.begin() + static_cast<long>(values.size() / 4);
  std::nth_element(values.begin(), q, values.end());
  return std::sqrt(*q / 36.0);
}

namespace {

// Chunks of kChunk consecutive elements of [0, n), handed to `threads` workers:
// work(chunk, begin, end) once per chunk.
constexpr size_t kChunk = 32768;
size_t chunkCount(size_t n) {
  return (n + kChunk - 1) / kChunk;
}
template <class Work>
void forEachChunk(size_t n, int threads, const Work& work) {
  forRowBands(
      static_cast<int>(chunkCount(n)), threads,
      [&](int first, int last) {
        for (int c = first; c < last; ++c) {
          const size_t begin = static_cast<size_t>(c) * kChunk;
          work(static_cast<size_t>(c), begin, std::min(n, begin + kChunk));
        }
      },
      1);
}

// Sums of the left and right grey levels of pixel pairs and of their squares; map(): the gain and
// offset that give the left ones the right ones' mean and standard deviation (none when either
// side is flat).
struct GreyMoments {
  double sumL = 0, sumLL = 0, sumR = 0, sumRR = 0, count = 0;
  void add(float l, float r) {
    sumL += l;
    sumLL += static_cast<double>(l) * l;
    sumR += r;
    sumRR += static_cast<double>(r) * r;
    count += 1;
  }
  std::optional<std::pair<double, double>> map() const {
    const double meanL = sumL / count, meanR = sumR / count;
    const double varL = sumLL / count - meanL * meanL, varR = sumRR / count - meanR * meanR;
    if (!(varL > 1e-12) || !(varR > 1e-12)) return std::nullopt;
    const double gain = std::sqrt(varL / varR);
    return std::pair{gain, meanL - gain * meanR};
  }
};

}  // namespace

// Gain and offset mapping the right view's grey levels to the left's, from the moments of the
// overlapping parts of the whole images (columns seen by both for a typical disparity). The two
// views see nearly the same scene, so their histograms differ by the exposures; a fit on one
// building's matches is too noisy (a few percent of gain is many noise sigmas on a bright roof).
std::pair<double, double> radiometricMap(const cv::Mat& left, const cv::Mat& right, int dmin,
                                         int dmax) {
  const int shift = std::clamp((dmin + dmax) / 2, -(left.cols - 1) / 2, (left.cols - 1) / 2);
  const int width = left.cols - std::abs(shift);
  // Every 4th row: the moments of a quarter of the image are as good, at a quarter of the time
  // (this runs for every building).
  const int rowStep = 4, rows = (left.rows + rowStep - 1) / rowStep;
  const cv::Mat l(rows, width, CV_32F, const_cast<float*>(left.ptr<float>(0, std::max(0, shift))),
                  left.step[0] * rowStep);
  const cv::Mat r(rows, width, CV_32F, const_cast<float*>(right.ptr<float>(0, std::max(0, -shift))),
                  right.step[0] * rowStep);
  GreyMoments moments;
  for (int y = 0; y < rows; ++y) {
    const float* pl = l.ptr<float>(y);
    const float* pr = r.ptr<float>(y);
    for (int x = 0; x < width; ++x) {
      if (!std::isfinite(pl[x]) || !std::isfinite(pr[x])) continue;
      moments.add(pl[x], pr[x]);
    }
  }
  if (moments.count < 2) return {1.0, 0.0};
  return moments.map().value_or(std::pair{1.0, 0.0});
}

std::pair<double, double> matchedRange(const cv::Mat& disparity, int threads) {
  CV_Assert(disparity.type() == CV_32F);
  constexpr int kBandRows = 64;
  const int bands = (disparity.rows + kBandRows - 1) / kBandRows;
  std::vector<float> bandLo(static_cast<size_t>(bands), std::numeric_limits<float>::infinity());
  std::vector<float> bandHi(static_cast<size_t>(bands), -std::numeric_limits<float>::infinity());
  forRowBands(
      disparity.rows, threads,
      [&](int rowStart, int rowEnd) {
        float lo = std::numeric_limits<float>::infinity(), hi = -lo;
        for (int y = rowStart; y < rowEnd; ++y) {
          const float* d = disparity.ptr<float>(y);
          // Without branches, so that it vectorises (with a branch per pixel: 6 ms at 1 Mpx); a
          // comparison with NaN is false, so an unmatched pixel never wins.
          for (int x = 0; x < disparity.cols; ++x) {
            lo = d[x] < lo ? d[x] : lo;
            hi = d[x] > hi ? d[x] : hi;
          }
        }
        bandLo[static_cast<size_t>(rowStart / kBandRows)] = lo;
        bandHi[static_cast<size_t>(rowStart / kBandRows)] = hi;
      },
      kBandRows);
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (int b = 0; b < bands; ++b) {
    lo = std::min(lo, bandLo[static_cast<size_t>(b)]);
    hi = std::max(hi, bandHi[static_cast<size_t>(b)]);
  }
  if (!(lo <= hi)) return {0.0, 0.0};
  return {lo, hi};
}

// Large sets by bucket selection: a histogram of 4096 equal bins between the
// extremes (monotone in the value, so the middle lies in the bin where the running count passes
// it), then nth_element over that bin only: the same value, in three passes without branches
// and one over a bin, instead of reordering a copy of the 250 000 values of a 1 Mpx map (three
// medians a call, three calls a match).
double middleValue(const std::vector<double>& values, int threads) {
  const size_t n = values.size();
  const size_t middle = n / 2;
  constexpr size_t kDirectBelow = 4096;
  if (n < kDirectBelow) {
    std::vector<double> copy = values;
    std::nth_element(copy.begin(), copy.begin() + static_cast<std::ptrdiff_t>(middle), copy.end());
    return copy[middle];
  }
  // Chunks of the values for the workers; every step below gives the same result in any split
  // (extremes, integer counts, and the bin's values, whose order nth_element does not depend on).
  const size_t chunks = chunkCount(n);
  // The extremes without branches (vectorised; values hold no NaN).
  std::vector<double> chunkLow(chunks), chunkHigh(chunks);
  forEachChunk(n, threads, [&](size_t c, size_t begin, size_t end) {
    double low = values[begin], high = values[begin];
    for (size_t i = begin; i < end; ++i) {
      const double v = values[i];
      low = v < low ? v : low;
      high = v > high ? v : high;
    }
    chunkLow[c] = low;
    chunkHigh[c] = high;
  });
  const double low = *std::min_element(chunkLow.begin(), chunkLow.end());
  const double high = *std::max_element(chunkHigh.begin(), chunkHigh.end());
  if (!(high > low)) return low;
  constexpr int kBins = 4096;
  const double scale = kBins / (high - low);
  // Each value's bin once (a loop without branches), then the counts.
  std::vector<uint16_t> bins(n);
  std::vector<std::vector<size_t>> chunkCounts(chunks);
  forEachChunk(n, threads, [&](size_t c, size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) {
      bins[i] =
          static_cast<uint16_t>(std::min(kBins - 1, static_cast<int>((values[i] - low) * scale)));
    }
    std::vector<size_t>& counts = chunkCounts[c];
    counts.assign(kBins, 0);
    for (size_t i = begin; i < end; ++i) ++counts[bins[i]];
  });
  std::vector<size_t> counts(kBins, 0);
  for (const auto& chunk : chunkCounts) {
    for (int b = 0; b < kBins; ++b) counts[static_cast<size_t>(b)] += chunk[static_cast<size_t>(b)];
  }
  size_t before = 0;
  int bin = 0;
  while (before + counts[static_cast<size_t>(bin)] <= middle) {
    before += counts[static_cast<size_t>(bin++)];
  }
  std::vector<double> inBin;
  inBin.reserve(counts[static_cast<size_t>(bin)]);
  for (size_t i = 0; i < n; ++i) {
    if (bins[i] == bin) inBin.push_back(values[i]);
  }
  const size_t at = middle - before;
  std::nth_element(inBin.begin(), inBin.begin() + static_cast<std::ptrdiff_t>(at), inBin.end());
  return inBin[at];
}

namespace {

// A first map of (left, right) pairs that wrong pairs cannot pull far: the median slope between
// pairs of pairs at least kSlopeSpread grey levels apart in the right view (Theil-Sen, on up to
// kSlopeSamples draws of a fixed sequence), then the median offset. None when too few draws are
// that far apart or the slope is not positive.
constexpr double kSlopeSpread = 10.0;
constexpr int kSlopeSamples = 20000;
std::optional<std::pair<double, double>> medianSlopeMap(const std::vector<cv::Vec2f>& pairs,
                                                        int threads) {
  std::vector<double> slopes;
  slopes.reserve(kSlopeSamples);
  std::uint64_t state = 0x9e3779b97f4a7c15ULL;  // xorshift64: the same draws on every run
  const auto draw = [&] {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return static_cast<size_t>(state % pairs.size());
  };
  for (int k = 0; k < 3 * kSlopeSamples && static_cast<int>(slopes.size()) < kSlopeSamples; ++k) {
    const cv::Vec2f& p = pairs[draw()];
    const cv::Vec2f& q = pairs[draw()];
    const double spread = static_cast<double>(p[1]) - q[1];
    if (std::abs(spread) >= kSlopeSpread)
      slopes.push_back((static_cast<double>(p[0]) - q[0]) / spread);
  }
  if (slopes.size() < 100) return std::nullopt;
  const double gain = middleValue(slopes);
  if (!(gain > 0)) return std::nullopt;
  std::vector<double> offsets(pairs.size());
  forEachChunk(pairs.size(), threads, [&](size_t, size_t begin, size_t end) {
    for (size_t i = begin; i < end; ++i) offsets[i] = pairs[i][0] - gain * pairs[i][1];
  });
  return std::pair{gain, middleValue(offsets, threads)};
}

}  // namespace

// Every 2nd row and column: a quarter of the matches gives the moments to well under a grey level.
// The moments are taken over the pairs within kInlierMads median absolute residuals (× 1.4826, a
// Gaussian's sigma) of the current map, twice, starting from the median-slope map. Wrong matches
// (an occluded pixel paired with the roof that hides it, a roof's value carried onto the ground)
// are far off; started from the moments of all pairs, a few of them at the
// end of the grey range pulled the map towards themselves and were kept by the refits (a unit
// scene of the snapping: gain 0.768 and offset 32.5 where the views' exposures are the same).
constexpr double kInlierMads = 2.5;
std::pair<double, double> radiometricMapOfMatches(
    const cv::Mat& left, const cv::Mat& right, const cv::Mat& disparity,
    const std::function<std::pair<double, double>()>& fallback, int minPairs, int threads) {
  // (left, right) grey levels of every 2nd row and column, by bands of rows, joined in row order.
  constexpr int kBandRows = 32;
  const int pairRows = (left.rows + 1) / 2;
  std::vector<std::vector<cv::Vec2f>> bandPairs(
      static_cast<size_t>((pairRows + kBandRows - 1) / kBandRows));
  forRowBands(
      pairRows, threads,
      [&](int first, int last) {
        std::vector<cv::Vec2f>& out = bandPairs[static_cast<size_t>(first / kBandRows)];
        for (int y = 2 * first; y < 2 * last; y += 2) {
          const float* pl = left.ptr<float>(y);
          const float* pr = right.ptr<float>(y);
          const float* d = disparity.ptr<float>(y);
          for (int x = 0; x < left.cols; x += 2) {
            if (!std::isfinite(d[x])) continue;
            const int xr = x - static_cast<int>(std::lround(d[x]));
            if (xr < 0 || xr >= right.cols || !std::isfinite(pl[x]) || !std::isfinite(pr[xr])) {
              continue;
            }
            out.emplace_back(pl[x], pr[xr]);
          }
        }
      },
      kBandRows);
  size_t total = 0;
  for (const auto& band : bandPairs) total += band.size();
  if (static_cast<int>(total) < minPairs) return fallback();
  std::vector<cv::Vec2f> pairs;
  pairs.reserve(total);
  for (const auto& band : bandPairs) pairs.insert(pairs.end(), band.begin(), band.end());
  const auto start = medianSlopeMap(pairs, threads);
  if (!start) return fallback();
  std::pair<double, double> map = *start;
  std::vector<double> residuals(pairs.size());
  for (int pass = 0; pass < 2; ++pass) {
    forEachChunk(pairs.size(), threads, [&](size_t, size_t begin, size_t end) {
      for (size_t i = begin; i < end; ++i) {
        residuals[i] = std::abs(pairs[i][0] - (map.first * pairs[i][1] + map.second));
      }
    });
    const double limit = kInlierMads * 1.4826 * middleValue(residuals, threads);
    // (In the pairs' order: the sums, and so the map, do not depend on the threads.)
    GreyMoments moments;
    for (size_t i = 0; i < pairs.size(); ++i) {
      if (residuals[i] <= limit) moments.add(pairs[i][0], pairs[i][1]);
    }
    if (moments.count < minPairs) return fallback();
    const auto fitted = moments.map();
    if (!fitted) return fallback();
    map = *fitted;
  }
  return map;
}

std::pair<double, double> radiometricMapOfMatches(const cv::Mat& left, const cv::Mat& right,
                                                  const cv::Mat& disparity,
                                                  std::pair<double, double> fallback, int minPairs,
                                                  int threads) {
  return radiometricMapOfMatches(
      left, right, disparity, [fallback] { return fallback; }, minPairs, threads);
}

}  // namespace delineo::stereo::detail
