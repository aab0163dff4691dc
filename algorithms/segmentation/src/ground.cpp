#include "delineo/segmentation/ground.hpp"

#include <algorithm>
#include <climits>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>
#include <opencv2/imgproc/detail/gcgraph.hpp>

#include "delineo/core/error.hpp"
#include "delineo/segmentation/dtm.hpp"
#include "delineo/segmentation/ground_model.hpp"
#include "delineo/segmentation/regions.hpp"

namespace delineo::segmentation {

namespace {

using core::Error;
using core::ErrorCode;
using Labels = std::vector<GroundLabel>;

void checkInputs(const cv::Mat& dem, double gsd, const GroundParams& params) {
  params.validate();
  if (dem.empty()) throw Error(ErrorCode::UnsupportedInput, "the DEM is empty");
  if (dem.type() != CV_32FC1) throw Error(ErrorCode::UnsupportedInput, "the DEM must be one band of float32");
  if (!std::isfinite(gsd) || gsd <= 0.0) {
    std::ostringstream msg;
    msg << "the ground size of a pixel (gsd) must be a positive number of metres, not " << gsd;
    throw Error(ErrorCode::InvalidParameter, msg.str());
  }
}

// Metres to whole pixels, clamped to [lo, INT_MAX / 4].
int toPixels(double metres, double gsd, int lo) {
  return static_cast<int>(std::clamp(std::round(metres / gsd), static_cast<double>(lo), INT_MAX / 4.0));
}

// The DTM from the pixels of the regions labelled ground.
cv::Mat groundDtm(const RegionGraph& graph, const cv::Mat& dem, const Labels& labels, int windowPx,
                  const GroundParams& params, int* samples = nullptr) {
  cv::Mat ground(dem.size(), CV_8U);
  for (int y = 0; y < dem.rows; ++y) {
    const int* r = graph.labels.ptr<int>(y);
    unsigned char* g = ground.ptr<unsigned char>(y);
    for (int x = 0; x < dem.cols; ++x) g[x] = r[x] >= 0 && labels[static_cast<size_t>(r[x])] == GroundLabel::Ground;
  }
  const std::vector<GroundSample> points = sampleGround(dem, ground, windowPx, params.regionThreshold, params.dtmLevelShare);
  if (samples) *samples = static_cast<int>(points.size());
  return interpolateDtm(points, dem.size());
}

// Average, lowest and highest DTM height over each region's pixels.
std::vector<GroundUnder> groundUnderRegions(const RegionGraph& graph, const cv::Mat& dtm) {
  const size_t n = graph.regions.size();
  std::vector<GroundUnder> under(n, GroundUnder{0.0, std::numeric_limits<double>::infinity(),
                                                -std::numeric_limits<double>::infinity()});
  for (int y = 0; y < dtm.rows; ++y) {
    const int* r = graph.labels.ptr<int>(y);
    const float* g = dtm.ptr<float>(y);
    for (int x = 0; x < dtm.cols; ++x) {
      if (r[x] < 0) continue;
      GroundUnder& u = under[static_cast<size_t>(r[x])];
      u.average += g[x];
      u.lowest = std::min<double>(u.lowest, g[x]);
      u.highest = std::max<double>(u.highest, g[x]);
    }
  }
  for (size_t i = 0; i < n; ++i) under[i].average /= graph.regions[i].pixels;
  return under;
}

// The labels of least α_d U_d + α_c U_c given the ground under each region. The pair potentials
// are submodular (V(g,g) + V(a,a) <= V(g,a) + V(a,g) for every step), so a minimum cut gives the
// exact minimum: source side = ground, sink side = above.
Labels labelRegions(const RegionGraph& graph, const std::vector<GroundUnder>& under, const GroundParams& params) {
  const size_t n = graph.regions.size();
  const double wd = params.dataWeight, wc = 1.0 - params.dataWeight, d0 = params.criticalHeight;
  // A region's data potential counts once per link it has (at least once), so that α_d : α_c
  // weighs its own height over the DTM against its neighbours whatever their number.
  std::vector<int> degree(n, 0);
  for (const RegionLink& link : graph.links) ++degree[static_cast<size_t>(link.a)], ++degree[static_cast<size_t>(link.b)];
  std::vector<double> cost0(n, 0.0), cost1(n, 0.0);  // unary cost of ground, of above
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(under[i].average)) continue;  // no DTM at all: no data term
    const double w = wd * std::max(1, degree[i]);
    cost0[i] = w * dataPotential(GroundLabel::Ground, graph.regions[i].meanHeight, under[i], d0);
    cost1[i] = w * dataPotential(GroundLabel::Above, graph.regions[i].meanHeight, under[i], d0);
  }
  cv::detail::GCGraph<double> cut(static_cast<unsigned>(n), static_cast<unsigned>(2 * graph.links.size()));
  for (size_t i = 0; i < n; ++i) cut.addVtx();
  bool anyEdge = false;
  for (const RegionLink& link : graph.links) {
    const double gg = wc * contextualPotential(GroundLabel::Ground, GroundLabel::Ground, link.step, d0);
    const double ga = wc * contextualPotential(GroundLabel::Ground, GroundLabel::Above, link.step, d0);
    const double ag = wc * contextualPotential(GroundLabel::Above, GroundLabel::Ground, link.step, d0);
    const double aa = wc * contextualPotential(GroundLabel::Above, GroundLabel::Above, link.step, d0);
    // E(xa, xb) = gg + (ag - gg) xa + (aa - ag) xb + (ga + ag - gg - aa) (1 - xa) xb
    cost1[static_cast<size_t>(link.a)] += ag - gg;
    cost1[static_cast<size_t>(link.b)] += aa - ag;
    const double w = std::max(0.0, ga + ag - gg - aa);
    if (w > 0.0) {
      cut.addEdges(link.a, link.b, w, 0.0);
      anyEdge = true;
    }
  }
  Labels labels(n, GroundLabel::Ground);
  if (!anyEdge) {
    for (size_t i = 0; i < n; ++i) labels[i] = cost1[i] < cost0[i] ? GroundLabel::Above : GroundLabel::Ground;
    return labels;
  }
  for (size_t i = 0; i < n; ++i) cut.addTermWeights(static_cast<int>(i), cost1[i], cost0[i]);
  cut.maxFlow();
  for (size_t i = 0; i < n; ++i) {
    labels[i] = cut.inSourceSegment(static_cast<int>(i)) ? GroundLabel::Ground : GroundLabel::Above;
  }
  return labels;
}

