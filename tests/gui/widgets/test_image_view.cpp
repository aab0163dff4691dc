#include <QSignalSpy>
#include <QTest>
#include <QElapsedTimer>
#include <QWheelEvent>
#include <cstdio>
#include <cmath>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/polygon_overlay.hpp"
#include "gui_test_support.hpp"

using delineo::widgets::ImageView;

namespace {

// 8-bit pattern whose value identifies the pixel well enough to check tile placement.
cv::Mat patternImage(int w, int h) {
  cv::Mat image(h, w, CV_8UC1);
  for (int y = 0; y < h; ++y) {
    uchar* row = image.ptr<uchar>(y);
    for (int x = 0; x < w; ++x) row[x] = static_cast<uchar>((x * 7 + y * 13) & 255);
  }
  return image;
}

void wheel(QWidget* w, QPointF pos, int delta) {
  QWheelEvent event(pos, w->mapToGlobal(pos), QPoint(), QPoint(0, delta), Qt::NoButton, Qt::NoModifier,
                    Qt::NoScrollPhase, false);
  QApplication::sendEvent(w, &event);
}

}  // namespace

TEST(ImageView, LargeImageZoomAndPanKeepTheTileCacheBounded) {
  const cv::Mat image = patternImage(10000, 10000);
  ImageView view;
  view.resize(800, 600);
  view.setTileCacheCapacity(64);
  QElapsedTimer timer;
  timer.start();
  view.setImage(image);
  const qint64 pyramidMs = timer.elapsed();
  // Shared, not copied: the view holds a reference to the caller's buffer.
  ASSERT_NE(image.u, nullptr);
  EXPECT_GE(image.u->refcount, 2);
  EXPECT_EQ(view.pyramidLevelCount(), 7);  // 10000 → 5000 → ... → 157
  view.grab();
  EXPECT_GE(view.currentLevel(), 4);  // fitted: about 1/16, served by a coarse level

  const size_t maxBytes = 64u * 256u * 256u * 4u;
  QPointF cursor(300, 250);
  timer.start();
  for (int step = 0; step < 40; ++step) {
    wheel(&view, cursor, 120);
    view.grab();
    EXPECT_LE(view.tileCacheSize(), 64u);
    EXPECT_LE(view.tileCacheBytes(), maxBytes);
  }
  const double zoomFrameMs = timer.elapsed() / 40.0;
  EXPECT_GE(view.zoom(), 8.0);
  EXPECT_EQ(view.currentLevel(), 0);
  std::printf("[ measure ] 10000x10000 8-bit: pyramid %lld ms, %.1f ms per zoom step + repaint (800x600)\n",
              static_cast<long long>(pyramidMs), zoomFrameMs);
  // Pan across a large part of the image with a middle-button drag.
  for (int i = 0; i < 20; ++i) {
    QTest::mousePress(&view, Qt::MiddleButton, {}, QPoint(700, 300));
    QTest::mouseMove(&view, QPoint(100, 300));
    QTest::mouseRelease(&view, Qt::MiddleButton, {}, QPoint(100, 300));
    view.grab();
    EXPECT_LE(view.tileCacheSize(), 64u);
  }
  // Only visible tiles were ever converted: far fewer than the 1600 tiles of level 0.
  EXPECT_LT(view.tilesConverted(), 400u);

  // At high zoom each widget pixel shows exactly its image pixel.
  view.setView(QPointF(5000.5, 5000.5), 8.0);
  const QImage shot = view.grab().toImage().convertToFormat(QImage::Format_RGB32);
  int checked = 0;
  for (int wy = 20; wy < 580; wy += 37) {
    for (int wx = 20; wx < 780; wx += 41) {
      const QPointF p = view.widgetToImage(QPointF(wx + 0.5, wy + 0.5));
      const int x = static_cast<int>(std::floor(p.x()));
      const int y = static_cast<int>(std::floor(p.y()));
      ASSERT_EQ(qGray(shot.pixel(wx, wy)), image.at<uchar>(y, x)) << "widget " << wx << "," << wy;
      ++checked;
    }
  }
  EXPECT_GT(checked, 200);
  delineo::widgets::test::saveScreenshot(view, QStringLiteral("image_view_zoom8"));
}

