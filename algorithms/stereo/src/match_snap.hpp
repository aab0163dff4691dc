#pragma once
// Depth steps moved onto the image contour between them (internal to delineo_stereo).
#include <opencv2/core.hpp>

namespace delineo::stereo::detail {

struct StepSnapSettings {
  double minStep = 2.0;      // px of disparity: smaller differences are slopes, not steps
  int maxGap = 16;           // px: most unmatched pixels between the two sides of a step
  int reach = 3;             // px: how far beyond the matched sides the contour is looked for
  double edgeSigmas = 4.0;   // × noise sigma: weakest contrast taken for the outline
  double checkSigmas = 3.0;  // × noise sigma: photometric check of the pixels changed (0 = off)
  // Checked cut of a roof's +x edge (see below).
  int cutReach = 8;                 // px: how far back over the near side the cut may go
  int nearHoleGap = 8;              // px: most unmatched pixels inside the near side it goes over
  int cutAhead = 4;                 // px: how far over the far side a line of cuts may take a row
  int carriedRuns = 1;              // px of a run on each side of a contour it crosses (0 = off)
  double carriedMargin = 1.0;       // noise sigmas: a farther disparity's lead over the run's
  double carriedOffset = 4.0;       // noise sigmas: brightness offset that splits a run (0 = off)
  double carriedOffsetGrey = 8.0;   // grey levels: the least such offset, whatever the noise
  int carriedOffsetPixels = 2;      // px: fewest pixels past the contour the offset is read on
  int carriedOwnRuns = 16;          // px: longest run of its own split off by the offset (0 = off)
  int carriedOwnGap = 2;            // px: most unmatched pixels between it and the nearer run
  int openReach = 5;                // px: farthest contour an open end reaches by the offset
  int openGrowth = 16;              // px: farthest an open end grows over pixels only it explains
  double hardEndPenalty = 2.0;      // × errorCap per px: cut before where the near side fails hard
  double contourWeight = 0.5;       // error (noise sigmas) traded for one sigma of contour contrast
  double rightContourWeight = 2.0;  // the same for the right view's contrast at x − dNear
  double rightContourCap = 6.0;     // noise sigmas: most right-view contrast counted
  double errorCap = 6.0;            // noise sigmas: most a single pixel's error counts
  int nearSlopePixels = 16;         // px: near-side pixels its slope is fitted on (0 = off)
  double maxNearSlope = 0.5;        // px of disparity per px: steepest near-side slope taken
  // Continuity of the checked cut across rows (see chooseCuts in match_snap_cut_lines.hpp).
  int lineRows = 6;            // rows each side of a row's line through the cuts (0 = off)
  double lineCap = 5.0;        // noise sigmas: most a row off the line adds to its cost
  double linkDisparity = 1.5;  // px: same step in the next row when both sides are this close
  double maxSlope = 6.0;       // px per row: steepest line tried (roof outlines reach 3.7 px
                               //   per row; 6 against 3: 38 scenes' mean edge +0.1)
  int slopeSteps = 24;         // slopes tried on each side of vertical (0.25 px per row apart)
  int threads = 1;             // workers over bands of rows (same result on any number)
};

// Along each row, two matched pixels a < b with only unmatched pixels between them (at most
// maxGap) and disparities at least minStep apart are the two sides of a depth step.
// Near side on the left (larger disparity: a roof's +x edge, where both views see the ground): with
// `right` given and checkSigmas > 0, the near side's last pixel e is chosen in [a − cutReach,
// b − 1] (back over the near side's own pixels only, and over holes of at most nearHoleGap
// unmatched pixels between them: a roof's pixel matched alone just before its outline, a few pixels
// after the roof's run, would otherwise stay an island that the speckle filter removes, leaving
// a hole) at the least total photometric error (mean |left − mapped right| of the pixel and its
// two vertical neighbours, in noise sigmas, capped at errorCap): near pixels at the near disparity
// up to e, far ones at the far disparity from e + 2 (the near disparity follows the near side's
// slope along the row: the least-squares line through the row's matched pixels of its last
// nearSlopePixels px on its side of the mid-level, through d[a], at most maxNearSlope px per px; a
// pitched roof's facet sloping to its outline comes out of fronto-parallel windows as steps, and at
// the last step's value its last pixels failed like the ground's) — pixel e + 1 mixes both surfaces
// through the image blur and was seen to pull the cut onto the ground —, less contourWeight × the
// left image's contrast between e and e + 1 (the step between the mean greys of 2 px on each side,
// in sigmas), less rightContourWeight × the right view's contrast where the cut falls in it
// (x − dNear: roof against the wall that view sees; capped at rightContourCap sigmas). With
// lineRows > 0 the cut of a row is taken on the line (through rows y ± lineRows of the same step)
// of least total cost, each row's cost relative to its own best and capped at lineCap: an outline
// is a line, and the rows whose own evidence is weak follow their neighbours. The line may also
// take a row up to cutAhead pixels over its far side (a roof edge that took the ground's value), at
// no less than the row's own best cost: never on the row's own evidence (that fattened objects of
// the real pairs), only where the neighbouring rows put the line. Where the near disparity (along
// its slope) fails hard (≥ errorCap) on two pixels of the gap that the far one explains
// (≤ checkSigmas), after gap pixels it explains within checkSigmas + carriedMargin on average, cuts
// before the pixel two before that failure cost hardEndPenalty × errorCap more per pixel: a plain
// roof beside plain ground of its grey ties both hypotheses, and only the ground past the outline
// (on the wall only the right view shows, at the roof's disparity) tells where it ends. Pixels up
// to e take the near disparity (along its slope, holes too; score `fillScore`), near pixels after
// it become unmatched. Unchecked (`right` empty), the near side ends at the strongest contrast
// within [a − reach, b + reach] when it is at least edgeSigmas sigmas.
// Near side on the right (the left map's −x edge of a roof): the unmatched pixels before it are
// mostly ground the right view does not see and stay unmatched; near pixels before the strongest
// contrast (as above) are cut, checked ones only when the far disparity explains them better.
// Open ends (checked only): a matched run followed by more than maxGap unmatched pixels (a roof
// next to a shadow or textureless ground) is extended to the strongest contrast within `reach`
// (at least edgeSigmas), over pixels that match at its disparity or whose grey is nearer the
// run's last pixel than the pixel beyond that contrast. Up to openReach px, a farther contour
// (the strongest from the run's end to it, at least edgeSigmas) is taken instead when the two
// pixels past its mixed pixel are offset from the right view at the run's disparity by at
// least max(carriedOffset sigmas, carriedOffsetGrey grey levels) and the pixels up to it are
// within half that on average: there the brightness says the run's surface ends. When the run is
// the near side of the run after the gap, it grows (up to openGrowth px) over the pixels its
// disparity explains better by carriedMargin than that run's (each within errorCap); a contour
// within 2 px of where that stops, at a peak of the contrast, is taken when the pixels up to it
// match at the run's disparity within checkSigmas on average.
// Runs carried across a contour (checked only; first, on each row): a matched run whose
// neighbours differ by ≤ 1 px, with the strongest left contour (≥ edgeSigmas) of its last
// maxGap px at least carriedRuns px from both ends. When an integer disparity at least minStep
// farther explains the run's pixels after the contour (mean capped error ≤ checkSigmas and
// carriedMargin below theirs at the run's disparity), those pixels become unmatched: a roof's
// value spread onto the dark ground beyond its +x edge, which at the roof's disparity falls on
// the wall the right view sees. They are also split when their mean signed residual
// (left − mapped right) at the run's disparity is at least max(carriedOffset sigmas,
// carriedOffsetGrey grey levels) while the run's pixels before the contour (as many, at most)
// stay within half that: ground the right view does not see, which no disparity explains,
// carries the roof's value onto the wall only that view shows. A run of its own (at most
// carriedOwnRuns px, at least carriedOffsetPixels) starting at most carriedOwnGap px after a
// nearer run's end, across a contour (≥ edgeSigmas) at that end, is split off the same way: its
// mean signed residual at its own disparities at least that bound, the nearer run's last pixels
// (as many, at most; its mixed last pixel left out) within half of it. The gap left is then snapped
// like the others.
// The far side is always left alone. "Mapped right": the right view's grey levels through the
// grey map of the matched pixel pairs (radiometricMapOfMatches; the images' moments when too few
// are matched). `left`, `right`: the original images (CV_32F, NaN = nodata). Returns the pixels
// changed.
int snapStepsToContours(const cv::Mat& left, const cv::Mat& right, const StepSnapSettings& settings,
                        float fillScore, cv::Mat& disparity, cv::Mat& score);

// What the snapping reads of the images alone, so that it can be prepared while the
// disparities are still being filled: the contrast between x and x + 1 (the step between the
// mean greys of 2 px on each side; CV_32F, (w − 1) × h, nodata as 0) of the left image and, when
// `right` is given, of the right one, and the left image's noise sigma (`leftNoise` when it is
// given, ≥ 0: the caller's noiseSigma of the left image).
struct StepContrast {
  cv::Mat contrast;
  cv::Mat rightContrast;
  double sigma = 1.0;
};
StepContrast stepContrast(const cv::Mat& left, const cv::Mat& right = cv::Mat(),
                          double leftNoise = -1);

// The same with the contrast prepared.
int snapStepsToContours(const cv::Mat& left, const cv::Mat& right, const StepContrast& prepared,
                        const StepSnapSettings& settings, float fillScore, cv::Mat& disparity,
                        cv::Mat& score);

}  // namespace delineo::stereo::detail