struct Rounds {
  Labels labels;
  std::vector<bool> oscillating;
  cv::Mat dtm;
  int samples = 0;
  int iterations = 0;
  bool converged = false;
  bool canceled = false;
};

// Regions whose label differs among `states` become ground in `labels`; returns how many.
int groundOscillating(const std::vector<Labels>& states, Labels& labels, std::vector<bool>& oscillating) {
  int count = 0;
  for (size_t i = 0; i < labels.size(); ++i) {
    bool differs = false;
    for (const Labels& s : states) differs = differs || s[i] != states.front()[i];
    if (!differs) continue;
    oscillating[i] = true;
    labels[i] = GroundLabel::Ground;
    ++count;
  }
  return count;
}

// Stages 5 and 6: from all ground, DTM then labels until the labels repeat. A return to an
// earlier state is an oscillation: the regions that change along the cycle become ground, as
// do those still changing after the last round. A labelling without any ground (no DTM then,
// and nothing to pull a region back) is refused: the rounds stop at the previous labels.
Rounds labelAndDtm(const RegionGraph& graph, const cv::Mat& dem, const GroundParams& params, int windowPx,
                   core::Progress* progress) {
  Rounds out;
  const size_t n = graph.regions.size();
  out.labels.assign(n, GroundLabel::Ground);
  out.oscillating.assign(n, false);
  std::vector<Labels> history{out.labels};
  out.dtm = groundDtm(graph, dem, out.labels, windowPx, params, &out.samples);
  for (int round = 1; round <= params.maxIterations; ++round) {
    if (core::isCanceled(progress)) {
      out.canceled = true;
      return out;
    }
    Labels next = labelRegions(graph, groundUnderRegions(graph, out.dtm), params);
    out.iterations = round;
    if (std::find(next.begin(), next.end(), GroundLabel::Ground) == next.end() && !next.empty()) {
      return out;  // no ground left means no DTM: keep the last labels that had one
    }
    if (next == out.labels) {
      out.converged = true;
      return out;
    }
    const auto seen = std::find(history.begin(), history.end(), next);
    const bool cycle = seen != history.end();
    const bool last = round == params.maxIterations;
    if (cycle || last) {
      const std::vector<Labels> states = cycle ? std::vector<Labels>(seen, history.end())
                                               : std::vector<Labels>{out.labels, next};
      out.labels = next;
      groundOscillating(states, out.labels, out.oscillating);
      out.dtm = groundDtm(graph, dem, out.labels, windowPx, params, &out.samples);
      return out;
    }
    history.push_back(next);
    out.labels = std::move(next);
    out.dtm = groundDtm(graph, dem, out.labels, windowPx, params, &out.samples);
    core::report(progress, static_cast<double>(round) / params.maxIterations);
  }
  return out;
}

