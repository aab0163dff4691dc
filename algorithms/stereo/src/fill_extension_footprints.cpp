// The cells of the fill's extensions for RowOrderedTasks: which of them may run side by side
// (see ExtensionFootprints in match_fill.hpp).
#include "fill_internal.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace delineo::stereo::detail {

namespace {

// Right-view positions x − d from lo to hi (lo > hi: none).
struct RightSpan {
  double lo = 1, hi = 0;
};

// The cells of extensionFootprints: the image's tiles of kImageTile px, then the right view's,
// columns of kRightTile positions by rows of kImageTile.
struct FootprintTiles {
  static constexpr int kImageTile = 32, kRightTile = 16;

  FootprintTiles(cv::Size size, int dmin, int dmax)
      : image(0, 0, size.width, size.height),
        tilesX((size.width + kImageTile - 1) / kImageTile),
        tilesY((size.height + kImageTile - 1) / kImageTile),
        shift(dmax + 4.0),
        rightTilesX((size.width + (dmax - dmin) + 8 + kRightTile - 1) / kRightTile) {}

  int cellCount() const { return tilesX * tilesY + rightTilesX * tilesY; }

  // The image's tiles `outer` and the pixel around it meet.
  void addImageCells(const cv::Rect& outer, std::vector<int>& cells) const {
    addTileCells(cv::Rect(outer.x - 1, outer.y - 1, outer.width + 2, outer.height + 2) & image,
                 kImageTile, tilesX, 0, cells);
  }

  // The right view's tiles of the span's positions (with a margin: the test's 0.5 px and the
  // values' rounding to float) on the rows of `outer`.
  void addRightCells(const RightSpan& span, const cv::Rect& outer, std::vector<int>& cells) const {
    const int first = std::clamp(static_cast<int>(std::floor((span.lo - 2.0 + shift) / kRightTile)),
                                 0, rightTilesX - 1);
    const int last = std::clamp(static_cast<int>(std::floor((span.hi + 2.0 + shift) / kRightTile)),
                                0, rightTilesX - 1);
    const cv::Rect columns(first, outer.y / kImageTile, last - first + 1,
                           (outer.br().y - 1) / kImageTile - outer.y / kImageTile + 1);
    addTileCells(columns, 1, rightTilesX, tilesX * tilesY, cells);
  }

  const cv::Rect image;
  const int tilesX, tilesY;
  // Right-view positions x − d lie in [−dmax, cols − 1 − dmin]; shifted to start at 0, with
  // room for the margins.
  const double shift;
  const int rightTilesX;
};

// Each extension's `outer` (its box ± extendReach, within the image) and the right-view
// positions of its candidates.
struct ExtensionReach {
  std::vector<cv::Rect> outers;
  std::vector<RightSpan> candidates;
};

ExtensionReach extensionReach(const std::vector<cv::Rect>& boxes,
                              const std::vector<FillPlane>& planes, int reach, int dmin, int dmax,
                              const cv::Rect& image) {
  ExtensionReach out;
  for (size_t k = 0; k < boxes.size(); ++k) {
    const cv::Rect& box = boxes[k];
    const FillPlane& plane = planes[k];
    const cv::Rect outer =
        cv::Rect(box.x - reach, box.y - reach, box.width + 2 * reach, box.height + 2 * reach) &
        image;
    out.outers.push_back(outer);
    // The plane's extremes over `outer` lie at its corners; a candidate out of the range is
    // never tested (matchesAt).
    double pmin = std::numeric_limits<double>::infinity(), pmax = -pmin;
    for (const int x : {outer.x, outer.br().x - 1}) {
      for (const int y : {outer.y, outer.br().y - 1}) {
        pmin = std::min(pmin, plane.at(x, y));
        pmax = std::max(pmax, plane.at(x, y));
      }
    }
    pmin = std::max(pmin, static_cast<double>(dmin));
    pmax = std::min(pmax, static_cast<double>(dmax));
    RightSpan span;
    if (pmin <= pmax && !outer.empty()) span = {outer.x - pmax, outer.br().x - 1 - pmin};
    out.candidates.push_back(span);
  }
  return out;
}

// The right-view positions x − d of the matches of a map, their least and greatest by row over
// blocks of kBlock columns: one pass over the map instead of one over each `outer` (those
// overlap, and took ~3 ms at 1000² alone on one worker).
class MatchPositionBlocks {
 public:
  MatchPositionBlocks() = default;  // none
  explicit MatchPositionBlocks(const cv::Mat& disparity)
      : blocksX_((disparity.cols + kBlock - 1) / kBlock),
        lo_(static_cast<size_t>(disparity.rows) * static_cast<size_t>(blocksX_), kInf),
        hi_(lo_.size(), -kInf) {
    const int cols = disparity.cols;
    for (int y = 0; y < disparity.rows; ++y) {
      const float* d = disparity.ptr<float>(y);
      for (int b = 0; b < blocksX_; ++b) {
        float lo = kInf, hi = -kInf;
        for (int x = b * kBlock; x < std::min(cols, (b + 1) * kBlock); ++x) {
          const bool isNumber = d[x] == d[x];  // (inf would give inf positions: as safe)
          const float p = static_cast<float>(x) - d[x];
          lo = std::min(lo, isNumber ? p : kInf);
          hi = std::max(hi, isNumber ? p : -kInf);
        }
        lo_[at(y, b)] = lo;
        hi_[at(y, b)] = hi;
      }
    }
  }

