#pragma once
// The 3D content of a scene: terrain, buildings and trees, in ground coordinates (X, Y in pixel
// units of the ground grid, Y = image row) with heights Z in metres.
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/sim/scene.hpp"

namespace delineo::sim::detail {

struct Terrain {
  double gradX = 0.0, gradY = 0.0;  // m per px of the plane
  double centreX = 0.0, centreY = 0.0;
  double undulation = 0.0;  // m
  double undulationPeriod = 1.0;  // px
  double undulationAtCentre = 0.0;
  std::uint64_t seed = 0;
  double z(double x, double y) const;
  double maxUndulation() const { return undulation; }
};

enum class RoofType { Flat, Gable, Hip };
enum class Shape { Rect, L, T, U, Courtyard, Angled };
const char* toString(RoofType r);
const char* toString(Shape s);

// A roof superstructure (chimney, machine room): an oriented box with a flat top.
struct Box {
  core::Ring ring;  // ground px
  double topZ = 0.0;
};

struct Building {
  int id = 0;  // 1-based
  Shape shape = Shape::Rect;
  RoofType roof = RoofType::Flat;
  core::Polygon footprint;  // ground px
  cv::Point2d centre;       // ground px, centre of the local frame
  double angle = 0.0;       // rad, local u axis direction
  double cosAngle = 1.0, sinAngle = 0.0;
  double halfLength = 0.0;  // px, along u (pitched roofs: the ridge direction)
  double halfWidth = 0.0;   // px, along v
  double baseZ = 0.0, eaveZ = 0.0, ridgeZ = 0.0, topZ = 0.0;  // m
  double pitchSlope = 0.0;  // m of rise per px of run, pitched roofs
  std::vector<Box> boxes;
  // Appearance.
  double roofAlbedo = 0.5, roofContrast = 1.0, wallAlbedo = 0.5, boxAlbedo = 0.5;
  std::uint64_t textureSeed = 0;

  // Roof surface height (m) and its gradient (m per px) at a point inside the footprint.
  double roofZ(double x, double y, double* gx = nullptr, double* gy = nullptr) const;
  // Local frame coordinates (px).
  cv::Point2d toLocal(double x, double y) const;
};

struct Tree {
  cv::Point2d centre;  // ground px
  double radius = 0.0;  // px, mean crown radius
  double lobeAmp = 0.0;
  double lobePhase[3] = {0, 0, 0};
  double baseZ = 0.0, rimZ = 0.0, topZ = 0.0;  // m
  double albedo = 0.3;
  std::uint64_t textureSeed = 0;
  double maxRadius() const { return radius * (1.0 + lobeAmp); }
  double radiusAt(double theta) const;
  // Crown height at (x, y); false outside the crown.
  bool crownZ(double x, double y, double* z, double* gx = nullptr, double* gy = nullptr) const;
};

struct Layout {
  Terrain terrain;
  std::vector<Building> buildings;
  std::vector<Tree> trees;
  double sunElevation = 0.8;  // rad
  int sunSide = -1;           // -1: sun in the west (light travels towards +X), +1: in the east
  std::uint64_t groundSeed = 0;
};

// Ground-to-view projection shift per metre of height (px/m) and constant offset (px).
struct ViewGeometry {
  double shiftPerMetre = 0.0;
  double offset = 0.0;
  double project(double x, double z) const { return x + shiftPerMetre * z + offset; }
};
ViewGeometry leftView(const SceneParams& p);
ViewGeometry rightView(const SceneParams& p);

Layout makeLayout(const SceneParams& params);

// Even-odd point-in-polygon (holes count as outside).
bool insidePolygon(const core::Polygon& polygon, double x, double y);

}  // namespace delineo::sim::detail
