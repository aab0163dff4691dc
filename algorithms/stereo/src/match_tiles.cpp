// Large pairs matched in overlapping tiles (see match_tiles.hpp and docs/stereo.md, "Large
// pairs: tiles").
#include "match_tiles.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fill_internal.hpp"
#include "radiometry.hpp"
#include "workers.hpp"

namespace delineo::stereo::detail {

namespace {
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Bounds of `parts` near-equal intervals of [0, length): part i is [bounds[i], bounds[i + 1]).
std::vector<int> splitEvenly(int length, int parts) {
  std::vector<int> bounds(static_cast<size_t>(parts) + 1);
  for (int i = 0; i <= parts; ++i) {
    bounds[static_cast<size_t>(i)] =
        static_cast<int>(static_cast<long long>(length) * i / parts);
  }
  return bounds;
}

int roundDownTo(int value, int step) {
  return value - value % step;  // value >= 0
}

// The crop of the kept part [x0, x1) x [y0, y1). A kept left pixel x reads the right pixels
// x − dmax .. x − dmin; their own right-view matches (the symmetric check) read the left pixels
// up to (dmax − dmin) from x: the columns take the farther of the two on each side.
cv::Rect cropAround(const cv::Rect& kept, cv::Size size, int context, int dmin, int dmax,
                    int alignment) {
  const int range = dmax - dmin;
  const int before = std::max(range, dmax) + context;
  const int after = std::max(range, -dmin) + context;
  const int x0 = roundDownTo(std::max(0, kept.x - before), alignment);
  const int y0 = roundDownTo(std::max(0, kept.y - context), alignment);
  const int x1 = std::min(size.width, kept.br().x + after);
  const int y1 = std::min(size.height, kept.br().y + context);
  return {x0, y0, x1 - x0, y1 - y0};
}

// The tile's kept part of `from` (the crop's map) into `into` (the image's).
void copyKeptPart(const cv::Mat& from, const MatchTile& tile, cv::Mat& into) {
  const cv::Rect inCrop(tile.kept.tl() - tile.crop.tl(), tile.kept.size());
  from(inCrop).copyTo(into(tile.kept));
}

MatchResult canceledMatch() {
  MatchResult r;
  r.status = core::RunStatus::Canceled;
  return r;
}

double keptArea(const MatchTile& tile) {
  return static_cast<double>(tile.kept.area());
}
}  // namespace

namespace {
// The noise sigma of an image with its nodata (non-finite) pixels taken as 0, as localMoments().
double noiseOfFinitePixels(const cv::Mat& image) {
  cv::Mat finite(image.size(), CV_32F);
  for (int y = 0; y < image.rows; ++y) {
    const float* in = image.ptr<float>(y);
    float* out = finite.ptr<float>(y);
    for (int x = 0; x < image.cols; ++x) out[x] = std::isfinite(in[x]) ? in[x] : 0.0F;
  }
  return noiseSigma(finite);
}
}  // namespace

WholePairStatistics wholePairStatistics(const cv::Mat& left, const cv::Mat& right, int dmin,
                                        int dmax, int threads) {
  WholePairStatistics s;
  s.pixels = static_cast<double>(left.total());
  runTasks({[&] { s.leftNoise = noiseOfFinitePixels(left); },
            [&] { s.rightNoise = noiseOfFinitePixels(right); }},
           threads);
  s.leftMedianGrey = medianGrey(left);
  s.greyMap = radiometricMap(left, right, dmin, dmax);
  return s;
}

int matchTileContext(int levels) {
  return std::max(kTileContext, kTileContextCoarsest << (levels - 1));
}

bool matchesInTiles(cv::Size size, int tile) {
  return tile > 0 && (size.width > tile || size.height > tile);
}

std::vector<MatchTile> matchTileGrid(cv::Size size, int tile, int context, int dmin, int dmax,
                                     int alignment) {
  const int columns = (size.width + tile - 1) / tile, rows = (size.height + tile - 1) / tile;
  const std::vector<int> xs = splitEvenly(size.width, columns), ys = splitEvenly(size.height, rows);
  std::vector<MatchTile> tiles;
  for (int j = 0; j < rows; ++j) {
    for (int i = 0; i < columns; ++i) {
      const auto ui = static_cast<size_t>(i), uj = static_cast<size_t>(j);
      const cv::Rect kept(xs[ui], ys[uj], xs[ui + 1] - xs[ui], ys[uj + 1] - ys[uj]);
      tiles.push_back({kept, cropAround(kept, size, context, dmin, dmax, alignment)});
    }
  }
  return tiles;
}

MatchResult matchInTiles(const cv::Mat& left, const cv::Mat& right,
                         const std::vector<MatchTile>& tiles, const TileMatcher& matchTile,
                         core::Progress* progress) {
  MatchResult stitched;
  stitched.disparity.create(left.size(), CV_32F);
  stitched.score.create(left.size(), CV_32F);
  stitched.disparity.setTo(kNaN);
  stitched.score.setTo(kNaN);
  double total = 0, done = 0;
  for (const MatchTile& tile : tiles) total += keptArea(tile);
  for (const MatchTile& tile : tiles) {
    if (core::isCanceled(progress)) return canceledMatch();
    core::Progress::Range share(progress, done / total, (done + keptArea(tile)) / total);
    // Copies: the steps read their images as whole, continuous matrices.
    const MatchResult part =
        matchTile(left(tile.crop).clone(), right(tile.crop).clone(), progress ? &share : nullptr);
    if (part.status == core::RunStatus::Canceled) return canceledMatch();
    copyKeptPart(part.disparity, tile, stitched.disparity);
    copyKeptPart(part.score, tile, stitched.score);
    stitched.levelsUsed = std::max(stitched.levelsUsed, part.levelsUsed);
    done += keptArea(tile);
  }
  core::report(progress, 1.0);
  return stitched;
}

}  // namespace delineo::stereo::detail
