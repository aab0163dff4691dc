#pragma once
// Row renderer: each image row is independent because both views share rows (epipolar pair).
// For every sub-row the scene is a height profile Z(X) sampled on a ground grid of
// `supersampling` samples per pixel plus exact vertical walls at polygon edges; the polyline is
// projected into each view and z-buffered (highest point wins), then shaded.
#include <cstdint>
#include <vector>

#include "layout.hpp"

namespace delineo::sim::detail {

// What one output row produces.
struct RowOutput {
  float* left = nullptr;       // W radiance values in grey levels, before gain/offset/noise
  float* right = nullptr;      // W
  float* disparity = nullptr;  // W ground truth at pixel centres (left view)
  float* disparityRight = nullptr;  // W ground truth at the right view's pixel centres
  float* dem = nullptr;        // W
  std::uint8_t* labels = nullptr;
  std::uint8_t* occlusion = nullptr;
};

class RowRenderer {
 public:
  RowRenderer(const SceneParams& params, const Layout& layout);
  // Renders image row y. Thread-safe: all scratch memory is local to the call.
  void renderRow(int y, const RowOutput& out) const;
  double zMin() const { return zMin_; }
  double zMax() const { return zMax_; }

 private:
  // The row's surface as a polyline: grid samples plus, at every footprint or superstructure
  // edge, a pair of vertices at the same X (outside then inside height) forming an exactly
  // vertical wall at the polygon's true position.
  struct Profile {
    std::vector<double> x;          // px, non-decreasing
    std::vector<double> z;          // m
    std::vector<std::int32_t> obj;  // encoded object id
    std::vector<float> shadow;      // 0 lit, 1 in cast shadow
    double zMax = 0.0;
  };
  struct ZBuffer {
    std::vector<double> z;
    std::vector<std::int32_t> seg;  // index of the profile segment seen, -1 when none
    std::vector<double> t;          // position along that segment
  };
  struct SurfacePoint {
    double x, y, z;
    std::int32_t owner;
    bool wall;
    std::uint8_t label;
  };

  // The row's profile at sub-row y: the steps below, in this order.
  void buildProfile(double y, Profile& prof) const;
  // Terrain heights at the grid samples, every sample ground.
  void groundProfile(double y, Profile& prof) const;
  // Roofs, then superstructures where higher; appends the row's edge crossings to `cuts`.
  void raiseBuildings(double y, Profile& prof, std::vector<double>& cuts) const;
  // Tree crowns where higher than what is there.
  void raiseTrees(double y, Profile& prof) const;
  // Sample positions, and a wall (outside and inside surface) at each of `cuts` (sorted here).
  void insertWalls(double y, std::vector<double>& cuts, Profile& prof) const;
  // Cast shadow of every vertex, and the profile's highest point.
  void castShadows(Profile& prof) const;
  // Grid samples whose centre lies in [xa, xb), clamped to the grid: [*i0, *i1).
  void sampleRange(double xa, double xb, std::int64_t* i0, std::int64_t* i1) const;
  // Height and object of the surface at one point (the same max rule as buildProfile).
  void surfaceAt(double x, double y, double* z, std::int32_t* obj) const;
  void renderView(const ViewGeometry& view, const Profile& prof, ZBuffer& zb) const;
  SurfacePoint pointOn(const Profile& prof, double y, std::int32_t seg, double t) const;
  double radiance(const Profile& prof, const SurfacePoint& sp, std::int32_t seg, double t) const;
  bool occludedInRight(const Profile& prof, std::int32_t seg, double x, double z) const;
  double groundX(std::int64_t i) const { return gridX0_ + (static_cast<double>(i) + 0.5) / ss_; }

  const SceneParams& p_;
  const Layout& layout_;
  ViewGeometry left_, right_;
  int ss_ = 3;
  double gridX0_ = 0.0;  // px, left edge of the ground grid
  std::int64_t samples_ = 0;
  double sampleMetres_ = 0.0;  // ground distance between samples
  double wallSlope_ = 3.0;     // |dZ/dX| above which a profile segment is a wall
  double zMin_ = 0.0, zMax_ = 0.0;
  double sunX_ = 0.0, sunZ_ = 1.0;  // unit vector towards the sun (it lies in the row plane)
  std::vector<cv::Rect2d> buildingBounds_;
};

}  // namespace delineo::sim::detail
