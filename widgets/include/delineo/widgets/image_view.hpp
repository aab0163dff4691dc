#pragma once
// A raster viewer for very large images (10000 x 10000 and more) with smooth pan and zoom.
//
// The base raster (grey 8/16-bit, float through a colour map, or BGR 8-bit colour) is shared,
// never copied: a pyramid of 2x reductions (INTER_AREA, built once per image) supplies the level
// that matches the zoom, and only the visible 256 x 256 tiles of that level are converted to
// QImage, lazily, through a bounded LRU cache. Zooming beyond 1:1 shows square pixels.
//
// Coordinates: image pixels, x right, y down, pixel (i, j) covers [i, i+1) x [j, j+1) (the same
// frame as core::Polygon). zoom = widget pixels per image pixel.
#include <QColor>
#include <QElapsedTimer>
#include <QImage>
#include <QPointF>
#include <QPointer>
#include <QPolygonF>
#include <QRectF>
#include <QWidget>
#include <cstdint>
#include <functional>
#include <limits>
#include <list>
#include <memory>
#include <optional>
#include <unordered_map>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/widgets/colour_maps.hpp"

namespace delineo::widgets {

class PolygonOverlay;

enum class InteractionMode {
  Navigate,       // drag (any button) pans, wheel zooms; a click on a polygon selects it
  PickRectangle,  // left-drag a rectangle → rectanglePicked
  PickPolygon,    // left-clicks add vertices; double-click or Enter closes → polygonPicked
  PickPoint,      // left-click → pointPicked
  EditPolygon,    // edit the selected polygon of polygons() (see PolygonOverlay)
  PickLine,       // left-drag a line, or click its two ends → linePicked; Esc drops it
  PickOutline,    // left-click a polygon of polygons() → outlinePicked; drag pans
};

// Labels of an overlay drawn hatched: those with `bit` set (0: none) show diagonal stripes of
// `colour` over the colour of the label without the bit (nothing for 0). The stripes are fixed on
// the pixels of the pyramid level drawn, so they stay 8 to 16 screen pixels apart when zoomed out.
struct OverlayHatch {
  int bit = 0;
  QColor colour;
};

// How a single-channel raster becomes colours. NaN limits = automatic (finite min/max of the
// coarsest pyramid level, cheap for any size). Ignored for 3-channel images.
struct RasterStyle {
  ColourMap map = ColourMap::Grey;
  double min = std::numeric_limits<double>::quiet_NaN();
  double max = std::numeric_limits<double>::quiet_NaN();
};

class ImageView : public QWidget {
  Q_OBJECT
 public:
  explicit ImageView(QWidget* parent = nullptr);
  ~ImageView() override;

  // --- layers ---
  // Shows `image` (CV_8UC1, CV_16UC1, CV_32FC1, CV_64FC1 or CV_8UC3 in BGR order, as OpenCV
  // reads colour). The data is shared with the caller (cv::Mat reference count), not copied.
  // Keeps the current view when the size is unchanged, otherwise fits the image to the window.
  void setImage(const cv::Mat& image, const RasterStyle& style = {});
  // The full-resolution raster shown (CV_64FC1 input is held as CV_32FC1); empty when none.
  cv::Mat image() const { return pyramid_.empty() ? cv::Mat() : pyramid_.front(); }
  void setRasterStyle(const RasterStyle& style);
  RasterStyle rasterStyle() const { return style_; }
  // The display range actually used (resolved automatic limits).
  std::pair<double, double> displayRange() const { return {resolvedMin_, resolvedMax_}; }
  void clearImage();
  bool hasImage() const { return !pyramid_.empty(); }
  cv::Size imageSize() const;

  // Label raster (CV_8U, CV_16U or CV_32S, same size as the image) drawn over the base with the
  // given opacity; label 0 is transparent. `palette` maps labels to colours (default: a fixed
  // hash palette); `hatch` marks labels drawn hatched.
  void setOverlay(const cv::Mat& labels, double opacity = 0.45,
                  std::function<QColor(int)> palette = {}, const OverlayHatch& hatch = {});
  void setOverlayOpacity(double opacity);
  void setOverlayVisible(bool visible);
  bool overlayVisible() const { return overlayVisible_; }
  void clearOverlay();

  // Polygons, evolving contour and ROI drawn over the rasters; owned by the view.
  PolygonOverlay& polygons() { return *polygons_; }
  const PolygonOverlay& polygons() const { return *polygons_; }

  // --- view transform ---
  QPointF viewCenter() const { return center_; }
  double zoom() const { return zoom_; }
  void setViewCenter(QPointF imagePos);
  void setZoom(double zoom);                            // keeps the centre
  void zoomAround(double factor, QPointF widgetAnchor);  // keeps the image point under the anchor
  void setView(QPointF center, double zoom);            // emits viewChanged once, if changed
  // Shows the whole image, centred, as large as the widget allows. The view then stays fitted
  // through resizes (a window still being laid out, a dock resized) until the view is moved or
  // zoomed some other way.
  void fitToWindow();
  bool isFitted() const { return fitted_; }
  double minimumZoom() const;  // the whole image fits in a quarter of the widget
  static constexpr double kMaximumZoom = 64.0;

  QPointF imageToWidget(QPointF imagePos) const;
  QPointF widgetToImage(QPointF widgetPos) const;
  QRectF visibleImageRect() const;  // the part of the image plane shown by the widget

  // --- interaction ---
  void setInteractionMode(InteractionMode mode);
  InteractionMode interactionMode() const { return mode_; }

