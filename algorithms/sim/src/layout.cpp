// Random but deterministic placement of terrain, buildings and trees.
#include "layout.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "noise.hpp"

namespace delineo::sim::detail {

namespace {
constexpr double kPi = std::numbers::pi;

// Axis-aligned ring from local (u, v) corners, transformed by rotation + translation.
core::Ring transform(const std::vector<cv::Point2d>& local, cv::Point2d centre, double angle,
                     bool mirror) {
  const double c = std::cos(angle), s = std::sin(angle);
  core::Ring out;
  out.reserve(local.size());
  for (const auto& p : local) {
    const double u = p.x, v = mirror ? -p.y : p.y;
    out.emplace_back(centre.x + u * c - v * s, centre.y + u * s + v * c);
  }
  return out;
}

std::vector<cv::Point2d> rectLocal(double hl, double hw) {
  return {{-hl, -hw}, {hl, -hw}, {hl, hw}, {-hl, hw}};
}

double distanceToSegment(cv::Point2d p, cv::Point2d a, cv::Point2d b) {
  const cv::Point2d ab = b - a;
  const double len2 = ab.dot(ab);
  double t = len2 > 0 ? (p - a).dot(ab) / len2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  const cv::Point2d q = a + t * ab;
  return std::hypot(p.x - q.x, p.y - q.y);
}

double distanceToRings(const core::Polygon& poly, cv::Point2d p) {
  double best = std::numeric_limits<double>::max();
  auto scan = [&](const core::Ring& r) {
    for (size_t i = 0; i < r.size(); ++i) {
      best = std::min(best, distanceToSegment(p, r[i], r[(i + 1) % r.size()]));
    }
  };
  scan(poly.outer);
  for (const auto& h : poly.holes) scan(h);
  return best;
}

std::vector<cv::Point> toFixedPoint(const core::Ring& ring, int shiftBits) {
  std::vector<cv::Point> pts;
  pts.reserve(ring.size());
  const double scale = static_cast<double>(1 << shiftBits);
  for (const auto& p : ring) {
    pts.emplace_back(static_cast<int>(std::lround(p.x * scale)),
                     static_cast<int>(std::lround(p.y * scale)));
  }
  return pts;
}

class Placer {
 public:
  explicit Placer(const SceneParams& p) : p_(p) {
    left_ = leftView(p);
    right_ = rightView(p);
    occupancy_ = cv::Mat::zeros(p.height, p.width, CV_8U);
  }

  // True when an object spanning ground [x0, x1] x [y0, y1] and heights [zLo, zHi] stays inside
  // both images with the margin.
  bool fits(double x0, double x1, double y0, double y1, double zLo, double zHi) const {
    const double m = p_.margin;
    if (y0 < m || y1 > p_.height - m) return false;
    for (const ViewGeometry& v : {left_, right_}) {
      const double a = std::min(v.project(x0, zLo), v.project(x0, zHi));
      const double b = std::max(v.project(x1, zLo), v.project(x1, zHi));
      if (a < m || b > p_.width - m) return false;
    }
    return true;
  }

  // True when the outer ring, grown by `gapPx`, overlaps no building placed so far.
  bool freeOfBuildings(const core::Ring& ring) const {
    // Work in the ring's bounding box only: the full-image mask is large for big scenes.
    const cv::Rect2d bb = core::boundingBox(ring);
    const cv::Rect roi = cv::Rect(static_cast<int>(std::floor(bb.x)) - 1,
                                  static_cast<int>(std::floor(bb.y)) - 1,
                                  static_cast<int>(std::ceil(bb.width)) + 3,
                                  static_cast<int>(std::ceil(bb.height)) + 3) &
                         cv::Rect(0, 0, occupancy_.cols, occupancy_.rows);
    if (roi.area() == 0) return true;
    core::Ring shifted = ring;
    for (auto& q : shifted) q -= cv::Point2d(roi.x, roi.y);
    cv::Mat candidate = cv::Mat::zeros(roi.size(), CV_8U);
    const std::vector<std::vector<cv::Point>> pts{toFixedPoint(shifted, 4)};
    cv::fillPoly(candidate, pts, cv::Scalar(255), cv::LINE_8, 4);
    cv::Mat both;
    cv::bitwise_and(candidate, occupancy_(roi), both);
    return cv::countNonZero(both) == 0;
  }

