#pragma once
// Parameters of box-fitting (docs/boxfit.md explains each stage and choice). Lengths are in
// left-image pixels, heights in metres (in px of disparity when the caller has no height model).
#include "delineo/core/params.hpp"

namespace delineo::boxfit {

struct BoxFitParams {
  // Preprocessing of the image (the paper: bilateral filter, then Canny).
  double bilateralSigma = 20.0;  // grey levels, range sigma of the 5 px bilateral filter (0 = off)
  double edgeContrast = 4.0;     // Canny's high threshold as a multiple of the median gradient
  // Building segments from the DEM (the paper: local thresholding, erosion, components).
  double minHeight = 2.0;          // m above the local ground for anything to be a building
  int groundWindow = 301;          // px, side of the grey opening that estimates the local ground
  double thresholdFraction = 0.8;  // the local threshold, as a fraction of the roof's height
  double roofBand = 0.5;           // heights above (1 + this) x roof + min-height: another building
  int erosionRadius = 2;           // px, disk separating touching segments (paper: 2)
  int minArea = 500;               // px, smaller segments are dropped (paper: 500)
  int leash = 0;                   // px the segment may reach outside the initial polygon (0: inside)
  int roiMargin = 24;              // px added around the initial polygon (or segment)
  // Seeds (the paper: skeleton, junctions, pieces of 20 px, centres of mass).
  int pieceLength = 20;         // px, skeleton pieces between junctions (paper: 20)
  double windowFactor = 3.0;    // window side = max(2 x piece length, this x local width)
  bool skipCovered = false;     // seeds already inside a fitted box add no box of their own
  // Boxes (the paper: grown on Canny edges for a sweep of angles, energy = distance to edges).
  double angleStep = 5.0;        // degrees between swept box orientations (paper: 30)
  double angleResolution = 1.0;  // degrees, refinement around each seed's best angle (0 = off)
  double stripInside = 0.8;      // a side grows while this share of its new row is in the segment
  int snapInward = 12;           // px a side may move inward from the segment onto an edge
  int snapOutward = 4;           // px a side may move outward from the segment onto an edge
  double edgeCap = 3.0;          // px, distance to the nearest edge is capped at this
  double segmentWeight = 1.0;    // weight of the segment's disagreement with a box side (0 = edges only)
  double maxEnergy = 2.0;        // px, whole image: a region whose boxes all fit worse is no building
  // Outline (the paper: fill, dilate and erode with radius 2, lines on 20 px pieces).
  int closingRadius = 2;        // px, disk of the closing that fuses the boxes (paper: 2)
  int refineLength = 20;        // px, border pieces that get one fitted line each (paper: 20)
  double cornerTolerance = 1.5; // px, deviation that makes a corner between border pieces
  double minHoleArea = 120.0;   // px², smaller holes of the merged boxes are filled