// For every pixel without a region, the nearest pixel with one (Euclidean distance transform).
cv::Mat nearestWithRegion(const cv::Mat& regions, std::vector<cv::Point>& pointOf) {
  const cv::Mat noRegion = regions < 0;
  cv::Mat distance, nearest;
  cv::distanceTransform(noRegion, distance, nearest, cv::DIST_L2, cv::DIST_MASK_5, cv::DIST_LABEL_PIXEL);
  pointOf.assign(regions.total() + 1, cv::Point(-1, -1));
  for (int y = 0; y < regions.rows; ++y) {
    for (int x = 0; x < regions.cols; ++x) {
      if (!noRegion.at<uchar>(y, x)) pointOf[static_cast<size_t>(nearest.at<int>(y, x))] = cv::Point(x, y);
    }
  }
  return nearest;
}

// Per region: its mean height, whether it is above-ground, and its 4-adjacent regions (sorted).
struct RegionContacts {
  std::vector<double> mean;
  std::vector<bool> above;
  std::vector<std::vector<int>> neighbours;
  bool adjacent(int a, int b) const {
    const auto& n = neighbours[static_cast<size_t>(a)];
    return std::binary_search(n.begin(), n.end(), b);
  }
  // Directly, or through one above-ground region between them (a wall between two roof levels).
  bool joined(int a, int b) const {
    if (adjacent(a, b)) return true;
    for (const int w : neighbours[static_cast<size_t>(a)]) {
      if (above[static_cast<size_t>(w)] && adjacent(w, b)) return true;
    }
    return false;
  }
};

RegionContacts regionContacts(const cv::Mat& regions, const cv::Mat& dem, const cv::Mat& above) {
  double maxLabel = -1;
  cv::minMaxLoc(regions, nullptr, &maxLabel);
  const size_t n = static_cast<size_t>(maxLabel + 1);
  RegionContacts c{std::vector<double>(n, 0.0), std::vector<bool>(n, false), std::vector<std::vector<int>>(n)};
  std::vector<int> count(n, 0);
  for (int y = 0; y < regions.rows; ++y) {
    for (int x = 0; x < regions.cols; ++x) {
      const int r = regions.at<int>(y, x);
      if (r < 0) continue;
      c.mean[static_cast<size_t>(r)] += dem.at<float>(y, x);
      ++count[static_cast<size_t>(r)];
      c.above[static_cast<size_t>(r)] = above.at<uchar>(y, x) != 0;
      const int right = x + 1 < regions.cols ? regions.at<int>(y, x + 1) : -1;
      const int below = y + 1 < regions.rows ? regions.at<int>(y + 1, x) : -1;
      for (const int o : {right, below}) {
        if (o < 0 || o == r) continue;
        c.neighbours[static_cast<size_t>(r)].push_back(o);
        c.neighbours[static_cast<size_t>(o)].push_back(r);
      }
    }
  }
  for (size_t i = 0; i < n; ++i) {
    c.mean[i] /= std::max(1, count[i]);
    auto& nb = c.neighbours[i];
    std::sort(nb.begin(), nb.end());
    nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
  }
  return c;
}

// Joined gap pixels next to a joined gap pixel of another region, when the two regions are not
// joined (regionContacts) and their mean heights differ by more than `minStep`, go back to no
// label: two buildings facing each other across an unmatched street stay two objects, while
// the patches of one roof that the matcher left apart (one level) stay together.
void unlabelSeams(const cv::Mat& regionsBefore, const cv::Mat& aboveBefore, const cv::Mat& dem, double minStep,
                  cv::Mat& regions, cv::Mat& above) {
  const RegionContacts contacts = regionContacts(regionsBefore, dem, aboveBefore);
  const cv::Mat joined = (regionsBefore < 0) & (regions >= 0);
  std::vector<cv::Point> seam;
  const cv::Point steps[4] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}};
  for (int y = 0; y < regions.rows; ++y) {
    for (int x = 0; x < regions.cols; ++x) {
      if (!joined.at<uchar>(y, x)) continue;
      const int r = regions.at<int>(y, x);
      for (const cv::Point& d : steps) {
        const cv::Point q(x + d.x, y + d.y);
        if (q.x < 0 || q.y < 0 || q.x >= regions.cols || q.y >= regions.rows || !joined.at<uchar>(q)) continue;
        const int rq = regions.at<int>(q);
        if (rq != r && std::abs(contacts.mean[static_cast<size_t>(r)] - contacts.mean[static_cast<size_t>(rq)]) > minStep &&
            !contacts.joined(r, rq)) {
          seam.emplace_back(x, y);
          break;
        }
      }
    }
  }
  for (const cv::Point& p : seam) {
    regions.at<int>(p) = -1;
    above.at<uchar>(p) = 0;
  }
}