  // The matches' positions over the blocks `outer` meets (a few pixels more: as safe).
  RightSpan over(const cv::Rect& outer) const {
    RightSpan span{kInf, -kInf};
    for (int y = outer.y; y < outer.br().y; ++y) {
      for (int b = outer.x / kBlock; b <= (outer.br().x - 1) / kBlock; ++b) {
        span.lo = std::min(span.lo, static_cast<double>(lo_[at(y, b)]));
        span.hi = std::max(span.hi, static_cast<double>(hi_[at(y, b)]));
      }
    }
    return span;
  }

 private:
  static constexpr int kBlock = 32;
  static constexpr float kInf = std::numeric_limits<float>::infinity();
  size_t at(int y, int b) const {
    return static_cast<size_t>(y) * static_cast<size_t>(blocksX_) + static_cast<size_t>(b);
  }

  int blocksX_ = 0;
  std::vector<float> lo_, hi_;
};

}  // namespace

ExtensionFootprints extensionFootprints(const std::vector<cv::Rect>& boxes,
                                        const std::vector<FillPlane>& planes,
                                        const RegionFillSettings& settings, int dmin, int dmax,
                                        const cv::Mat& disparity) {
  CV_Assert(boxes.size() == planes.size() && disparity.type() == CV_32F);
  const FootprintTiles tiles(disparity.size(), dmin, dmax);
  ExtensionFootprints out;
  out.cellCount = tiles.cellCount();
  const ExtensionReach reach =
      extensionReach(boxes, planes, settings.extendReach, dmin, dmax, tiles.image);
  const std::vector<cv::Rect>& outers = reach.outers;
  const std::vector<RightSpan>& candidates = reach.candidates;
  // An extension may replace matches: those now (in blocks, made once) and the values of the
  // earlier extensions that meet it.
  const bool replaces = settings.extendReplaceOff > 0 && boxes.size() > 1;
  const MatchPositionBlocks matches =
      replaces ? MatchPositionBlocks(disparity) : MatchPositionBlocks();
  for (size_t k = 0; k < boxes.size(); ++k) {
    const cv::Rect& outer = outers[k];
    std::vector<int>& cells = out.cells.emplace_back();
    if (outer.empty()) continue;
    tiles.addImageCells(outer, cells);
    // The right-view positions it reads or changes.
    std::vector<RightSpan> spans;
    if (candidates[k].lo <= candidates[k].hi) spans.push_back(candidates[k]);
    if (replaces) {
      const RightSpan now = matches.over(outer);
      if (now.lo <= now.hi) spans.push_back(now);
      for (size_t h = 0; h < k; ++h) {
        if ((outers[h] & outer).empty() || candidates[h].lo > candidates[h].hi) continue;
        spans.push_back(candidates[h]);
      }
    }
    for (const RightSpan& span : spans) tiles.addRightCells(span, outer, cells);
  }
  return out;
}

}  // namespace delineo::stereo::detail
