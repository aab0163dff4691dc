#include "delineo/widgets/image_view.hpp"

#include <QKeyEvent>
#include <QMouseEvent>
#include <QPainter>
#include <QWheelEvent>
#include <algorithm>
#include <cmath>

#include <opencv2/imgproc.hpp>

#include "delineo/widgets/polygon_overlay.hpp"

namespace delineo::widgets {
namespace {

QColor hashPalette(int label) {
  // Golden-ratio hue steps give neighbouring labels clearly different colours.
  const double hue = std::fmod(static_cast<double>(static_cast<unsigned>(label)) * 0.618033988749895, 1.0);
  return QColor::fromHsvF(static_cast<float>(hue), 0.75f, 0.95f);
}

bool sameView(QPointF a, double za, QPointF b, double zb) {
  return std::abs(a.x() - b.x()) < 1e-9 && std::abs(a.y() - b.y()) < 1e-9 &&
         std::abs(za - zb) <= 1e-12 * std::max(za, zb);
}

}  // namespace

size_t ImageView::TileKeyHash::operator()(const TileKey& k) const noexcept {
  size_t h = static_cast<size_t>(k.layer);
  h = h * 31 + static_cast<size_t>(k.level);
  h = h * 1000003u + static_cast<size_t>(k.tx);
  h = h * 1000003u + static_cast<size_t>(k.ty);
  return h;
}

ImageView::ImageView(QWidget* parent)
    : QWidget(parent), polygons_(std::make_unique<PolygonOverlay>(this)) {
  setMouseTracking(true);
  setFocusPolicy(Qt::StrongFocus);
  setAttribute(Qt::WA_OpaquePaintEvent);
  setMinimumSize(64, 64);
  connect(polygons_.get(), &PolygonOverlay::changed, this, qOverload<>(&QWidget::update));
}

ImageView::~ImageView() = default;

std::vector<cv::Mat> ImageView::buildPyramid(const cv::Mat& level0, bool nearest) {
  std::vector<cv::Mat> levels{level0};
  while (std::max(levels.back().cols, levels.back().rows) > kTileSize) {
    const cv::Mat& prev = levels.back();
    cv::Mat next;
    const cv::Size size((prev.cols + 1) / 2, (prev.rows + 1) / 2);
    if (nearest) {
      // Labels must stay labels: pick, never average.
      cv::resize(prev, next, size, 0, 0, cv::INTER_NEAREST);
    } else {
      cv::resize(prev, next, size, 0, 0, cv::INTER_AREA);
    }
    levels.push_back(next);
  }
  return levels;
}

void ImageView::setImage(const cv::Mat& image, const RasterStyle& style) {
  const int type = image.type();
  if (image.empty() || !(type == CV_8UC1 || type == CV_16UC1 || type == CV_32FC1 ||
                         type == CV_64FC1 || type == CV_8UC3)) {
    clearImage();
    return;
  }
  const cv::Size previous = imageSize();
  if (type == CV_64FC1) {
    cv::Mat asFloat;
    image.convertTo(asFloat, CV_32F);  // float is enough for display and halves the pyramid
    pyramid_ = buildPyramid(asFloat, false);
  } else {
    pyramid_ = buildPyramid(image, false);
  }
  invalidateTiles(Layer::Base);
  tilesConverted_ = 0;
  if (!overlayPyramid_.empty() && overlayPyramid_.front().size() != image.size()) clearOverlay();
  setRasterStyle(style);
  if (previous == image.size()) {
    update();
    return;
  }
  for (const QPointer<ImageView>& partner : links_) {
    if (partner && partner->imageSize() == image.size()) {
      setView(partner->viewCenter(), partner->zoom());
      return;
    }
  }
  fitToWindow();
}

void ImageView::setRasterStyle(const RasterStyle& style) {
  style_ = style;
  resolvedMin_ = style.min;
  resolvedMax_ = style.max;
  if (!pyramid_.empty() && (std::isnan(resolvedMin_) || std::isnan(resolvedMax_))) {
    double lo = 0.0;
    double hi = 255.0;
    if (pyramid_.front().depth() != CV_8U) {
      // The coarsest level is at most 256 x 256: cheap, and close enough for a display range.
      std::tie(lo, hi) = finiteRange(pyramid_.back());
      if (std::isnan(lo)) {
        lo = 0.0;
        hi = 1.0;
      }
    }
    if (std::isnan(resolvedMin_)) resolvedMin_ = lo;
    if (std::isnan(resolvedMax_)) resolvedMax_ = hi;
  }
  invalidateTiles(Layer::Base);
  update();
}

void ImageView::clearImage() {
  pyramid_.clear();
  fitted_ = false;
  invalidateTiles(Layer::Base);
  clearOverlay();
  update();
}

cv::Size ImageView::imageSize() const { return pyramid_.empty() ? cv::Size() : pyramid_.front().size(); }

void ImageView::setOverlay(const cv::Mat& labels, double opacity, std::function<QColor(int)> palette,
                           const OverlayHatch& hatch) {
  const int depth = labels.depth();
  if (labels.empty() || labels.channels() != 1 || !(depth == CV_8U || depth == CV_16U || depth == CV_32S)) {
    clearOverlay();
    return;
  }
  overlayPyramid_ = buildPyramid(labels, true);
  palette_ = palette ? std::move(palette) : hashPalette;
  hatch_ = hatch;
  overlayOpacity_ = std::clamp(opacity, 0.0, 1.0);
  invalidateTiles(Layer::Overlay);
  update();
}

void ImageView::setOverlayOpacity(double opacity) {
  overlayOpacity_ = std::clamp(opacity, 0.0, 1.0);  // applied when drawing: tiles stay valid
  update();
}

void ImageView::setOverlayVisible(bool visible) {
  overlayVisible_ = visible;
  update();
}

void ImageView::clearOverlay() {
  overlayPyramid_.clear();
  invalidateTiles(Layer::Overlay);
  update();
}

// --- tiles ----------------------------------------------------------------------------------

void ImageView::setTileCacheCapacity(size_t tiles) {
  cacheCapacity_ = std::max<size_t>(tiles, 4);
  while (cacheList_.size() > cacheCapacity_) {
    cacheIndex_.erase(cacheList_.back().key);
    cacheList_.pop_back();
  }
}

size_t ImageView::tileCacheBytes() const {
  size_t bytes = 0;
  for (const CachedTile& t : cacheList_) bytes += static_cast<size_t>(t.image.sizeInBytes());
  return bytes;
}

void ImageView::invalidateTiles(Layer layer) {
  for (auto it = cacheList_.begin(); it != cacheList_.end();) {
    if (it->key.layer == layer) {
      cacheIndex_.erase(it->key);
      it = cacheList_.erase(it);
    } else {
      ++it;
    }
  }
}

QImage ImageView::convertBaseTile(const cv::Mat& region, cv::Point origin) const {
  if (region.type() == CV_8UC3) {
    QImage out(region.cols, region.rows, QImage::Format_RGB888);
    for (int y = 0; y < region.rows; ++y) {
      const auto* src = region.ptr<cv::Vec3b>(y);
      uchar* dst = out.scanLine(y);
      for (int x = 0; x < region.cols; ++x) {
        dst[3 * x + 0] = src[x][2];
        dst[3 * x + 1] = src[x][1];
        dst[3 * x + 2] = src[x][0];
      }
    }
    return out;
  }
  if (region.type() == CV_8UC1 && style_.map == ColourMap::Grey && resolvedMin_ == 0.0 &&
      resolvedMax_ == 255.0) {
    QImage out(region.cols, region.rows, QImage::Format_Grayscale8);
    for (int y = 0; y < region.rows; ++y) std::copy_n(region.ptr<uchar>(y), region.cols, out.scanLine(y));
    return out;
  }
  const cv::Mat rgba = colourise(region, resolvedMin_, resolvedMax_, style_.map, origin);
  QImage out(rgba.cols, rgba.rows, QImage::Format_RGBA8888);
  for (int y = 0; y < rgba.rows; ++y) std::copy_n(rgba.ptr<uchar>(y), rgba.cols * 4, out.scanLine(y));
  return out;
}

QImage ImageView::convertOverlayTile(const cv::Mat& region, cv::Point origin) const {
  // Hatching: stripes 3 level pixels wide every 8, along the anti-diagonals of the level's grid.
  constexpr int kHatchPeriod = 8, kHatchWidth = 3;
  cv::Mat labels;
  region.convertTo(labels, CV_32S);
  QImage out(labels.cols, labels.rows, QImage::Format_ARGB32_Premultiplied);
  const QRgb hatchColour = hatch_.colour.rgb() | 0xff000000u;
  int lastLabel = 0;
  QRgb lastColour = 0;
  for (int y = 0; y < labels.rows; ++y) {
    const int* src = labels.ptr<int>(y);
    auto* dst = reinterpret_cast<QRgb*>(out.scanLine(y));
    for (int x = 0; x < labels.cols; ++x) {
      int label = src[x];
      if (hatch_.bit != 0 && (label & hatch_.bit) != 0) {
        if ((origin.x + x + origin.y + y) % kHatchPeriod < kHatchWidth) {
          dst[x] = hatchColour;
          continue;
        }
        label &= ~hatch_.bit;
      }
      if (label == 0) {
        dst[x] = 0;
        continue;
      }
      if (label != lastLabel) {
        lastLabel = label;
        lastColour = palette_(label).rgb() | 0xff000000u;
      }
      dst[x] = lastColour;
    }
  }
  return out;
}

const QImage& ImageView::tile(Layer layer, int level, int tx, int ty) {
  const TileKey key{layer, level, tx, ty};
  if (auto it = cacheIndex_.find(key); it != cacheIndex_.end()) {
    cacheList_.splice(cacheList_.begin(), cacheList_, it->second);  // mark most recently used
    return it->second->image;
  }
  const cv::Mat& source = layer == Layer::Base ? pyramid_[level] : overlayPyramid_[level];
  const cv::Rect rect = cv::Rect(tx * kTileSize, ty * kTileSize, kTileSize, kTileSize) &
                        cv::Rect(0, 0, source.cols, source.rows);
  const cv::Mat region = source(rect);  // a view, no copy
  QImage image = layer == Layer::Base ? convertBaseTile(region, rect.tl()) : convertOverlayTile(region, rect.tl());
  ++tilesConverted_;
  cacheList_.push_front(CachedTile{key, std::move(image)});
  cacheIndex_[key] = cacheList_.begin();
  while (cacheList_.size() > cacheCapacity_) {
    cacheIndex_.erase(cacheList_.back().key);
    cacheList_.pop_back();
  }
  return cacheList_.front().image;
}

int ImageView::currentLevel() const {
  if (pyramid_.empty() || zoom_ >= 1.0) return 0;
  // Level L has 2^-L of the resolution: use the finest level not magnified less than 1:1... i.e.
  // the coarsest one that still has at least one level pixel per screen pixel.
  const int level = static_cast<int>(std::floor(std::log2(1.0 / zoom_) + 1e-9));
  return std::clamp(level, 0, static_cast<int>(pyramid_.size()) - 1);
}

void ImageView::drawLayer(QPainter& painter, Layer layer, const QRectF& exposed) {
  const std::vector<cv::Mat>& levels = layer == Layer::Base ? pyramid_ : overlayPyramid_;
  if (levels.empty()) return;
  const int level = std::min(currentLevel(), static_cast<int>(levels.size()) - 1);
  const cv::Mat& source = levels[level];
  const cv::Size full = levels.front().size();
  const double sx = static_cast<double>(full.width) / source.cols;  // image px per level px
  const double sy = static_cast<double>(full.height) / source.rows;

  const QRectF imageRect = QRectF(widgetToImage(exposed.topLeft()), widgetToImage(exposed.bottomRight()))
                               .normalized()
                               .intersected(QRectF(0, 0, full.width, full.height));
  if (imageRect.isEmpty()) return;
  const int tilesX = (source.cols + kTileSize - 1) / kTileSize;
  const int tilesY = (source.rows + kTileSize - 1) / kTileSize;
  const int tx0 = std::clamp(static_cast<int>(std::floor(imageRect.left() / sx / kTileSize)), 0, tilesX - 1);
  const int tx1 = std::clamp(static_cast<int>(std::floor(imageRect.right() / sx / kTileSize)), 0, tilesX - 1);
  const int ty0 = std::clamp(static_cast<int>(std::floor(imageRect.top() / sy / kTileSize)), 0, tilesY - 1);
  const int ty1 = std::clamp(static_cast<int>(std::floor(imageRect.bottom() / sy / kTileSize)), 0, tilesY - 1);

  // Magnified pixels stay square (nearest); reductions are filtered.
  const double screenPerLevelPixel = zoom_ * sx;
  painter.setRenderHint(QPainter::SmoothPixmapTransform, screenPerLevelPixel < 1.5 && layer == Layer::Base);
  for (int ty = ty0; ty <= ty1; ++ty) {
    for (int tx = tx0; tx <= tx1; ++tx) {
      const QImage& image = tile(layer, level, tx, ty);
      const QPointF topLeft = imageToWidget(QPointF(tx * kTileSize * sx, ty * kTileSize * sy));
      const QPointF bottomRight = imageToWidget(
          QPointF((tx * kTileSize + image.width()) * sx, (ty * kTileSize + image.height()) * sy));
      painter.drawImage(QRectF(topLeft, bottomRight), image);
    }
  }
}

// --- view transform -------------------------------------------------------------------------

double ImageView::minimumZoom() const {
  const cv::Size size = imageSize();
  if (size.empty()) return 1.0 / kMaximumZoom;
  const double fit = std::min(static_cast<double>(width()) / size.width,
                              static_cast<double>(height()) / size.height);
  return std::min(1.0, std::max(fit / 4.0, 1e-4));
}

QPointF ImageView::imageToWidget(QPointF imagePos) const {
  return (imagePos - center_) * zoom_ + QPointF(width() / 2.0, height() / 2.0);
}

QPointF ImageView::widgetToImage(QPointF widgetPos) const {
  return (widgetPos - QPointF(width() / 2.0, height() / 2.0)) / zoom_ + center_;
}

QRectF ImageView::visibleImageRect() const {
  return QRectF(widgetToImage(QPointF(0, 0)), widgetToImage(QPointF(width(), height())));
}

void ImageView::setViewCenter(QPointF imagePos) { setView(imagePos, zoom_); }

void ImageView::setZoom(double zoom) { setView(center_, zoom); }

void ImageView::zoomAround(double factor, QPointF widgetAnchor) {
  const QPointF anchorImage = widgetToImage(widgetAnchor);
  const double zoom = std::clamp(zoom_ * factor, minimumZoom(), kMaximumZoom);
  // Solve for the centre that keeps anchorImage under widgetAnchor at the new zoom.
  const QPointF center = anchorImage - (widgetAnchor - QPointF(width() / 2.0, height() / 2.0)) / zoom;
  setView(center, zoom);
}

void ImageView::setView(QPointF center, double zoom) {
  // Any view asked for other than a fit ends the fitted state, even when it changes nothing.
  fitted_ = fitting_;
  const QPointF oldCenter = center_;
  const double oldZoom = zoom_;
  center_ = center;
  zoom_ = zoom;
  clampView();
  if (sameView(oldCenter, oldZoom, center_, zoom_)) return;
  update();
  emit viewChanged(center_, zoom_);
}

void ImageView::clampView() {
  if (!std::isfinite(zoom_) || zoom_ <= 0) zoom_ = 1.0;
  zoom_ = std::clamp(zoom_, minimumZoom(), kMaximumZoom);
  const cv::Size size = imageSize();
  if (size.empty()) return;
  center_.setX(std::clamp(center_.x(), 0.0, static_cast<double>(size.width)));
  center_.setY(std::clamp(center_.y(), 0.0, static_cast<double>(size.height)));
}

void ImageView::fitToWindow() {
  const cv::Size size = imageSize();
  if (size.empty()) return;
  const double fit = std::min(static_cast<double>(std::max(width(), 1)) / size.width,
                              static_cast<double>(std::max(height(), 1)) / size.height);
  fitting_ = true;
  setView(QPointF(size.width / 2.0, size.height / 2.0), fit);
  fitting_ = false;
  fitted_ = true;  // also when the view was already fitted (no change)
}

// --- painting --------------------------------------------------------------------------------

void ImageView::paintEvent(QPaintEvent*) {
  QPainter painter(this);
  painter.fillRect(rect(), QColor(48, 48, 52));
  if (pyramid_.empty()) {
    painter.setPen(QColor(190, 190, 190));
    painter.drawText(rect(), Qt::AlignCenter, tr("No image"));
    return;
  }
  const QRectF exposed(rect());
  drawLayer(painter, Layer::Base, exposed);
  if (overlayVisible_ && !overlayPyramid_.empty() && overlayOpacity_ > 0.0) {
    painter.setOpacity(overlayOpacity_);
    drawLayer(painter, Layer::Overlay, exposed);
    painter.setOpacity(1.0);
  }
  painter.setRenderHint(QPainter::Antialiasing, true);
  polygons_->paint(painter);

  // Gesture previews.
  if (rectDragging_) {
    QPen pen(QColor(255, 220, 0), 1.5, Qt::DashLine);
    painter.setPen(pen);
    painter.setBrush(QColor(255, 220, 0, 40));
    painter.drawRect(QRectF(imageToWidget(rectStartImage_), imageToWidget(rectEndImage_)).normalized());
  }
  if (mode_ == InteractionMode::PickPolygon && !pickPolygon_.isEmpty()) {
    QPolygonF shown;
    for (const QPointF& p : pickPolygon_) shown << imageToWidget(p);
    if (hoverValid_) shown << imageToWidget(hoverImage_);
    painter.setPen(QPen(QColor(255, 220, 0), 1.5, Qt::DashLine));
    painter.setBrush(QColor(255, 220, 0, 30));
    painter.drawPolygon(shown);
    painter.setBrush(QColor(255, 220, 0));
    for (const QPointF& p : pickPolygon_) painter.drawEllipse(imageToWidget(p), 3.0, 3.0);
  }
  if (mode_ == InteractionMode::PickLine && lineStart_) paintLine(painter);
}

// The line being drawn, dashed over a dark underlay so that it reads on any image.
void ImageView::paintLine(QPainter& painter) const {
  const QPointF a = imageToWidget(*lineStart_);
  const QPointF b = imageToWidget(hoverImage_);
  painter.setBrush(Qt::NoBrush);
  painter.setPen(QPen(QColor(0, 0, 0, 160), 3.5));
  painter.drawLine(a, b);
  painter.setPen(QPen(QColor(255, 220, 0), 2.0, Qt::DashLine));
  painter.drawLine(a, b);
  painter.setBrush(QColor(255, 220, 0));
  painter.drawEllipse(a, 3.0, 3.0);
}

void ImageView::resizeEvent(QResizeEvent*) {
  // A fitted view follows the widget's size: an image opened before the window has its final
  // layout still fills the view once it has.
  if (fitted_) {
    fitToWindow();
    return;
  }
  const QPointF oldCenter = center_;
  const double oldZoom = zoom_;
  clampView();
  if (!sameView(oldCenter, oldZoom, center_, zoom_)) emit viewChanged(center_, zoom_);
}

// --- interaction -----------------------------------------------------------------------------

void ImageView::setInteractionMode(InteractionMode mode) {
  if (mode == mode_) return;
  mode_ = mode;
  rectDragging_ = false;
  pickPolygon_.clear();
  lineStart_.reset();
  polygons_->clearVertexSelection();
  restoreModeCursor();
  update();
  emit interactionModeChanged(mode);
}

void ImageView::restoreModeCursor() {
  setCursor(mode_ == InteractionMode::Navigate      ? Qt::OpenHandCursor
            : mode_ == InteractionMode::EditPolygon ? Qt::ArrowCursor
            : mode_ == InteractionMode::PickOutline ? Qt::PointingHandCursor
                                                    : Qt::CrossCursor);
}

void ImageView::beginPan(QPointF widgetPos) {
  panning_ = true;
  panLastWidget_ = widgetPos;
  setCursor(Qt::ClosedHandCursor);
}

void ImageView::wheelEvent(QWheelEvent* event) {
  const double steps = event->angleDelta().y() / 120.0;
  if (steps != 0.0) zoomAround(std::pow(1.25, steps), event->position());
  event->accept();
}

void ImageView::mousePressEvent(QMouseEvent* event) {
  pressWidget_ = event->position();
  pressMoved_ = false;
  const bool panButton = event->button() == Qt::MiddleButton || event->button() == Qt::RightButton ||
                         (event->button() == Qt::LeftButton && spaceHeld_);
  if (panButton) {
    beginPan(event->position());
    return;
  }
  if (event->button() != Qt::LeftButton) return;
  const QPointF imagePos = widgetToImage(event->position());
  switch (mode_) {
    case InteractionMode::Navigate: beginPan(event->position()); break;
    case InteractionMode::PickRectangle:
      rectDragging_ = true;
      rectStartImage_ = rectEndImage_ = imagePos;
      update();
      break;
    case InteractionMode::PickPolygon:
      pickPolygon_ << imagePos;
      update();
      break;
    case InteractionMode::PickPoint: break;
    case InteractionMode::PickLine: pressLine(imagePos); break;
    case InteractionMode::PickOutline: beginPan(event->position()); break;
    case InteractionMode::EditPolygon:
      if (polygons_->mousePress(event)) return;
      beginPan(event->position());
      break;
  }
}

void ImageView::mouseMoveEvent(QMouseEvent* event) {
  const QPointF imagePos = widgetToImage(event->position());
  hoverImage_ = imagePos;
  hoverValid_ = true;
  if ((event->position() - pressWidget_).manhattanLength() > 3) pressMoved_ = true;
  emit cursorMoved(imagePos);
  if (panning_) {
    const QPointF delta = event->position() - panLastWidget_;
    panLastWidget_ = event->position();
    setViewCenter(center_ - delta / zoom_);
    return;
  }
  if (rectDragging_) {
    rectEndImage_ = imagePos;
    update();
    return;
  }
  if (mode_ == InteractionMode::EditPolygon && polygons_->mouseMove(event)) return;
  if ((mode_ == InteractionMode::PickPolygon && !pickPolygon_.isEmpty()) || lineStart_) update();
}

void ImageView::mouseReleaseEvent(QMouseEvent* event) {
  if (panning_ && (event->button() == Qt::MiddleButton || event->button() == Qt::RightButton ||
                   event->button() == Qt::LeftButton)) {
    panning_ = false;
    restoreModeCursor();
    // A click without movement on a polygon selects it (Navigate and EditPolygon modes); in
    // EditPolygon it also drops the vertex selection. PickOutline reports it instead.
    if (event->button() == Qt::LeftButton && !pressMoved_ && !spaceHeld_) {
      const int id = polygons_->polygonAt(event->position());
      if (mode_ == InteractionMode::PickOutline) {
        emit outlinePicked(id);
        return;
      }
      if (mode_ == InteractionMode::EditPolygon) polygons_->clearVertexSelection();
      if (id >= 0 || mode_ == InteractionMode::Navigate) polygons_->setSelectedId(id);
    }
    return;
  }
  if (event->button() != Qt::LeftButton) return;
  if (rectDragging_) {
    rectDragging_ = false;
    rectEndImage_ = widgetToImage(event->position());
    const cv::Size size = imageSize();
    const QRectF picked = QRectF(rectStartImage_, rectEndImage_)
                              .normalized()
                              .intersected(QRectF(0, 0, size.width, size.height));
    update();
    if (picked.width() > 0 && picked.height() > 0) emit rectanglePicked(picked);
    return;
  }
  if (mode_ == InteractionMode::PickLine) {
    releaseLine(widgetToImage(event->position()));
    return;
  }
  if (mode_ == InteractionMode::PickPoint && !pressMoved_) {
    emit pointPicked(widgetToImage(event->position()));
    return;
  }
  if (mode_ == InteractionMode::EditPolygon) polygons_->mouseRelease(event);
}

void ImageView::mouseDoubleClickEvent(QMouseEvent* event) {
  if (event->button() != Qt::LeftButton) return;
  if (mode_ == InteractionMode::PickPolygon) {
    // The first click of the double-click already added its vertex.
    if (pickPolygon_.size() >= 3) {
      const QPolygonF picked = pickPolygon_;
      pickPolygon_.clear();
      update();
      emit polygonPicked(picked);
    }
    return;
  }
  if (mode_ == InteractionMode::EditPolygon) polygons_->mouseDoubleClick(event);
}

void ImageView::pressLine(QPointF imagePos) {
  if (lineStart_) {
    finishLine(imagePos);
    return;
  }
  lineStart_ = imagePos;
  hoverImage_ = imagePos;
  update();
}

void ImageView::releaseLine(QPointF imagePos) {
  // A click leaves the line following the cursor until the next click; a drag ends it here.
  if (lineStart_ && pressMoved_) finishLine(imagePos);
}

void ImageView::finishLine(QPointF end) {
  const QPointF start = *lineStart_;
  lineStart_.reset();
  update();
  const QPointF span = imageToWidget(end) - imageToWidget(start);
  if (std::hypot(span.x(), span.y()) >= 3.0) emit linePicked(start, end);
}

void ImageView::keyPressEvent(QKeyEvent* event) {
  if (event->key() == Qt::Key_Space) {
    if (!event->isAutoRepeat()) spaceHeld_ = true;
    event->accept();
    return;
  }
  if (mode_ == InteractionMode::EditPolygon && polygons_->keyPress(event)) return;
  switch (event->key()) {
    case Qt::Key_Plus:
    case Qt::Key_Equal: zoomAround(1.25, QPointF(width() / 2.0, height() / 2.0)); return;
    case Qt::Key_Minus: zoomAround(0.8, QPointF(width() / 2.0, height() / 2.0)); return;
    case Qt::Key_Return:
    case Qt::Key_Enter:
      if (mode_ == InteractionMode::PickPolygon && pickPolygon_.size() >= 3) {
        const QPolygonF picked = pickPolygon_;
        pickPolygon_.clear();
        update();
        emit polygonPicked(picked);
        return;
      }
      break;
    case Qt::Key_Backspace:
      if (mode_ == InteractionMode::PickPolygon && !pickPolygon_.isEmpty()) {
        pickPolygon_.removeLast();
        update();
        return;
      }
      break;
    case Qt::Key_Escape:
      if (rectDragging_ || !pickPolygon_.isEmpty() || lineStart_) {
        rectDragging_ = false;
        pickPolygon_.clear();
        lineStart_.reset();
        update();
        return;
      }
      // The choice of an outline is a one-shot mode: Esc leaves it.
      if (mode_ == InteractionMode::PickOutline) {
        setInteractionMode(InteractionMode::Navigate);
        return;
      }
      break;
    default: break;
  }
  QWidget::keyPressEvent(event);
}

void ImageView::keyReleaseEvent(QKeyEvent* event) {
  if (event->key() == Qt::Key_Space && !event->isAutoRepeat()) {
    spaceHeld_ = false;
    event->accept();
    return;
  }
  QWidget::keyReleaseEvent(event);
}

void ImageView::contextMenuEvent(QContextMenuEvent* event) {
  // Right-drag pans; the menu is only for a vertex or edge of the polygon being edited.
  if (mode_ == InteractionMode::EditPolygon && polygons_->contextMenu(event)) {
    panning_ = false;
    return;
  }
  event->ignore();
}

bool ImageView::wantsKey(const QKeyEvent& event) const {
  if (mode_ == InteractionMode::EditPolygon && polygons_->wantsKey(event)) return true;
  switch (event.key()) {
    case Qt::Key_Escape:
      return rectDragging_ || !pickPolygon_.isEmpty() || lineStart_ || mode_ == InteractionMode::PickOutline;
    case Qt::Key_Backspace:
      return mode_ == InteractionMode::PickPolygon && !pickPolygon_.isEmpty();
    default:
      return false;
  }
}

bool ImageView::event(QEvent* event) {
  // Shortcuts are matched before the focused widget sees the key; accepting the override gives
  // the key to keyPressEvent instead (Delete on a hovered vertex must not remove the building).
  if (event->type() == QEvent::ShortcutOverride && wantsKey(*static_cast<QKeyEvent*>(event))) {
    event->accept();
    return true;
  }
  return QWidget::event(event);
}

void ImageView::leaveEvent(QEvent*) {
  hoverValid_ = false;
  update();
}

// ---------------------------------------------------------------------------------------------

void linkViews(ImageView* a, ImageView* b) {
  // One flag per link: while one side propagates, the echo from the other is ignored, even when
  // clamping makes the values differ slightly.
  auto busy = std::make_shared<bool>(false);
  auto forward = [busy](ImageView* target) {
    return [busy, target](QPointF center, double zoom) {
      // A target already there is left alone (a fitted view stays fitted).
      if (*busy || sameView(target->viewCenter(), target->zoom(), center, zoom)) return;
      *busy = true;
      target->setView(center, zoom);
      *busy = false;
    };
  };
  a->links_.emplace_back(b);
  b->links_.emplace_back(a);
  QObject::connect(a, &ImageView::viewChanged, b, forward(b));
  QObject::connect(b, &ImageView::viewChanged, a, forward(a));
}

}  // namespace delineo::widgets
