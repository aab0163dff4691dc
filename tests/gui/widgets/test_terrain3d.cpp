// Runs under xvfb-run twice: QT_QPA_PLATFORM=xcb (QOpenGLWidget backend) and =offscreen (VTK
// offscreen render painted by a plain widget).
#include <QGuiApplication>
#include <QTest>
#include <cmath>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "delineo/widgets/terrain3d_view.hpp"
#include "gui_test_support.hpp"

using delineo::widgets::Terrain3DView;

namespace {
cv::Mat syntheticDem(int size) {
  cv::Mat dem(size, size, CV_32F);
  for (int y = 0; y < size; ++y) {
    for (int x = 0; x < size; ++x) {
      const double dx = (x - size * 0.3) / (size * 0.2);
      const double dy = (y - size * 0.6) / (size * 0.25);
      dem.at<float>(y, x) = static_cast<float>(100.0 + 25.0 * std::exp(-(dx * dx + dy * dy)) + 0.01 * x);
    }
  }
  dem(cv::Rect(size / 2, size / 5, size / 5, size / 6)) += 18.0f;  // a building block
  dem(cv::Rect(size / 10, size / 10, size / 12, size / 12)).setTo(std::numeric_limits<float>::quiet_NaN());
  return dem;
}

int countDifferent(const QImage& a, const QImage& b) {
  int n = 0;
  for (int y = 0; y < std::min(a.height(), b.height()); ++y) {
    for (int x = 0; x < std::min(a.width(), b.width()); ++x) {
      const QColor ca(a.pixel(x, y));
      const QColor cb(b.pixel(x, y));
      if (std::abs(ca.red() - cb.red()) + std::abs(ca.green() - cb.green()) + std::abs(ca.blue() - cb.blue()) > 30) ++n;
    }
  }
  return n;
}

int countNonBlack(const QImage& image) {
  int n = 0;
  for (int y = 0; y < image.height(); ++y)
    for (int x = 0; x < image.width(); ++x) n += qGray(image.pixel(x, y)) > 20 ? 1 : 0;
  return n;
}
}  // namespace

TEST(Terrain3DView, RendersTheDemWithTheBackendOfThePlatform) {
  Terrain3DView view;
  const bool offscreen = QGuiApplication::platformName() == QLatin1String("offscreen");
  EXPECT_EQ(view.backend(), offscreen ? Terrain3DView::Backend::Offscreen : Terrain3DView::Backend::OpenGLWidget);
  view.resize(480, 360);
  view.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&view));

  const QImage empty = view.renderImage().convertToFormat(QImage::Format_RGB32);
  ASSERT_FALSE(empty.isNull());

  const cv::Mat dem = syntheticDem(1200);
  view.setDem(dem, 0.5);
  EXPECT_LE(std::max(view.displayedGridSize().width, view.displayedGridSize().height), 500);
  EXPECT_LE(std::max(view.interactiveGridSize().width, view.interactiveGridSize().height), 160);
  delineo::widgets::BuildingOutline building;
  building.polygon.outer = {{600, 240}, {840, 240}, {840, 440}, {600, 440}};
  building.baseHeight = 100;
  building.topHeight = 118;
  view.setBuildings({building});
  QTest::qWait(50);
  const QImage shot = view.renderImage().convertToFormat(QImage::Format_RGB32);
  const int total = shot.width() * shot.height();
  EXPECT_GT(countNonBlack(shot), total / 2);
  // The terrain covers a good part of the view.
  EXPECT_GT(countDifferent(shot, empty), total / 5);
  delineo::widgets::test::saveImage(shot, offscreen ? QStringLiteral("terrain3d_offscreen")
                                                    : QStringLiteral("terrain3d_glwidget"));

  // A mouse drag rotates the camera (events reach VTK) and the view keeps rendering.
  QWidget* surface = view.findChild<QWidget*>();
  ASSERT_NE(surface, nullptr);
  QTest::mousePress(surface, Qt::LeftButton, {}, QPoint(240, 180));
  for (int i = 1; i <= 5; ++i) QTest::mouseMove(surface, QPoint(240 + 20 * i, 180));
  QTest::mouseRelease(surface, Qt::LeftButton, {}, QPoint(340, 180));
  QTest::qWait(50);
  const QImage rotated = view.renderImage().convertToFormat(QImage::Format_RGB32);
  EXPECT_GT(countDifferent(rotated, shot), total / 50);
  EXPECT_GT(countNonBlack(rotated), total / 2);

  // Draped texture.
  cv::Mat grey(600, 600, CV_8U);
  cv::randu(grey, 0, 255);
  view.setTexture(grey);
  QTest::qWait(50);
  const QImage textured = view.renderImage().convertToFormat(QImage::Format_RGB32);
  EXPECT_GT(countDifferent(textured, rotated), total / 10);
  delineo::widgets::test::saveImage(textured, offscreen ? QStringLiteral("terrain3d_offscreen_textured")
                                                        : QStringLiteral("terrain3d_glwidget_textured"));
}