  // --- tile machinery (exposed for tests and diagnostics) ---
  int pyramidLevelCount() const { return static_cast<int>(pyramid_.size()); }
  // Pyramid level drawn at the current zoom (0 = full resolution).
  int currentLevel() const;
  static constexpr int kTileSize = 256;
  size_t tileCacheSize() const { return cacheList_.size(); }
  size_t tileCacheCapacity() const { return cacheCapacity_; }
  void setTileCacheCapacity(size_t tiles);
  // Bytes held by cached QImages (bounded by capacity x 256 x 256 x 4).
  size_t tileCacheBytes() const;
  // Number of tile conversions since the image was set (cache misses).
  uint64_t tilesConverted() const { return tilesConverted_; }

 signals:
  void viewChanged(QPointF center, double zoom);
  void cursorMoved(QPointF imagePos);  // image position under the mouse
  void rectanglePicked(QRectF imageRect);
  void polygonPicked(QPolygonF imagePolygon);
  void pointPicked(QPointF imagePos);
  // A line drawn in PickLine mode (image pixels), at least 3 widget px long.
  void linePicked(QPointF from, QPointF to);
  // The polygon clicked in PickOutline mode (-1: the click hit none).
  void outlinePicked(int id);
  void interactionModeChanged(delineo::widgets::InteractionMode mode);

 protected:
  void paintEvent(QPaintEvent* event) override;
  void resizeEvent(QResizeEvent* event) override;
  void wheelEvent(QWheelEvent* event) override;
  void mousePressEvent(QMouseEvent* event) override;
  void mouseMoveEvent(QMouseEvent* event) override;
  void mouseReleaseEvent(QMouseEvent* event) override;
  void mouseDoubleClickEvent(QMouseEvent* event) override;
  void keyPressEvent(QKeyEvent* event) override;
  void keyReleaseEvent(QKeyEvent* event) override;
  void contextMenuEvent(QContextMenuEvent* event) override;
  void leaveEvent(QEvent* event) override;
  bool event(QEvent* event) override;

 private:
  friend void linkViews(ImageView* a, ImageView* b);
  enum class Layer : uint8_t { Base = 0, Overlay = 1 };
  struct TileKey {
    Layer layer;
    int level;
    int tx;
    int ty;
    bool operator==(const TileKey&) const = default;
  };
  struct TileKeyHash {
    size_t operator()(const TileKey& k) const noexcept;
  };
  struct CachedTile {
    TileKey key;
    QImage image;
  };

  static std::vector<cv::Mat> buildPyramid(const cv::Mat& level0, bool nearest);
  const QImage& tile(Layer layer, int level, int tx, int ty);
  QImage convertBaseTile(const cv::Mat& region, cv::Point origin) const;
  QImage convertOverlayTile(const cv::Mat& region, cv::Point origin) const;
  void drawLayer(QPainter& painter, Layer layer, const QRectF& exposed);
  void invalidateTiles(Layer layer);
  void clampView();
  void beginPan(QPointF widgetPos);
  void restoreModeCursor();
  // True when the view has a use for this key now (a gesture to cancel, a vertex to delete), so
  // it takes precedence over a window shortcut on the same key.
  bool wantsKey(const QKeyEvent& event) const;
  // PickLine: a press starts the line or, after a click, ends it; a release after a drag ends it.
  void pressLine(QPointF imagePos);
  void releaseLine(QPointF imagePos);
  void finishLine(QPointF end);  // linePicked when long enough; the line is dropped either way
  void paintLine(QPainter& painter) const;

  std::vector<cv::Mat> pyramid_;
  std::vector<cv::Mat> overlayPyramid_;
  RasterStyle style_;
  double resolvedMin_ = 0.0;
  double resolvedMax_ = 1.0;
  double overlayOpacity_ = 0.45;
  bool overlayVisible_ = true;
  std::function<QColor(int)> palette_;
  OverlayHatch hatch_;

  std::list<CachedTile> cacheList_;  // most recently used first
  std::unordered_map<TileKey, std::list<CachedTile>::iterator, TileKeyHash> cacheIndex_;
  size_t cacheCapacity_ = 192;
  uint64_t tilesConverted_ = 0;

  QPointF center_{0, 0};
  double zoom_ = 1.0;
  bool fitted_ = false;   // the last view change was a fit: refit on resize
  bool fitting_ = false;  // inside fitToWindow()
  InteractionMode mode_ = InteractionMode::Navigate;
  std::unique_ptr<PolygonOverlay> polygons_;
  std::vector<QPointer<ImageView>> links_;  // views showing the same place (linkViews)

  // gesture state
  bool panning_ = false;
  QPointF panLastWidget_;
  bool spaceHeld_ = false;
  bool rectDragging_ = false;
  QPointF rectStartImage_;
  QPointF rectEndImage_;
  QPolygonF pickPolygon_;
  std::optional<QPointF> lineStart_;  // PickLine: the line being drawn, from here to hoverImage_
  QPointF hoverImage_;
  bool hoverValid_ = false;
  QPointF pressWidget_;
  bool pressMoved_ = false;
};

// Keeps the centres and zooms of two views equal in both directions, without feedback loops.
// The link lasts as long as both views exist. A linked view given its first image (or one of a
// new size) takes the view of a partner showing an image of that size instead of fitting its
// own widget, so a hidden dock's view never moves the visible one.
void linkViews(ImageView* a, ImageView* b);

}  // namespace delineo::widgets
