#pragma once
// The six-term energy of the statistical active polygon, in ROI pixel coordinates.
//
//   F(C) = Σ_Ω c_roof + Σ_E c_ground + Σ_O NoMatchCost
//          - λ Σ_C |∇I1·n| - λ Σ_C |∇I2(x - d_xy, y)·n| + β Σ_s R(θ_s)
//
// Inputs are plain images so that tests can feed hand-made costs. Polygons have integer
// vertices in [0, W] x [0, H] (pixel corners); a pixel belongs to the polygon when its centre
// does (same rule as core::rasterize).
#include <array>
#include <cstdint>
#include <unordered_map>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"

namespace delineo::delineation {

using IntRing = std::vector<cv::Point>;
struct IntPolygon {
  IntRing outer;
  std::vector<IntRing> holes;
  size_t ringCount() const { return 1 + holes.size(); }
  const IntRing& ring(size_t r) const { return r == 0 ? outer : holes[r - 1]; }
  IntRing& ring(size_t r) { return r == 0 ? outer : holes[r - 1]; }
  int vertexCount() const;
};
core::Polygon toPolygon(const IntPolygon& p, cv::Point2d offset = {0, 0});
// Every ring simple with >= 3 vertices, no two rings touching, holes inside the outer ring and
// outside each other.
bool isValidPolygon(const IntPolygon& p);

struct EnergyImages {
  cv::Mat roofCost;       // CV_32F, c_roof = min over the roof interval of Crit
  cv::Mat groundCost;     // CV_32F, c_ground, same size
  float noMatchCost = 1;  // cost of each pixel of the wall/occlusion band
  // CV_32F, optional: c_ground - c_roof before the costs were capped (`cost-cap`). The edge
  // gate, the region stage and the courtyard seeds read it (a wall or a shadowed floor is told
  // apart by values above the cap); empty = groundCost - roofCost.
  cv::Mat uncappedDifference;
  // CV_32S, same size, >= 0: width in px of the occlusion band next to a roof run whose edge is
  // at this pixel (|roof disparity - ground disparity| there). Empty = no band.
  cv::Mat occlusionWidth;
  // -1: the band lies on the -x side of roof runs (roof disparity > ground disparity with
  // x_right = x_left - d); +1: on the +x side.
  int occlusionSide = -1;
  // Normalised image gradients (CV_32F, same size); empty pairs disable the term. The right
  // gradients are already resampled at (x - d_xy, y).
  cv::Mat leftGradX, leftGradY, rightGradX, rightGradY;
  // CV_8U, same size, optional: non-zero where a vertex may go (a vertex at pixel corner (x, y)
  // is allowed when one of the four pixels around it is). Empty = anywhere in the ROI.
  cv::Mat allowed;
  // CV_8U, same size, optional: non-zero where the matcher's map puts the pixel above the roof
  // interval (a plant room, a taller neighbour). No courtyard starts there: a courtyard is lower
  // than its roof. Empty = no map.
  cv::Mat aboveRoof;
};

struct EnergyWeights {
  double edgeWeight = 5.0;  // λ
  double rigidity = 15.0;   // β
  // Edge gate (units of Crit): each edge sample's |∇I·n| is weighted by
  // clamp(1 + D_in / edgeContrast, 0, 1), D_in = c_ground - c_roof averaged 1..5 px inside the
  // contour along the normal. An edge is a roof edge only where the roof side is not ground:
  // a thin spike or finger has ground (or the far side) inside and earns nothing, while a
  // textureless roof (D_in ~ 0) keeps its edges. 0 disables the gate (the paper's terms).
  double edgeContrast = 0.1;
  // Shape limits of a change (not of the initial polygon): no vertex angle below minAngle
  // degrees around the change unless the sharpest one there gets blunter, and no changed edge
  // closer than minGap px to a non-adjacent edge pointing the opposite way (more than 135°
  // apart: the two sides of a finger or slit). 0 disables each.
  double minAngle = 20.0;
  double minGap = 2.0;
};

// Contour length unit of the edge terms: a full-contrast edge (normalised gradient 1) across the
// contour is worth edgeUnit * λ per pixel of contour, i.e. 0.75 with λ = 5. docs/delineation.md
// explains the choice.
inline constexpr double kEdgeUnit = 0.15;

struct EnergyTerms {
  std::array<double, 6> term{};  // (1) roof, (2) ground, (3) occlusion, (4) left edges,
                                 // (5) right edges, (6) shape prior; already weighted and signed
  double total() const {
    double t = 0;
    for (double v : term) t += v;
    return t;
  }
};

// R(θ), θ in radians: 2 - |sin 2θ| when cos θ >= |sin θ|, else |sin 2θ|.
double anglePrior(double theta);
// Angle at vertex v between the edges to `prev` and `next`, in [0, π].
double vertexAngle(cv::Point prev, cv::Point v, cv::Point next);

// Energy by rasterising the polygon and summing pixels: slow, simple, the reference.
EnergyTerms referenceEnergy(const EnergyImages& images, const EnergyWeights& weights,
                            const IntPolygon& polygon);

// Incremental energy: per-row prefix sums of the costs turn area sums into sums over boundary
// crossings; a local change re-evaluates only the rows its edges cross and its edges' samples.
class PolygonEnergy {
 public:
  // A local change: in ring `ring`, the `removeCount` vertices starting at `first` (cyclic) are
  // replaced by `inserted` (moves: 1 → 1, edge moves: 2 → 2, deletion: 1 → 0).
  struct Change {
    int ring = 0;
    int first = 0;
    int removeCount = 1;
    std::vector<cv::Point> inserted;
  };