// Kept gaps (no height) inside above-ground objects: a gap whose 8-adjacent border pixels are
// above-ground on more than `share` of them is labelled, each of its pixels with the label and
// region of the nearest pixel with a height. An occlusion beside a wall borders the roof on one
// side and the ground on the other and stays unlabelled; an unmatched patch of a roof or a crown
// joins it; a gap that spans a roof and the shaded street beside it is split between the two
// instead of joining the roof whole. In left-image geometry (x_right = x_left - d) what the right
// view cannot see lies left of a building: a run along a row that starts at the ground and ends
// at a surface more than `occlusionStep` higher stays unlabelled (ground hidden by that surface).
// Where the parts given to two separate regions of different heights meet, a seam stays
// unlabelled (unlabelSeams).
void labelKeptGaps(const dem::GapResult& gaps, double share, double occlusionStep, double seamStep, cv::Mat& regions,
                   cv::Mat& above) {
  const size_t n = gaps.gaps.size();
  std::vector<int> border(n, 0), aboveBorder(n, 0);
  const cv::Mat& g = gaps.gapLabels;
  for (int y = 0; y < g.rows; ++y) {
    for (int x = 0; x < g.cols; ++x) {
      const int gap = g.at<int>(y, x) - 1;
      if (gap < 0 || gaps.gaps[static_cast<size_t>(gap)].merged) continue;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int yy = y + dy, xx = x + dx;
          if (yy < 0 || xx < 0 || yy >= g.rows || xx >= g.cols || g.at<int>(yy, xx) != 0) continue;
          ++border[static_cast<size_t>(gap)];
          aboveBorder[static_cast<size_t>(gap)] += above.at<uchar>(yy, xx) != 0;
        }
      }
    }
  }
  const auto joins = [&](size_t i) { return border[i] > 0 && aboveBorder[i] > share * border[i]; };
  bool any = false;
  for (size_t i = 0; i < n; ++i) any = any || (!gaps.gaps[i].merged && joins(i));
  if (!any) return;
  std::vector<cv::Point> pointOf;
  const cv::Mat nearest = nearestWithRegion(regions, pointOf);
  const cv::Mat before = above.clone(), regionsBefore = regions.clone();
  for (int y = 0; y < g.rows; ++y) {
    int runStart = -1, runEnd = -1;  // the current run without region along the row: [runStart, runEnd)
    bool hidden = false;             // that run is hidden by a building at its right end
    for (int x = 0; x < g.cols; ++x) {
      const int gap = g.at<int>(y, x) - 1;
      if (gap < 0 || gaps.gaps[static_cast<size_t>(gap)].merged || !joins(static_cast<size_t>(gap))) continue;
      if (x >= runEnd) {
        for (runStart = x, runEnd = x; runEnd < g.cols && regionsBefore.at<int>(y, runEnd) < 0;) ++runEnd;
        hidden = runStart > 0 && runEnd < g.cols && !before.at<uchar>(y, runStart - 1) &&
                 gaps.dem.at<float>(y, runEnd) - gaps.dem.at<float>(y, runStart - 1) > occlusionStep;
      }
      if (hidden) continue;  // the ground the right view cannot see beside a building
      const cv::Point q = pointOf[static_cast<size_t>(nearest.at<int>(y, x))];
      if (q.x < 0 || !before.at<uchar>(q)) continue;
      above.at<uchar>(y, x) = 255;
      regions.at<int>(y, x) = regionsBefore.at<int>(q);
    }
  }
  unlabelSeams(regionsBefore, before, gaps.dem, seamStep, regions, above);
}

GroundResult canceledResult(GroundResult result) {
  result.status = core::RunStatus::Canceled;
  return result;
}

}  // namespace

void GroundParams::validate() const {
  core::checkDeclaredRanges(*this);
  gaps.validate();
  if (criticalHeight < 2.0 * regionThreshold) {
    std::ostringstream msg;
    msg << "critical-height (" << criticalHeight << " m) must be at least twice region-threshold ("
        << regionThreshold << " m)";
    throw Error(ErrorCode::InvalidParameter, msg.str());
  }
}