  void occupy(const core::Ring& ring, double gapPx) {
    const std::vector<std::vector<cv::Point>> pts{toFixedPoint(ring, 4)};
    cv::fillPoly(occupancy_, pts, cv::Scalar(255), cv::LINE_8, 4);
    const int thickness = std::max(1, static_cast<int>(std::ceil(2.0 * gapPx)));
    cv::polylines(occupancy_, pts, true, cv::Scalar(255), thickness, cv::LINE_8, 4);
  }

 private:
  const SceneParams& p_;
  ViewGeometry left_, right_;
  cv::Mat occupancy_;
};

struct ShapeGeometry {
  std::vector<cv::Point2d> outer;
  std::vector<std::vector<cv::Point2d>> holes;
};

// Footprint in local coordinates (px), u in [-hl, hl], v in [-hw, hw]. Returns false when the
// dimensions cannot hold the shape (the caller draws again).
bool makeShape(Shape shape, double hl, double hw, double metre, Rng& rng, ShapeGeometry* out) {
  out->holes.clear();
  const double L = 2 * hl, W = 2 * hw;
  switch (shape) {
    case Shape::Rect:
      out->outer = rectLocal(hl, hw);
      return true;
    case Shape::L: {
      const double a = L * rng.uniform(0.35, 0.55), b = W * rng.uniform(0.35, 0.55);
      out->outer = {{-hl, -hw}, {-hl + a, -hw}, {-hl + a, hw - b}, {hl, hw - b}, {hl, hw}, {-hl, hw}};
      return true;
    }
    case Shape::T: {
      const double a = L * rng.uniform(0.3, 0.45), b = W * rng.uniform(0.35, 0.5);
      out->outer = {{-hl, -hw},        {hl, -hw},         {hl, -hw + b}, {a / 2, -hw + b},
                    {a / 2, hw},       {-a / 2, hw},      {-a / 2, -hw + b}, {-hl, -hw + b}};
      return true;
    }
    case Shape::U: {
      const double a = L * rng.uniform(0.25, 0.33), b = W * rng.uniform(0.3, 0.45);
      if (L - 2 * a < 5 * metre) return false;  // the inner yard must stay a few metres wide
      out->outer = {{-hl, -hw},        {-hl + a, -hw},    {-hl + a, hw - b}, {hl - a, hw - b},
                    {hl - a, -hw},     {hl, -hw},         {hl, hw},          {-hl, hw}};
      return true;
    }
    case Shape::Courtyard: {
      const double t = rng.uniform(5.0, 8.0) * metre;  // wing depth
      if (W - 2 * t < 6 * metre || L - 2 * t < 6 * metre) return false;
      out->outer = rectLocal(hl, hw);
      out->holes.push_back(rectLocal(hl - t, hw - t));
      return true;
    }
    case Shape::Angled: {
      // One corner cut at an arbitrary angle, sometimes a second one at 45 degrees.
      const double phi = rng.uniform(30.0, 60.0) * kPi / 180.0;
      double cu = std::min(L, W) * rng.uniform(0.25, 0.45);
      double cv = cu * std::tan(phi);
      if (cv > 0.6 * W) {
        cv = 0.6 * W;
        cu = cv / std::tan(phi);
      }
      std::vector<cv::Point2d> ring{{-hl, -hw}, {hl, -hw}, {hl, hw - cv}, {hl - cu, hw}, {-hl, hw}};
      if (rng.chance(0.5)) {
        const double c2 = std::min(L, W) * rng.uniform(0.15, 0.3);
        ring = {{-hl + c2, -hw}, {hl, -hw}, {hl, hw - cv}, {hl - cu, hw}, {-hl, hw}, {-hl, -hw + c2}};
      }
      out->outer = ring;
      return true;
    }
  }
  return false;
}

cv::Rect2d boundsOf(const core::Ring& ring) { return core::boundingBox(ring); }

// The random draws of a layout, in the order that makes a seed give its scene: the terrain and
// the sun, then each building's attempts, then each tree's.
struct LayoutDraw {
  explicit LayoutDraw(const SceneParams& params)
      : p(params), rng(static_cast<std::uint64_t>(params.seed)), placer(params) {}

