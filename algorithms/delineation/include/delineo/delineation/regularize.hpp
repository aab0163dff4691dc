#pragma once
// Outline regularization: turns a ragged building outline (the active polygon's, box-fitting's,
// one drawn by hand; holes included) into a clean one with right angles (or right angles and
// diagonals, or any angles), few vertices and a bounded distance from the input. Qt-free; the
// energy check of the acceptance gate needs the stereo pair and lives in delineate.hpp.
// docs/delineation.md, "Regularization", explains each stage.
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/core/params.hpp"

namespace delineo::delineation {

struct RegularizationParams {
  static constexpr double kMinTolerance = 0.5;  // px, the smallest tolerance
  // right-angles | right-angles-and-diagonals | any-angle | none
  std::string mode = "right-angles";
  // px: farthest any point of the result may lie from the input outline. delineate() also tries
  // half and a quarter of it when a gate refuses the result.
  double tolerance = 12.0;
  double minEdge = 4.0;    // px: edges shorter than this are merged away when the tolerance allows
  double minWidth = 4.0;   // px: spikes, fingers and slits narrower than this are cut off first
  double maxAreaChange = 8.0;  // %: largest change of the enclosed area
  double energyMargin = 0.25;  // F per px of outline: how much worse the energy may get (delineate)
  double imageEdgeWeight = 1.0;  // weight of the image edges along the outline in the orientation
  template <class V>
  void visit(V&& v) {
    v(core::ParamInfo{"regularize", "Regularize", "",
                      "Last stage of the outline: right angles, right angles and 45-degree "
                      "diagonals, any angles (collinear edges merged), or none (the raw outline)",
                      0, 0, "right-angles|right-angles-and-diagonals|any-angle|none"},
      mode);
    v(core::ParamInfo{"regularize-tolerance", "Regularize tolerance", "px",
                      "Farthest any point of the regularized outline may lie from the raw outline "
                      "(half and a quarter of it are tried when the result is refused)",
                      kMinTolerance, 50},
      tolerance);
    v(core::ParamInfo{"regularize-min-edge", "Regularize min edge", "px",
                      "Edges shorter than this are merged into their neighbours when the tolerance "
                      "allows",
                      0, 100},
      minEdge);
    v(
        core::ParamInfo{
            "regularize-min-width", "Regularize min width", "px",
            "Spikes, fingers and slits narrower than this are cut off before regularizing "
            "(the tolerance applies to the outline without them; 0 = off)",
            0, 50},
        minWidth);
    v(
        core::ParamInfo{
            "regularize-max-area-change", "Regularize area change", "%",
            "The raw outline is kept when regularizing changes its area by more than this", 0, 100},
        maxAreaChange);
    v(
        core::ParamInfo{
            "regularize-energy-margin", "Regularize energy margin", "per px",
            "The raw outline is kept when regularizing raises the active polygon's energy "
            "by more than this per pixel of outline length",
            0, 1000},
        energyMargin);
    v(core::ParamInfo{"regularize-image-edges", "Regularize image edges", "",
                      "Weight of the image edges along the outline against the outline's own edges "
                      "when finding the building's orientation (0 = outline only)",
                      0, 100},
      imageEdgeWeight);
  }
  void validate() const;
};

enum class RegularizationMode { None, RightAngles, RightAnglesAndDiagonals, AnyAngle };
// Throws core::Error(InvalidParameter) for an unknown name.
RegularizationMode regularizationMode(const std::string& name);

enum class RegularizationStatus {
  Off,          // mode none (or the run did not complete): the raw outline
  Regularized,  // the regularized outline passed the gate
  KeptRaw,      // the gate failed: the raw outline, and `reason` says why
};
// "off", "regularized", "kept-raw"
std::string toString(RegularizationStatus status);

struct RegularizationOutcome {
  core::Polygon polygon;  // the regularized outline, or the input when kept
  RegularizationStatus status = RegularizationStatus::Off;
  std::string reason;         // why the input was kept (empty when regularized or off)
  double orientationDeg = 0;  // dominant orientation, degrees in [0, 90)
  double tolerance = 0;       // px: the tolerance this outcome was regularized within
  double deviation = 0;       // px: farthest point of the result from the input outline
  double areaRatio = 1;       // area(result) / area(input)
  double energyChange = 0;    // F(result) - F(input) when the energy gate ran (delineate)
  int inputVertices = 0, outputVertices = 0;
};

// The building's dominant orientation in radians, in [0, π/2): the peak of the length-weighted
// histogram of the directions modulo 90° of the outline's chords (the outline simplified at
// `epsilon` px), plus `imageEdgeWeight` times the gradient-weighted histogram of the image edges
// within 2 px of the outline (`image`: single-channel, in the outline's coordinates; empty =
// outline only).
double dominantOrientation(const core::Polygon& outline, const cv::Mat& image,
                           double imageEdgeWeight, double epsilon = 1.5);

// Regularizes every ring of `outline` (left-image pixels) and gates the result: every ring
// simple, holes inside the outer ring and apart, no point farther than `tolerance` from the
// input (once its parts narrower than `minWidth` are cut off), area within `maxAreaChange` of
// the input's, no more vertices than the input, not a round outline. When the gate fails the
// input comes back with status KeptRaw and the reason. `image` (optional, single-channel, the
// image the outline was drawn on) adds its edges to the orientation and bounds the result: edges
// running along the image border stay on it. Throws core::Error(InvalidParameter) for bad
// parameters or an outline that is not a polygon (fewer than 3 vertices, non-finite
// coordinates, zero area). `orientation` (radians), when given, is the building's dominant
// orientation instead of the one read from the outline: a part of a building squared like the
// building (project::roofParts).
RegularizationOutcome regularizeOutline(const core::Polygon& outline,
                                        const RegularizationParams& params,
                                        const cv::Mat& image = {},
                                        std::optional<double> orientation = std::nullopt);

}  // namespace delineo::delineation
