#include <cmath>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "delineo/widgets/colour_maps.hpp"
#include "gui_test_support.hpp"

using namespace delineo::widgets;

TEST(ColourMaps, EndsNaNAndClamping) {
  cv::Mat v(1, 5, CV_32F);
  v.at<float>(0) = 0.0f;
  v.at<float>(1) = 10.0f;
  v.at<float>(2) = std::numeric_limits<float>::quiet_NaN();
  v.at<float>(3) = -5.0f;   // below min → first colour
  v.at<float>(4) = 99.0f;   // above max → last colour
  const cv::Mat rgba = colourise(v, 0.0, 10.0, ColourMap::Viridis);
  ASSERT_EQ(rgba.type(), CV_8UC4);
  const QColor lo = mapColour(ColourMap::Viridis, 0.0);
  const QColor hi = mapColour(ColourMap::Viridis, 1.0);
  auto px = [&](int i) { const auto c = rgba.at<cv::Vec4b>(0, i); return QColor(c[0], c[1], c[2], c[3]); };
  EXPECT_EQ(px(0), lo);
  EXPECT_EQ(px(1), hi);
  EXPECT_EQ(px(3), lo);
  EXPECT_EQ(px(4), hi);
  const QColor nodata = px(2);
  EXPECT_EQ(nodata, noDataColour(2, 0));
  EXPECT_EQ(nodata.red(), nodata.green());  // neutral grey, never in viridis or terrain
  for (double t = 0; t <= 1.0; t += 0.01) {
    for (ColourMap m : {ColourMap::Viridis, ColourMap::Terrain}) {
      const QColor c = mapColour(m, t);
      EXPECT_FALSE(c.red() == c.green() && c.green() == c.blue() && c.red() > 100 && c.red() < 230)
          << "map colour at " << t << " looks like no-data";
    }
  }
}

TEST(ColourMaps, HillshadeLightsSlopesFacingTheSun) {
  // Two planes: one rising towards the north-west (facing the 315° sun), one away from it.
  cv::Mat dem(40, 80, CV_32F);
  for (int y = 0; y < dem.rows; ++y) {
    for (int x = 0; x < dem.cols; ++x) {
      const float ramp = x < 40 ? static_cast<float>(x + y) : static_cast<float>(-(x + y));
      dem.at<float>(y, x) = ramp;
    }
  }
  dem.at<float>(20, 60) = std::numeric_limits<float>::quiet_NaN();
  const cv::Mat shade = hillshade(dem, 1.0);
  ASSERT_EQ(shade.type(), CV_8UC1);
  // Height grows towards south-east on the left half: the slope faces north-west, lit.
  EXPECT_GT(shade.at<uchar>(20, 20), shade.at<uchar>(20, 70) + 100);
  EXPECT_EQ(shade.at<uchar>(20, 60), 0);
  // Flat ground: cos(zenith) = sin(45°) ≈ 0.707.
  const cv::Mat flat = hillshade(cv::Mat(10, 10, CV_32F, cv::Scalar(5)), 0.5);
  EXPECT_NEAR(flat.at<uchar>(5, 5), 1 + 254 * std::sqrt(0.5), 1.0);
}

TEST(ColourMaps, LegendRenders) {
  ColourLegend legend;
  legend.setColourMap(ColourMap::Terrain);
  legend.setRange(12.0, 47.5);
  legend.setUnit(QStringLiteral("m"));
  legend.setTitle(QStringLiteral("Height"));
  legend.resize(legend.sizeHint());
  const QImage shot = legend.grab().toImage();
  EXPECT_FALSE(shot.isNull());
  test::saveScreenshot(legend, QStringLiteral("colour_legend"));
}
