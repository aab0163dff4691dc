#pragma once
// Disparity of flat (textureless) regions from the matches along their outline (internal to
// delineo_stereo).
#include <functional>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

namespace delineo::stereo::detail {

struct RegionFillSettings {
  double flatSigmas = 2.0;   // × noise sigma: 5x5 standard deviation below this is flat
  int minUnmatched = 30;     // px: flat regions with fewer unmatched pixels are left alone
  double maxShare = 0.25;    // flat regions larger than this share of the image are skipped
  int minMatched = 20;       // px: matches around a region needed to propose a disparity
  double photometric = 6.0;  // × noise sigma: mean |left − mapped right| allowed on the outline
  double contrast = 0.5;     // the best candidate's outline error must be below this × the other's
  double scanAgreement = 0.93;    // a full-range scan confirming the best candidate (0 = off)
  double scanReach = 1.5;         // px: the scan's minimum this close to the candidate confirms it
  double scanVeto = 0.8;          // a disparity > 2 px from the chosen candidate whose outline
                                  //   error is below this × the candidate's vetoes it (0 = off)
  double refocusReach = 1.0;      // px: the value filled is the median of the matches this close
                                  //   to the cluster's median (0: the cluster's median)
  double ringArbiterReach = 1.5;  // px: the value filled is the median of that median, the
                                  //   cluster's mean and the ring error's minimum within this of
                                  //   the mean (0 = the median alone)
  int edgeMinSamples = 20;        // row ends whose sub-pixel edges, measured in both views, set a
                                  //   plain region's constant instead (fewer: the estimates above
                                  //   are kept; 0 = off)
  double edgeReach = 2.0;         // px: the row ends read are those within this of the candidate,
                                  //   and their value is filled when it lies within it too
  double edgeDecideShare = 0.7;   // where the ring cannot tell the candidate from other
                                  //   disparities (the scan does not confirm it), the edges decide
                                  //   when this share of the row ends read agree (0 = off;
                                  //   at 0.8, seed 49 600²'s plain roof, which agreed on 26 of
                                  //   36, stayed unmatched) ...
  int edgeDecidePerSide = 5;      //   and this many of those on each side of the region (a facet
                                  //   sloping along the rows agrees on one side only)
  int growReach = 3;              // px: the filled region grows back to its contour by at most this
  double growSigmas = 3.0;        // × noise sigma: grown pixel vs the region's local mean grey
  double growPhotometric = 4.0;   // × noise sigma: a grown pixel's |left − mapped right|
  int coreOpening = 5;            // px: square opening that gives a region's core (0 = off)
  double coreMinShare = 0.5;      // the core replaces the region only when this share of it
  double coreErrorRatio = 0.85;   //   and when its ring's error is below this × the region's
  // Sloped facets (regions whose outline lines up at no constant disparity): a plane through
  // the row ends of the region and of its counterpart in the right view.
  int planeMinRows = 10;         // rows (and right pixels) needed; 0 = no sloped facets
  double planeGreySigmas = 3.0;  // × noise sigma: counterpart's mean grey vs the region's
  double planeInlier = 1.0;      // px: a row end agrees with the plane within this
  double planeMinShare = 0.7;    // share of the row ends that must agree
  double planeSideShare = 0.9;   // or: share of one side's row ends that agree (> 1 = off)
  double planeEaveShare = 0.33;  //   with this share of the other side's (a hip facet's eave)
  double planeMaxSlope = 0.5;    // px of disparity per px, in x and in y
  bool planeEdgeEnds = true;     // where no constant passed, the plane through the row ends'
                                 //   sub-pixel edges (as for edgeMinSamples) is tried first and
                                 //   limited row by row; the whole-pixel ends' plane if it fails
  double planeTrimShare = 0.1;   // worst share of row ends dropped per trimmed refit (0 = off)
  double planeMargin = 0.95;     // a plane replaces a constant the outline lines up at only when
                                 //   its outline error is below this × the constant's (where no
                                 //   constant passed: the constant of the region's edges)
  double planeMinSpan = 1.5;     // px: and when it changes by at least this over the region's
                                 //   bounding box (|a| · width + |b| · height; 0 = off)
  bool planeWithinMatches = true;    // over a constant, a plane only when its values over the
                                     //   region stay within planeInlier of the range of the
                                     //   matches within 3 px of the region
  double planeCandidateRatio = 1.1;  // where no constant is filled, a plane only when its outline
                                     //   error is below this × the best candidate's (0 = off)
  double planeHiddenRatio = 4.0;     // a plane is not filled when it would hide more matches in
                                     //   the right view than this × the region's area (0 = off)
  // A region darker than the left image's median grey whose outline lines up at no candidate
  // within `photometric` is decided again with each candidate's ring error taken in the region's
  // own light: the ring's median |left − mapped right| residual removed before the mean. The
  // images' grey map is the sunlit scene's; in a shadow the views' brightness can differ from it
  // by several grey levels, the same at every disparity (Toulouse 0051's shaded low roof: ring
  // error 12.8 at its disparity through the map, 1.9 in its own light, limit 4.9).
  bool shadowOwnLight = true;
  // The error in the region's own light ignores the brightness the views disagree on, so the ring
  // decides less there: the value is kept only when this share of the matches beside the region
  // on its rows lie within 1.5 px of it. A shaded alley between two roofs lines up in its own
  // light at the roof's level that its walls' matches carry (Toulouse 0051: 70 % agreeing;
  // filled, it gives the GUI's big roof 35 vertices instead of 4); the shaded low roof there
  // agrees at 98 %, most shaded streets at 90–100 %.
  double ownLightAgreement = 0.9;
  // Beyond the filled pixels, over unmatched ones that match at the fill's disparity on their own.
  int extendReach = 40;             // px (4-connected steps) from the filled pixels; 0 = off
  double extendRestartAgree = 0.5;  // px: extendReach counts from the matches this close to
                                    //   the fill too (the surface itself; < 0: none)
  double extendAgree = 1.0;        // px: matches this close to the fill are passed over (< 0: none)
  int extendWindow = 3;            // px: side of the square window tested
  double extendPhotometric = 2.0;  // × noise sigma: the window's mean |left − mapped right|
  double extendPixelSigmas = 4.0;  // × noise sigma: |left − mapped right| of each window pixel
  double extendContrast = 0.8;     // the window's mean error below this × the one at any
                                   //   disparity 2 px or more away (0 = off)
  int extendWideWindow = 5;        // px: side of the wider window that decides where the
                                   //   extendWindow one is not clearly best (≤ extendWindow: off)
  double extendReplaceOff = 4.0;   // px: matches off the fill by this much or more are replaced
                                   //   where its window matches clearly best (≤ 0: off)
  // Matches inside a filled region that carry another surface's disparity.
  double inRegionReplaceOff = 3.0;  // px: a region's matches off its fill by this much or more
                                    //   are replaced (≤ 0: off)
  double inRegionRatio = 1.25;      //   when the fill's window error is below this × their own
  int inRegionWindow = 5;           // px: side of that window
  // What a tile of a larger pair takes from the whole pair instead of its crops (docs/stereo.md,
  // "Large pairs: tiles"); unset: from the images filled.
  double wholePixels = 0;                // px: the image maxShare is a share of (0: unset)
  double wholeLeftMedianGrey = std::numeric_limits<double>::quiet_NaN();  // for shadowOwnLight
  std::optional<std::pair<double, double>> wholeGreyMap;  // the images' map (radiometricMap)
};

// Flat regions: 4-connected components of the valid left pixels whose 5x5 standard deviation is
// below flatSigmas noise sigmas (NCC leaves them unmatched: a textureless roof). Candidates for a
// region: the two largest clusters (±1 px) of the matches within 3 px of it (its edge pixels,
// matched on windows that reach its outline, and the pixels beyond). Each candidate is scored by
// the mean |left − (gain · right + offset)| over the region's outline ring (2 px on both sides),
// where only the right disparity lines the outlines up: inside a flat region every disparity
// that stays in it matches. The best is kept when below `photometric` noise sigmas and clearly
// better than the other, or, failing the latter, when a scan of the whole range (the right
// view mapped by the grey map of the matched pairs) finds its minimum there too
// (scanAgreement), and vetoed when a scan of the range finds a disparity more than 2 px away
// that lines the outline up clearly better (scanVeto: 2000² roof RMS 1.334 -> 1.193 px, Cones
// bad-2 1.91 -> 1.84 %). The region is then grown back to its image contour (it
// stops 2 px short: its 5x5 windows straddle it) over pixels that look like it and match at its
// disparity on their own; its unmatched pixels and the grown ones whose own disparity explains
// them worse take it, with `fillScore` as score.
// A region that no constant lines up (a gable roof's plain facet, whose disparity changes along
// its outline) takes a plane instead: the one through the row ends of the region and of its
// counterpart in the right view (a right flat region of the same grey), when most rows agree
// with it within `planeInlier` px (see fill_sloped_facet.cpp), and when it lines the
// outline up within planeCandidateRatio × the best cluster candidate's error (a plain roof strip
// between seams takes the next strip over in the right view as its counterpart: 2000², 16 px
// off, 1.2 × the candidate's error; roof RMS 1.193 -> 1.128 px). A region a constant
// lines up takes that plane too when the constant disagrees with most row ends, lies within the
// plane's range over the region and lines the outline up less well than the plane (a hip roof's
// facet, which a constant fills as a step). A hip facet's eave-side row ends scatter in the right
// view (the facade beside it): the plane is also kept when one side's ends agree with it on
// planeSideShare of the rows and the other side's on planeEaveShare, its offset then set where
// the outline lines up best, within planeInlier of the fit. When the plane through all the row
// ends is not kept and no constant lines the outline up, a trimmed fit (the worst planeTrimShare
// of the ends dropped per refit) is tried: a facet joined in the left view to a surface of its
// grey. A plane not kept on both sides' ends fills only the rows one of whose ends agrees, up to
// where the right view's counterpart maps.
// A region's core is the region without its parts thinner than `coreOpening` (a morphological
// opening): the core takes the region's place when it keeps at least `coreMinShare` of it and
// the best candidate's error on the core's ring is below `coreErrorRatio` × the best one on the
// whole region's ring. Then
// the thin parts, joined through the roof's grey (a facade's plain bands between its window
// rows), no longer decide whether the roof is filled, and are not filled with it.
// Once every region is filled, the fill goes on from each over the unmatched pixels next to it
// that are not flat enough for it (a weakly textured roof is flat only in patches, between them
// and up to its contour NCC finds too little), at most `extendReach` px, passing over the
// matches within `extendAgree` px of the fill (the roof's matched parts); a second walk counts
// the reach from the matches within `extendRestartAgree` px of the fill too, and fills only where
// no passed-over match beside the pixel is off the fill by more (2000² edge 89.3 -> 89.6 %).
// A pixel is taken when its extendWindow² window matches at the region's disparity — every
// pixel within `extendPixelSigmas`, the mean within `extendPhotometric` noise sigmas of the
// mapped right view, plus the region's own mean brightness offset between the views — and
// clearly better (`extendContrast`) than at any disparity 2 px or more away, and when the right
// pixel it maps to is no other pixel's match (an occluded pixel beside the roof). A window
// across the contour meets another part of the scene in the right view: the extension stops 1 px
// short of it.
// Seed 3 600²: edge 85.4 → 88.1 %, passing over the agreeing matches 90.6 % (a ring-shaped
// tiled roof).
// Matches off the fill by `extendReplaceOff` px or more do not stop the walk: they are taken
// by the same test as an unmatched pixel, which their own disparity must then fail clearly
// (windows that met a surface as plain as the roof in the right view, such as the facade
// beside it; 2000² edge 89.6 -> 89.9 %). The reach, 40 px (against 32): 2000² edge
// 89.9 -> 90.1 %, a roof whose one filled patch lies about 40 steps from its outline's
// unmatched end; 48 px cost seed 5 0.2 points.
// A region's own matches off its fill by `inRegionReplaceOff` px or more take the fill when its
// inRegionWindow² window explains them about as well as their own disparity: mean |left − mapped
// right| at the fill at most `inRegionRatio` × the one at their disparity. Inside a flat region
// NCC finds no texture of the region's own: its matches come from windows that reached texture
// beyond, across gaps of the contour, and a band along an outline that runs with the rows can
// carry the far side's disparity (seed 3 600²: 469 of 37 240 roof matches > 5 px off, roof RMS
// 5.38 px). A plain pixel is explained alike at both disparities, so the region's fill wins;
// where its own disparity explains it clearly better it is kept. Smaller offsets are left alone
// (matches within 3 px of a fill are mostly the surface's own, sub-pixel ones). At 8 px a plain
// roof kept, around the raised boxes on it, the boxes' disparity 3.5 px above
// it (seed 5 600²: roof RMS 0.285 px, 0.245 at 3 px). A plain slanted surface (Aloe's leaves)
// differs from its constant fill by a few px and its matches are right: Aloe bad-2 2.51 -> 2.55 %
// at 3 px (2 / 2.5 / 3.5 / 4 px: seed 5 0.246 / 0.245 / 0.256 / 0.284 px).
// The constant filled in is the median of the cluster's matches within `refocusReach` px of the
// cluster's median: the tail of windows matched 1-2 px too far along an outline (seed 5's plain
// roof, beside raised boxes) no longer pulls it (+0.39 -> +0.035 px). Each of the three
// estimates of a plain roof's disparity errs on its own roofs: that refocused median (the
// matches beside a rooftop box, 1.8 px high on sim seed 16 1000²), the cluster's mean (the
// tail above), and the ring error's minimum (pulled by the parts of the outline that do not
// line up: filled alone, it took seed 3 600² from 0.17 to 0.63 px; docs/stereo.md). Their
// median (ringArbiterReach: the minimum within 1.5 px of the mean, on a 0.05 px grid) is filled
// instead: on 44 filled roofs of 14 failing scenes, RMS 0.362 -> 0.298 px against the truth;
// over the five battery groups (47 scenes) roof RMS lower on 19, higher on 5.
// Those three estimates all come from the matches and the ring, which a plain roof's outline
// biases the same way: a textured ground of the roof's grey beside an edge draws the windows and
// the ring's outer half across it (sim seed 13 1000²: a roof at 70.42 filled at 71.20, its
// matches, mean and ring minimum all 0.3-1.1 px high). Its edges, measured in the images, are not:
// on each row whose ends lie within edgeReach (2 px) of the best candidate in both views, each
// end's position is read to a fraction of a pixel from the grey of its mixed pixel (the share of
// the roof between the roof's grey and the grey beyond), in the left view and at the counterpart's
// row end in the right view (the right view's flat region of the region's grey whose row ends
// agree with the candidate on most rows); their difference is that row end's disparity. With
// edgeMinSamples or more of them (edges with a contrast of 6 noise sigmas or more), the mean of
// those within 0.75 px of their median is filled when it lies within edgeReach of the candidate
// (that roof: 70.82; four others of that scene within 0.1 px of the truth). The reach is 2 px
// rather than the arbiter's 1.5: beside a rooftop box the matches' candidate can be 1.9 px off
// (sim seed 18 1000²: a roof at 43.29 filled at 45.2, 43.3 from its edges).
// `left`/`right`: the original images (CV_32F, NaN = nodata). Returns the pixels filled.
// `threads` > 1: the grey maps and the right view's flat regions are made on a second worker,
// which then runs `alongside` (the caller's own work on the images: it must not touch the
// disparities the fill writes) while the fill goes on; else `alongside` runs after the fill.
// Same result on any number of threads.
// The 5x5 means of an image's grey levels and of their squares, and its noise sigma, the nodata
// (non-finite) pixels taken as 0: what the flat tests read. Made once for the left image, they
// serve the fill's flat regions, the plain pixels and the snapping's contrast.
struct LocalMoments {
  cv::Mat mean, meanSquare;  // CV_32F
  double noise = 0;          // noiseSigma (radiometry.hpp)
};
// `noise` >= 0: taken as the image's noise sigma instead of its own estimate (a tile of a larger
// image takes the whole image's, docs/stereo.md, "Large pairs: tiles").
LocalMoments localMoments(const cv::Mat& image, double noise = -1);

// `leftMoments` (optional): localMoments(left), made beforehand; `rightFlatPixels` (optional):
// the right view's flat pixels, plainPixels(right, settings.flatSigmas), made beforehand (the
// right flat regions, which the fill waits for, start from them). `afterRegions` (optional, the
// caller's work that touches neither the images nor the maps): run by the second worker once the
// regions are decided, while this one extends them over the unmatched pixels (a step that leaves
// a worker idle at times); after the fill on one thread.
int fillFlatRegions(const cv::Mat& left, const cv::Mat& right, const RegionFillSettings& settings,
                    int dmin, int dmax, float fillScore, cv::Mat& disparity, cv::Mat& score,
                    int threads = 1, const std::function<void()>& alongside = {},
                    const LocalMoments* leftMoments = nullptr,
                    const std::function<void()>& afterRegions = {},
                    const cv::Mat* rightFlatPixels = nullptr);

// Pixels of `image` (CV_32F, NaN = nodata) whose 5x5 standard deviation is below `sigmas` times
// the image's noise sigma (CV_8U 0/255): the fill's flat test, at another threshold. `moments`
// (optional): localMoments(image), made beforehand.
cv::Mat plainPixels(const cv::Mat& image, double sigmas, const LocalMoments* moments = nullptr);

// The disparity a region is filled with: c + a·x + b·y in image coordinates (a = b = 0 for the
// constant of the outline's matches).
struct FillPlane {
  double c = 0, a = 0, b = 0;
  double at(int x, int y) const { return c + a * x + b * y; }
  // How far a row-end point (x, y, disparity) lies from the plane, signed.
  double residual(const cv::Point3d& p) const { return p.z - (c + a * p.x + b * p.y); }
};

// What the fill's extensions over unmatched pixels share, one per filled region (its box and
// plane, in the fill's order): cells (ids 0 .. cellCount − 1) for RowOrderedTasks, the extensions
// that share none giving the same maps side by side as in order. An extension writes the
// disparities and scores only within its box ± extendReach (`outer`) and reads the maps there and
// one pixel beyond: the 32 px tiles of the image these cover. Further along its rows it reads only
// whether a match maps to the right-view position x − d of one of its candidates: the right-view
// positions its candidates map to on its rows, those of the values it writes (the same) and those
// of the values it may replace (the matches in `outer` in `disparity`, the map before the
// extensions, and the values of the earlier extensions whose `outer` meets its own) are its cells
// in the right view, 16 px tiles by 32 rows. (The rectangles of the range's width beyond the box,
// its cells before, kept most of them in order: at 1000² / 128 d they ran at ~110 % of one core.)
struct ExtensionFootprints {
  std::vector<std::vector<int>> cells;
  int cellCount = 0;
};
ExtensionFootprints extensionFootprints(const std::vector<cv::Rect>& boxes,
                                        const std::vector<FillPlane>& planes,
                                        const RegionFillSettings& settings, int dmin, int dmax,
                                        const cv::Mat& disparity);

}  // namespace delineo::stereo::detail
