// Raised planar surfaces replaced by their plane (internal fitRoofPlanes).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"
#include "delineo/stereo/match.hpp"
#include "roof_planes.hpp"

namespace delineo::stereo::detail {
namespace {

constexpr int kSide = 160;
const cv::Rect kRoof(40, 50, 80, 60);

// Noise correlated over about a correlation window (blotches, as the matches of a weakly
// textured roof show), of standard deviation `sigma` px.
cv::Mat blotchyNoise(double sigma, int seed) {
  cv::Mat white(kSide, kSide, CV_32F);
  cv::RNG rng(static_cast<std::uint64_t>(seed));
  rng.fill(white, cv::RNG::NORMAL, 0.0, 1.0);
  cv::Mat blotches;
  cv::GaussianBlur(white, blotches, {0, 0}, 4.0);
  cv::Scalar mean, deviation;
  cv::meanStdDev(blotches, mean, deviation);
  return (blotches - mean[0]) * (sigma / deviation[0]);
}

// Sloped ground at 10 px (0.01 px/px), and inside kRoof the surface `roof` (none when empty),
// plus blotchy noise of 0.25 px everywhere.
cv::Mat scene(const std::function<float(int, int)>& roof) {
  cv::Mat disparity = blotchyNoise(0.25, 3);
  for (int y = 0; y < kSide; ++y) {
    for (int x = 0; x < kSide; ++x) {
      const bool onRoof = roof && kRoof.contains({x, y});
      disparity.at<float>(y, x) += onRoof ? roof(x, y) : 10.0F + 0.01F * static_cast<float>(x);
    }
  }
  return disparity;
}

float roofPlane(int x, int y) {
  return 30.0F + 0.02F * static_cast<float>(x) - 0.01F * static_cast<float>(y);
}

double rmsOnRoof(const cv::Mat& disparity, const std::function<float(int, int)>& truth) {
  double sq = 0;
  int n = 0;
  for (int y = kRoof.y; y < kRoof.y + kRoof.height; ++y) {
    for (int x = kRoof.x; x < kRoof.x + kRoof.width; ++x) {
      const double e = disparity.at<float>(y, x) - truth(x, y);
      sq += e * e;
      ++n;
    }
  }
  return std::sqrt(sq / n);
}

bool identical(const cv::Mat& a, const cv::Mat& b) {
  return cv::countNonZero(a != b) == 0;  // (no NaN in these maps)
}

TEST(FitRoofPlanes, ARaisedPlanarRoofTakesItsPlaneAndTheRestIsLeft) {
  cv::Mat disparity = scene(roofPlane);
  // Outliers on the roof (a wrong peak every 97th pixel, 3 px high) are not the plane's.
  for (int i = 0; i < kRoof.area(); i += 97) {
    disparity.at<float>(kRoof.y + i / kRoof.width, kRoof.x + i % kRoof.width) += 3.0F;
  }
  const cv::Mat before = disparity.clone();
  const double rmsBefore = rmsOnRoof(before, roofPlane);
  const RoofPlaneCounts counts = fitRoofPlanes(disparity, RoofPlaneSettings{});
  EXPECT_EQ(counts.planes, 1);
  // Every roof pixel but the outliers (those 3 px off, not within the inlier band).
  const int outliers = (kRoof.area() + 96) / 97;
  // Every roof pixel but the outliers: the inliers, and the noise's tail beyond the inlier band
  // (2.5 RMS) as the roof's other pixels within 1.5 px of its plane.
  EXPECT_GE(counts.pixels, (kRoof.area() - outliers) * 98 / 100);
  EXPECT_EQ(counts.pixels + counts.absorbed, kRoof.area() - outliers);
  int outliersKept = 0, within = 0;
  for (int i = 0; i < kRoof.area(); ++i) {
    const int x = kRoof.x + i % kRoof.width, y = kRoof.y + i / kRoof.width;
    if (i % 97 == 0) {
      outliersKept += disparity.at<float>(y, x) == before.at<float>(y, x) ? 1 : 0;
    } else {
      within += std::abs(disparity.at<float>(y, x) - roofPlane(x, y)) <= 0.15F ? 1 : 0;
    }
  }
  EXPECT_EQ(outliersKept, outliers);
  EXPECT_GE(within, counts.pixels * 9 / 10);
  EXPECT_GT(rmsBefore, 0.3);  // the blotches and the outliers
  // The plane's error over the roof's non-outliers, against their noise of 0.25 px.
  cv::Mat plane = disparity.clone();
  for (int i = 0; i < kRoof.area(); i += 97) {
    plane.at<float>(kRoof.y + i / kRoof.width, kRoof.x + i % kRoof.width) =
        roofPlane(kRoof.x + i % kRoof.width, kRoof.y + i / kRoof.width);
  }
  EXPECT_LT(rmsOnRoof(plane, roofPlane), 0.1) << rmsOnRoof(plane, roofPlane);
  // The ground (planar too, but nothing around it is lower) is left as it was.
  cv::Mat groundBefore = before.clone(), groundAfter = disparity.clone();
  groundBefore(kRoof).setTo(0);
  groundAfter(kRoof).setTo(0);
  EXPECT_TRUE(identical(groundBefore, groundAfter));
}

TEST(FitRoofPlanes, ARoofsOtherPixelsNearItsPlaneTakeItButNotABoxOnIt) {
  cv::Mat disparity = scene(roofPlane);
  // Single pixels 1 px high (cut from the surface: more than 0.5 px from their neighbours), a box
  // 2.5 px high on the roof, and a column of the ground beside the roof carrying the roof's value
  // 1.2 px high (a window that reached across the outline).
  std::vector<cv::Point> high;
  for (int i = 0; i < kRoof.area(); i += 53) {
    const cv::Point p(kRoof.x + i % kRoof.width, kRoof.y + i / kRoof.width);
    if (p.x >= 70 && p.x < 82 && p.y >= 70 && p.y < 82) continue;  // clear of the box
    disparity.at<float>(p) += 1.0F;
    high.push_back(p);
  }
  const cv::Rect box(72, 72, 8, 8);
  disparity(box) += 2.5;
  const int beside = kRoof.x + kRoof.width;
  for (int y = 60; y < 70; ++y) disparity.at<float>(y, beside) = roofPlane(beside, y) + 1.2F;
  const cv::Mat before = disparity.clone();
  const RoofPlaneCounts counts = fitRoofPlanes(disparity, RoofPlaneSettings{});
  EXPECT_EQ(counts.planes, 1);
  EXPECT_GE(counts.absorbed, static_cast<long>(high.size()) + 10);
  for (const cv::Point& p : high) {
    EXPECT_LT(std::abs(disparity.at<float>(p) - roofPlane(p.x, p.y)), 0.3F) << p;
  }
  for (int y = 60; y < 70; ++y) {
    EXPECT_LT(std::abs(disparity.at<float>(y, beside) - roofPlane(beside, y)), 0.3F) << y;
  }
  EXPECT_TRUE(identical(disparity(box), before(box)));
  // Without it, those pixels keep their values.
  cv::Mat kept = before.clone();
  RoofPlaneSettings inliersOnly;
  inliersOnly.absorbWithin = 0;
  EXPECT_EQ(fitRoofPlanes(kept, inliersOnly).absorbed, 0);
  for (const cv::Point& p : high) EXPECT_EQ(kept.at<float>(p), before.at<float>(p));
}

TEST(FitRoofPlanes, AStructureOnTheRoofKeepsItsValuesAndASmallPieceTakesThePlane) {
  // Three things 1.2 px above the roof: a 20x20 box with sharp sides (a surface of its own), the
  // same box with sides ramped over 3 px (part of the roof's surface, beyond its inlier band), and
  // a 5x5 patch (a piece of 25 px).
  cv::Mat disparity = scene(roofPlane);
  const cv::Rect sharp(48, 58, 20, 20), ramped(84, 58, 20, 20), patch(60, 92, 5, 5);
  for (int y = 0; y < kSide; ++y) {
    for (int x = 0; x < kSide; ++x) {
      float rise = 0;
      if (sharp.contains({x, y}) || patch.contains({x, y})) rise = 1.2F;
      // Ramped: 1.2 px on the box, down by 0.3 px per px over the 3 px around it (no jump of
      // more than 0.5 px with the noise of the blotches, which are alike from pixel to pixel).
      const int dx = std::max({ramped.x - x, x - (ramped.br().x - 1), 0});
      const int dy = std::max({ramped.y - y, y - (ramped.br().y - 1), 0});
      const int out = std::max(dx, dy);
      if (out <= 3) rise = std::max(rise, 1.2F - 0.3F * static_cast<float>(out));
      disparity.at<float>(y, x) += rise;
    }
  }
  const RoofPlaneCounts counts = fitRoofPlanes(disparity, RoofPlaneSettings{});
  // The roof, and the sharp box may be a plane of its own (raised above the ground beyond the
  // roof): either way both boxes keep their height.
  EXPECT_GE(counts.planes, 1);
  // The ramped box's top: beyond the roof's band (> 0.6 px above the plane), one blob of 324 px.
  const cv::Rect top(ramped.x + 1, ramped.y + 1, ramped.width - 2, ramped.height - 2);
  for (const cv::Rect& box : {sharp, top}) {
    int high = 0;
    for (int y = box.y; y < box.br().y; ++y) {
      for (int x = box.x; x < box.br().x; ++x) {
        high += disparity.at<float>(y, x) - roofPlane(x, y) > 0.8F ? 1 : 0;
      }
    }
    EXPECT_GE(high, box.area() * 95 / 100) << box;
  }
  for (int y = patch.y; y < patch.br().y; ++y) {
    for (int x = patch.x; x < patch.br().x; ++x) {
      EXPECT_LT(std::abs(disparity.at<float>(y, x) - roofPlane(x, y)), 0.3F) << x << "," << y;
    }
  }
}

TEST(FitRoofPlanes, TheGroundAndASunkenCourtyardAreNotRaised) {
  cv::Mat disparity = scene([](int, int) { return 4.0F; });  // a courtyard 6 px below the ground
  const cv::Mat before = disparity.clone();
  EXPECT_EQ(fitRoofPlanes(disparity, RoofPlaneSettings{}).planes, 0);
  EXPECT_TRUE(identical(disparity, before));
  // The ground alone, but for a ditch 4 px lower at the image's border (3 x 6 px): the ground's
  // outer outline is the border but there, and its ring those 18 pixels, all lower. Too few to
  // tell (fewer than the square root of its 25 600 pixels).
  cv::Mat ditch = scene({});
  ditch(cv::Rect(0, 70, 3, 6)) -= 4.0;
  const cv::Mat withDitch = ditch.clone();
  EXPECT_EQ(fitRoofPlanes(ditch, RoofPlaneSettings{}).planes, 0);
  EXPECT_TRUE(identical(ditch, withDitch));
}

TEST(FitRoofPlanes, RaisedSurfacesNoPlaneFitsAreLeft) {
  // A crown (dome 4 px high) and a hip roof (two facets of ±0.08 px/px meeting at a ridge, with
  // no step between them).
  const std::function<float(int, int)> crown = [](int x, int y) {
    const double u = (x - 80.0) / 40.0, v = (y - 80.0) / 30.0;
    return static_cast<float>(30.0 + 4.0 * (1.0 - u * u - v * v));
  };
  const std::function<float(int, int)> hip = [](int x, int) {
    return 30.0F - 0.08F * static_cast<float>(std::abs(x - 80));
  };
  for (const auto& surface : {crown, hip}) {
    cv::Mat disparity = scene(surface);
    const cv::Mat before = disparity.clone();
    EXPECT_EQ(fitRoofPlanes(disparity, RoofPlaneSettings{}).planes, 0);
    EXPECT_TRUE(identical(disparity, before));
  }
  // Each facet alone, raised, is a plane (the test above fails for the right reason).
  cv::Mat oneFacet = scene([](int x, int) { return 30.0F - 0.08F * static_cast<float>(x - 80); });
  EXPECT_EQ(fitRoofPlanes(oneFacet, RoofPlaneSettings{}).planes, 1);
}

TEST(FitRoofPlanes, UnmatchedPixelsAreNeitherFittedNorAround) {
  constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
  cv::Mat disparity = scene(roofPlane);
  // The roof's outermost pixels unmatched, and the ground left of x = 30: the ring is what
  // remains matched within 2 px around the roof.
  const cv::Rect inner(kRoof.x + 1, kRoof.y + 1, kRoof.width - 2, kRoof.height - 2);
  cv::Mat unmatched(disparity.size(), CV_8U, cv::Scalar(0));
  unmatched(kRoof).setTo(1);
  unmatched(inner).setTo(0);
  unmatched(cv::Rect(0, 0, 30, kSide)).setTo(1);
  disparity.setTo(kNaN, unmatched);
  const int matched = cv::countNonZero(disparity == disparity);
  const RoofPlaneCounts counts = fitRoofPlanes(disparity, RoofPlaneSettings{});
  EXPECT_EQ(counts.planes, 1);
  EXPECT_LE(counts.pixels, inner.area());
  EXPECT_GE(counts.pixels, inner.area() * 98 / 100);
  EXPECT_EQ(cv::countNonZero(disparity == disparity), matched);
  // An unmatched band all around the roof (an occluded or unmatched border): the ring is what is
  // matched beyond it, up to 8 px (gapReach) out; a wider band leaves nothing to tell.
  const auto bandAround = [&](int width) {
    cv::Mat m = scene(roofPlane);
    cv::Mat band(m.size(), CV_8U, cv::Scalar(0));
    band(cv::Rect(kRoof.x - width, kRoof.y - width, kRoof.width + 2 * width,
                  kRoof.height + 2 * width))
        .setTo(1);
    band(inner).setTo(0);
    m.setTo(kNaN, band);
    return m;
  };
  cv::Mat narrow = bandAround(6), wide = bandAround(12);
  EXPECT_EQ(fitRoofPlanes(narrow, RoofPlaneSettings{}).planes, 1);
  EXPECT_EQ(fitRoofPlanes(wide, RoofPlaneSettings{}).planes, 0);
  RoofPlaneSettings adjacentOnly;
  adjacentOnly.gapReach = 0;
  cv::Mat narrowAgain = bandAround(6);
  EXPECT_EQ(fitRoofPlanes(narrowAgain, adjacentOnly).planes, 0);
}

TEST(FitRoofPlanes, ARimAtTheRoofsLevelIsCrossedToWhatLiesBelow) {
  // The roof's outer 3 px 0.7 or 1.3 px high in a checkerboard (a rough rim: no two neighbours
  // within 0.5 px, so no surface of its own, and cut from the roof's), then the ground: past the
  // rim the ring is the ground, and the rim takes the roof's plane.
  cv::Mat disparity = scene(roofPlane);
  const cv::Rect inner(kRoof.x + 3, kRoof.y + 3, kRoof.width - 6, kRoof.height - 6);
  cv::Mat rim(disparity.size(), CV_8U, cv::Scalar(0));
  rim(kRoof).setTo(1);
  rim(inner).setTo(0);
  disparity.setTo(0, rim);
  cv::Mat raisedRim = disparity.clone();
  for (int y = 0; y < kSide; ++y) {
    for (int x = 0; x < kSide; ++x) {
      if (rim.at<uchar>(y, x) != 0) {
        raisedRim.at<float>(y, x) = roofPlane(x, y) + ((x + y) % 2 == 0 ? 0.7F : 1.3F);
      }
    }
  }
  disparity = raisedRim;
  const cv::Mat before = disparity.clone();
  const RoofPlaneCounts counts = fitRoofPlanes(disparity, RoofPlaneSettings{});
  EXPECT_EQ(counts.planes, 1);
  int rimOnPlane = 0;
  for (int y = 0; y < kSide; ++y) {
    for (int x = 0; x < kSide; ++x) {
      if (rim.at<uchar>(y, x) == 0) continue;
      rimOnPlane += std::abs(disparity.at<float>(y, x) - roofPlane(x, y)) < 0.3F ? 1 : 0;
    }
  }
  EXPECT_GE(rimOnPlane, cv::countNonZero(rim) * 99 / 100);  // (measured: 800 of 804)
  // Stopped at the rim (gapReach 0), the ring is the rim itself, at the roof's level: not raised.
  RoofPlaneSettings adjacentOnly;
  adjacentOnly.gapReach = 0;
  cv::Mat again = before.clone();
  EXPECT_EQ(fitRoofPlanes(again, adjacentOnly).planes, 0);
}

TEST(FitRoofPlanes, GivesTheSameMapOnAnyNumberOfThreads) {
  const cv::Mat disparity = scene(roofPlane);
  cv::Mat one = disparity.clone(), three = disparity.clone();
  RoofPlaneSettings settings;
  settings.threads = 1;
  const RoofPlaneCounts counts = fitRoofPlanes(one, settings);
  settings.threads = 3;
  EXPECT_EQ(fitRoofPlanes(three, settings).pixels, counts.pixels);
  EXPECT_GT(counts.pixels, 0);
  EXPECT_TRUE(identical(one, three));
}

TEST(FitRoofPlanes, ItsParametersAreChecked) {
  MatchParams p;
  p.planeResidual = -0.1;
  EXPECT_THROW(p.validate(), core::Error);
  p.planeResidual = 0.0;  // off
  EXPECT_NO_THROW(p.validate());
  p.planeMinArea = 5;
  EXPECT_THROW(p.validate(), core::Error);
}

}  // namespace
}  // namespace delineo::stereo::detail
