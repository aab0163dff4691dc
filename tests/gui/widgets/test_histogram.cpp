#include <QSignalSpy>
#include <QTest>
#include <cmath>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "delineo/widgets/disparity_histogram.hpp"
#include "gui_test_support.hpp"

using delineo::widgets::DisparityHistogramWidget;

namespace {
cv::Mat roiDisparities() {
  cv::Mat d(60, 100, CV_32F);
  cv::RNG rng(3);
  for (int y = 0; y < d.rows; ++y) {
    for (int x = 0; x < d.cols; ++x) {
      const bool building = x > 40 && x < 80 && y > 15 && y < 50;
      d.at<float>(y, x) = static_cast<float>((building ? 27.0 : 10.0) + rng.gaussian(1.2));
    }
  }
  d(cv::Rect(0, 0, 10, 10)).setTo(std::numeric_limits<float>::quiet_NaN());
  d(cv::Rect(0, 59, 5, 1)).setTo(45.0f);  // a few outliers (e.g. a mast) widen the range
  return d;
}

QPoint at(const DisparityHistogramWidget& h, double d) {
  return QPoint(static_cast<int>(std::lround(h.xOfDisparity(d))), 50);
}
}  // namespace

TEST(DisparityHistogram, CountsIgnoreNaNAndMask) {
  DisparityHistogramWidget h;
  const cv::Mat d = roiDisparities();
  h.setDisparities(d);
  EXPECT_EQ(h.sampleCount(), 60 * 100 - 100);
  EXPECT_GE(h.displayMax(), 47);
  int total = 0;
  for (int c : h.counts()) total += c;
  EXPECT_EQ(total, h.sampleCount());
  cv::Mat mask(d.size(), CV_8U, cv::Scalar(0));
  mask(cv::Rect(50, 20, 10, 10)).setTo(255);
  h.setDisparities(d, mask);
  EXPECT_EQ(h.sampleCount(), 100);
}

TEST(DisparityHistogram, DraggingHandlesAndBandChangesTheInterval) {
  DisparityHistogramWidget h;
  h.resize(420, 160);
  h.setDisparities(roiDisparities());
  h.setGroundLevel(10.0);
  h.setInterval(24, 31);
  h.show();
  QSignalSpy changed(&h, &DisparityHistogramWidget::intervalChanged);
  QSignalSpy finished(&h, &DisparityHistogramWidget::intervalEditingFinished);

  // Upper handle (right edge of bin 31) to 34.
  QTest::mousePress(&h, Qt::LeftButton, {}, at(h, 31.5));
  QTest::mouseMove(&h, at(h, 33.0));
  QTest::mouseMove(&h, at(h, 34.0));
  QTest::mouseRelease(&h, Qt::LeftButton, {}, at(h, 34.0));
  EXPECT_EQ(h.lowerBound(), 24);
  EXPECT_EQ(h.upperBound(), 34);
  ASSERT_GE(changed.count(), 1);
  EXPECT_EQ(changed.last().at(0).toInt(), 24);
  EXPECT_EQ(changed.last().at(1).toInt(), 34);
  ASSERT_EQ(finished.count(), 1);

  // The whole band, +3.
  QTest::mousePress(&h, Qt::LeftButton, {}, at(h, 28.0));
  QTest::mouseMove(&h, at(h, 29.5));
  QTest::mouseRelease(&h, Qt::LeftButton, {}, at(h, 31.0));
  EXPECT_EQ(h.lowerBound(), 27);
  EXPECT_EQ(h.upperBound(), 37);
  EXPECT_EQ(finished.count(), 2);

  // Lower handle down to 22.
  QTest::mousePress(&h, Qt::LeftButton, {}, at(h, 26.5));
  QTest::mouseRelease(&h, Qt::LeftButton, {}, at(h, 22.0));
  EXPECT_EQ(h.lowerBound(), 22);

  // Keyboard: band right by one, then the upper bound alone.
  QTest::keyClick(&h, Qt::Key_Right);
  EXPECT_EQ(h.lowerBound(), 23);
  EXPECT_EQ(h.upperBound(), 38);
  QTest::keyClick(&h, Qt::Key_Left, Qt::ShiftModifier);
  EXPECT_EQ(h.lowerBound(), 23);
  EXPECT_EQ(h.upperBound(), 37);
  EXPECT_EQ(changed.last().at(1).toInt(), 37);
  delineo::widgets::test::saveScreenshot(h, QStringLiteral("disparity_histogram"));
}

