#include "render.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "noise.hpp"

namespace delineo::sim::detail {

namespace {
// Encoded object ids of profile samples: kind in the top byte, index below.
enum Kind : std::int32_t { kGround = 0, kRoof = 1, kBox = 2, kTree = 3 };
constexpr std::int32_t encode(Kind kind, size_t index) {
  return (static_cast<std::int32_t>(kind) << 24) | static_cast<std::int32_t>(index);
}
constexpr Kind kindOf(std::int32_t obj) { return static_cast<Kind>(obj >> 24); }
constexpr size_t indexOf(std::int32_t obj) { return static_cast<size_t>(obj & 0xffffff); }

constexpr double kAmbient = 0.3;

// Smooth 0..1 pulse of width `w` (same units as x) repeating with period 1, centred on 0.
double seam(double x, double w) {
  const double f = x - std::floor(x);
  const double d = std::min(f, 1.0 - f);
  if (d >= w) return 0.0;
  const double s = 1.0 - d / w;
  return s * s * (3 - 2 * s);
}

// Sorted crossings of the horizontal line at y with the rings of a polygon.
void rowCrossings(const core::Ring& ring, double y, std::vector<double>& xs) {
  const size_t n = ring.size();
  for (size_t i = 0, j = n - 1; i < n; j = i++) {
    const cv::Point2d& a = ring[i];
    const cv::Point2d& b = ring[j];
    if ((a.y > y) != (b.y > y)) xs.push_back(a.x + (y - a.y) * (b.x - a.x) / (b.y - a.y));
  }
}
}  // namespace

RowRenderer::RowRenderer(const SceneParams& params, const Layout& layout)
    : p_(params), layout_(layout), left_(leftView(params)), right_(rightView(params)) {
  ss_ = params.supersampling;
  sunX_ = layout.sunSide * std::cos(layout.sunElevation);
  sunZ_ = std::sin(layout.sunElevation);
  sampleMetres_ = params.gsd / ss_;
  double objectTop = -std::numeric_limits<double>::max();
  for (const auto& b : layout.buildings) {
    objectTop = std::max(objectTop, b.topZ);
    buildingBounds_.push_back(core::boundingBox(b.footprint.outer));
  }
  for (const auto& t : layout.trees) objectTop = std::max(objectTop, t.topZ);

  // The ground grid must cover every ground point that either view can see: its extent
  // depends on the height range, which depends on the extent (the terrain is a plane), so
  // iterate a few times from the image itself.
  const Terrain& ter = layout.terrain;
  double x0 = 0.0, x1 = params.width;
  for (int iter = 0; iter < 4; ++iter) {
    double lo = std::numeric_limits<double>::max(), hi = -lo;
    for (double cx : {x0, x1}) {
      for (double cy : {0.0, static_cast<double>(params.height)}) {
        const double plane = ter.gradX * (cx - ter.centreX) + ter.gradY * (cy - ter.centreY);
        lo = std::min(lo, plane - 2 * ter.undulation);
        hi = std::max(hi, plane + 2 * ter.undulation);
      }
    }
    zMin_ = lo;
    zMax_ = std::max(hi, objectTop);
    double nx0 = 0.0, nx1 = params.width;
    for (const ViewGeometry& v : {left_, right_}) {
      for (double z : {zMin_, zMax_}) {
        nx0 = std::min(nx0, 0.0 - v.shiftPerMetre * z - v.offset);
        nx1 = std::max(nx1, params.width - v.shiftPerMetre * z - v.offset);
      }
    }
    x0 = std::floor(nx0) - 2.0;
    x1 = std::ceil(nx1) + 2.0;
  }
  gridX0_ = x0;
  samples_ = static_cast<std::int64_t>((x1 - x0) * ss_);
}

void RowRenderer::buildProfile(double y, Profile& prof) const {
  std::vector<double> cuts;  // px, where the row crosses a footprint or superstructure edge
  groundProfile(y, prof);
  raiseBuildings(y, prof, cuts);
  raiseTrees(y, prof);
  insertWalls(y, cuts, prof);
  castShadows(prof);
}

void RowRenderer::sampleRange(double xa, double xb, std::int64_t* i0, std::int64_t* i1) const {
  *i0 = std::max<std::int64_t>(0, static_cast<std::int64_t>(std::ceil((xa - gridX0_) * ss_ - 0.5)));
  *i1 = std::min<std::int64_t>(samples_,
                               static_cast<std::int64_t>(std::ceil((xb - gridX0_) * ss_ - 0.5)));
}

void RowRenderer::groundProfile(double y, Profile& prof) const {
  const size_t n = static_cast<size_t>(samples_);
  prof.z.resize(n);
  prof.obj.assign(n, encode(kGround, 0));
  const Terrain& ter = layout_.terrain;
  for (size_t i = 0; i < n; ++i) prof.z[i] = ter.z(groundX(static_cast<std::int64_t>(i)), y);
}

void RowRenderer::raiseBuildings(double y, Profile& prof, std::vector<double>& cuts) const {
  std::vector<double> xs;
  for (size_t b = 0; b < layout_.buildings.size(); ++b) {
    const cv::Rect2d& bb = buildingBounds_[b];
    if (y < bb.y || y > bb.y + bb.height) continue;
    const Building& bld = layout_.buildings[b];
    xs.clear();
    rowCrossings(bld.footprint.outer, y, xs);
    for (const auto& h : bld.footprint.holes) rowCrossings(h, y, xs);
    std::sort(xs.begin(), xs.end());
    cuts.insert(cuts.end(), xs.begin(), xs.end());
    for (size_t c = 0; c + 1 < xs.size(); c += 2) {
      std::int64_t i0, i1;
      sampleRange(xs[c], xs[c + 1], &i0, &i1);
      for (std::int64_t i = i0; i < i1; ++i) {
        prof.z[static_cast<size_t>(i)] = bld.roofZ(groundX(i), y);
        prof.obj[static_cast<size_t>(i)] = encode(kRoof, b);
      }
    }
    for (const Box& box : bld.boxes) {
      xs.clear();
      rowCrossings(box.ring, y, xs);
      std::sort(xs.begin(), xs.end());
      cuts.insert(cuts.end(), xs.begin(), xs.end());
      for (size_t c = 0; c + 1 < xs.size(); c += 2) {
        std::int64_t i0, i1;
        sampleRange(xs[c], xs[c + 1], &i0, &i1);
        for (std::int64_t i = i0; i < i1; ++i) {
          if (box.topZ > prof.z[static_cast<size_t>(i)]) {
            prof.z[static_cast<size_t>(i)] = box.topZ;
            prof.obj[static_cast<size_t>(i)] = encode(kBox, b);
          }
        }
      }
    }
  }
}

void RowRenderer::raiseTrees(double y, Profile& prof) const {
  for (size_t k = 0; k < layout_.trees.size(); ++k) {
    const Tree& tree = layout_.trees[k];
    const double r = tree.maxRadius();
    if (std::abs(y - tree.centre.y) >= r) continue;
    std::int64_t i0, i1;
    sampleRange(tree.centre.x - r, tree.centre.x + r, &i0, &i1);
    for (std::int64_t i = i0; i < i1; ++i) {
      double z;
      if (tree.crownZ(groundX(i), y, &z) && z > prof.z[static_cast<size_t>(i)]) {
        prof.z[static_cast<size_t>(i)] = z;
        prof.obj[static_cast<size_t>(i)] = encode(kTree, k);
      }
    }
  }
}

// Grid positions, then the vertical walls: at each polygon edge crossing insert the surface
// just outside and just inside, at the same X.
void RowRenderer::insertWalls(double y, std::vector<double>& cuts, Profile& prof) const {
  const size_t n = static_cast<size_t>(samples_);
  prof.x.resize(n);
  for (size_t i = 0; i < n; ++i) prof.x[i] = groundX(static_cast<std::int64_t>(i));
  if (cuts.empty()) return;
  std::sort(cuts.begin(), cuts.end());
  std::vector<double> mx, mz;
  std::vector<std::int32_t> mobj;
  mx.reserve(n + 2 * cuts.size());
  mz.reserve(n + 2 * cuts.size());
  mobj.reserve(n + 2 * cuts.size());
  constexpr double kSide = 1e-7;  // px: far below any feature, far above rounding at 1e4 px
  size_t c = 0;
  for (size_t i = 0; i < n; ++i) {
    while (c < cuts.size() && cuts[c] <= prof.x[i]) {
      if (cuts[c] > prof.x[0]) {
        for (double side : {-kSide, kSide}) {
          double z;
          std::int32_t obj;
          surfaceAt(cuts[c] + side, y, &z, &obj);
          mx.push_back(cuts[c]);
          mz.push_back(z);
          mobj.push_back(obj);
        }
      }
      ++c;
    }
    mx.push_back(prof.x[i]);
    mz.push_back(prof.z[i]);
    mobj.push_back(prof.obj[i]);
  }
  prof.x.swap(mx);
  prof.z.swap(mz);
  prof.obj.swap(mobj);
}

// The sun lies in the plane of the row: sweep along the light direction keeping the height of
// the highest shadow ray reaching the current vertex.
void RowRenderer::castShadows(Profile& prof) const {
  const size_t m = prof.x.size();
  prof.shadow.assign(m, 0.0f);
  const double dropPerPx = std::tan(layout_.sunElevation) * p_.gsd;
  double ray = -std::numeric_limits<double>::max();
  const bool fromWest = layout_.sunSide < 0;
  for (size_t step = 0; step < m; ++step) {
    const size_t i = fromWest ? step : m - 1 - step;
    if (step > 0) {
      const size_t prev = fromWest ? i - 1 : i + 1;
      ray -= dropPerPx * std::abs(prof.x[i] - prof.x[prev]);
    }
    if (ray > prof.z[i] + 1e-3) prof.shadow[i] = 1.0f;
    ray = std::max(ray, prof.z[i]);
  }
  prof.zMax = *std::max_element(prof.z.begin(), prof.z.end());
}

void RowRenderer::surfaceAt(double x, double y, double* z, std::int32_t* obj) const {
  *z = layout_.terrain.z(x, y);
  *obj = encode(kGround, 0);
  for (size_t b = 0; b < layout_.buildings.size(); ++b) {
    const cv::Rect2d& bb = buildingBounds_[b];
    if (y < bb.y || y > bb.y + bb.height || x < bb.x || x > bb.x + bb.width) continue;
    const Building& bld = layout_.buildings[b];
    if (!insidePolygon(bld.footprint, x, y)) continue;
    *z = bld.roofZ(x, y);
    *obj = encode(kRoof, b);
    for (const Box& box : bld.boxes) {
      core::Polygon boxPolygon;
      boxPolygon.outer = box.ring;
      if (box.topZ > *z && insidePolygon(boxPolygon, x, y)) {
        *z = box.topZ;
        *obj = encode(kBox, b);
      }
    }
  }
  for (size_t k = 0; k < layout_.trees.size(); ++k) {
    double zt;
    if (layout_.trees[k].crownZ(x, y, &zt) && zt > *z) {
      *z = zt;
      *obj = encode(kTree, k);
    }
  }
}

void RowRenderer::renderView(const ViewGeometry& view, const Profile& prof, ZBuffer& zb) const {
  const std::int64_t wOut = static_cast<std::int64_t>(p_.width) * ss_;
  zb.z.assign(static_cast<size_t>(wOut), -std::numeric_limits<double>::max());
  zb.seg.assign(static_cast<size_t>(wOut), -1);
  zb.t.assign(static_cast<size_t>(wOut), 0.0);
  // Output sample k sits at x = (k + 0.5) / ss, so a ground point maps to sample coordinate
  // project(X, Z) * ss - 0.5.
  const std::int64_t vertices = static_cast<std::int64_t>(prof.x.size());
  double xa = view.project(prof.x[0], prof.z[0]) * ss_ - 0.5;
  for (std::int64_t i = 0; i + 1 < vertices; ++i) {
    const double za = prof.z[static_cast<size_t>(i)], zbv = prof.z[static_cast<size_t>(i + 1)];
    const double xb = view.project(prof.x[static_cast<size_t>(i + 1)], zbv) * ss_ - 0.5;
    if (xb > xa) {  // back-facing segments (xb <= xa) are always hidden in a height field
      const std::int64_t k0 = std::max<std::int64_t>(0, static_cast<std::int64_t>(std::ceil(xa)));
      const std::int64_t k1 = std::min<std::int64_t>(wOut, static_cast<std::int64_t>(std::ceil(xb)));
      for (std::int64_t k = k0; k < k1; ++k) {
        const double t = (static_cast<double>(k) - xa) / (xb - xa);
        const double z = za + t * (zbv - za);
        const size_t kk = static_cast<size_t>(k);
        if (z > zb.z[kk]) {
          zb.z[kk] = z;
          zb.seg[kk] = static_cast<std::int32_t>(i);
          zb.t[kk] = t;
        }
      }
    }
    xa = xb;
  }
}

RowRenderer::SurfacePoint RowRenderer::pointOn(const Profile& prof, double y, std::int32_t seg,
                                               double t) const {
  const size_t i = static_cast<size_t>(seg);
  const double za = prof.z[i], zb = prof.z[i + 1];
  SurfacePoint sp;
  sp.x = prof.x[i] + t * (prof.x[i + 1] - prof.x[i]);
  sp.y = y;
  sp.z = za + t * (zb - za);
  // A wall is the open segment between a low and a high sample; a sample landing exactly on
  // its lower vertex (t == 0, e.g. a nadir view) sees that vertex's own surface.
  sp.wall = t > 0.0 && std::abs(zb - za) > wallSlope_ * (prof.x[i + 1] - prof.x[i]) * p_.gsd;
  if (sp.wall) {
    sp.owner = zb > za ? prof.obj[i + 1] : prof.obj[i];  // a wall belongs to its top
  } else {
    sp.owner = t < 0.5 ? prof.obj[i] : prof.obj[i + 1];
  }
  switch (kindOf(sp.owner)) {
    case kGround: sp.label = kLabelGround; break;
    case kRoof: sp.label = sp.wall ? kLabelFacade : kLabelBuilding; break;
    case kBox: sp.label = kLabelBuilding; break;
    case kTree: sp.label = kLabelVegetation; break;
  }
  return sp;
}

double RowRenderer::radiance(const Profile& prof, const SurfacePoint& sp, std::int32_t seg,
                             double t) const {
  const size_t i = static_cast<size_t>(seg);
  const double shadow = prof.shadow[i] + t * (prof.shadow[i + 1] - prof.shadow[i]);
  const double sunX = sunX_, sunZ = sunZ_;
  const double gsd = p_.gsd;
  const double xm = sp.x * gsd, ym = sp.y * gsd;  // texture coordinates in metres

  double cosine;
  if (sp.wall) {
    const double nx = prof.z[i + 1] > prof.z[i] ? -1.0 : 1.0;  // rising to the east faces west
    cosine = nx * sunX;
  } else {
    double gx = 0.0, gy = 0.0;  // m per px
    switch (kindOf(sp.owner)) {
      case kGround:
        gx = layout_.terrain.gradX;
        gy = layout_.terrain.gradY;
        break;
      case kRoof: layout_.buildings[indexOf(sp.owner)].roofZ(sp.x, sp.y, &gx, &gy); break;
      case kBox: break;
      case kTree: {
        double z;
        layout_.trees[indexOf(sp.owner)].crownZ(sp.x, sp.y, &z, &gx, &gy);
        break;
      }
    }
    const double gxm = gx / gsd, gym = gy / gsd;
    cosine = (-gxm * sunX + sunZ) / std::sqrt(gxm * gxm + gym * gym + 1.0);
  }
  const double shade =
      kAmbient + (1.0 - kAmbient) * std::max(0.0, cosine) * (1.0 - p_.shadowStrength * shadow);

  double albedo = 0.4;
  switch (kindOf(sp.owner)) {
    case kGround: {
      const std::uint64_t s = layout_.groundSeed;
      const double patches = fbm(s, xm, ym, 30.0, 3);
      const double detail = fbm(s + 1, xm, ym, 2.5, 3);
      const double fine = valueNoise(s + 2, xm / 1.0, ym / 1.0);
      albedo = 0.2 + 0.35 * patches + 0.5 * (detail - 0.5) + 0.2 * (fine - 0.5);
      break;
    }
    case kRoof: {
      const Building& b = layout_.buildings[indexOf(sp.owner)];
      if (sp.wall) {
        // Facade: storeys of 3 m with a window grid; the along-wall coordinate is the row.
        const double storey = (sp.z - b.baseZ) / 3.0;
        const double fs = storey - std::floor(storey);
        const double column = ym / 2.6 + static_cast<double>(b.textureSeed % 97) / 97.0;
        const double fc = column - std::floor(column);
        const bool window = fs > 0.35 && fs < 0.8 && fc > 0.25 && fc < 0.75 && sp.z > b.baseZ + 1.0;
        albedo = b.wallAlbedo * (window ? 0.45 : 1.0) +
                 0.05 * (fbm(b.textureSeed, ym, sp.z, 1.5, 2) - 0.5);
        break;
      }
      const cv::Point2d l = b.toLocal(sp.x, sp.y);
      const double um = l.x * gsd, vm = l.y * gsd;
      const double grain = fbm(b.textureSeed, xm, ym, 3.0, 3) - 0.5;
      const double fineGrain = fbm(b.textureSeed + 7, xm, ym, 1.6, 2) - 0.5;
      double pattern;
      if (b.roof == RoofType::Flat) {
        // Membrane sheets with seams every 4 m.
        pattern = -0.5 * seam(um / 4.0, 0.06) + 0.5 * grain + 0.4 * fineGrain;
      } else {
        // Tile courses parallel to the eaves.
        const double run = (b.roof == RoofType::Hip &&
                            b.halfLength - std::abs(l.x) < b.halfWidth - std::abs(l.y))
                               ? um
                               : vm;
        pattern = 0.2 * std::sin(2.0 * std::numbers::pi * run / 1.5) + 0.5 * grain + 0.4 * fineGrain;
      }
      albedo = b.roofAlbedo + 0.4 * b.roofContrast * pattern;
      break;
    }
    case kBox: {
      const Building& b = layout_.buildings[indexOf(sp.owner)];
      albedo = b.boxAlbedo + 0.08 * (fbm(b.textureSeed + 3, xm, ym, 1.0, 2) - 0.5);
      break;
    }
    case kTree: {
      const Tree& tree = layout_.trees[indexOf(sp.owner)];
      albedo = tree.albedo + 0.9 * (fbm(tree.textureSeed, xm, ym, 1.3, 2) - 0.5);
      break;
    }
  }
  albedo = std::clamp(albedo, 0.03, 1.0);
  return std::clamp(255.0 * albedo * shade, 0.0, 255.0);
}

bool RowRenderer::occludedInRight(const Profile& prof, std::int32_t seg, double x,
                                  double z) const {
  const double xr = right_.project(x, z);
  if (xr < 0.0 || xr >= p_.width) return true;
  // The right view's ray through the point climbs towards +X by `run` px per metre.
  const double run = -right_.shiftPerMetre;
  if (run <= 0.0) return false;  // a nadir right view sees every point of a height field
  const std::int64_t vertices = static_cast<std::int64_t>(prof.x.size());
  for (std::int64_t j = seg + 1; j < vertices; ++j) {
    const double rayZ = z + (prof.x[static_cast<size_t>(j)] - x) / run;
    if (rayZ > prof.zMax + 1e-3) break;
    if (prof.z[static_cast<size_t>(j)] > rayZ + 5e-4) return true;
  }
  return false;
}

void RowRenderer::renderRow(int y, const RowOutput& out) const {
  const int width = p_.width;
  const int s = ss_;
  const std::int64_t wOut = static_cast<std::int64_t>(width) * s;
  Profile prof;
  ZBuffer zl, zr;
  std::vector<double> accL(static_cast<size_t>(width), 0.0), accR(static_cast<size_t>(width), 0.0);
  const int centre = s / 2;
  for (int q = 0; q < s; ++q) {
    const double ySub = y + (q + 0.5) / s;
    buildProfile(ySub, prof);
    renderView(left_, prof, zl);
    renderView(right_, prof, zr);
    for (std::int64_t k = 0; k < wOut; ++k) {
      const size_t kk = static_cast<size_t>(k);
      const size_t px = static_cast<size_t>(k / s);
      const bool gtSample = q == centre && k % s == centre;
      if (zl.seg[kk] >= 0) {
        const SurfacePoint sp = pointOn(prof, ySub, zl.seg[kk], zl.t[kk]);
        accL[px] += radiance(prof, sp, zl.seg[kk], zl.t[kk]);
        if (gtSample) {
          out.disparity[px] = static_cast<float>(sp.z / p_.metresPerDisparity + p_.groundDisparity);
          out.dem[px] = static_cast<float>(sp.z);
          out.labels[px] = sp.label;
          out.occlusion[px] = occludedInRight(prof, zl.seg[kk], sp.x, sp.z) ? 255 : 0;
        }
      } else if (gtSample) {
        out.disparity[px] = std::numeric_limits<float>::quiet_NaN();
        out.dem[px] = std::numeric_limits<float>::quiet_NaN();
        out.labels[px] = kLabelGround;
        out.occlusion[px] = 0;
      }
      if (zr.seg[kk] >= 0) {
        const SurfacePoint sp = pointOn(prof, ySub, zr.seg[kk], zr.t[kk]);
        accR[px] += radiance(prof, sp, zr.seg[kk], zr.t[kk]);
        if (gtSample) {
          out.disparityRight[px] =
              static_cast<float>(sp.z / p_.metresPerDisparity + p_.groundDisparity);
        }
      } else if (gtSample) {
        out.disparityRight[px] = std::numeric_limits<float>::quiet_NaN();
      }
    }
  }
  const double norm = 1.0 / (s * s);
  for (int x = 0; x < width; ++x) {
    out.left[x] = static_cast<float>(accL[static_cast<size_t>(x)] * norm);
    out.right[x] = static_cast<float>(accR[static_cast<size_t>(x)] * norm);
  }
}

}  // namespace delineo::sim::detail