TEST(ImageView, CoordinatesRoundTripAndZoomKeepsTheAnchor) {
  ImageView view;
  view.resize(640, 480);
  view.setImage(patternImage(3000, 2000));
  for (double zoom : {0.05, 0.37, 1.0, 5.5, 40.0}) {
    view.setView(QPointF(1234.5, 987.25), zoom);
    for (QPointF p : {QPointF(0, 0), QPointF(1500.25, 10.5), QPointF(2999, 1999)}) {
      const QPointF back = view.widgetToImage(view.imageToWidget(p));
      EXPECT_NEAR(back.x(), p.x(), 1e-9);
      EXPECT_NEAR(back.y(), p.y(), 1e-9);
    }
  }
  view.setView(QPointF(1500, 1000), 1.0);
  const QPointF anchor(100, 400);
  const QPointF under = view.widgetToImage(anchor);
  view.zoomAround(3.0, anchor);
  const QPointF after = view.imageToWidget(under);
  EXPECT_NEAR(after.x(), anchor.x(), 1e-9);
  EXPECT_NEAR(after.y(), anchor.y(), 1e-9);
  EXPECT_DOUBLE_EQ(view.zoom(), 3.0);
  view.setZoom(1e6);
  EXPECT_DOUBLE_EQ(view.zoom(), ImageView::kMaximumZoom);
}

TEST(ImageView, LinkedViewsFollowEachOtherWithoutLoops) {
  ImageView a;
  ImageView b;
  a.resize(400, 300);
  b.resize(400, 300);
  const cv::Mat image = patternImage(1000, 800);
  a.setImage(image);
  b.setImage(image);
  delineo::widgets::linkViews(&a, &b);
  QSignalSpy spyA(&a, &ImageView::viewChanged);
  QSignalSpy spyB(&b, &ImageView::viewChanged);
  a.setView(QPointF(300, 200), 2.5);
  EXPECT_EQ(b.viewCenter(), QPointF(300, 200));
  EXPECT_DOUBLE_EQ(b.zoom(), 2.5);
  EXPECT_EQ(spyA.count(), 1);
  EXPECT_EQ(spyB.count(), 1);
  wheel(&b, QPointF(50, 60), 240);
  EXPECT_EQ(a.viewCenter(), b.viewCenter());
  EXPECT_DOUBLE_EQ(a.zoom(), b.zoom());
  EXPECT_EQ(spyA.count(), 2);
  EXPECT_EQ(spyB.count(), 2);
}

TEST(ImageView, PickModesEmitImageGeometry) {
  ImageView view;
  view.resize(400, 400);
  view.setImage(patternImage(200, 200));
  view.setView(QPointF(100, 100), 2.0);  // image (x, y) ↔ widget (2x, 2y)

  view.setInteractionMode(delineo::widgets::InteractionMode::PickRectangle);
  QSignalSpy rectSpy(&view, &ImageView::rectanglePicked);
  QTest::mousePress(&view, Qt::LeftButton, {}, QPoint(40, 60));
  QTest::mouseMove(&view, QPoint(120, 100));
  QTest::mouseRelease(&view, Qt::LeftButton, {}, QPoint(140, 160));
  ASSERT_EQ(rectSpy.count(), 1);
  EXPECT_EQ(rectSpy.at(0).at(0).toRectF(), QRectF(QPointF(20, 30), QPointF(70, 80)));

  view.setInteractionMode(delineo::widgets::InteractionMode::PickPolygon);
  QSignalSpy polySpy(&view, &ImageView::polygonPicked);
  QTest::mouseClick(&view, Qt::LeftButton, {}, QPoint(20, 20));
  QTest::mouseClick(&view, Qt::LeftButton, {}, QPoint(200, 20));
  // A real double-click is press, release, double-click, release: the first press adds the vertex.
  QTest::mouseClick(&view, Qt::LeftButton, {}, QPoint(200, 200));
  QTest::mouseDClick(&view, Qt::LeftButton, {}, QPoint(200, 200));
  ASSERT_EQ(polySpy.count(), 1);
  const QPolygonF polygon = polySpy.at(0).at(0).value<QPolygonF>();
  ASSERT_EQ(polygon.size(), 3);
  EXPECT_EQ(polygon[0], QPointF(10, 10));
  EXPECT_EQ(polygon[1], QPointF(100, 10));
  EXPECT_EQ(polygon[2], QPointF(100, 100));

  view.setInteractionMode(delineo::widgets::InteractionMode::PickPoint);
  QSignalSpy pointSpy(&view, &ImageView::pointPicked);
  QTest::mouseClick(&view, Qt::LeftButton, {}, QPoint(50, 70));
  ASSERT_EQ(pointSpy.count(), 1);
  EXPECT_EQ(pointSpy.at(0).at(0).toPointF(), QPointF(25, 35));
}

