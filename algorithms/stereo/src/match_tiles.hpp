#pragma once
// Large pairs matched in overlapping tiles, one after another (internal to delineo_stereo): each
// tile's crop holds its kept part plus the columns every disparity of the range reaches and the
// context the levels and the region-based steps read; the kept parts are stitched into the maps.
#include <functional>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/progress.hpp"
#include "delineo/stereo/match.hpp"

namespace delineo::stereo::detail {

// Context around a tile's kept part beyond the range's columns (docs/stereo.md, "Large pairs:
// tiles"): at least kTileContext px for the steps on the full-resolution map (regions, their
// extensions, the snapping, the roof planes) and kTileContextCoarsest pixels of the coarsest
// pyramid level for its windows and search neighbourhoods.
constexpr int kTileContext = 128;
constexpr int kTileContextCoarsest = 16;

// A tile: the part of the maps it writes (`kept`) and the part of both images it matches (`crop`),
// in image coordinates.
struct MatchTile {
  cv::Rect kept;
  cv::Rect crop;
};

// True when an image of `size` is matched in tiles of `tile` px (0 = never).
bool matchesInTiles(cv::Size size, int tile);

// The tiles of an image of `size`: kept parts of at most `tile` px a side, of near-equal sizes,
// covering every pixel once, row by row; each crop reaches `context` px beyond its kept part,
// plus on the columns what the disparities [dmin, dmax] and the right view's own validation
// reach, its origin rounded down to a multiple of `alignment` (the coarsest pyramid level's
// pixel: the crop's pyramid then samples the image's) and clipped to the image.
// The context for a pyramid of `levels`.
int matchTileContext(int levels);

std::vector<MatchTile> matchTileGrid(cv::Size size, int tile, int context, int dmin, int dmax,
                                     int alignment);

// What a tile takes from the whole pair rather than from its crops: the grey mapping of both
// views (match.cpp) and each view's noise sigma.
struct WholePairStatistics {
  double greyOffset = 0, greyScale = 1;
  double leftNoise = -1, rightNoise = -1;  // < 0: the crop's own estimate
  double pixels = 0;                       // the image's
  double leftMedianGrey = 0;               // the flat-region fill's (fill_own_light.cpp)
  std::pair<double, double> greyMap{1, 0};  // the fill's right-to-left map (radiometry.hpp)
};

// The whole pair's statistics but the grey mapping (match.cpp's), as the matcher's steps estimate
// them on the pair they are given.
WholePairStatistics wholePairStatistics(const cv::Mat& left, const cv::Mat& right, int dmin,
                                        int dmax, int threads);

// One tile's match: its crops of both images, and the tile's share of the progress.
using TileMatcher =
    std::function<MatchResult(const cv::Mat& left, const cv::Mat& right, core::Progress*)>;

// The maps of `left`/`right` matched tile by tile through `matchTile`, each tile's kept part
// copied into them; the bar goes through the tiles by kept area. Canceled (between or inside a
// tile): status Canceled and empty maps.
MatchResult matchInTiles(const cv::Mat& left, const cv::Mat& right,
                         const std::vector<MatchTile>& tiles, const TileMatcher& matchTile,
                         core::Progress* progress);

}  // namespace delineo::stereo::detail
