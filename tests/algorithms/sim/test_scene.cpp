// Tests of the synthetic scene generator. The key property: the right image warped with the
// ground-truth disparity reproduces the left image wherever the ground truth says the point is
// visible in both views.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"
#include "delineo/sim/scene.hpp"

namespace {
using delineo::core::AttributeValue;
using delineo::core::Feature;
using delineo::sim::Scene;
using delineo::sim::SceneParams;
namespace sim = delineo::sim;

SceneParams smallParams(int seed) {
  SceneParams p;
  p.seed = seed;
  p.width = 320;
  p.height = 240;
  p.buildings = 6;
  p.trees = 8;
  return p;
}

double number(const Feature& f, const std::string& key) {
  const AttributeValue& v = f.attributes.at(key);
  if (const double* d = std::get_if<double>(&v)) return *d;
  return static_cast<double>(std::get<long long>(v));
}
// Default-size scenes shared by the tests that only read them (each takes a fraction of a second).
const Scene& defaultScene(int seed) {
  static std::map<int, Scene> cache;
  auto it = cache.find(seed);
  if (it == cache.end()) {
    SceneParams p;
    p.seed = seed;
    it = cache.emplace(seed, sim::simulateScene(p)).first;
  }
  return it->second;
}

std::string text(const Feature& f, const std::string& key) {
  return std::get<std::string>(f.attributes.at(key));
}

bool sameBytes(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return false;
  const size_t rowBytes = a.cols * a.elemSize();
  for (int y = 0; y < a.rows; ++y) {
    if (std::memcmp(a.ptr(y), b.ptr(y), rowBytes) != 0) return false;
  }
  return true;
}

// Writes PNGs for a person to look at when DELINEO_TEST_DUMP names a directory.
void dump(const Scene& s, const std::string& name) {
  const char* dir = std::getenv("DELINEO_TEST_DUMP");
  if (dir == nullptr) return;
  const std::string base = std::string(dir) + "/" + name;
  cv::imwrite(base + "_left.png", s.left);
  cv::imwrite(base + "_right.png", s.right);
  cv::Mat d8;
  const double span = std::max(1, s.disparityMax - s.disparityMin);
  s.disparity.convertTo(d8, CV_8U, 255.0 / span, -255.0 * s.disparityMin / span);
  cv::Mat colour;
  cv::applyColorMap(d8, colour, cv::COLORMAP_JET);
  cv::imwrite(base + "_disparity.png", colour);
  cv::imwrite(base + "_labels.png", s.labels * 80);
  cv::imwrite(base + "_occlusion.png", s.occlusion);
}

// Pixels whose 3x3 neighbourhood is a single smooth surface seen by both views: no depth edge
// (second differences of the disparity), no label change, no occlusion.
cv::Mat smoothVisibleMask(const Scene& s) {
  cv::Mat mask(s.disparity.size(), CV_8U, cv::Scalar(0));
  for (int y = 2; y < s.disparity.rows - 2; ++y) {
    for (int x = 2; x < s.disparity.cols - 2; ++x) {
      bool ok = true;
      for (int dy = -1; dy <= 1 && ok; ++dy) {
        for (int dx = -1; dx <= 1 && ok; ++dx) {
          const int yy = y + dy, xx = x + dx;
          const float* d = s.disparity.ptr<float>(yy);
          const float* du = s.disparity.ptr<float>(yy - 1);
          const float* dd = s.disparity.ptr<float>(yy + 1);
          const float secondX = d[xx - 1] + d[xx + 1] - 2 * d[xx];
          const float secondY = du[xx] + dd[xx] - 2 * d[xx];
          ok = std::isfinite(d[xx]) && std::abs(secondX) < 0.05f && std::abs(secondY) < 0.05f &&
               s.occlusion.at<uchar>(yy, xx) == 0 &&
               s.labels.at<uchar>(yy, xx) == s.labels.at<uchar>(y, x);
        }
      }
      if (ok) mask.at<uchar>(y, x) = 255;
    }
  }
  return mask;
}

struct WarpStats {
  double meanAbs = 0.0;
  double p99 = 0.0;
  int count = 0;
};

// Samples the right image at x - d (linear interpolation along the row), undoes the right
// view's gain and offset, and compares with the left image on `mask`.
WarpStats warpError(const Scene& s, const SceneParams& p, const cv::Mat& mask, float extraShift = 0) {
  std::vector<double> errors;
  for (int y = 0; y < s.left.rows; ++y) {
    for (int x = 0; x < s.left.cols; ++x) {
      if (mask.at<uchar>(y, x) == 0) continue;
      const double xr = x - (s.disparity.at<float>(y, x) + extraShift);
      const int x0 = static_cast<int>(std::floor(xr));
      if (x0 < 0 || x0 + 1 >= s.right.cols) continue;
      const double f = xr - x0;
      const double r = (1 - f) * s.right.at<uchar>(y, x0) + f * s.right.at<uchar>(y, x0 + 1);
      const double unmapped = (r - p.rightOffset) / p.rightGain;
      errors.push_back(std::abs(unmapped - s.left.at<uchar>(y, x)));
    }
  }
  WarpStats st;
  st.count = static_cast<int>(errors.size());
  if (errors.empty()) return st;
  double sum = 0;
  for (double e : errors) sum += e;
  st.meanAbs = sum / errors.size();
  std::sort(errors.begin(), errors.end());
  st.p99 = errors[static_cast<size_t>(0.99 * (errors.size() - 1))];
  return st;
}

}  // namespace