  template <class V>
  void visit(V&& v) {
    using core::ParamInfo;
    v(ParamInfo{"bilateral-sigma", "Bilateral sigma", "grey levels",
                "Range sigma of the edge-preserving bilateral filter applied before Canny (0 = off)",
                0, 255},
      bilateralSigma);
    v(ParamInfo{"edge-contrast", "Edge contrast", "",
                "Canny edges start where the gradient exceeds this many times the region's median "
                "gradient and continue down to half of that",
                1, 100},
      edgeContrast);
    v(ParamInfo{"min-height", "Min height", "m",
                "Height above the local ground below which nothing is a building", 0.1, 1000},
      minHeight);
    v(ParamInfo{"ground-window", "Ground window", "px",
                "Side of the grey opening of the DEM that estimates the local ground; wider than "
                "the widest building",
                9, 100001},
      groundWindow);
    v(ParamInfo{"threshold-fraction", "Threshold fraction", "",
                "Local threshold of the DEM at this fraction of the roof's height above the ground",
                0.05, 0.95},
      thresholdFraction);
    v(ParamInfo{"roof-band", "Roof band", "",
                "Heights above (1 + this) x the roof height + min-height belong to another, taller "
                "building",
                0, 100},
      roofBand);
    v(ParamInfo{"erosion-radius", "Erosion radius", "px",
                "Radius of the disk eroding the segments to separate touching buildings (paper: 2)",
                0, 50},
      erosionRadius);
    v(ParamInfo{"min-area", "Min area", "px",
                "Segments smaller than this after the erosion are dropped (paper: 500)", 1, 1e8},
      minArea);
    v(ParamInfo{"leash", "Leash", "px",
                "Farthest the building segment may reach outside the initial polygon (0 = it "
                "stays inside)",
                0, 10000},
      leash);
    v(ParamInfo{"roi-margin", "ROI margin", "px",
                "Margin added around the initial polygon (or segment) to make the region of "
                "interest",
                4, 10000},
      roiMargin);
    v(ParamInfo{"piece-length", "Piece length", "px",
                "Length of the skeleton pieces whose centres seed the boxes (paper: 20)", 4, 10000},
      pieceLength);
    v(ParamInfo{"window-factor", "Window factor", "",
                "A box grows inside a square window of side max(2 x piece length, this x the "
                "building's local width)",
                1, 100},
      windowFactor);
    v(ParamInfo{"skip-covered", "Skip covered seeds", "",
                "Seeds already inside a fitted box grow no box of their own (speed)"},
      skipCovered);
    v(ParamInfo{"angle-step", "Angle step", "deg",
                "Step of the swept box orientations over a quarter turn (paper: 30)", 0.5, 45},
      angleStep);
    v(ParamInfo{"angle-resolution", "Angle resolution", "deg",
                "Step of the refinement around each seed's best orientation (0 = off)", 0, 45},
      angleResolution);
    v(ParamInfo{"strip-inside", "Strip inside", "",
                "A box side moves out while at least this share of its new row lies in the "
                "building segment",
                0.05, 1},
      stripInside);
    v(ParamInfo{"snap-inward", "Snap inward", "px",
                "Farthest a box side moves inward from where the segment stops it, onto the "
                "best-fitting edge",
                0, 1000},
      snapInward);
    v(ParamInfo{"snap-outward", "Snap outward", "px",
                "Farthest a box side moves outward from where the segment stops it, onto the "
                "best-fitting edge",
                0, 1000},
      snapOutward);
    v(ParamInfo{"edge-cap", "Edge distance cap", "px",
                "Distance from a box side to the nearest Canny edge is capped at this in the energy",
                0.5, 100},
      edgeCap);
    v(ParamInfo{"segment-weight", "Segment weight", "",
                "Weight of the DEM segment's disagreement with a box side beside its edge distance "
                "(0 = the image's edges alone, as in the paper)",
                0, 100},
      segmentWeight);
    v(ParamInfo{"max-energy", "Max energy", "px",
                "Without an initial polygon, a raised region none of whose boxes lies closer than "
                "this to the edges on average (a tree crown) is not taken as a building",
                0.1, 100},
      maxEnergy);
    v(ParamInfo{"closing-radius", "Closing radius", "px",
                "Radius of the disk that closes the union of the boxes (paper: 2)", 0, 50},
      closingRadius);
    v(ParamInfo{"refine-length", "Refine length", "px",
                "Length of the border pieces that each get a fitted line (paper: 20)", 3, 10000},
      refineLength);
    v(ParamInfo{"corner-tolerance", "Corner tolerance", "px",
                "Deviation of the merged border from a straight line that makes a corner", 0.25, 50},
      cornerTolerance);
    v(ParamInfo{"min-hole-area", "Min hole area", "px²",
                "Holes of the merged boxes smaller than this are filled", 0, 1e9},
      minHoleArea);
  }
  void validate() const;
};

}  // namespace delineo::boxfit