TEST(DisparityHistogram, APlaceholderTakesNoEdits) {
  DisparityHistogramWidget h;
  h.resize(420, 160);
  h.setDisparities(roiDisparities());
  h.setInterval(24, 31);
  h.setPlaceholder(QStringLiteral("Select a building"));
  h.show();
  QSignalSpy changed(&h, &DisparityHistogramWidget::intervalChanged);
  QTest::mousePress(&h, Qt::LeftButton, {}, at(h, 31.5));
  QTest::mouseMove(&h, at(h, 34.0));
  QTest::mouseRelease(&h, Qt::LeftButton, {}, at(h, 34.0));
  QTest::keyClick(&h, Qt::Key_Right);
  EXPECT_EQ(changed.count(), 0);
  EXPECT_EQ(h.upperBound(), 31);
  // Back to the plot, the same drag moves the bound.
  h.setPlaceholder({});
  QTest::mousePress(&h, Qt::LeftButton, {}, at(h, 31.5));
  QTest::mouseMove(&h, at(h, 34.0));
  QTest::mouseRelease(&h, Qt::LeftButton, {}, at(h, 34.0));
  EXPECT_EQ(h.upperBound(), 34);
}

TEST(DisparityHistogram, DragSignalsAreThrottled) {
  DisparityHistogramWidget h;
  h.resize(420, 160);
  h.setDisparities(roiDisparities());
  h.setInterval(24, 31);
  QSignalSpy changed(&h, &DisparityHistogramWidget::intervalChanged);
  QTest::mousePress(&h, Qt::LeftButton, {}, at(h, 31.5));
  for (int i = 0; i < 12; ++i) QTest::mouseMove(&h, at(h, 32.0 + (i % 2 == 0 ? i / 2 : -1)));
  QTest::mouseRelease(&h, Qt::LeftButton, {}, at(h, 36.0));
  // 12 moves within a few ms: the first is emitted at once, the rest coalesced into the final one.
  EXPECT_LE(changed.count(), 3);
  EXPECT_EQ(changed.last().at(1).toInt(), 36);
}

TEST(DisparityHistogram, TheIntervalsLabelStaysClearOfTheBand) {
  DisparityHistogramWidget h;
  h.resize(360, 150);
  h.setDisparities(roiDisparities());
  h.setGroundLevel(10.0);
  const auto band = [&h] {
    const double top = h.intervalLabelRect().top();
    return QRectF(QPointF(h.xOfDisparity(h.lowerBound() - 0.5) - 5, top),
                  QPointF(h.xOfDisparity(h.upperBound() + 0.5) + 5, top + 1));
  };
  // In the middle of the axis: top right, as always.
  h.setInterval(24, 31);
  const QRectF topRight = h.intervalLabelRect();
  EXPECT_FALSE(topRight.intersects(band()));
  // At the right end of the axis (where the label used to sit on the grips): left of the band.
  h.setInterval(h.displayMax() - 2, h.displayMax());
  const QRectF beside = h.intervalLabelRect();
  EXPECT_FALSE(beside.intersects(band()));
  EXPECT_LT(beside.right(), h.xOfDisparity(h.lowerBound() - 0.5));
  EXPECT_LT(beside.left(), topRight.left());
  EXPECT_GE(beside.left(), 0.0);
  if (const QString dir = qEnvironmentVariable("DELINEO_SCREENSHOT_DIR"); !dir.isEmpty()) {
    h.show();
    h.grab().save(dir + QStringLiteral("/histogram-interval-at-right-end.png"));
  }
}