TEST(SimScene, SameSeedGivesIdenticalBytes) {
  const SceneParams p = smallParams(7);
  const Scene a = sim::simulateScene(p);
  const Scene b = sim::simulateScene(p);
  EXPECT_TRUE(sameBytes(a.left, b.left));
  EXPECT_TRUE(sameBytes(a.right, b.right));
  EXPECT_TRUE(sameBytes(a.disparity, b.disparity));
  EXPECT_TRUE(sameBytes(a.occlusion, b.occlusion));
  EXPECT_TRUE(sameBytes(a.dem, b.dem));
  EXPECT_TRUE(sameBytes(a.labels, b.labels));
  ASSERT_EQ(a.footprints.size(), b.footprints.size());
  for (size_t i = 0; i < a.footprints.size(); ++i) {
    EXPECT_EQ(a.footprints[i].polygon.outer, b.footprints[i].polygon.outer);
    EXPECT_EQ(a.footprints[i].attributes, b.footprints[i].attributes);
  }
  EXPECT_EQ(a.disparityMin, b.disparityMin);
  EXPECT_EQ(a.disparityMax, b.disparityMax);
}

TEST(SimScene, DifferentSeedsGiveDifferentScenes) {
  const Scene a = sim::simulateScene(smallParams(1));
  const Scene b = sim::simulateScene(smallParams(2));
  EXPECT_FALSE(sameBytes(a.left, b.left));
  EXPECT_FALSE(sameBytes(a.disparity, b.disparity));
}

TEST(SimScene, OutputsHaveDocumentedTypesAndSizes) {
  const SceneParams p = smallParams(3);
  const Scene s = sim::simulateScene(p);
  EXPECT_EQ(s.status, delineo::core::RunStatus::Completed);
  for (const cv::Mat* m : {&s.left, &s.right, &s.occlusion, &s.labels}) {
    EXPECT_EQ(m->type(), CV_8U);
    EXPECT_EQ(m->size(), cv::Size(p.width, p.height));
  }
  for (const cv::Mat* m : {&s.disparity, &s.dem}) {
    EXPECT_EQ(m->type(), CV_32F);
    EXPECT_EQ(m->size(), cv::Size(p.width, p.height));
  }
  EXPECT_GT(s.buildingsPlaced, 0);
  EXPECT_EQ(static_cast<int>(s.footprints.size()), s.buildingsPlaced);
  EXPECT_LT(s.disparityMin, s.disparityMax);
  double lo, hi;
  cv::minMaxIdx(s.disparity, &lo, &hi);
  EXPECT_GE(lo, s.disparityMin + 1);
  EXPECT_LE(hi, s.disparityMax - 1);
}

// THE key test: GT disparity maps the left image onto the right one.
TEST(SimScene, RightWarpedByGroundTruthMatchesLeftWithoutNoise) {
  SceneParams p = smallParams(11);
  p.noise = 0.0;
  const Scene s = sim::simulateScene(p);
  dump(s, "warp_noise0");
  const cv::Mat mask = smoothVisibleMask(s);
  const WarpStats st = warpError(s, p, mask);
  ASSERT_GT(st.count, p.width * p.height / 2);  // most of the image is smooth and visible
  EXPECT_LT(st.meanAbs, 1.0) << "p99 " << st.p99;
  EXPECT_LT(st.p99, 6.0) << "mean " << st.meanAbs;

  // The comparison has teeth: one pixel of disparity error is clearly visible.
  const WarpStats shifted = warpError(s, p, mask, 1.0f);
  EXPECT_GT(shifted.meanAbs, 3.0 * st.meanAbs + 1.0);
}