GroundResult segmentGround(const cv::Mat& dem, double gsd, const GroundParams& params, core::Progress* progress) {
  checkInputs(dem, gsd, params);
  GroundResult result;

  // 1. Elevation gaps: merged into their surface when their border is level, kept otherwise.
  core::Progress::Range gapProgress(progress, 0.0, 0.3);
  const dem::GapResult gaps = dem::handleGaps(dem, params.gaps, &gapProgress);
  if (gaps.status == core::RunStatus::Canceled) return canceledResult(result);
  result.demUsed = gaps.dem;
  result.mergedGapPixels = gaps.mergedPixels;
  result.keptGapPixels = gaps.keptPixels;

  // 2. Regions of homogeneous height (steps of at most δ_g between 4-neighbours), walls apart.
  //    In left-image geometry a wall the left view sees is a ramp of small steps from the
  //    ground to the eave: grown through, it would make the roof and the ground one region.
  const cv::Mat steep = params.wallSlope < 90.0
                            ? steepPixels(gaps.dem, std::tan(params.wallSlope * CV_PI / 180.0) * gsd)
                            : cv::Mat();
  int count = 0;
  cv::Mat labels = growRegions(gaps.dem, params.regionThreshold, steep, count);
  if (core::isCanceled(progress)) return canceledResult(result);
  core::report(progress, 0.35);

  // 3. Small regions (noise, speckles) merged into the neighbour of closest height.
  const double minPixels = std::ceil(params.minRegionArea / (gsd * gsd));
  count = mergeSmallRegions(labels, gaps.dem, count, static_cast<int>(std::min(minPixels, INT_MAX / 4.0)));
  if (core::isCanceled(progress)) return canceledResult(result);
  core::report(progress, 0.4);

  // 4. Region adjacency graph, with links across kept gaps along the rows.
  const RegionGraph graph = buildRegionGraph(labels, gaps.dem, count, toPixels(params.stepBand, gsd, 0),
                                             toPixels(params.gapLinkLength, gsd, 0));
  if (core::isCanceled(progress)) return canceledResult(result);
  core::report(progress, 0.45);

  // 5-6. Labelling and DTM rounds; oscillating regions become ground.
  core::Progress::Range roundProgress(progress, 0.45, 0.95);
  const Rounds rounds = labelAndDtm(graph, gaps.dem, params, toPixels(params.dtmWindow, gsd, 1), &roundProgress);
  if (rounds.canceled) return canceledResult(result);

  // 7. Outputs: regions, above-ground mask, DTM, nDSM.
  result.regions = graph.labels.clone();
  result.regionCount = count;
  result.links = static_cast<int>(graph.links.size());
  result.gapLinks = graph.gapLinks;
  result.dtm = rounds.dtm;
  result.groundSamples = rounds.samples;
  result.iterations = rounds.iterations;
  result.converged = rounds.converged;
  result.aboveGround = cv::Mat(dem.size(), CV_8U, cv::Scalar(0));
  for (int y = 0; y < dem.rows; ++y) {
    const int* r = graph.labels.ptr<int>(y);
    unsigned char* a = result.aboveGround.ptr<unsigned char>(y);
    for (int x = 0; x < dem.cols; ++x) {
      if (r[x] >= 0 && rounds.labels[static_cast<size_t>(r[x])] == GroundLabel::Above) a[x] = 255;
    }
  }
  // 8. Kept gaps inside above-ground objects (unmatched roof or crown patches) join them.
  if (params.gapAboveShare < 1.0) labelKeptGaps(gaps, params.gapAboveShare, params.criticalHeight, params.regionThreshold, result.regions,
                  result.aboveGround);
  result.regionInfo.resize(static_cast<size_t>(count));
  for (size_t i = 0; i < result.regionInfo.size(); ++i) {
    GroundRegionInfo& info = result.regionInfo[i];
    info.pixels = graph.regions[i].pixels;
    info.meanHeight = graph.regions[i].meanHeight;
    info.above = rounds.labels[i] == GroundLabel::Above;
    info.oscillating = rounds.oscillating[i];
    result.oscillatingRegions += info.oscillating ? 1 : 0;
  }
  cv::subtract(gaps.dem, result.dtm, result.ndsm);  // NaN in either stays NaN
  core::report(progress, 1.0);
  return result;
}

}  // namespace delineo::segmentation