namespace {
// Share of the image in yellow (the top of the viridis map): neither the purple low end nor the
// grey-blue background are.
double yellowShare(const QImage& image) {
  int n = 0;
  for (int y = 0; y < image.height(); ++y) {
    for (int x = 0; x < image.width(); ++x) {
      const QColor c(image.pixel(x, y));
      if (c.red() > 110 && c.green() > 110 && c.blue() < 0.6 * std::min(c.red(), c.green())) ++n;
    }
  }
  return static_cast<double>(n) / (image.width() * image.height());
}
}  // namespace

TEST(Terrain3DView, FramesARegionAndSuggestsAnExaggeration) {
  Terrain3DView view;
  view.resize(400, 300);
  view.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&view));
  // Flat ground at 0 m with one 10 m block in a corner, coloured by height.
  cv::Mat dem(400, 400, CV_32F, cv::Scalar(0.0f));
  dem(cv::Rect(300, 40, 40, 40)).setTo(10.0f);
  view.setDem(dem, 0.25);
  view.setColourMap(delineo::widgets::ColourMap::Viridis);
  view.resetCamera();
  QTest::qWait(50);
  const QImage whole = view.renderImage().convertToFormat(QImage::Format_RGB32);
  view.frameRegion(cv::Rect2d(280, 20, 80, 80));
  QTest::qWait(50);
  const QImage framed = view.renderImage().convertToFormat(QImage::Format_RGB32);
  const double wholeShare = yellowShare(whole);
  const double framedShare = yellowShare(framed);
  delineo::widgets::test::saveImage(framed, QStringLiteral("terrain3d_framed"));
  // The block is 1 % of the DEM; framed on it with as much again around, it fills the view.
  EXPECT_LT(wholeShare, 0.05);
  EXPECT_GT(framedShare, 0.10);
  EXPECT_GT(framedShare, 4 * wholeShare);
  // A region outside the DEM frames the whole DEM again.
  view.frameRegion(cv::Rect2d(5000, 5000, 10, 10));
  QTest::qWait(50);
  EXPECT_LT(countDifferent(view.renderImage().convertToFormat(QImage::Format_RGB32), whole),
            whole.width() * whole.height() / 100);

  // Town: 10 m over 100 m is readable as it is; gentle terrain gets exaggerated, within 5.
  EXPECT_DOUBLE_EQ(Terrain3DView::suggestedExaggeration(dem, 0.25), 1.0);
  EXPECT_DOUBLE_EQ(Terrain3DView::suggestedExaggeration(dem, 0.5), 2.0);
  cv::Mat gentle(200, 200, CV_32F);
  for (int y = 0; y < gentle.rows; ++y)
    for (int x = 0; x < gentle.cols; ++x) gentle.at<float>(y, x) = static_cast<float>(0.02 * x);  // 4 m over 200 m
  EXPECT_DOUBLE_EQ(Terrain3DView::suggestedExaggeration(gentle, 1.0), 5.0);
  EXPECT_DOUBLE_EQ(Terrain3DView::suggestedExaggeration(gentle, 0.5), 2.5);
  EXPECT_DOUBLE_EQ(Terrain3DView::suggestedExaggeration(cv::Mat(), 1.0), 1.0);
}
