#include "roof_planes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "union_find.hpp"
#include "workers.hpp"

namespace delineo::stereo::detail {

namespace {

constexpr int kPiece = -2;  // label of a matched pixel whose surface is a small piece

// One surface and its plane d = a (x − cx) + b (y − cy) + c, in coordinates centred on the
// surface (the normal equations stay well conditioned far from the image's origin).
struct Surface {
  long count = 0;
  double cx = 0, cy = 0;
  double a = 0, b = 0, c = 0;
  double z0 = 0;     // px, the disparity of its first pixel (a reference for the sums)
  double rms = 0;    // px, residuals of the pixels the last fit used
  long inliers = 0;  // pixels within the inlier band of the last plane
  bool fitted = true;
  long ring = 0, lower = 0;  // matched pixels around it, and those well below its plane
  cv::Rect box;              // its bounding box
  [[nodiscard]] double at(int x, int y) const { return a * (x - cx) + b * (y - cy) + c; }
};

// A row's matched pixels x0..x1 whose left neighbours are within `link` of them: a piece of a
// surface.
struct Run {
  int y, x0, x1;
};

// The runs of every row, in row order: row y's are runs[rowStart[y] .. rowStart[y + 1]).
struct RowRuns {
  std::vector<Run> runs;
  std::vector<size_t> rowStart;
};

// The runs, found by bands of rows on `threads` workers and put together in row order (one pass
// on one worker, they were most of this labelling's ~2.5 ms at 1000²).
RowRuns rowRuns(const cv::Mat& disparity, float link, int threads) {
  const int W = disparity.cols, H = disparity.rows;
  constexpr int kBandRows = 32;
  std::vector<std::vector<Run>> bandRuns(static_cast<size_t>((H + kBandRows - 1) / kBandRows));
  std::vector<size_t> runsInRow(static_cast<size_t>(H), 0);
  forRowBands(
      H, threads,
      [&](int rowStart, int rowEnd) {
        std::vector<Run>& out = bandRuns[static_cast<size_t>(rowStart / kBandRows)];
        for (int y = rowStart; y < rowEnd; ++y) {
          const size_t before = out.size();
          const float* d = disparity.ptr<float>(y);
          for (int x = 0; x < W; ++x) {
            if (!std::isfinite(d[x])) continue;
            const int x0 = x;
            while (x + 1 < W && std::abs(d[x + 1] - d[x]) <= link) ++x;  // (NaN fails the test)
            out.push_back({y, x0, x});
          }
          runsInRow[static_cast<size_t>(y)] = out.size() - before;
        }
      },
      kBandRows);
  RowRuns rows;
  for (const std::vector<Run>& band : bandRuns) {
    rows.runs.insert(rows.runs.end(), band.begin(), band.end());
  }
  rows.rowStart.assign(static_cast<size_t>(H) + 1, 0);
  for (int y = 0; y < H; ++y) {
    rows.rowStart[static_cast<size_t>(y) + 1] =
        rows.rowStart[static_cast<size_t>(y)] + runsInRow[static_cast<size_t>(y)];
  }
  return rows;
}

// The union-find parents of the runs, joined across rows where a pixel of one and the pixel
// below it in the other are within `link`.
std::vector<int> joinRunsAcrossRows(const cv::Mat& disparity, const RowRuns& rows, float link) {
  const std::vector<Run>& runs = rows.runs;
  const std::vector<size_t>& rowStart = rows.rowStart;
  std::vector<int> parent(runs.size());
  for (size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  for (int y = 1; y < disparity.rows; ++y) {
    const float* up = disparity.ptr<float>(y - 1);
    const float* d = disparity.ptr<float>(y);
    size_t a = rowStart[static_cast<size_t>(y - 1)], b = rowStart[static_cast<size_t>(y)];
    const size_t aEnd = rowStart[static_cast<size_t>(y)],
                 bEnd = rowStart[static_cast<size_t>(y) + 1];
    while (a < aEnd && b < bEnd) {
      const Run& ra = runs[a];
      const Run& rb = runs[b];
      for (int x = std::max(ra.x0, rb.x0); x <= std::min(ra.x1, rb.x1); ++x) {
        if (std::abs(d[x] - up[x]) <= link) {
          joinRoots(parent, static_cast<int>(a), static_cast<int>(b));
          break;
        }
      }
      if (ra.x1 < rb.x1) {
        ++a;
      } else {
        ++b;
      }
    }
  }
  return parent;
}

// The labels of the joined runs (see labelSurfaces), numbered in the order of their first run,
// with the surfaces' pixel counts, centroids, first disparities and boxes.
cv::Mat numberSurfaces(const cv::Mat& disparity, const std::vector<Run>& runs,
                       std::vector<int>& parent, int minPixels, int maxPiece,
                       std::vector<Surface>& surfaces) {
  std::vector<int> size(runs.size(), 0);
  for (size_t i = 0; i < runs.size(); ++i) {
    size[static_cast<size_t>(findRoot(parent, static_cast<int>(i)))] += runs[i].x1 - runs[i].x0 + 1;
  }
  std::vector<int> index(runs.size(), -1);
  cv::Mat labels(disparity.size(), CV_32S, cv::Scalar(-1));
  for (size_t i = 0; i < runs.size(); ++i) {
    const Run& run = runs[i];
    const auto root = static_cast<size_t>(findRoot(parent, static_cast<int>(i)));
    int* l = labels.ptr<int>(run.y);
    if (size[root] < minPixels) {
      if (size[root] < maxPiece) std::fill(l + run.x0, l + run.x1 + 1, kPiece);
      continue;
    }
    if (index[root] < 0) {
      index[root] = static_cast<int>(surfaces.size());
      surfaces.emplace_back();
      surfaces.back().z0 = disparity.at<float>(run.y, run.x0);
      surfaces.back().box = cv::Rect(run.x0, run.y, 1, 1);
    }
    Surface& s = surfaces[static_cast<size_t>(index[root])];
    s.box |= cv::Rect(run.x0, run.y, run.x1 - run.x0 + 1, 1);
    for (int x = run.x0; x <= run.x1; ++x) {
      l[x] = index[root];
      ++s.count;
      s.cx += x;
      s.cy += run.y;
    }
  }
  for (Surface& s : surfaces) {
    s.cx /= static_cast<double>(s.count);
    s.cy /= static_cast<double>(s.count);
  }
  return labels;
}

// The 4-connected surfaces of `disparity` (neighbours within `link`), as labels 0.. of the
// surfaces of minPixels or more (kPiece on the matched pixels of those under maxPiece, −1
// elsewhere), with their pixel counts and centroids. The union-find works on runs of a row's
// pixels, not on pixels.
cv::Mat labelSurfaces(const cv::Mat& disparity, float link, int minPixels, int maxPiece,
                      int threads, std::vector<Surface>& surfaces) {
  const RowRuns rows = rowRuns(disparity, link, threads);
  std::vector<int> parent = joinRunsAcrossRows(disparity, rows, link);
  return numberSurfaces(disparity, rows.runs, parent, minPixels, maxPiece, surfaces);
}

// Moments of u = x − cx, v = y − cy and z = d − z0 over a surface's kept pixels (z0: the
// surface's first pixel, so that Σz² stays small and the residual sum below keeps its precision).
struct Moments {
  double n = 0, u = 0, v = 0, uu = 0, uv = 0, vv = 0, z = 0, uz = 0, vz = 0, zz = 0;

  void add(double pu, double pv, double pz) {
    n += 1;
    u += pu;
    v += pv;
    uu += pu * pu;
    uv += pu * pv;
    vv += pv * pv;
    z += pz;
    uz += pu * pz;
    vz += pv * pz;
    zz += pz * pz;
  }
  Moments& operator+=(const Moments& b) {
    n += b.n;
    u += b.u;
    v += b.v;
    uu += b.uu;
    uv += b.uv;
    vv += b.vv;
    z += b.z;
    uz += b.uz;
    vz += b.vz;
    zz += b.zz;
    return *this;
  }
};

// The least-squares plane of the moments and the RMS of its residuals, into f (f.fitted false
// when they hold a line of pixels or nothing).
void solvePlane(const Moments& t, Surface& f) {
  const cv::Matx33d m(t.uu, t.uv, t.u, t.uv, t.vv, t.v, t.u, t.v, t.n);
  cv::Vec3d plane;
  if (t.n < 3 || !cv::solve(m, cv::Vec3d(t.uz, t.vz, t.z), plane, cv::DECOMP_LU)) {
    f.fitted = false;  // a line of pixels, or nothing left in the band
    return;
  }
  f.a = plane[0];
  f.b = plane[1];
  f.c = plane[2] + f.z0;
  // The least-squares residual is orthogonal to the regressors: Σr² = Σz² − θ·(Σuz, Σvz, Σz).
  const double sq = t.zz - (plane[0] * t.uz + plane[1] * t.vz + plane[2] * t.z);
  f.rms = std::sqrt(std::max(0.0, sq) / t.n);
}

// The passes of fitPlanes over the image, by bands of kBandRows rows, each band with its own
// moments and inlier counts by surface, added up in band order.
struct TrimmedFit {
  static constexpr int kBandRows = 32;

  void pass(bool trim, bool sum);
  void passOverRows(int rowStart, int rowEnd, bool trim, bool sum);
  void countInliers();
  void solvePlanes();

  const cv::Mat& disparity;
  const cv::Mat& labels;
  cv::Mat& keep;
  std::vector<Surface>& surfaces;
  const RoofPlaneSettings& s;
  const size_t bands = static_cast<size_t>((disparity.rows + kBandRows - 1) / kBandRows);
  std::vector<std::vector<Moments>> bandSums = std::vector<std::vector<Moments>>(bands);
  std::vector<std::vector<long>> bandInliers = std::vector<std::vector<long>>(bands);
};

// One pass: with `trim`, `keep` set from the surfaces' planes; with `sum`, the moments of the
// pixels kept.
void TrimmedFit::pass(bool trim, bool sum) {
  forRowBands(
      disparity.rows, s.threads,
      [&](int rowStart, int rowEnd) { passOverRows(rowStart, rowEnd, trim, sum); }, kBandRows);
}

void TrimmedFit::passOverRows(int rowStart, int rowEnd, bool trim, bool sum) {
  const auto band = static_cast<size_t>(rowStart / kBandRows);
  std::vector<Moments>& sums = bandSums[band];
  std::vector<long>& inliers = bandInliers[band];
  if (sum) sums.assign(surfaces.size(), Moments{});
  if (trim) inliers.assign(surfaces.size(), 0);
  for (int y = rowStart; y < rowEnd; ++y) {
    const float* d = disparity.ptr<float>(y);
    const int* l = labels.ptr<int>(y);
    std::uint8_t* k = keep.ptr<std::uint8_t>(y);
    for (int x = 0; x < disparity.cols; ++x) {
      if (l[x] < 0) continue;
      const Surface& f = surfaces[static_cast<size_t>(l[x])];
      if (trim) {
        const double within = std::max(s.trimFactor * f.rms, s.trimFloor);
        const bool in = f.fitted && std::abs(d[x] - f.at(x, y)) <= within;
        k[x] = in ? 1 : 0;
        inliers[static_cast<size_t>(l[x])] += in ? 1 : 0;
      }
      if (!sum || k[x] == 0) continue;
      sums[static_cast<size_t>(l[x])].add(x - f.cx, y - f.cy, d[x] - f.z0);
    }
  }
}

// Each surface's inliers, from the bands' counts.
void TrimmedFit::countInliers() {
  for (size_t i = 0; i < surfaces.size(); ++i) {
    surfaces[i].inliers = 0;
    for (const std::vector<long>& band : bandInliers) surfaces[i].inliers += band[i];
  }
}

// Each surface's plane, from the bands' moments.
void TrimmedFit::solvePlanes() {
  for (size_t i = 0; i < surfaces.size(); ++i) {
    Moments t;
    for (const std::vector<Moments>& band : bandSums) t += band[i];
    solvePlane(t, surfaces[i]);
  }
}

// The trimmed fit, `rounds` rounds: the least-squares plane of each surface's pixels marked in
// `keep`, the RMS of their residuals to it, then `keep` set anew to the pixels within the band.
// One pass over the image per round plus one: a pass sets `keep` from the previous round's planes
// and sums the next round's moments over the pixels it keeps. Bands of rows on `threads`
// workers, each with its own sums, added up in band order: the same result for any number of
// threads.
void fitPlanes(const cv::Mat& disparity, const cv::Mat& labels, cv::Mat& keep,
               std::vector<Surface>& surfaces, const RoofPlaneSettings& s, int rounds) {
  TrimmedFit fit{
      .disparity = disparity, .labels = labels, .keep = keep, .surfaces = surfaces, .s = s};
  for (int pass = 0; pass <= rounds; ++pass) {
    const bool trim = pass > 0;      // keep from the previous round's planes
    const bool sum = pass < rounds;  // this round's moments
    fit.pass(trim, sum);
    if (trim) fit.countInliers();
    if (!sum) break;
    fit.solvePlanes();
  }
}

// fitRoofPlanes in its stages (docs/stereo.md step 18): the surfaces labelled, fitted, and the
// planar ones kept (fitSurfaces); the ring around each measured (measureRings) and the raised
// ones kept (keepRaised); their inliers set to their plane (setInliers); then the small pieces
// on or around them within absorbWithin of it (absorbPieces).
struct RoofPlanes {
  bool fitSurfaces();
  void measureRings();
  void measureRing(size_t i);
  cv::Mat surfaceWithHoles(size_t i, const cv::Rect& area) const;
  cv::Mat acrossRim(const Surface& f, const cv::Mat& filled, const cv::Rect& area) const;
  void countRing(Surface& f, const cv::Mat& across, const cv::Rect& area) const;
  int keepRaised();
  long setInliers();
  long absorbPieces();
  int absorbAround(size_t i, cv::Mat& taken);

  cv::Mat& disparity;
  const RoofPlaneSettings& s;
  // The roofs' other pixels (absorbPieces) come from small pieces only: a piece as large as a
  // surface is a structure (a box on a roof, a parapet), not the matches' noise.
  const int maxPiece = s.minPixels;
  const cv::Rect image = cv::Rect(0, 0, disparity.cols, disparity.rows);
  const cv::Mat square = cv::Mat::ones(2 * s.ringRadius + 1, 2 * s.ringRadius + 1, CV_8U);
  std::vector<Surface> surfaces{};
  cv::Mat labels{};                    // the surfaces (labelSurfaces)
  cv::Mat keep{};                      // each surface's pixels within its plane's inlier band
  std::vector<std::uint8_t> planar{};  // by surface: it takes its plane
  // By planar surface: its box with the margin the ring needs, and over it where its small pieces
  // are looked for.
  std::vector<cv::Rect> areaOf{};
  std::vector<cv::Mat> grownOf{};
};

// The surfaces labelled and fitted with their trimmed planes; `planar` marks those whose inliers'
// RMS is within maxResidual and that are minInlierShare of their pixels. False when there is no
// surface.
bool RoofPlanes::fitSurfaces() {
  labels = labelSurfaces(disparity, s.link, s.minPixels, maxPiece, s.threads, surfaces);
  if (surfaces.empty()) return false;
  keep = cv::Mat(disparity.size(), CV_8U);
  keep.setTo(1);
  constexpr int kRounds = 3;  // the band settles after two; the third confirms it
  fitPlanes(disparity, labels, keep, surfaces, s, kRounds);
  planar.assign(surfaces.size(), 0);
  for (size_t i = 0; i < surfaces.size(); ++i) {
    const Surface& f = surfaces[i];
    planar[i] = f.fitted && f.rms <= s.maxResidual &&
                        static_cast<double>(f.inliers) >= s.minInlierShare * f.count
                    ? 1
                    : 0;
  }
  return true;
}

// The ring around each planar surface, one task per surface (each writes only its own ring, mask
// and area).
void RoofPlanes::measureRings() {
  grownOf.resize(surfaces.size());
  areaOf.resize(surfaces.size());
  std::vector<std::function<void()>> ringTasks;
  for (size_t i = 0; i < surfaces.size(); ++i) {
    if (planar[i] == 0) continue;
    ringTasks.emplace_back([this, i] { measureRing(i); });
  }
  runTasks(ringTasks, s.threads);
}

// The ring around planar surface i: the matched pixels within ringRadius outside its outer
// outline (its holes filled: the ground around a sunken courtyard would be raised above it),
// past its rim; and where its small pieces are looked for (grownOf).
void RoofPlanes::measureRing(size_t i) {
  Surface& f = surfaces[i];
  // The box with a margin of r + 1 + gapReach: the complement's part reached from the margin
  // is outside.
  const int m = s.ringRadius + 1 + s.gapReach;
  const cv::Rect& b = f.box;
  const cv::Rect area(b.x - m, b.y - m, b.width + 2 * m, b.height + 2 * m);
  const cv::Mat filled = surfaceWithHoles(i, area);
  cv::Mat grown;
  cv::dilate(filled, grown, square);
  areaOf[i] = area;
  const cv::Mat across = acrossRim(f, filled, area);
  // The roofs' other pixels (absorbPieces) are looked for there too: within ringRadius of the
  // outer outline and across its rim.
  grownOf[i] = grown | across;
  countRing(f, across, area);
}

// Surface i and its holes, over `area` (CV_8U 0/255).
cv::Mat RoofPlanes::surfaceWithHoles(size_t i, const cv::Rect& area) const {
  cv::Mat filled(area.size(), CV_8U, cv::Scalar(0));
  const cv::Rect inImage = area & image;
  filled(inImage - area.tl()).setTo(255, labels(inImage) == static_cast<int>(i));
  // From a corner of the margin, which is never the surface; 8-connected, as the complement of
  // a 4-connected surface is.
  cv::floodFill(filled, cv::Point(0, 0), cv::Scalar(128), nullptr, cv::Scalar(), cv::Scalar(), 8);
  filled = filled != 128;  // the surface and its holes
  return filled;
}

// Across the unmatched pixels along the surface's outline (a roof's occluded or unmatched border)
// and those at its level (its own rim, cut from the surface by jumps), up to gapReach px from
// `filled` (over `area`): the ring is what lies beyond them.
cv::Mat RoofPlanes::acrossRim(const Surface& f, const cv::Mat& filled, const cv::Rect& area) const {
  const cv::Rect inImage = area & image;
  cv::Mat passable(area.size(), CV_8U, cv::Scalar(0));
  for (int y = inImage.y; y < inImage.br().y; ++y) {
    const float* d = disparity.ptr<float>(y);
    std::uint8_t* out = passable.ptr<std::uint8_t>(y - area.y);
    for (int x = inImage.x; x < inImage.br().x; ++x) {
      const bool level = std::isfinite(d[x]) && std::abs(d[x] - f.at(x, y)) < s.lowerBy;
      out[x - area.x] = !std::isfinite(d[x]) || level ? 255 : 0;
    }
  }
  cv::Mat across = filled.clone(), step;
  const cv::Mat cross = cv::getStructuringElement(cv::MORPH_RECT, {3, 3});
  for (int k = 0; k < s.gapReach; ++k) {
    cv::dilate(across, step, cross);
    step &= passable;
    if (cv::countNonZero(step & ~across) == 0) break;
    across |= step;
  }
  return across;
}

// f.ring and f.lower: the matched pixels within ringRadius of `across` (over `area`) outside it,
// and those lowerBy or more below the plane.
void RoofPlanes::countRing(Surface& f, const cv::Mat& across, const cv::Rect& area) const {
  const cv::Rect inImage = area & image;
  cv::Mat ring;
  cv::dilate(across, ring, square);
  for (int y = inImage.y; y < inImage.y + inImage.height; ++y) {
    const float* d = disparity.ptr<float>(y);
    const std::uint8_t* in = across.ptr<std::uint8_t>(y - area.y);
    const std::uint8_t* near = ring.ptr<std::uint8_t>(y - area.y);
    for (int x = inImage.x; x < inImage.x + inImage.width; ++x) {
      const int u = x - area.x;
      if (in[u] != 0 || near[u] == 0 || !std::isfinite(d[x])) continue;
      ++f.ring;
      if (d[x] <= f.at(x, y) - s.lowerBy) ++f.lower;
    }
  }
}

// The planar surfaces that are raised: `planar` keeps those only. Returns their count.
int RoofPlanes::keepRaised() {
  int planes = 0;
  for (size_t i = 0; i < surfaces.size(); ++i) {
    const Surface& f = surfaces[i];
    // A ring of a few pixels tells nothing (the ground, whose outer outline is the image's
    // border but for a few pixels): at least √count, an eighth of the 2 px ring around a
    // square of that area.
    const bool raised = static_cast<double>(f.ring) >= std::sqrt(static_cast<double>(f.count)) &&
                        static_cast<double>(f.lower) >= s.minLowerShare * f.ring;
    planar[i] = planar[i] != 0 && raised ? 1 : 0;
    if (planar[i] != 0) ++planes;
  }
  return planes;
}

// The kept surfaces' inliers set to their plane, by bands of rows. Returns the pixels set.
long RoofPlanes::setInliers() {
  std::vector<int> setIn(static_cast<size_t>(disparity.rows), 0);
  forRowBands(disparity.rows, s.threads, [&](int rowStart, int rowEnd) {
    for (int y = rowStart; y < rowEnd; ++y) {
      float* d = disparity.ptr<float>(y);
      const int* l = labels.ptr<int>(y);
      const std::uint8_t* k = keep.ptr<std::uint8_t>(y);
      int set = 0;
      for (int x = 0; x < disparity.cols; ++x) {
        if (l[x] < 0 || k[x] == 0 || planar[static_cast<size_t>(l[x])] == 0) continue;
        d[x] = static_cast<float>(surfaces[static_cast<size_t>(l[x])].at(x, y));
        ++set;
      }
      setIn[static_cast<size_t>(y)] = set;
    }
  });
  long pixels = 0;
  for (const int n : setIn) pixels += n;
  return pixels;
}

// Then the other matched pixels on the roof or around it (within ringRadius of its outer
// outline, and across its rim) that lie within absorbWithin of its plane, when they are small
// pieces: a roof's pixels beyond the inlier band (or cut from the surface by a jump of more
// than `link`) are its matches' outliers, at the roof's level all the same. In surface order;
// a pixel takes the first roof that claims it.
// A surface reads and writes only the rows of its area: surfaces on disjoint rows are absorbed
// side by side, in surface order where their rows overlap (the same result). Returns the pixels
// set.
long RoofPlanes::absorbPieces() {
  cv::Mat taken(disparity.size(), CV_8U, cv::Scalar(0));
  std::vector<size_t> order;
  std::vector<std::pair<int, int>> rows;
  for (size_t i = 0; i < surfaces.size(); ++i) {
    if (planar[i] == 0) continue;
    const cv::Rect inImage = areaOf[i] & image;
    order.push_back(i);
    rows.emplace_back(inImage.y, inImage.y + inImage.height);
  }
  std::vector<int> absorbedBy(order.size(), 0);
  const auto absorb = [&](size_t task) { absorbedBy[task] = absorbAround(order[task], taken); };
  const int helpers = order.size() > 1 ? std::max(0, s.threads - 1) : 0;
  RowOrderedTasks(rows, absorb, helpers).runWithHelpers();
  long absorbed = 0;
  for (const int n : absorbedBy) absorbed += n;
  return absorbed;
}

// The small pieces around kept surface i set to its plane, those not `taken` by an earlier
// roof (marked as taken). Returns their count.
int RoofPlanes::absorbAround(size_t i, cv::Mat& taken) {
  const Surface& f = surfaces[i];
  const cv::Rect area = areaOf[i];
  const cv::Rect inImage = area & image;
  // The surface's own pixels beyond its inlier band, by 8-connected blob: a blob of maxPiece
  // pixels or more is a structure on the roof (a box, a parapet), not its noise.
  cv::Mat outside(area.size(), CV_8U, cv::Scalar(0));
  outside(inImage - area.tl())
      .setTo(255, (labels(inImage) == static_cast<int>(i)) & (keep(inImage) == 0));
  cv::Mat blobs, blobStats, blobCentroids;
  cv::connectedComponentsWithStats(outside, blobs, blobStats, blobCentroids, 8, CV_32S);
  int absorbed = 0;
  for (int y = inImage.y; y < inImage.y + inImage.height; ++y) {
    float* d = disparity.ptr<float>(y);
    const int* l = labels.ptr<int>(y);
    const std::uint8_t* k = keep.ptr<std::uint8_t>(y);
    const int* blob = blobs.ptr<int>(y - area.y);
    const std::uint8_t* near = grownOf[i].ptr<std::uint8_t>(y - area.y);
    std::uint8_t* t = taken.ptr<std::uint8_t>(y);
    for (int x = inImage.x; x < inImage.x + inImage.width; ++x) {
      if (near[x - area.x] == 0 || !std::isfinite(d[x]) || t[x] != 0) continue;
      if (l[x] >= 0 && k[x] != 0 && planar[static_cast<size_t>(l[x])] != 0) continue;
      const bool piece = l[x] == kPiece;
      const bool ownNoise = l[x] == static_cast<int>(i) &&
                            blobStats.at<int>(blob[x - area.x], cv::CC_STAT_AREA) < maxPiece;
      if (!piece && !ownNoise) continue;
      const double p = f.at(x, y);
      if (std::abs(d[x] - p) <= s.absorbWithin) {
        d[x] = static_cast<float>(p);
        t[x] = 1;
        ++absorbed;
      }
    }
  }
  return absorbed;
}

}  // namespace

RoofPlaneCounts fitRoofPlanes(cv::Mat& disparity, const RoofPlaneSettings& settings) {
  CV_Assert(disparity.type() == CV_32F);
  RoofPlaneCounts counts;
  RoofPlanes roofs{disparity, settings};
  if (!roofs.fitSurfaces()) return counts;
  roofs.measureRings();
  counts.planes = roofs.keepRaised();
  counts.pixels = roofs.setInliers();
  if (settings.absorbWithin > 0) counts.absorbed = roofs.absorbPieces();
  return counts;
}

}  // namespace delineo::stereo::detail