// PickLine: a drag, or a click at each end, gives the line; one shorter than 3 widget px, or one
// dropped with Esc, gives nothing.
TEST(ImageView, PickLineGivesTheLineDraggedOrClicked) {
  ImageView view;
  view.resize(400, 400);
  view.setImage(patternImage(200, 200));
  view.setView(QPointF(100, 100), 2.0);  // image (x, y) ↔ widget (2x, 2y)
  view.setInteractionMode(delineo::widgets::InteractionMode::PickLine);
  QSignalSpy lines(&view, &ImageView::linePicked);
  QTest::mousePress(&view, Qt::LeftButton, {}, QPoint(20, 40));
  QTest::mouseMove(&view, QPoint(100, 100));
  QTest::mouseRelease(&view, Qt::LeftButton, {}, QPoint(200, 160));
  ASSERT_EQ(lines.count(), 1);
  EXPECT_EQ(lines.at(0).at(0).toPointF(), QPointF(10, 20));
  EXPECT_EQ(lines.at(0).at(1).toPointF(), QPointF(100, 80));
  QTest::mouseClick(&view, Qt::LeftButton, {}, QPoint(40, 40));
  QTest::mouseMove(&view, QPoint(120, 60));
  QTest::mouseClick(&view, Qt::LeftButton, {}, QPoint(240, 80));
  ASSERT_EQ(lines.count(), 2);
  EXPECT_EQ(lines.at(1).at(0).toPointF(), QPointF(20, 20));
  EXPECT_EQ(lines.at(1).at(1).toPointF(), QPointF(120, 40));
  QTest::mouseClick(&view, Qt::LeftButton, {}, QPoint(40, 40));
  QTest::mouseClick(&view, Qt::LeftButton, {}, QPoint(41, 41));  // too short: dropped
  QTest::mouseClick(&view, Qt::LeftButton, {}, QPoint(40, 40));
  QTest::keyClick(&view, Qt::Key_Escape);
  QTest::mouseClick(&view, Qt::LeftButton, {}, QPoint(240, 80));  // begins a new line
  EXPECT_EQ(lines.count(), 2);
}

// PickOutline: a click gives the polygon under it (-1 for none), a drag pans, Esc leaves the mode.
TEST(ImageView, PickOutlineGivesThePolygonClicked) {
  ImageView view;
  view.resize(400, 400);
  view.setImage(patternImage(200, 200));
  view.setView(QPointF(100, 100), 2.0);
  delineo::widgets::OverlayPolygon square;
  square.id = 7;
  square.polygon.outer = {{10, 10}, {60, 10}, {60, 60}, {10, 60}};
  view.polygons().setPolygons({square});
  view.setInteractionMode(delineo::widgets::InteractionMode::PickOutline);
  QSignalSpy picked(&view, &ImageView::outlinePicked);
  QTest::mouseClick(&view, Qt::LeftButton, {}, QPoint(60, 60));
  QTest::mouseClick(&view, Qt::LeftButton, {}, QPoint(300, 300));
  ASSERT_EQ(picked.count(), 2);
  EXPECT_EQ(picked.at(0).at(0).toInt(), 7);
  EXPECT_EQ(picked.at(1).at(0).toInt(), -1);
  EXPECT_EQ(view.polygons().selectedId(), -1);  // it reports, it does not select
  const QPointF centre = view.viewCenter();
  QTest::mousePress(&view, Qt::LeftButton, {}, QPoint(200, 200));
  QTest::mouseMove(&view, QPoint(240, 200));
  QTest::mouseRelease(&view, Qt::LeftButton, {}, QPoint(240, 200));
  EXPECT_EQ(picked.count(), 2);
  EXPECT_NE(view.viewCenter(), centre);
  QTest::keyClick(&view, Qt::Key_Escape);
  EXPECT_EQ(view.interactionMode(), delineo::widgets::InteractionMode::Navigate);
}

TEST(ImageView, FloatRasterWithColourMapAndOverlay) {
  cv::Mat dem(300, 400, CV_32F);
  for (int y = 0; y < dem.rows; ++y)
    for (int x = 0; x < dem.cols; ++x) dem.at<float>(y, x) = static_cast<float>(x) * 0.1f;
  dem(cv::Rect(150, 100, 60, 50)).setTo(std::numeric_limits<float>::quiet_NaN());
  cv::Mat labels(300, 400, CV_32S, cv::Scalar(0));
  labels(cv::Rect(20, 20, 80, 60)).setTo(3);
  ImageView view;
  view.resize(400, 300);
  view.setImage(dem, {delineo::widgets::ColourMap::Viridis, 0.0, 40.0});
  view.setOverlay(labels, 0.5);
  view.setView(QPointF(200, 150), 1.0);
  const QImage shot = view.grab().toImage().convertToFormat(QImage::Format_RGB32);
  // Hole → neutral grey checker; left → viridis dark purple; right → yellow.
  const QColor hole(shot.pixel(180, 125));
  EXPECT_EQ(hole.red(), hole.green());
  EXPECT_EQ(hole.green(), hole.blue());
  const QColor left(shot.pixel(2, 290));
  EXPECT_LT(left.green(), 40);
  EXPECT_GT(left.blue(), left.green());
  const QColor right(shot.pixel(397, 290));
  EXPECT_GT(right.red(), 200);
  EXPECT_GT(right.green(), 200);
  // The overlay tints its rectangle.
  const QColor tinted(shot.pixel(60, 50));
  const QColor plain(shot.pixel(60, 150));
  EXPECT_NE(tinted.rgb(), plain.rgb());
  delineo::widgets::test::saveScreenshot(view, QStringLiteral("image_view_float_overlay"));
}