TEST(SimScene, RightWarpedByGroundTruthMatchesLeftWithNoise) {
  SceneParams p = smallParams(12);
  p.noise = 2.0;
  const Scene s = sim::simulateScene(p);
  const WarpStats st = warpError(s, p, smoothVisibleMask(s));
  // Two independent N(0, 2) noises, the right one interpolated: E|e| is about 2.
  EXPECT_LT(st.meanAbs, 3.0);
  EXPECT_GT(st.meanAbs, 1.0);
}

TEST(SimScene, OccludedPixelsDoNotMatch) {
  SceneParams p = smallParams(13);
  p.noise = 0.0;
  const Scene s = sim::simulateScene(p);
  cv::Mat occluded = s.occlusion.clone();
  // Keep points occluded by a building in the middle of the image (not the left border strip).
  occluded.colRange(0, s.disparityMax + 2).setTo(0);
  ASSERT_GT(cv::countNonZero(occluded), 200);
  const WarpStats visible = warpError(s, p, smoothVisibleMask(s));
  const WarpStats hidden = warpError(s, p, occluded);
  EXPECT_GT(hidden.meanAbs, 4.0 * visible.meanAbs);
}

// The occlusion mask (ray casting in the left geometry) agrees with what the right view's
// z-buffer shows: a visible point is found again at x - d, a hidden one is covered there by a
// nearer (higher-disparity) surface.
TEST(SimScene, OcclusionAgreesWithTheRightViewGroundTruth) {
  const SceneParams p = smallParams(14);
  const Scene s = sim::simulateScene(p);
  const cv::Mat smooth = smoothVisibleMask(s);
  int visibleChecked = 0, visibleAgree = 0, hiddenChecked = 0, hiddenCovered = 0;
  for (int y = 0; y < s.left.rows; ++y) {
    for (int x = 0; x < s.left.cols; ++x) {
      const float d = s.disparity.at<float>(y, x);
      const int xr = static_cast<int>(std::lround(x - d));
      if (x < 1 || x + 1 >= s.left.cols || xr < 1 || xr + 1 >= s.right.cols) continue;
      const float dr = s.disparityRight.at<float>(y, xr);
      if (s.occlusion.at<uchar>(y, x) == 0) {
        if (!smooth.at<uchar>(y, x)) continue;
        ++visibleChecked;
        // The right pixel centre is within half a pixel of the point: same smooth surface.
        if (std::abs(dr - d) < 0.6f) ++visibleAgree;
      } else if (s.occlusion.at<uchar>(y, x - 1) && s.occlusion.at<uchar>(y, x + 1)) {
        // Away from the occlusion boundary, where the occluder's edge may fall between the
        // right pixel centres.
        ++hiddenChecked;
        if (dr > d + 0.3f) ++hiddenCovered;
      }
    }
  }
  ASSERT_GT(visibleChecked, 10000);
  ASSERT_GT(hiddenChecked, 500);
  EXPECT_EQ(visibleAgree, visibleChecked);
  // Measured 99.6 %: the rest are wall points just below a roof edge, covered by the roof at a
  // disparity less than 0.3 px higher.
  EXPECT_GT(hiddenCovered, 0.99 * hiddenChecked) << hiddenCovered << " of " << hiddenChecked;
}