  void terrainAndSun();
  void buildings();
  bool drawFootprint(Shape shape, double scale, Building& bld);
  void drawRoof(Building& bld);
  void drawSuperstructures(Building& bld);
  bool fitsInScene(const Building& bld) const;
  void drawAppearance(Building& bld);
  void trees();
  bool placeTree();
  cv::Point2d treeCentre(const Tree& tree);
  bool clearOfOthers(const Tree& tree) const;

  const SceneParams& p;
  Rng rng;
  const double metre = 1.0 / p.gsd;             // px per metre
  const double grad = p.slope / 100.0 * p.gsd;  // m per px
  Placer placer;
  Layout layout;
};

// Terrain: a plane of the given slope in a random direction, plus gentle relief.
void LayoutDraw::terrainAndSun() {
  Terrain& t = layout.terrain;
  const double dir = rng.uniform(0.0, 2.0 * kPi);
  t.gradX = grad * std::cos(dir);
  t.gradY = grad * std::sin(dir);
  t.centreX = 0.5 * p.width;
  t.centreY = 0.5 * p.height;
  t.undulation = p.undulation;
  t.undulationPeriod = 60.0 * metre;
  t.seed = rng.next();
  t.undulationAtCentre = fbm(t.seed, t.centreX, t.centreY, t.undulationPeriod, 2);
  layout.groundSeed = rng.next();
  layout.sunElevation = rng.uniform(35.0, 55.0) * kPi / 180.0;
  layout.sunSide = rng.chance(0.5) ? -1 : 1;
}

// Buildings: shapes cycle through a shuffled list so every six buildings show each shape.
void LayoutDraw::buildings() {
  std::array<Shape, 6> shapes{Shape::Rect, Shape::L, Shape::T, Shape::U, Shape::Courtyard,
                              Shape::Angled};
  const int attemptsPerBuilding = 80;
  for (int b = 0; b < p.buildings; ++b) {
    if (b % 6 == 0) {
      for (int i = 5; i > 0; --i) std::swap(shapes[i], shapes[rng.uniformInt(0, i)]);
    }
    const Shape shape = shapes[b % 6];
    bool placed = false;
    for (int attempt = 0; attempt < attemptsPerBuilding && !placed; ++attempt) {
      Building bld;
      // Shrink the size draw as attempts fail, so crowded scenes still fill up.
      const double scale = 1.0 - 0.5 * attempt / attemptsPerBuilding;
      if (!drawFootprint(shape, scale, bld)) continue;
      drawRoof(bld);
      drawSuperstructures(bld);
      if (!fitsInScene(bld)) continue;
      drawAppearance(bld);
      bld.id = static_cast<int>(layout.buildings.size()) + 1;
      placer.occupy(bld.footprint.outer, rng.uniform(3.0, 7.0) * metre);
      layout.buildings.push_back(std::move(bld));
      placed = true;
    }
  }
}

// The building's size (drawn at `scale`), shape, orientation, position and footprint; false when
// the size cannot hold the shape.
bool LayoutDraw::drawFootprint(Shape shape, double scale, Building& bld) {
  double lengthM = rng.uniform(14.0, 36.0) * scale;
  double widthM = rng.uniform(9.0, 22.0) * scale;
  if (shape == Shape::Courtyard || shape == Shape::U) {
    lengthM = rng.uniform(24.0, 40.0) * std::max(scale, 0.8);
    widthM = rng.uniform(20.0, 30.0) * std::max(scale, 0.8);
  }
  if (widthM > lengthM) std::swap(widthM, lengthM);
  const double hl = 0.5 * lengthM * metre, hw = 0.5 * widthM * metre;

  bld.shape = shape;
  ShapeGeometry geom;
  if (!makeShape(shape, hl, hw, metre, rng, &geom)) return false;

  const double orient = rng.uniform();
  double angle;
  if (orient < 0.35) {
    angle = rng.chance(0.5) ? 0.0 : 0.5 * kPi;
  } else if (orient < 0.55) {
    angle = rng.chance(0.5) ? 0.25 * kPi : 0.75 * kPi;
  } else {
    angle = rng.uniform(0.0, kPi);
  }
  const bool mirror = rng.chance(0.5);
  const cv::Point2d centre(rng.uniform(0.0, p.width), rng.uniform(0.0, p.height));
  bld.centre = centre;
  bld.angle = angle;
  bld.cosAngle = std::cos(angle);
  bld.sinAngle = std::sin(angle);
  bld.halfLength = hl;
  bld.halfWidth = hw;
  bld.footprint.outer = transform(geom.outer, centre, angle, mirror);
  for (const auto& h : geom.holes) bld.footprint.holes.push_back(transform(h, centre, angle, mirror));
  return true;
}

// Roof: pitched roofs on plain rectangles only (their ridge follows the long axis).
void LayoutDraw::drawRoof(Building& bld) {
  const double roofDraw = rng.uniform();
  if (bld.shape == Shape::Rect && roofDraw < 0.35) {
    bld.roof = RoofType::Gable;
  } else if (bld.shape == Shape::Rect && roofDraw < 0.6) {
    bld.roof = RoofType::Hip;
  }
  const double heightM = bld.roof == RoofType::Flat ? rng.uniform(6.0, 30.0) : rng.uniform(6.0, 15.0);
  bld.baseZ = layout.terrain.z(bld.centre.x, bld.centre.y);
  bld.eaveZ = bld.baseZ + heightM;
  bld.ridgeZ = bld.eaveZ;
  if (bld.roof != RoofType::Flat) {
    const double pitch = rng.uniform(20.0, 38.0) * kPi / 180.0;
    bld.pitchSlope = std::tan(pitch) / metre;  // m per px
    bld.ridgeZ = bld.eaveZ + bld.pitchSlope * bld.halfWidth;
  }
}

// Superstructures: machine rooms on flat roofs, chimneys on pitched ones.
void LayoutDraw::drawSuperstructures(Building& bld) {
  const double hl = bld.halfLength, hw = bld.halfWidth;
  const int boxCount = bld.roof == RoofType::Flat ? rng.uniformInt(0, 3) : rng.uniformInt(0, 2);
  bld.topZ = bld.ridgeZ;
  for (int k = 0; k < boxCount; ++k) {
    const bool chimney = bld.roof != RoofType::Flat;
    const double sizeU = (chimney ? rng.uniform(0.7, 1.3) : rng.uniform(1.5, 4.0)) * metre;
    const double sizeV = (chimney ? rng.uniform(0.7, 1.3) : rng.uniform(1.5, 3.5)) * metre;
    const double rise = chimney ? rng.uniform(0.9, 1.8) : rng.uniform(1.0, 2.5);
    const double u = rng.uniform(-hl, hl), v = rng.uniform(-hw, hw);
    // Keep the box and a 1.5 m border inside the footprint (checked on a 5x5 grid).
    const double border = 1.5 * metre;
    bool inside = true;
    for (int gy = 0; gy < 5 && inside; ++gy) {
      for (int gx = 0; gx < 5 && inside; ++gx) {
        const double lu = u + (gx / 4.0 - 0.5) * (sizeU + 2 * border);
        const double lv = v + (gy / 4.0 - 0.5) * (sizeV + 2 * border);
        const core::Ring probe = transform({{lu, lv}}, bld.centre, bld.angle, false);
        inside = insidePolygon(bld.footprint, probe[0].x, probe[0].y);
      }
    }
    if (!inside) continue;
    Box box;
    box.ring = transform({{u - sizeU / 2, v - sizeV / 2}, {u + sizeU / 2, v - sizeV / 2},
                          {u + sizeU / 2, v + sizeV / 2}, {u - sizeU / 2, v + sizeV / 2}},
                         bld.centre, bld.angle, false);
    double base = bld.eaveZ;
    for (const auto& c : box.ring) base = std::max(base, bld.roofZ(c.x, c.y));
    box.topZ = base + rise;
    bld.topZ = std::max(bld.topZ, box.topZ);
    bld.boxes.push_back(std::move(box));
  }
}

// Whether the building stays inside both views and clear of the buildings placed so far.
bool LayoutDraw::fitsInScene(const Building& bld) const {
  const cv::Rect2d bb = boundsOf(bld.footprint.outer);
  // Terrain under the footprint may sit below the base: the walls reach down to it.
  const double zLo = bld.baseZ - std::abs(grad) * std::hypot(bb.width, bb.height) - 2 * p.undulation;
  if (!placer.fits(bb.x, bb.x + bb.width, bb.y, bb.y + bb.height, zLo, bld.topZ)) return false;
  return placer.freeOfBuildings(bld.footprint.outer);
}

// Appearance: a quarter of the roofs are weakly textured (hard for matchers).
void LayoutDraw::drawAppearance(Building& bld) {
  bld.roofAlbedo = rng.uniform(0.3, 0.8);
  bld.roofContrast = rng.chance(0.25) ? rng.uniform(0.03, 0.1) : rng.uniform(0.6, 1.2);
  bld.wallAlbedo = rng.uniform(0.35, 0.75);
  bld.boxAlbedo = std::clamp(bld.roofAlbedo + rng.uniform(-0.25, 0.25), 0.15, 0.9);
  bld.textureSeed = rng.next();
}

// Trees: round-ish crowns; about a third of them touch a building.
void LayoutDraw::trees() {
  for (int k = 0; k < p.trees; ++k) {
    for (int attempt = 0; attempt < 40; ++attempt) {
      if (placeTree()) break;
    }
  }
}

// One attempt at a tree: its crown, position and heights; false when it does not fit.
bool LayoutDraw::placeTree() {
  Tree tree;
  tree.radius = rng.uniform(2.0, 5.0) * metre;
  tree.lobeAmp = rng.uniform(0.05, 0.18);
  for (double& ph : tree.lobePhase) ph = rng.uniform(0.0, 2.0 * kPi);
  const double heightM = rng.uniform(5.0, 20.0);
  const double rimShare = rng.uniform(0.35, 0.6);
  tree.albedo = rng.uniform(0.2, 0.38);
  tree.textureSeed = rng.next();
  const double rmax = tree.maxRadius();
  tree.centre = treeCentre(tree);
  if (!clearOfOthers(tree)) return false;
  tree.baseZ = layout.terrain.z(tree.centre.x, tree.centre.y);
  tree.topZ = tree.baseZ + heightM;
  tree.rimZ = tree.baseZ + rimShare * heightM;
  const double zLo = tree.baseZ - std::abs(grad) * rmax - 2 * p.undulation;
  if (!placer.fits(tree.centre.x - rmax, tree.centre.x + rmax, tree.centre.y - rmax,
                   tree.centre.y + rmax, zLo, tree.topZ)) {
    return false;
  }
  layout.trees.push_back(tree);
  return true;
}

// The crown's centre: beside a random edge of a random building (35 % of the draws), else
// anywhere.
cv::Point2d LayoutDraw::treeCentre(const Tree& tree) {
  if (!layout.buildings.empty() && rng.chance(0.35)) {
    const Building& bld = layout.buildings[static_cast<size_t>(
        rng.uniformInt(0, static_cast<int>(layout.buildings.size()) - 1))];
    const core::Ring& ring = bld.footprint.outer;
    const size_t e = static_cast<size_t>(rng.uniformInt(0, static_cast<int>(ring.size()) - 1));
    const cv::Point2d a = ring[e], b = ring[(e + 1) % ring.size()];
    const cv::Point2d onEdge = a + rng.uniform(0.2, 0.8) * (b - a);
    cv::Point2d normal(b.y - a.y, -(b.x - a.x));
    normal *= 1.0 / std::max(1e-9, std::hypot(normal.x, normal.y));
    const cv::Point2d probe = onEdge + normal * 0.5;
    if (insidePolygon(bld.footprint, probe.x, probe.y)) normal = -normal;
    return onEdge + normal * (tree.radius + 0.3);
  }
  return {rng.uniform(0.0, p.width), rng.uniform(0.0, p.height)};
}

// Whether the crown stays off every building and apart from the trees placed so far.
bool LayoutDraw::clearOfOthers(const Tree& tree) const {
  for (const auto& bld : layout.buildings) {
    if (insidePolygon(bld.footprint, tree.centre.x, tree.centre.y) ||
        distanceToRings(bld.footprint, tree.centre) < tree.radius) {
      return false;
    }
  }
  for (const auto& other : layout.trees) {
    const double d = std::hypot(other.centre.x - tree.centre.x, other.centre.y - tree.centre.y);
    if (d < 0.7 * (other.radius + tree.radius)) return false;
  }
  return true;
}

}  // namespace

const char* toString(RoofType r) {
  switch (r) {
    case RoofType::Flat: return "flat";
    case RoofType::Gable: return "gable";
    case RoofType::Hip: return "hip";
  }
  return "flat";
}

const char* toString(Shape s) {
  switch (s) {
    case Shape::Rect: return "rect";
    case Shape::L: return "L";
    case Shape::T: return "T";
    case Shape::U: return "U";
    case Shape::Courtyard: return "courtyard";
    case Shape::Angled: return "angled";
  }
  return "rect";
}

double Terrain::z(double x, double y) const {
  const double plane = gradX * (x - centreX) + gradY * (y - centreY);
  if (undulation <= 0.0) return plane;
  return plane + 2.0 * undulation * (fbm(seed, x, y, undulationPeriod, 2) - undulationAtCentre);
}

cv::Point2d Building::toLocal(double x, double y) const {
  const double c = cosAngle, s = sinAngle;
  const double dx = x - centre.x, dy = y - centre.y;
  return {dx * c + dy * s, -dx * s + dy * c};
}

double Building::roofZ(double x, double y, double* gx, double* gy) const {
  if (gx) *gx = 0.0;
  if (gy) *gy = 0.0;
  if (roof == RoofType::Flat) return eaveZ;
  const cv::Point2d l = toLocal(x, y);
  const double c = cosAngle, s = sinAngle;
  const double runV = halfWidth - std::abs(l.y);
  const double runU = halfLength - std::abs(l.x);
  double run = runV;
  // Gradient of the run in ground coordinates: d|v|/dX = sign(v) * dv/dX with dv/dX = -s,
  // dv/dY = c; d|u|/dX = sign(u) * c, d|u|/dY = sign(u) * s.
  double drx = -(l.y >= 0 ? 1.0 : -1.0) * -s, dry = -(l.y >= 0 ? 1.0 : -1.0) * c;
  if (roof == RoofType::Hip && runU < runV) {
    run = runU;
    drx = -(l.x >= 0 ? 1.0 : -1.0) * c;
    dry = -(l.x >= 0 ? 1.0 : -1.0) * s;
  }
  run = std::max(0.0, run);
  if (gx) *gx = pitchSlope * drx;
  if (gy) *gy = pitchSlope * dry;
  return eaveZ + pitchSlope * run;
}

double Tree::radiusAt(double theta) const {
  const double w = std::sin(3.0 * theta + lobePhase[0]) * 0.5 +
                   std::sin(5.0 * theta + lobePhase[1]) * 0.3 +
                   std::sin(2.0 * theta + lobePhase[2]) * 0.2;
  return radius * (1.0 + lobeAmp * w);
}

bool Tree::crownZ(double x, double y, double* z, double* gx, double* gy) const {
  const double dx = x - centre.x, dy = y - centre.y;
  const double rho2 = dx * dx + dy * dy;
  const double rmax = maxRadius();
  if (rho2 >= rmax * rmax) return false;
  const double rho = std::sqrt(rho2);
  const double r = radiusAt(std::atan2(dy, dx));
  if (rho >= r) return false;
  const double q = rho / r;
  const double root = std::sqrt(std::max(1e-9, 1.0 - q * q));
  *z = rimZ + (topZ - rimZ) * root;
  if (gx || gy) {
    const double dzdrho = std::min(20.0, (topZ - rimZ) * q / (r * root));
    const double ux = rho > 1e-9 ? dx / rho : 0.0, uy = rho > 1e-9 ? dy / rho : 0.0;
    if (gx) *gx = -dzdrho * ux;
    if (gy) *gy = -dzdrho * uy;
  }
  return true;
}

ViewGeometry leftView(const SceneParams& p) {
  return {p.leftObliquity / p.metresPerDisparity, 0.0};
}
ViewGeometry rightView(const SceneParams& p) {
  return {-(1.0 - p.leftObliquity) / p.metresPerDisparity, -p.groundDisparity};
}

bool insidePolygon(const core::Polygon& polygon, double x, double y) {
  bool inside = false;
  auto scan = [&](const core::Ring& r) {
    const size_t n = r.size();
    for (size_t i = 0, j = n - 1; i < n; j = i++) {
      if ((r[i].y > y) != (r[j].y > y) &&
          x < (r[j].x - r[i].x) * (y - r[i].y) / (r[j].y - r[i].y) + r[i].x) {
        inside = !inside;
      }
    }
  };
  scan(polygon.outer);
  for (const auto& h : polygon.holes) scan(h);
  return inside;
}

Layout makeLayout(const SceneParams& p) {
  LayoutDraw draw(p);
  draw.terrainAndSun();
  draw.buildings();
  draw.trees();
  return std::move(draw.layout);
}

}  // namespace delineo::sim::detail