TEST(ImageView, ColourImagesAreShownInTheirColours) {
  // OpenCV order: blue, green, red. Four quadrants: red, green, blue, yellow.
  cv::Mat bgr(100, 100, CV_8UC3);
  bgr(cv::Rect(0, 0, 50, 50)).setTo(cv::Scalar(0, 0, 255));
  bgr(cv::Rect(50, 0, 50, 50)).setTo(cv::Scalar(0, 255, 0));
  bgr(cv::Rect(0, 50, 50, 50)).setTo(cv::Scalar(255, 0, 0));
  bgr(cv::Rect(50, 50, 50, 50)).setTo(cv::Scalar(0, 255, 255));
  ImageView view;
  view.resize(200, 200);
  view.setImage(bgr);
  EXPECT_EQ(view.image().type(), CV_8UC3);
  view.setView(QPointF(50, 50), 2.0);  // image (x, y) ↔ widget (2x, 2y)
  const QImage shot = view.grab().toImage().convertToFormat(QImage::Format_RGB32);
  EXPECT_EQ(QColor(shot.pixel(50, 50)), QColor(255, 0, 0));
  EXPECT_EQ(QColor(shot.pixel(150, 50)), QColor(0, 255, 0));
  EXPECT_EQ(QColor(shot.pixel(50, 150)), QColor(0, 0, 255));
  EXPECT_EQ(QColor(shot.pixel(150, 150)), QColor(255, 255, 0));
  // Reduced levels keep the colours too.
  view.setView(QPointF(50, 50), 0.5);
  const QImage small = view.grab().toImage().convertToFormat(QImage::Format_RGB32);
  const QPointF red = view.imageToWidget(QPointF(20, 20));
  EXPECT_EQ(QColor(small.pixel(red.toPoint())), QColor(255, 0, 0));
  delineo::widgets::test::saveScreenshot(view, QStringLiteral("image_view_colour"));
}

TEST(ImageView, AFittedViewStaysFittedThroughResizesUntilMoved) {
  // An image set while the widget is still small (a window not laid out yet) fills the widget
  // once it has its final size.
  ImageView view;
  view.resize(100, 30);
  view.show();
  ASSERT_TRUE(QTest::qWaitForWindowExposed(&view));
  view.setImage(patternImage(1024, 1024));
  EXPECT_TRUE(view.isFitted());
  view.resize(900, 700);
  EXPECT_TRUE(view.isFitted());
  EXPECT_DOUBLE_EQ(view.zoom(), 700.0 / 1024.0);
  EXPECT_EQ(view.viewCenter(), QPointF(512, 512));
  // The whole image is shown and touches two sides of the widget.
  const QRectF shown(view.imageToWidget(QPointF(0, 0)), view.imageToWidget(QPointF(1024, 1024)));
  EXPECT_NEAR(shown.top(), 0.0, 1e-9);
  EXPECT_NEAR(shown.bottom(), 700.0, 1e-9);
  // Once the operator zooms, a resize keeps the operator's view.
  wheel(&view, QPointF(300, 300), 120);
  EXPECT_FALSE(view.isFitted());
  const double zoomed = view.zoom();
  view.resize(800, 600);
  EXPECT_DOUBLE_EQ(view.zoom(), zoomed);
}

TEST(ImageView, ALinkedViewTakesItsPartnersViewForItsFirstImage) {
  // The visible view is fitted; a hidden dock's view (other size) gets an image of the same
  // size: it follows the visible one instead of fitting itself and dragging the visible one.
  ImageView visible;
  ImageView hidden;
  visible.resize(900, 700);
  hidden.resize(160, 120);
  delineo::widgets::linkViews(&visible, &hidden);
  visible.setImage(patternImage(1024, 1024));
  ASSERT_TRUE(visible.isFitted());
  const double fitted = visible.zoom();
  hidden.setImage(patternImage(1024, 1024));
  EXPECT_DOUBLE_EQ(visible.zoom(), fitted);
  EXPECT_TRUE(visible.isFitted());
  EXPECT_DOUBLE_EQ(hidden.zoom(), fitted);
  EXPECT_EQ(hidden.viewCenter(), visible.viewCenter());
}