// An independent off-the-shelf matcher (OpenCV SGBM, which uses x_right = x_left - d) agrees
// with the ground truth: checks the sign convention and that the scene is matchable.
TEST(SimScene, OffTheShelfMatcherAgreesWithGroundTruth) {
  const SceneParams p = smallParams(15);
  const Scene s = sim::simulateScene(p);
  const int count = ((s.disparityMax - s.disparityMin + 15) / 16) * 16;
  auto sgbm = cv::StereoSGBM::create(s.disparityMin, count, 5, 8 * 25, 32 * 25, 1, 0, 10, 100, 2);
  cv::Mat fixedPoint;
  sgbm->compute(s.left, s.right, fixedPoint);
  int visible = 0, valid = 0, withinOnePixel = 0;
  for (int y = 0; y < s.left.rows; ++y) {
    for (int x = s.disparityMax; x < s.left.cols; ++x) {
      if (s.occlusion.at<uchar>(y, x)) continue;
      ++visible;
      const short v = fixedPoint.at<short>(y, x);
      if (v <= (s.disparityMin - 1) * 16) continue;  // SGBM's invalid value
      ++valid;
      if (std::abs(v / 16.0 - s.disparity.at<float>(y, x)) < 1.0) ++withinOnePixel;
    }
  }
  // Measured on 640x480 scenes: 84 % valid, 96 % of them within 1 px.
  EXPECT_GT(valid, 0.7 * visible);
  EXPECT_GT(withinOnePixel, 0.9 * valid);
}

TEST(SimScene, DemLabelsAndDisparityAgree) {
  const SceneParams p = smallParams(5);
  const Scene s = sim::simulateScene(p);
  // disparity = Z / mpd + d0 everywhere.
  for (int y = 0; y < s.dem.rows; ++y) {
    for (int x = 0; x < s.dem.cols; ++x) {
      ASSERT_NEAR(s.disparity.at<float>(y, x),
                  s.dem.at<float>(y, x) / p.metresPerDisparity + p.groundDisparity, 1e-3);
    }
  }
  // Ground stays within the terrain's relief around the ground disparity.
  const double diagonalM = std::hypot(p.width, p.height) * p.gsd;
  const double reliefM = 0.5 * diagonalM * p.slope / 100.0 + 2 * p.undulation;
  for (int y = 0; y < s.dem.rows; ++y) {
    for (int x = 0; x < s.dem.cols; ++x) {
      if (s.labels.at<uchar>(y, x) != sim::kLabelGround) continue;
      ASSERT_LE(std::abs(s.dem.at<float>(y, x)), reliefM + 1e-3);
    }
  }
  // Each building: attributes agree with each other and with the roof pixels.
  for (const Feature& f : s.footprints) {
    const double ground = number(f, "ground_disparity");
    const double eave = number(f, "roof_disparity_min");
    const double ridge = number(f, "roof_disparity_max");
    const double top = number(f, "superstructure_disparity_max");
    EXPECT_NEAR(eave, ground + number(f, "height_m") / p.metresPerDisparity, 1e-9);
    EXPECT_NEAR(ridge, ground + number(f, "ridge_height_m") / p.metresPerDisparity, 1e-9);
    EXPECT_LE(eave, ridge);
    EXPECT_LE(ridge, top);
    EXPECT_GE(number(f, "height_m"), 6.0 - 1e-9);
    EXPECT_LE(number(f, "height_m"), 30.0 + 1e-9);
    const cv::Mat inside = delineo::core::rasterize(f.polygon, s.left.size());
    std::vector<float> roof;
    for (int y = 0; y < s.dem.rows; ++y) {
      for (int x = 0; x < s.dem.cols; ++x) {
        if (inside.at<uchar>(y, x) && s.labels.at<uchar>(y, x) == sim::kLabelBuilding) {
          const float d = s.disparity.at<float>(y, x);
          EXPECT_GE(d, eave - 1e-3);
          EXPECT_LE(d, top + 1e-3);
          roof.push_back(d);
        }
      }
    }
    ASSERT_FALSE(roof.empty()) << "building " << number(f, "id");
    if (text(f, "roof_type") == "flat") {
      std::nth_element(roof.begin(), roof.begin() + roof.size() / 2, roof.end());
      EXPECT_NEAR(roof[roof.size() / 2], eave, 1e-3);  // most of a flat roof is at the eave
    } else {
      EXPECT_GT(*std::max_element(roof.begin(), roof.end()), ridge - 0.5);
    }
  }
}

TEST(SimScene, FootprintsCoverTheRoofLabels) {
  for (int seed : {21, 22}) {
    const SceneParams p = smallParams(seed);
    const Scene s = sim::simulateScene(p);
    cv::Mat footprints(s.left.size(), CV_8U, cv::Scalar(0));
    for (const Feature& f : s.footprints) {
      footprints |= delineo::core::rasterize(f.polygon, s.left.size());
    }
    const cv::Mat roofs = s.labels == sim::kLabelBuilding;
    const double inter = cv::countNonZero(footprints & roofs);
    const double uni = cv::countNonZero(footprints | roofs);
    ASSERT_GT(uni, 0);
    EXPECT_GT(inter / uni, 0.93) << "seed " << seed;
  }
}

