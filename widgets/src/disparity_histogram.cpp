#include "delineo/widgets/disparity_histogram.hpp"

#include <QKeyEvent>
#include <QMouseEvent>
#include <QPainter>
#include <QPainterPath>
#include <algorithm>
#include <cmath>

namespace delineo::widgets {
namespace {
constexpr int kThrottleMs = 50;
constexpr double kHandleGrabPx = 6.0;
}  // namespace

DisparityHistogramWidget::DisparityHistogramWidget(QWidget* parent) : QWidget(parent) {
  setFocusPolicy(Qt::StrongFocus);
  setMouseTracking(true);
  throttle_.setSingleShot(true);
  connect(&throttle_, &QTimer::timeout, this, &DisparityHistogramWidget::flushPendingSignal);
}

void DisparityHistogramWidget::setDisparities(const cv::Mat& disparities, const cv::Mat& mask) {
  CV_Assert(disparities.channels() == 1);
  CV_Assert(mask.empty() || (mask.type() == CV_8UC1 && mask.size() == disparities.size()));
  cv::Mat values;
  disparities.convertTo(values, CV_32F);
  std::vector<float> samples;
  for (int y = 0; y < values.rows; ++y) {
    const float* row = values.ptr<float>(y);
    const uchar* m = mask.empty() ? nullptr : mask.ptr<uchar>(y);
    for (int x = 0; x < values.cols; ++x) {
      if ((m == nullptr || m[x] != 0) && std::isfinite(row[x])) samples.push_back(row[x]);
    }
  }
  setValues(samples);
}

void DisparityHistogramWidget::setValues(const std::vector<float>& values) {
  counts_.clear();
  samples_ = 0;
  float lo = std::numeric_limits<float>::infinity();
  float hi = -std::numeric_limits<float>::infinity();
  for (float v : values) {
    if (!std::isfinite(v)) continue;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  if (lo <= hi) {
    firstBin_ = static_cast<int>(std::lround(lo));
    const int last = static_cast<int>(std::lround(hi));
    counts_.assign(static_cast<size_t>(last - firstBin_ + 1), 0);
    for (float v : values) {
      if (!std::isfinite(v)) continue;
      ++counts_[static_cast<size_t>(std::lround(v) - firstBin_)];
      ++samples_;
    }
    setInterval(a_, b_);  // clamp into the new range
  }
  update();
}

int DisparityHistogramWidget::displayMin() const {
  int lo = counts_.empty() ? std::min(a_, b_) : firstBin_;
  if (ground_) lo = std::min(lo, static_cast<int>(std::floor(*ground_)));
  return lo - 2;
}

int DisparityHistogramWidget::displayMax() const {
  int hi = counts_.empty() ? std::max(a_, b_) : firstBin_ + static_cast<int>(counts_.size()) - 1;
  if (ground_) hi = std::max(hi, static_cast<int>(std::ceil(*ground_)));
  return std::max(hi + 2, displayMin() + 4);
}

QRectF DisparityHistogramWidget::plotRect() const {
  const QFontMetrics fm(font());
  return QRectF(8, 6, std::max(width() - 16, 10), std::max(height() - 12 - fm.height() - 4, 10));
}

double DisparityHistogramWidget::xOfDisparity(double d) const {
  const QRectF r = plotRect();
  // Bin k spans [k - 0.5, k + 0.5]; the axis spans [displayMin - 0.5, displayMax + 0.5].
  const double lo = displayMin() - 0.5;
  const double hi = displayMax() + 0.5;
  return r.left() + (d - lo) / (hi - lo) * r.width();
}

double DisparityHistogramWidget::disparityAtX(double x) const {
  const QRectF r = plotRect();
  const double lo = displayMin() - 0.5;
  const double hi = displayMax() + 0.5;
  return lo + (x - r.left()) / r.width() * (hi - lo);
}

void DisparityHistogramWidget::setInterval(int a, int b) {
  if (a > b) std::swap(a, b);
  if (!counts_.empty()) {
    const int lo = displayMin();
    const int hi = displayMax();
    a = std::clamp(a, lo, hi);
    b = std::clamp(b, lo, hi);
  }
  a_ = a;
  b_ = b;
  update();
}

void DisparityHistogramWidget::setGroundLevel(double disparity) {
  ground_ = disparity;
  update();
}

void DisparityHistogramWidget::clearGroundLevel() {
  ground_.reset();
  update();
}

QSize DisparityHistogramWidget::sizeHint() const { return {360, 150}; }
QSize DisparityHistogramWidget::minimumSizeHint() const { return {160, 80}; }

void DisparityHistogramWidget::moveInterval(int a, int b, bool fromDrag) {
  const int oldA = a_;
  const int oldB = b_;
  setInterval(a, b);
  if (a_ == oldA && b_ == oldB) return;
  if (!fromDrag) {
    emit intervalChanged(a_, b_);
    return;
  }
  // Throttle: at most one signal per kThrottleMs, the latest values always delivered.
  pending_ = true;
  if (!lastEmit_.isValid() || lastEmit_.elapsed() >= kThrottleMs) {
    flushPendingSignal();
  } else if (!throttle_.isActive()) {
    throttle_.start(kThrottleMs - static_cast<int>(lastEmit_.elapsed()));
  }
}

void DisparityHistogramWidget::flushPendingSignal() {
  throttle_.stop();
  if (!pending_) return;
  pending_ = false;
  lastEmit_.start();
  emit intervalChanged(a_, b_);
}

void DisparityHistogramWidget::setPlaceholder(const QString& text) {
  if (text == placeholder_) return;
  placeholder_ = text;
  drag_ = DragPart::None;
  update();
}

void DisparityHistogramWidget::mousePressEvent(QMouseEvent* event) {
  if (event->button() != Qt::LeftButton || !placeholder_.isEmpty()) return;
  const double x = event->position().x();
  const double xa = xOfDisparity(a_ - 0.5);
  const double xb = xOfDisparity(b_ + 0.5);
  dragStartD_ = disparityAtX(x);
  dragStartA_ = a_;
  dragStartB_ = b_;
  if (std::abs(x - xa) <= kHandleGrabPx && std::abs(x - xa) <= std::abs(x - xb)) {
    drag_ = DragPart::Lower;
  } else if (std::abs(x - xb) <= kHandleGrabPx) {
    drag_ = DragPart::Upper;
  } else if (x > xa && x < xb) {
    drag_ = DragPart::Band;
  } else {
    // Outside the band: the nearest bound jumps to the clicked bin, then follows the drag.
    const int d = static_cast<int>(std::lround(dragStartD_));
    if (x < xa) {
      drag_ = DragPart::Lower;
      moveInterval(d, b_, true);
    } else {
      drag_ = DragPart::Upper;
      moveInterval(a_, d, true);
    }
  }
  update();
}

void DisparityHistogramWidget::mouseMoveEvent(QMouseEvent* event) {
  if (!placeholder_.isEmpty()) return;
  const double x = event->position().x();
  if (drag_ == DragPart::None) {
    const bool nearHandle = std::abs(x - xOfDisparity(a_ - 0.5)) <= kHandleGrabPx ||
                            std::abs(x - xOfDisparity(b_ + 0.5)) <= kHandleGrabPx;
    setCursor(nearHandle ? Qt::SizeHorCursor : Qt::ArrowCursor);
    setToolTip(tr("Disparity %1").arg(std::lround(disparityAtX(x))));
    return;
  }
  const double d = disparityAtX(x);
  switch (drag_) {
    case DragPart::Lower: moveInterval(std::min(static_cast<int>(std::lround(d)), b_), b_, true); break;
    case DragPart::Upper: moveInterval(a_, std::max(static_cast<int>(std::lround(d)), a_), true); break;
    case DragPart::Band: {
      int shift = static_cast<int>(std::lround(d - dragStartD_));
      // Keep the band's width: stop at the display range instead of squeezing it.
      shift = std::clamp(shift, displayMin() - dragStartA_, displayMax() - dragStartB_);
      moveInterval(dragStartA_ + shift, dragStartB_ + shift, true);
      break;
    }
    case DragPart::None: break;
  }
}

void DisparityHistogramWidget::mouseReleaseEvent(QMouseEvent* event) {
  if (event->button() != Qt::LeftButton || drag_ == DragPart::None) return;
  mouseMoveEvent(event);  // the release position is the final one
  drag_ = DragPart::None;
  flushPendingSignal();
  update();
  if (a_ != dragStartA_ || b_ != dragStartB_) emit intervalEditingFinished(a_, b_);
}

void DisparityHistogramWidget::keyPressEvent(QKeyEvent* event) {
  if (!placeholder_.isEmpty()) {
    QWidget::keyPressEvent(event);
    return;
  }
  int step = 0;
  if (event->key() == Qt::Key_Left) step = -1;
  if (event->key() == Qt::Key_Right) step = 1;
  if (step == 0) {
    QWidget::keyPressEvent(event);
    return;
  }
  const int oldA = a_;
  const int oldB = b_;
  if (event->modifiers() & Qt::ShiftModifier) {
    moveInterval(a_, std::max(a_, b_ + step), false);
  } else if (event->modifiers() & Qt::ControlModifier) {
    moveInterval(std::min(a_ + step, b_), b_, false);
  } else {
    if (!counts_.empty() && (a_ + step < displayMin() || b_ + step > displayMax())) return;
    moveInterval(a_ + step, b_ + step, false);
  }
  if (a_ != oldA || b_ != oldB) emit intervalEditingFinished(a_, b_);
}

QRectF DisparityHistogramWidget::groundLabelRect() const {
  if (!ground_) return {};
  const QFontMetrics fm(font());
  return QRectF(xOfDisparity(*ground_) + 3, plotRect().top() + 8, fm.horizontalAdvance(tr("ground")), fm.height());
}

QRectF DisparityHistogramWidget::intervalLabelRect() const {
  const QRectF plot = plotRect();
  const QFontMetrics fm(font());
  const double width = fm.horizontalAdvance(tr("[%1, %2] px").arg(a_).arg(b_));
  const double height = fm.height();
  const double xa = xOfDisparity(a_ - 0.5), xb = xOfDisparity(b_ + 0.5);
  // The band with its grips (5 px each side), and the ground's label (drawn 8 px lower).
  const QRectF band(QPointF(xa - 6, plot.top()), QPointF(xb + 6, plot.top() + height));
  const QRectF ground = groundLabelRect();
  const auto at = [&](double left) { return QRectF(left, plot.top(), width, height); };
  for (const double left : {plot.right() - width, xa - 8 - width, xb + 8, plot.left()}) {
    const QRectF r = at(left);
    if (r.left() >= plot.left() && r.right() <= plot.right() + 0.5 && !r.intersects(band) &&
        !(ground_ && r.intersects(ground))) {
      return r;
    }
  }
  return at(plot.right() - width);  // no free place: where it always was
}

void DisparityHistogramWidget::paintEvent(QPaintEvent*) {
  QPainter painter(this);
  painter.fillRect(rect(), palette().color(QPalette::Base));
  if (!placeholder_.isEmpty()) {
    painter.setPen(palette().color(QPalette::PlaceholderText));
    painter.drawText(rect().adjusted(8, 8, -8, -8), Qt::AlignCenter | Qt::TextWordWrap, placeholder_);
    return;
  }
  const QRectF plot = plotRect();
  const QFontMetrics fm(font());
  const QColor text = palette().color(QPalette::Text);

  // Band behind the bars.
  const double xa = xOfDisparity(a_ - 0.5);
  const double xb = xOfDisparity(b_ + 0.5);
  painter.fillRect(QRectF(QPointF(xa, plot.top()), QPointF(xb, plot.bottom())), QColor(255, 200, 0, 70));

  // Bars, square-root scale so that the small building mode is visible next to the ground mode.
  int maxCount = 1;
  for (int c : counts_) maxCount = std::max(maxCount, c);
  const double denom = std::sqrt(static_cast<double>(maxCount));
  for (size_t i = 0; i < counts_.size(); ++i) {
    if (counts_[i] == 0) continue;
    const int d = firstBin_ + static_cast<int>(i);
    const double h = std::sqrt(static_cast<double>(counts_[i])) / denom * plot.height();
    const QRectF bar(QPointF(xOfDisparity(d - 0.5), plot.bottom() - h), QPointF(xOfDisparity(d + 0.5), plot.bottom()));
    const bool inside = d >= a_ && d <= b_;
    painter.fillRect(bar.adjusted(0, 0, -std::min(1.0, bar.width() * 0.15), 0),
                     inside ? QColor(33, 144, 141) : QColor(130, 130, 140));
  }

  // Handles.
  painter.setRenderHint(QPainter::Antialiasing, true);
  painter.setPen(QPen(QColor(230, 140, 0), 2.0));
  painter.drawLine(QPointF(xa, plot.top()), QPointF(xa, plot.bottom()));
  painter.drawLine(QPointF(xb, plot.top()), QPointF(xb, plot.bottom()));
  painter.setBrush(QColor(230, 140, 0));
  for (double x : {xa, xb}) {
    QPolygonF grip;
    grip << QPointF(x - 5, plot.top()) << QPointF(x + 5, plot.top()) << QPointF(x, plot.top() + 7);
    painter.drawPolygon(grip);
  }

  // Ground level.
  if (ground_) {
    const double xg = xOfDisparity(*ground_);
    painter.setPen(QPen(QColor(200, 30, 30), 1.5, Qt::DashLine));
    painter.drawLine(QPointF(xg, plot.top()), QPointF(xg, plot.bottom()));
    painter.setPen(QColor(200, 30, 30));
    painter.drawText(groundLabelRect().topLeft() + QPointF(0, fm.ascent()), tr("ground"));
  }

  // Axis with a few integer ticks.
  painter.setPen(text);
  painter.drawLine(plot.bottomLeft(), plot.bottomRight());
  const int lo = displayMin();
  const int hi = displayMax();
  const int span = std::max(hi - lo, 1);
  const int maxTicks = std::max(2, static_cast<int>(plot.width() / (fm.horizontalAdvance(QStringLiteral("-0000")) + 8)));
  int step = 1;
  for (int s : {1, 2, 5, 10, 20, 50, 100, 200, 500, 1000}) {
    step = s;
    if (span / s <= maxTicks) break;
  }
  for (int d = static_cast<int>(std::ceil(static_cast<double>(lo) / step)) * step; d <= hi; d += step) {
    const double x = xOfDisparity(d);
    painter.drawLine(QPointF(x, plot.bottom()), QPointF(x, plot.bottom() + 3));
    const QString label = QString::number(d);
    painter.drawText(QPointF(x - fm.horizontalAdvance(label) / 2.0, plot.bottom() + 4 + fm.ascent()), label);
  }
  const QRectF label = intervalLabelRect();
  painter.drawText(QPointF(label.left(), plot.top() + fm.ascent()), tr("[%1, %2] px").arg(a_).arg(b_));
  if (counts_.empty()) {
    painter.drawText(plot, Qt::AlignCenter, tr("No disparities in the ROI"));
  }
  if (hasFocus()) {
    painter.setPen(QPen(palette().color(QPalette::Highlight), 1.0, Qt::DotLine));
    painter.setBrush(Qt::NoBrush);
    painter.drawRect(rect().adjusted(0, 0, -1, -1));
  }
}

}  // namespace delineo::widgets
