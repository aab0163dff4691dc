#pragma once
// Synthetic urban stereo scenes with exact ground truth, deterministic from a seed.
//
// Model (docs/simulator.md has the full description): a height field Z(X, Y) in metres over a
// ground grid in pixel units (terrain plane + undulation, buildings with flat/gable/hip roofs
// and superstructures, round-ish tree crowns) viewed by two parallel oblique projections that
// share rows (an epipolar pair):
//   x_left  = X + a * Z / mpd          a = leftObliquity
//   x_right = X - b * Z / mpd - d0     b = 1 - leftObliquity
//   d = x_left - x_right = Z / mpd + d0,   so x_right = x_left - d (d larger for higher points)
// with mpd = metresPerDisparity and d0 = groundDisparity (the disparity of Z = 0, which is the
// terrain height at the image centre). The default a = b = 0.5 is symmetric: the left view sees
// west-facing walls, the right view east-facing walls. Each view is rendered with a z-buffer
// (highest point along the ray wins) at supersampling x supersampling samples per pixel, then
// box-averaged. Radiance is a function of the 3D surface point only (Lambertian), then each view
// gets its gain/offset and Gaussian noise.
//
// Ground truth is sampled at the exact centre of each left pixel (the centre supersample).
// No file I/O here: the CLI command `simulate` writes the rasters through delineo::io.
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/core/params.hpp"
#include "delineo/core/progress.hpp"

namespace delineo::sim {

struct SceneParams {
  int seed = 1;                     // every random choice derives from it
  int width = 640;                  // px
  int height = 480;                 // px
  int buildings = 12;               // requested count; fewer when they do not fit (see Scene)
  int trees = 16;                   // requested count
  double slope = 3.0;               // % terrain slope, in a seeded direction
  double undulation = 0.4;          // m, amplitude of gentle low-frequency terrain relief
  double noise = 2.0;               // grey levels, Gaussian noise sigma added to each view
  double gsd = 0.25;                // m/px, ground sampling distance
  double metresPerDisparity = 0.5;  // m of height per px of disparity
  double groundDisparity = 8.0;     // px, disparity of Z = 0 (ground at the image centre)
  double leftObliquity = 0.5;       // share a of the parallax carried by the left view (0 = nadir)
  double rightGain = 0.92;          // right = gain * radiance + offset (left: gain 1, offset 0)
  double rightOffset = 6.0;         // grey levels
  double shadowStrength = 0.45;     // 0..1, darkening of cast shadows (sun along the rows)
  int supersampling = 3;            // odd samples per pixel per axis (the centre one is the GT)
  double margin = 10.0;             // px, objects (both views) keep this far from image borders