// Walls stand exactly on the footprint edges, so the outline of a flat roof and its labels
// agree at every pixel centre (trees may hide parts of a roof).
TEST(SimScene, FlatRoofOutlinesAreExactAtPixelCentres) {
  int flatRoofs = 0;
  for (int seed : {1, 2, 3}) {
    const Scene& s = defaultScene(seed);
    for (const Feature& f : s.footprints) {
      if (text(f, "roof_type") != "flat") continue;
      ++flatRoofs;
      const cv::Mat inside = delineo::core::rasterize(f.polygon, s.left.size());
      const cv::Mat seen = (s.labels == sim::kLabelBuilding) | (s.labels == sim::kLabelVegetation);
      const int missing = cv::countNonZero(inside & ~seen);
      EXPECT_LE(missing, 2) << "seed " << seed << " building " << number(f, "id");
      // And no roof pixel of this building's height lies just outside its outline.
      cv::Mat ring;
      cv::dilate(inside, ring, cv::Mat::ones(5, 5, CV_8U));
      ring &= ~inside;
      const double eave = number(f, "roof_disparity_min");
      int outside = 0;
      for (int y = 0; y < s.labels.rows; ++y) {
        for (int x = 0; x < s.labels.cols; ++x) {
          if (ring.at<uchar>(y, x) && s.labels.at<uchar>(y, x) == sim::kLabelBuilding &&
              std::abs(s.disparity.at<float>(y, x) - eave) < 1e-3) {
            ++outside;
          }
        }
      }
      EXPECT_LE(outside, 2) << "seed " << seed << " building " << number(f, "id");
    }
  }
  EXPECT_GT(flatRoofs, 10);
}

TEST(SimScene, EveryShapeAndRoofTypeOccurs) {
  std::set<std::string> shapes, roofs;
  for (int seed : {1, 2, 3}) {
    const Scene& s = defaultScene(seed);
    for (const Feature& f : s.footprints) {
      shapes.insert(text(f, "shape"));
      roofs.insert(text(f, "roof_type"));
      EXPECT_TRUE(delineo::core::isSimple(f.polygon.outer));
    }
  }
  EXPECT_EQ(shapes, (std::set<std::string>{"rect", "L", "T", "U", "courtyard", "angled"}));
  EXPECT_EQ(roofs, (std::set<std::string>{"flat", "gable", "hip"}));
}

TEST(SimScene, CourtyardsAreHolesWithGroundInside) {
  int courtyards = 0;
  for (int seed : {1, 2, 3}) {
    const Scene& s = defaultScene(seed);
    for (const Feature& f : s.footprints) {
      if (text(f, "shape") != "courtyard") continue;
      ++courtyards;
      ASSERT_EQ(f.polygon.holes.size(), 1u);
      delineo::core::Polygon hole;
      hole.outer = f.polygon.holes[0];
      const cv::Mat inHole = delineo::core::rasterize(hole, s.left.size());
      const int holePixels = cv::countNonZero(inHole);
      ASSERT_GT(holePixels, 100);
      const int roofInHole = cv::countNonZero(inHole & (s.labels == sim::kLabelBuilding));
      EXPECT_LT(roofInHole, 0.02 * holePixels);
      const int groundInHole = cv::countNonZero(inHole & (s.labels == sim::kLabelGround));
      EXPECT_GT(groundInHole, 0.3 * holePixels);
    }
  }
  EXPECT_GT(courtyards, 0);
}

TEST(SimScene, WallsAreSeenByOneViewOnly) {
  SceneParams p = smallParams(31);
  const Scene s = sim::simulateScene(p);
  const cv::Mat facade = s.labels == sim::kLabelFacade;
  const int facadePixels = cv::countNonZero(facade);
  ASSERT_GT(facadePixels, 500);  // symmetric geometry: the left view sees west walls
  const int hidden = cv::countNonZero(facade & s.occlusion);
  EXPECT_GT(hidden, 0.97 * facadePixels);

  // Left nadir: no wall in the left view, all the parallax is in the right one.
  p.leftObliquity = 0.0;
  const Scene nadir = sim::simulateScene(p);
  EXPECT_EQ(cv::countNonZero(nadir.labels == sim::kLabelFacade), 0);
  EXPECT_GT(cv::countNonZero(nadir.occlusion), 500);
}

