#pragma once
// Histogram of the disparities inside the ROI with a draggable integer interval [a, b] (the
// building's disparity band) and the ground level marked as a vertical line.
//
// Interaction: drag a handle to move one bound, drag inside the band to move both, click outside
// the band to move the nearest bound there; keyboard: Left/Right move the whole band by 1,
// Shift+Left/Right move the upper bound, Ctrl+Left/Right move the lower bound.
#include <QElapsedTimer>
#include <QString>
#include <QTimer>
#include <QWidget>
#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace delineo::widgets {

class DisparityHistogramWidget : public QWidget {
  Q_OBJECT
 public:
  explicit DisparityHistogramWidget(QWidget* parent = nullptr);

  // Float disparities (any single-channel depth; NaN ignored). `mask` (CV_8U, same size, optional)
  // restricts the samples. Bins are one disparity unit wide, centred on integers.
  void setDisparities(const cv::Mat& disparities, const cv::Mat& mask = {});
  void setValues(const std::vector<float>& values);
  // Bin counts for integer disparities firstBin, firstBin + 1, ...
  const std::vector<int>& counts() const { return counts_; }
  int firstBin() const { return firstBin_; }
  int sampleCount() const { return samples_; }

  // The interval, clamped to the histogram range (kept as is when there are no samples).
  void setInterval(int a, int b);
  int lowerBound() const { return a_; }
  int upperBound() const { return b_; }

  void setGroundLevel(double disparity);
  void clearGroundLevel();
  std::optional<double> groundLevel() const { return ground_; }

  // A text shown instead of the plot, the band and its label, which take no mouse or key input
  // meanwhile (nothing to show: no building selected); empty = the plot.
  void setPlaceholder(const QString& text);
  const QString& placeholder() const { return placeholder_; }

  // Horizontal range shown (defaults to the data range plus a margin).
  int displayMin() const;
  int displayMax() const;
  // Widget x of a disparity value and back (for tests and tooltips).
  double xOfDisparity(double d) const;
  double disparityAtX(double x) const;
  // Where the "[a, b] px" label is drawn: top right, or beside the interval's band (left of it,
  // else right of it) when the band or the ground label would cover it there (for tests).
  QRectF intervalLabelRect() const;

  QSize sizeHint() const override;
  QSize minimumSizeHint() const override;

 signals:
  // Emitted while the user drags (at most every 50 ms, and once more when the drag ends) and on
  // each keyboard step.
  void intervalChanged(int a, int b);
  // The user finished a change (mouse release or key press).
  void intervalEditingFinished(int a, int b);

 protected:
  void paintEvent(QPaintEvent* event) override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  void keyPressEvent(QKeyEvent* event) override;

 private:
  enum class DragPart { None, Lower, Upper, Band };
  QRectF plotRect() const;
  QRectF groundLabelRect() const;  // where "ground" is written; empty without a ground level
  void moveInterval(int a, int b, bool fromDrag);
  void flushPendingSignal();

  std::vector<int> counts_;
  int firstBin_ = 0;
  int samples_ = 0;
  int a_ = 0;
  int b_ = 0;
  std::optional<double> ground_;
  QString placeholder_;
  DragPart drag_ = DragPart::None;
  double dragStartD_ = 0.0;
  int dragStartA_ = 0;
  int dragStartB_ = 0;
  QElapsedTimer lastEmit_;
  QTimer throttle_;
  bool pending_ = false;
};

}  // namespace delineo::widgets