  template <class V>
  void visit(V&& v) {
    using core::ParamInfo;
    v(ParamInfo{"seed", "Seed", "", "Random seed: the same seed gives the same scene", 0,
                2147483647},
      seed);
    v(ParamInfo{"width", "Width", "px", "Image width", 64, 20000}, width);
    v(ParamInfo{"height", "Height", "px", "Image height", 64, 20000}, height);
    v(ParamInfo{"buildings", "Buildings", "", "Number of buildings requested", 0, 10000},
      buildings);
    v(ParamInfo{"trees", "Trees", "", "Number of trees requested", 0, 100000}, trees);
    v(ParamInfo{"slope", "Terrain slope", "%", "Slope of the terrain plane", 0, 30}, slope);
    v(ParamInfo{"undulation", "Undulation", "m", "Amplitude of gentle terrain relief", 0, 10},
      undulation);
    v(ParamInfo{"noise", "Noise", "grey levels", "Gaussian noise sigma added to each view", 0,
                50},
      noise);
    v(ParamInfo{"gsd", "GSD", "m/px", "Ground sampling distance", 0.01, 10}, gsd);
    v(ParamInfo{"metres-per-disparity", "Metres per disparity", "m/px",
                "Height difference giving one pixel of disparity", 0.01, 100},
      metresPerDisparity);
    v(ParamInfo{"ground-disparity", "Ground disparity", "px",
                "Disparity of the ground at the image centre", -10000, 10000},
      groundDisparity);
    v(ParamInfo{"left-obliquity", "Left obliquity", "",
                "Share of the parallax carried by the left view (0 = left nadir, 0.5 = symmetric)",
                0, 1},
      leftObliquity);
    v(ParamInfo{"right-gain", "Right gain", "", "Radiometric gain of the right view", 0.2, 5},
      rightGain);
    v(ParamInfo{"right-offset", "Right offset", "grey levels",
                "Radiometric offset of the right view", -128, 128},
      rightOffset);
    v(ParamInfo{"shadow-strength", "Shadow strength", "",
                "Darkening of cast shadows (0 = no shadows)", 0, 1},
      shadowStrength);
    v(ParamInfo{"supersampling", "Supersampling", "",
                "Odd number of samples per pixel per axis for anti-aliasing", 1, 9},
      supersampling);
    v(ParamInfo{"margin", "Margin", "px", "Distance kept between objects and the image borders",
                0, 1000},
      margin);
  }
  void validate() const;
};

// Labels of the ground-truth label raster.
enum Label : std::uint8_t {
  kLabelGround = 0,
  kLabelBuilding = 1,    // roof surfaces and roof superstructures
  kLabelVegetation = 2,  // tree crowns (top and sides)
  kLabelFacade = 3,      // building walls between the ground and the roof edge
};

struct Scene {
  core::RunStatus status = core::RunStatus::Completed;  // Canceled: the rasters are empty
  cv::Mat left, right;  // CV_8U grey, the epipolar pair
  cv::Mat disparity;    // CV_32F, left geometry: x_right = x_left - d; NaN where no surface
  cv::Mat occlusion;    // CV_8U, 255 where the left pixel's point is not seen in the right view
                        // (hidden by nearer surfaces, or projected outside the right image)
  cv::Mat disparityRight;  // CV_32F, right geometry: the point seen at right pixel x is at
                           // left x + d (for left-right consistency checks)
  cv::Mat dem;          // CV_32F, metres, height of the left pixel's visible point
  cv::Mat labels;       // CV_8U, Label values of the left pixel's visible point
  // One Feature per building: the roof outline at roof-edge (eave) height projected into the
  // left image (holes for courtyards). Attributes: id (int, 1-based), roof_disparity_min (eave),
  // roof_disparity_max (ridge; superstructures excluded), superstructure_disparity_max (highest
  // point including superstructures), ground_disparity (terrain under the footprint centroid),
  // height_m (eave above that ground), ridge_height_m, roof_type (flat|gable|hip),
  // shape (rect|L|T|U|courtyard|angled), orientation_deg.
  std::vector<core::Feature> footprints;
  int disparityMin = 0;  // full search range covering every GT disparity with a 2 px margin
  int disparityMax = 0;
  double gsd = 0.0;
  double metresPerDisparity = 0.0;
  double groundDisparity = 0.0;
  int seed = 0;
  int buildingsPlaced = 0;  // may be below the requested count when the image is crowded
  int treesPlaced = 0;
};

// Generates the scene. Throws core::Error(InvalidParameter) for invalid parameters. Polls
// `progress` once per band of rows; a cancel returns a Scene with status Canceled.
Scene simulateScene(const SceneParams& params, core::Progress* progress = nullptr);

// The square scene of the stereo benchmarks (bench_stereo --size N --seed S): N x N px, one
// building per 40 000 px and one tree per 30 000 px (at least one of each), the rest at the
// defaults above.
SceneParams squareSceneParams(int size, int seed);

// scene.json: image size, disparity search range, GSD, metres per disparity, seed, the
// geometry convention, the output file names and the full parameters.
nlohmann::json sceneDescription(const Scene& scene, const SceneParams& params);
// Writes sceneDescription() to `path`. Throws core::Error(WriteFailed).
void writeSceneJson(const std::string& path, const Scene& scene, const SceneParams& params);

// What a consumer of a simulated scene directory needs from scene.json.
struct SceneInfo {
  int width = 0, height = 0;
  int disparityMin = 0, disparityMax = 0;
  double gsd = 0.0, metresPerDisparity = 0.0, groundDisparity = 0.0;
  int seed = 0;
  SceneParams params;
};
// Reads scene.json. Throws FileNotFound, UnreadableFile.
SceneInfo readSceneJson(const std::string& path);

// File names written by the CLI into a scene directory (also listed in scene.json).
struct SceneFiles {
  static constexpr const char* left = "left.tif";
  static constexpr const char* right = "right.tif";
  static constexpr const char* disparity = "disparity_gt.tif";
  static constexpr const char* disparityRight = "disparity_right_gt.tif";
  static constexpr const char* occlusion = "occlusion_gt.tif";
  static constexpr const char* dem = "dem_gt.tif";
  static constexpr const char* labels = "labels_gt.tif";
  static constexpr const char* footprints = "footprints_gt.geojson";
  static constexpr const char* description = "scene.json";
};

}  // namespace delineo::sim