TEST(SimScene, RadiometryFollowsGainAndOffset) {
  SceneParams p = smallParams(8);
  p.noise = 0.0;
  p.rightGain = 1.2;
  p.rightOffset = -20.0;
  const Scene s = sim::simulateScene(p);
  const WarpStats st = warpError(s, p, smoothVisibleMask(s));
  EXPECT_LT(st.meanAbs, 1.0);
  // Least-squares fit right(x - d) = g * left(x) + o over pixels seen by both views.
  const cv::Mat mask = smoothVisibleMask(s);
  double n = 0, sl = 0, sr = 0, sll = 0, slr = 0;
  for (int y = 0; y < s.left.rows; ++y) {
    for (int x = 0; x < s.left.cols; ++x) {
      if (!mask.at<uchar>(y, x)) continue;
      const int xr = static_cast<int>(std::lround(x - s.disparity.at<float>(y, x)));
      if (xr < 0 || xr >= s.right.cols) continue;
      const double l = s.left.at<uchar>(y, x), r = s.right.at<uchar>(y, xr);
      if (r <= 0 || r >= 255) continue;  // saturated
      n += 1; sl += l; sr += r; sll += l * l; slr += l * r;
    }
  }
  const double gain = (n * slr - sl * sr) / (n * sll - sl * sl);
  const double offset = (sr - gain * sl) / n;
  EXPECT_NEAR(gain, 1.2, 0.03);
  EXPECT_NEAR(offset, -20.0, 3.0);
}

TEST(SimScene, InvalidParametersAreRejected) {
  SceneParams p;
  p.width = 10;
  EXPECT_THROW(sim::simulateScene(p), delineo::core::Error);
  p = SceneParams{};
  p.supersampling = 2;
  EXPECT_THROW(p.validate(), delineo::core::Error);
  p = SceneParams{};
  p.metresPerDisparity = 0.0;
  try {
    p.validate();
    FAIL() << "expected an error";
  } catch (const delineo::core::Error& e) {
    EXPECT_EQ(e.code(), delineo::core::ErrorCode::InvalidParameter);
    EXPECT_NE(std::string(e.what()).find("metres-per-disparity"), std::string::npos);
  }
}

TEST(SimScene, CancelIsAnOutcome) {
  delineo::core::Progress progress;
  progress.cancelAfterReports(3);
  const Scene s = sim::simulateScene(smallParams(4), &progress);
  EXPECT_EQ(s.status, delineo::core::RunStatus::Canceled);
  EXPECT_TRUE(s.left.empty());
}

TEST(SimScene, ProgressReachesOne) {
  delineo::core::Progress progress;
  sim::simulateScene(smallParams(4), &progress);
  EXPECT_DOUBLE_EQ(progress.fraction(), 1.0);
}

TEST(SimScene, SceneJsonRoundTrip) {
  const SceneParams p = smallParams(9);
  const Scene s = sim::simulateScene(p);
  const auto dir = std::filesystem::temp_directory_path() / "delineo_sim_json_test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "scene.json").string();
  sim::writeSceneJson(path, s, p);
  const sim::SceneInfo info = sim::readSceneJson(path);
  EXPECT_EQ(info.width, p.width);
  EXPECT_EQ(info.height, p.height);
  EXPECT_EQ(info.disparityMin, s.disparityMin);
  EXPECT_EQ(info.disparityMax, s.disparityMax);
  EXPECT_DOUBLE_EQ(info.gsd, p.gsd);
  EXPECT_DOUBLE_EQ(info.metresPerDisparity, p.metresPerDisparity);
  EXPECT_EQ(info.seed, p.seed);
  EXPECT_EQ(delineo::core::toJson(info.params), delineo::core::toJson(p));
  EXPECT_THROW(sim::readSceneJson((dir / "missing.json").string()), delineo::core::Error);
  std::filesystem::remove_all(dir);
}

TEST(SimScene, DefaultSceneIsFast) {
  const auto t0 = std::chrono::steady_clock::now();
  const Scene s = sim::simulateScene(SceneParams{});
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  RecordProperty("seconds_640x480", std::to_string(seconds));
  dump(s, "default");
  EXPECT_LT(seconds, 10.0);  // about 0.5 s on one core; generous for loaded CI machines
}

