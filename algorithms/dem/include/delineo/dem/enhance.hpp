#pragma once
// DEM enhancement from building footprints (after Sirmacek, d'Angelo and Reinartz): inside each
// footprint the roof is median-filtered with a window chosen from the DEM's gradients (Otsu),
// the walls become vertical at the outline, and the ground beyond a band along the outline is
// kept as it is. docs/dem-enhancement.md describes each stage.
//
// Geometry: the DEM is a height per left-image pixel (CV_32F, metres, NaN = no data); the
// footprints are in the same left-image pixel coordinates (core/geometry.hpp). No GUI
// interaction here: the CLI and the GUI call the same function.
#include <limits>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/core/params.hpp"
#include "delineo/core/progress.hpp"

namespace delineo::dem {

struct EnhanceParams {
  int wallBand = 3;              // px, band on each side of an outline whose heights are replaced
  double gradientSigma = 0.5;    // px, sigma of the derivative-of-Gaussian gradient (paper: 0.5)
  int smallWindow = 3;           // px, median window on a roof with an object on it (paper: 3)
  int largeWindow = 9;           // px, median window on a plain roof (paper: 9)
  int minObjectPixels = 16;      // px, connected roof pixels above the Otsu threshold that make
                                 // an object (paper: 1)
  int groundWindow = 5;          // px, median window over the ground that fills the outer band
  int outlineTolerance = 2;      // px, outline/DEM disagreements up to this thick follow the
                                 // outline, thicker ones the DEM (0: the outline as given)
  int outlineReach = 12;         // px, how far outside its outline a footprint may grow

  template <class V>
  void visit(V&& v) {
    using core::ParamInfo;
    v(ParamInfo{"wall-band", "Wall band", "px",
                "Width of the band on each side of an outline where the wall's ramp is replaced "
                "by the roof inside and the ground outside",
                0, 100},
      wallBand);
    v(ParamInfo{"gradient-sigma", "Gradient sigma", "px",
                "Sigma of the smoothed gradient whose Otsu threshold finds roof objects (paper: "
                "0.5)",
                0.3, 10},
      gradientSigma);
    v(ParamInfo{"small-window", "Small median window", "px",
                "Odd median window on a roof with an object on it (paper: 3)", 1, 99},
      smallWindow);
    v(ParamInfo{"large-window", "Large median window", "px",
                "Odd median window on a plain roof (paper: 9)", 1, 99},
      largeWindow);
    v(ParamInfo{"min-object-pixels", "Roof object pixels", "px",
                "Size of the largest connected group of roof pixels whose gradient exceeds the "
                "Otsu threshold from which the roof has an object (paper: 1)",
                1, 1000000},
      minObjectPixels);
    v(ParamInfo{"ground-window", "Ground median window", "px",
                "Odd median window over the ground whose values fill the outer band", 1, 99},
      groundWindow);
    v(ParamInfo{"outline-tolerance", "Outline tolerance", "px",
                "Thickness up to which the outline wins where the DEM disagrees with it (ground "
                "inside, roof outside); thicker disagreements follow the DEM (0: off)",
                0, 50},
      outlineTolerance);
    v(ParamInfo{"outline-reach", "Outline reach", "px",
                "How far outside its outline a footprint may grow to take in roof the outline "
                "missed",
                0, 1000},
      outlineReach);
  }
  // Throws core::Error(InvalidParameter): a field outside its domain, an even window, or a
  // small window larger than the large one.
  void validate() const;
};

// What the enhancement did to one footprint.
struct FootprintEnhancement {
  int pixels = 0;            // pixels of the DEM inside the footprint
  int window = 0;            // px, median window used on the roof (0: no data on the roof)
  int objectPixels = 0;      // largest connected group of roof pixels above the Otsu threshold
  int band = 0;              // px, inner band actually used (narrower on narrow footprints)
  int filledPixels = 0;      // no-data pixels inside the footprint that got a height
  int addedPixels = 0;       // roof pixels outside the outline taken into the footprint
  int removedPixels = 0;     // ground pixels inside the outline left out of the footprint
  double roofHeight = std::numeric_limits<double>::quiet_NaN();    // m, median of the roof
  double groundHeight = std::numeric_limits<double>::quiet_NaN();  // m, median around it
};

struct EnhanceResult {
  core::RunStatus status = core::RunStatus::Completed;
  cv::Mat dem;                     // CV_32F, the input's size; the input itself when canceled
  double gradientThreshold = 0.0;  // m/px, Otsu threshold t_d of the gradient magnitude
  std::vector<FootprintEnhancement> footprints;  // one per input footprint, same order
};

// Enhances `dem` (CV_32F, one channel, heights in metres, NaN = no data) with `footprints`
// (left-image pixel coordinates, holes allowed; a footprint may run off the image, pixels
// outside are ignored). Where footprints overlap, the earlier one owns the shared pixels.
// Throws core::Error: UnsupportedInput for an empty DEM, another type, infinite heights or a
// DEM without any height; InvalidParameter for a footprint with fewer than 3 vertices or
// non-finite coordinates; MismatchedInputs for a footprint that covers no pixel of the DEM.
// Polls cancel once per footprint and per band of rows; a cancel returns status Canceled and
// the input DEM unchanged.
EnhanceResult enhanceDem(const cv::Mat& dem, const std::vector<core::Polygon>& footprints,
                         const EnhanceParams& params, core::Progress* progress = nullptr);

// The smoothed gradient magnitude |∇(g_σ * D)| in m/px (derivative-of-Gaussian filters
// normalised so that a plane of slope s gives s); NaN where the filter reaches a no-data pixel.
cv::Mat gradientMagnitude(const cv::Mat& dem, double sigma);

// Otsu's threshold of the finite values of `values` (CV_32F), over 256 bins between the
// minimum and the 99.9th percentile. 0 when there are fewer than two distinct values.
double otsuThreshold(const cv::Mat& values);

}  // namespace delineo::dem
