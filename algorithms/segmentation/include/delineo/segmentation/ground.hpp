#pragma once
// Ground / above-ground segmentation of a DEM and its DTM (after Baillard and Maître, "3-D
// reconstruction of urban scenes from aerial stereo imagery: a focusing strategy"; docs/dem.md).
//
// Stages (segmentGround()):
//   1. elevation gaps: dem::handleGaps() merges the gaps inside one surface, keeps the others;
//   2. regions: 4-connected growing with steps of at most δ_g between neighbours, walls (pixels
//      steeper than a slope: oblique walls are ramps in left-image geometry) apart;
//   3. regions smaller than an area merged into the neighbour of closest mean height;
//   4. region adjacency graph, plus links across kept gaps along the rows (occlusions);
//   5. labelling ground / above-ground by the exact minimum (graph cut) of α_d U_d + α_c U_c over
//      the graph (ground_model.hpp), alternated with the DTM (dtm.hpp) made from the regions
//      labelled ground, starting from all ground, until the labels repeat;
//   6. regions whose label oscillates become ground;
//   7. above-ground mask and nDSM = DEM - DTM;
//   8. kept gaps whose border is mostly above-ground (unmatched patches of a roof or a crown)
//      join the above-ground mask, each pixel with the label and region of the nearest pixel
//      with a height (a gap spanning a roof and the street beside it is split between them),
//      except the runs along a row from the ground to a surface δ_0 higher (the ground hidden in
//      the right view left of a building) and a seam where the parts of two separate regions of
//      different heights meet (two buildings across an unmatched street stay apart).
// No GUI interaction here: the CLI and the GUI call the same function.
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/params.hpp"
#include "delineo/core/progress.hpp"
#include "delineo/dem/heights.hpp"

namespace delineo::segmentation {

struct GroundParams {
  double regionThreshold = 1.0;  // m, δ_g: largest height step between 4-neighbours of one region
  double wallSlope = 60.0;       // °, pixels steeper than this are walls: regions do not grow
                                 // from them into flatter pixels (90: no split)
  double minRegionArea = 2.0;    // m², smaller regions are merged into the neighbour of closest height
  double criticalHeight = 2.0;   // m, δ_0: least height of an above-ground object over its
                                 // neighbourhood (δ_0 >= 2 δ_g)
  double dataWeight = 0.5;       // α_d, weight of the data potential (α_c = 1 - α_d)
  double dtmWindow = 20.0;       // m, side of the windows of the DTM's ground sampling
  double dtmLevelShare = 0.3;    // a DTM window's ground point lies in the lowest height bin holding
                                 // at least this share of its most populated bin (1: that bin)
  double stepBand = 2.0;         // m, how far inside two neighbouring regions their step is read
  double gapLinkLength = 40.0;   // m, longest kept-gap run along a row across which regions are
                                 // linked (0: no links across gaps)
  double gapAboveShare = 0.5;    // a kept gap whose border is above-ground on more than this share
                                 // of its pixels is above-ground too (1: kept gaps stay unlabelled)
  int maxIterations = 10;        // rounds of labelling and DTM
  dem::GapParams gaps;           // elevation gaps merged or kept (docs/dem.md)

  template <class V>
  void visit(V&& v) {
    using core::ParamInfo;
    v(ParamInfo{"region-threshold", "Region step", "m",
                "Largest height step between neighbouring pixels of one region (paper: 1 m)", 0.001, 1000},
      regionThreshold);
    v(ParamInfo{"wall-slope", "Wall slope", "°",
                "Slope from which a pixel belongs to a wall, whose ramp then does not join roofs to the ground (90: "
                "none)",
                1, 90},
      wallSlope);
    v(ParamInfo{"min-region-area", "Smallest region", "m²",
                "Regions smaller than this are merged into the neighbour of closest height", 0, 1e6},
      minRegionArea);
    v(ParamInfo{"critical-height", "Critical height", "m",
                "Least height of an above-ground object over its surroundings (paper: 2 m, at least twice the "
                "region step)",
                0.002, 10000},
      criticalHeight);
    v(ParamInfo{"data-weight", "Data weight", "",
                "Weight of the height-over-DTM term against the neighbours' term (paper: 0.5)", 0, 1},
      dataWeight);
    v(ParamInfo{"dtm-window", "DTM window", "m",
                "Side of the windows in which the DTM takes one ground point each", 0.001, 1e6},
      dtmWindow);
    v(ParamInfo{"dtm-level-share", "DTM level share", "",
                "A DTM window's ground point is at the lowest height holding this share of its most frequent one (1: "
                "the most frequent)",
                0.001, 1},
      dtmLevelShare);
    v(ParamInfo{"step-band", "Step band", "m",
                "How far inside two neighbouring regions the height step between them is read", 0, 1e4},
      stepBand);
    v(ParamInfo{"gap-link-length", "Gap link length", "m",
                "Longest no-data run along a row across which the regions at its ends are neighbours (0: none)",
                0, 1e6},
      gapLinkLength);
    v(ParamInfo{"gap-above-share", "Gap above share", "",
                "A no-data gap whose border is above-ground on more than this share is above-ground (1: never)", 0, 1},
      gapAboveShare);
    v(ParamInfo{"max-iterations", "Iterations", "",
                "Most rounds of labelling and DTM before unstable regions are set to ground", 1, 1000},
      maxIterations);
    gaps.visit(v);
  }
  // Throws core::Error(InvalidParameter): a field outside its domain, or δ_0 < 2 δ_g.
  void validate() const;
};

struct GroundRegionInfo {
  int pixels = 0;
  double meanHeight = 0.0;  // m
  bool above = false;
  bool oscillating = false;  // its label did not settle: set to ground
};

struct GroundResult {
  core::RunStatus status = core::RunStatus::Completed;
  cv::Mat regions;      // CV_32S region index per pixel, -1 where no height remains (kept gaps not
                        // joined to an above-ground region by stage 8)
  cv::Mat aboveGround;  // CV_8U, 255 above-ground, 0 ground or no height
  cv::Mat dtm;          // CV_32F m, everywhere; NaN only when no region is ground
  cv::Mat ndsm;         // CV_32F m, DEM (merged gaps filled) - DTM, NaN in kept gaps
  cv::Mat demUsed;      // CV_32F m, the DEM after gap handling (what the regions were grown on)
  std::vector<GroundRegionInfo> regionInfo;  // per region index
  int regionCount = 0;
  int links = 0;        // links of the region graph
  int gapLinks = 0;     // of which only across kept gaps
  int groundSamples = 0;  // points of the final DTM
  int iterations = 0;   // labelling rounds run
  bool converged = false;
  int oscillatingRegions = 0;
  int mergedGapPixels = 0, keptGapPixels = 0;
};

// Segments `dem` (CV_32F heights in metres, NaN = no data, in the left image's grid) into ground
// and above-ground and computes its DTM; `gsd` is the ground size of a pixel (m/px, > 0).
// Throws core::Error: InvalidParameter for bad parameters or gsd, UnsupportedInput for an empty
// DEM, another type or infinite heights. A DEM without any height gives no region, an empty mask
// and a NaN DTM. Polls cancel between stages and once per round; a cancel returns status
// Canceled (the rasters then may be empty).
GroundResult segmentGround(const cv::Mat& dem, double gsd, const GroundParams& params,
                           core::Progress* progress = nullptr);

}  // namespace delineo::segmentation
