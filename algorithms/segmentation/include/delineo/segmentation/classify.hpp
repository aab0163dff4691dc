#pragma once
// Building vs vegetation on the above-ground pixels (Baillard & Maître, docs/dem.md, "Building vs
// vegetation, objects and proposals"): a dark-and-textured radiometric rule, a greenness index
// on colour images, then one label per height-homogeneous region (the majority of its pixels) so that an
// object is of one class. Left-image geometry throughout. No GUI interaction here.
#include <cstdint>

#include <opencv2/core.hpp>

#include "delineo/core/params.hpp"
#include "delineo/core/progress.hpp"

namespace delineo::segmentation {

// Labels of the classification (the simulator's ground-truth values, without its facade class).
enum ClassLabel : std::uint8_t {
  kClassGround = 0,  // ground or no data
  kClassBuilding = 1,
  kClassVegetation = 2,
};

struct ClassifyParams {
  double window = 3.0;             // m, side of the square window of the local measures
  double textureVariation = 0.3;   // std / mean of the window's grey levels above which a dark window is vegetation
  double darkLevel = 90.0;         // grey levels, mean brightness under which a textured window is vegetation (0: off)
  double greenThreshold = 0.1;     // colour only: excess green (2G - R - B) / (R + G + B) above which a pixel is vegetation (1: off)
  double regionStep = 1.0;         // m, largest height step inside one region when no region map is given
  double minObjectArea = 10.0;     // m², smaller one-class pieces take the class of the neighbour they share most border with

  template <class V>
  void visit(V&& v) {
    using core::ParamInfo;
    v(ParamInfo{"window", "Window", "m", "Side of the square window of the local measures", 0.25, 100}, window);
    v(ParamInfo{"texture-variation", "Texture variation", "",
                "Standard deviation over mean of the window's grey levels above which a dark window is vegetation",
                0, 10},
      textureVariation);
    v(ParamInfo{"dark-level", "Dark level", "grey levels",
                "Mean brightness under which a textured window is vegetation (0: off)", 0, 255},
      darkLevel);
    v(ParamInfo{"green-threshold", "Greenness threshold", "",
                "On colour images, the excess green (2G - R - B) / (R + G + B) above which a pixel is vegetation (1: off)", -1, 1},
      greenThreshold);
    v(ParamInfo{"region-step", "Region step", "m",
                "Largest height step between neighbours of one region when no region map is given", 0.05, 100},
      regionStep);
    v(ParamInfo{"min-object-area", "Minimum piece area", "m²",
                "Smaller pieces of one class take the class of the neighbour they share most border with", 0, 100000},
      minObjectArea);
  }
  void validate() const;  // throws core::Error(InvalidParameter)
};

struct Classification {
  core::RunStatus status = core::RunStatus::Completed;  // Canceled: labels empty
  cv::Mat labels;      // CV_8U ClassLabel, one class per region
  cv::Mat pixelLabels; // CV_8U ClassLabel per pixel, before the regions' majority
  cv::Mat greenness;   // CV_32F excess green (2G - R - B) / (R + G + B), window mean; empty for a grey image
  cv::Mat regions;     // CV_32S region index used for the majority (-1 outside the above-ground mask)
};

// Classifies the above-ground pixels. `image`: the left image, CV_8UC1 grey or CV_8UC3 BGR.
// `aboveGround`: CV_8U, non-zero above ground. `ndsm`: CV_32F heights above the DTM (m, NaN no
// data). `regions`: optional CV_32S region map (-1 no data); when empty, the above-ground mask is
// split into regions where neighbouring heights differ by more than `region-step`. `gsd`: metres
// per pixel of the left image. Throws core::Error: UnsupportedInput for empty or wrongly typed
// rasters, MismatchedInputs for sizes that differ, InvalidParameter for bad parameters or gsd.
// Polls `progress` (may be null); a cancel returns status Canceled.
Classification classify(const cv::Mat& image, const cv::Mat& aboveGround, const cv::Mat& ndsm, double gsd,
                        const ClassifyParams& params = {}, const cv::Mat& regions = {},
                        core::Progress* progress = nullptr);

// The above-ground mask split into 4-connected regions whose neighbouring heights differ by at
// most `maxStep` m (no-data heights join the neighbour they touch). CV_32S, -1 outside the mask.
cv::Mat heightRegions(const cv::Mat& aboveGround, const cv::Mat& ndsm, double maxStep);

}  // namespace delineo::segmentation