  PolygonEnergy(const EnergyImages& images, const EnergyWeights& weights);
  void setPolygon(const IntPolygon& polygon);
  const IntPolygon& polygon() const { return polygon_; }
  EnergyTerms terms() const;
  double total() const { return terms().total(); }
  // F(after change) - F(now), without applying it.
  double delta(const Change& change) const;
  // True when the changed polygon stays simple: no crossing edges within or between rings,
  // no fold-back, every ring keeps >= 3 vertices, its orientation and a non-zero area, and
  // every vertex stays within [0, W] x [0, H].
  bool valid(const Change& change) const;
  void apply(const Change& change);
  IntPolygon changed(const Change& change) const;
  cv::Size size() const { return size_; }

 private:
  struct RowTerms {
    double roof = 0, ground = 0, band = 0;  // Σ c_roof, Σ c_ground over E, NoMatch * |O|
  };
  struct Crossing {
    double x;
    int edge;  // edge id: ringOffset[ring] + index of the edge's first vertex
  };
  RowTerms rowTerms(int y, const std::vector<double>& xs) const;
  // Left and right edge terms of a→b, memoised: the same candidate edges come back sweep after
  // sweep, and sampling them is the most expensive part of a candidate's energy.
  // `inwardLeft`: the polygon's interior lies on the side of n = (-dy, dx) (the edge's left in
  // image coordinates); edges are stored in that normalised direction.
  const std::array<double, 2>& edgeTerms(cv::Point a, cv::Point b, bool inwardLeft) const;
  double vertexPrior(const IntRing& ring, int i) const;
  void rebuild();
  // Steps of delta() on scratch_: the change of the edge terms and priors, and the rows'
  // changes added to `d`.
  double contourDelta(const Change& c) const;
  void addRowChanges(int yLow, int yHigh, double& d) const;

  EnergyImages images_;
  EnergyWeights weights_;
  cv::Size size_;
  std::vector<double> roofPrefix_, groundPrefix_;  // (W + 1) per row
  IntPolygon polygon_;
  std::vector<int> ringOffset_;
  std::vector<bool> ringInwardLeft_;  // per ring: the interior is on the (-dy, dx) side
  cv::Mat costDifference_;            // c_ground - c_roof, sampled by the edge gate
  std::vector<std::vector<Crossing>> rowCrossings_;
  std::vector<RowTerms> rowTerms_;
  // Scratch of delta(), kept to avoid allocations in the optimiser's inner loop.
  struct DeltaScratch {
    std::vector<cv::Point> chain;
    std::vector<int> oldEdges, oldVertices, addedCount;
    std::vector<double> addedX, xs;
  };
  mutable DeltaScratch scratch_;
  std::vector<std::array<double, 2>> edgeTerms_;  // by edge id
  std::vector<double> vertexPriors_;              // by vertex id (same ids as edges)
  mutable std::unordered_map<std::uint64_t, std::array<double, 2>> edgeCache_;
};

}  // namespace delineo::delineation
