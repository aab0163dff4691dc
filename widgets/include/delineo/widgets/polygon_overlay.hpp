#pragma once
// Vector overlays drawn on an ImageView: building polygons (with holes), the interactive editing
// of the selected one, the "evolving contour" of a running active polygon and the ROI rectangle.
//
// The overlay never changes the model: every finished editing gesture is reported through
// editRequested() with the complete new ring (or polygonEditRequested() with all the rings when
// a gesture changes several rings or removes one), so the application can wrap it in a
// QUndoCommand and push the updated polygons back with setPolygons(). While a gesture is in
// progress a live preview is drawn instead of the stored ring.
#include <QColor>
#include <QList>
#include <QObject>
#include <QPolygonF>
#include <QRectF>
#include <QString>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"

class QPainter;
class QMouseEvent;
class QKeyEvent;
class QContextMenuEvent;
class QMenu;

namespace delineo::widgets {

class ImageView;

// Conversions between the core geometry and Qt (same pixel frame: x right, y down).
QPolygonF toQPolygon(const core::Ring& ring);
core::Ring toRing(const QPolygonF& polygon);
// rings[0] = outer, the others holes (as polygonEditRequested() reports them).
core::Polygon toPolygon(const QList<QPolygonF>& rings);

enum class PolygonStatus {
  Candidate,  // produced by the algorithm, not yet reviewed
  Accepted,   // reviewed and kept
  Rejected,   // reviewed and discarded (drawn dimmed)
  Edited,     // changed by hand
  Failed,     // the algorithm did not converge
};

// Default colour of a status (colour-blind safe choices, distinct from the colour maps).
QColor statusColour(PolygonStatus status);

struct OverlayPolygon {
  int id = 0;
  core::Polygon polygon;  // image pixels; ring 0 = outer, ring k = holes[k - 1]
  PolygonStatus status = PolygonStatus::Candidate;
  QColor colour;  // invalid = statusColour(status)
  QString label;  // drawn near the first vertex when not empty
};

// A shape drawn for reference only (another method's outline, its parts): never selected nor
// edited, drawn over the building polygons with a dark underlay so it reads on any image.
struct OverlayGuide {
  core::Polygon polygon;  // image pixels
  QColor colour;
  double width = 1.5;     // px on screen
  Qt::PenStyle style = Qt::SolidLine;
};

class PolygonOverlay : public QObject {
  Q_OBJECT
 public:
  explicit PolygonOverlay(ImageView* view);

  // --- content ---
  void setPolygons(std::vector<OverlayPolygon> polygons);
  const std::vector<OverlayPolygon>& polygons() const { return polygons_; }
  void clearPolygons();
  // Selection is view state (the edited polygon); -1 = none. Emits selectionChanged when it changes.
  void setSelectedId(int id);
  int selectedId() const { return selectedId_; }
  const OverlayPolygon* selectedPolygon() const;

  // Dashed polygon updated while an active polygon runs; empty = hidden.
  void setEvolvingContour(const QPolygonF& contour);
  void clearEvolvingContour();
  QPolygonF evolvingContour() const { return evolving_; }

  // Reference shapes (e.g. box-fitting's boxes and outline beside the building's outline).
  void setGuides(std::vector<OverlayGuide> guides);
  const std::vector<OverlayGuide>& guides() const { return guides_; }

  // The region of interest rectangle (image pixels); null rectangle = hidden.
  void setRoi(const QRectF& roi);
  QRectF roi() const { return roi_; }

  // --- snapping while dragging (each toggleable) ---
  void setSnapToRightAngles(bool enabled) { snapRightAngles_ = enabled; }
  bool snapToRightAngles() const { return snapRightAngles_; }
  // An edge makes a right angle with a neighbour when within this many degrees of 90°.
  void setRightAngleTolerance(double degrees) { rightAngleToleranceDeg_ = degrees; }
  void setSnapToEdges(bool enabled) { snapEdges_ = enabled; }
  bool snapToEdges() const { return snapEdges_; }
  // Edge strength map in image pixels (any single-channel depth, e.g. gradient magnitude or a
  // Canny mask); pixels >= threshold are "strong". The map is shared, not copied.
  void setEdgeMap(const cv::Mat& edgeStrength, double threshold);
  // Search radius for the nearest strong edge pixel, in image pixels.
  void setEdgeSnapRadius(double pixels) { edgeSnapRadius_ = pixels; }

  // Applies the enabled snaps to a dragged vertex of `ring` (index `vertex`) proposed at `pos`.
  // Exposed so the same rule can be tested and reused; edge snapping wins over right angles
  // when both apply within tolerance.
  QPointF snapVertex(const QPolygonF& ring, int vertex, QPointF pos) const;

  // True while a drag gesture is in progress (the preview is drawn).
  bool isDragging() const { return drag_.has_value(); }

  // --- vertex selection of the selected polygon (Ctrl+drag a rubber band in EditPolygon) ---
  // Vertices as (ring, index): ring 0 = outer, k = hole k-1. Cleared when the selected polygon
  // changes (another selection, or an edit of its geometry).
  const std::set<std::pair<int, int>>& selectedVertices() const { return selectedVertices_; }
  // Replaces the selection by the vertices inside `imageRect` (image pixels); returns their count.
  int selectVerticesIn(const QRectF& imageRect);
  void clearVertexSelection();
  // Removes the selected vertices as one polygonEditRequested(). A hole whose vertices are all
  // selected goes with them. Refused (editRefused(), nothing emitted, selection kept) when a
  // ring would keep fewer than 3 vertices or the polygon would cross itself.
  bool deleteSelectedVertices();
  // Removes hole `ringIndex` (>= 1) of the selected polygon as one polygonEditRequested().
  bool deleteHole(int ringIndex);
  // The rubber band being dragged, in image pixels (null when none).
  QRectF rubberBand() const;

  // Adds the editing entries for the widget position (a vertex, an edge, a hole's ring, the
  // vertex selection) to `menu`; their actions apply the edit when triggered. False when
  // nothing applies there.
  bool fillContextMenu(QMenu& menu, QPointF widgetPos);
  // True when the overlay would use this key now (Delete/Backspace with a vertex to delete,
  // Escape with a gesture or a selection to cancel): the view then claims it before the
  // window's shortcuts.
  bool wantsKey(const QKeyEvent& event) const;

  // --- used by ImageView ---
  void paint(QPainter& painter) const;
  // Returns true when the event was consumed (edit gestures on the selected polygon).
  bool mousePress(QMouseEvent* event);
  bool mouseMove(QMouseEvent* event);
  bool mouseRelease(QMouseEvent* event);
  bool mouseDoubleClick(QMouseEvent* event);
  bool keyPress(QKeyEvent* event);
  bool contextMenu(QContextMenuEvent* event);
  // Id of the polygon whose outer ring contains the widget position (topmost), or -1.
  int polygonAt(QPointF widgetPos) const;

 signals:
  // A finished gesture on polygon `id`: `newRing` replaces ring `ringIndex` (0 = outer,
  // k = hole k-1). `description` is a translated sentence for the undo stack.
  void editRequested(int id, int ringIndex, const QPolygonF& newRing, const QString& description);
  // A finished gesture that changes the ring list of polygon `id`: `rings` is the complete new
  // polygon (rings[0] outer, the others holes).
  void polygonEditRequested(int id, const QList<QPolygonF>& rings, const QString& description);
  // A gesture that was not applied, with a translated sentence saying why.
  void editRefused(const QString& reason);
  void selectionChanged(int id);
  // Emitted by the view while the overlay content changes (repaint request).
  void changed();

 private:
  struct Hit {
    int ring = -1;
    int vertex = -1;  // >= 0 when a vertex was hit
    int edge = -1;    // >= 0 when an edge (vertex, vertex+1) was hit
    QPointF imagePos;
  };
  struct Drag {
    enum class Kind { Vertex, Edge } kind;
    int ring = 0;
    int index = 0;            // vertex index or first vertex of the edge
    QPointF pressImagePos;
    QPolygonF original;
    QPolygonF preview;
  };
  QPolygonF ringOf(const OverlayPolygon& polygon, int ringIndex) const;
  std::optional<Hit> hitTest(QPointF widgetPos) const;
  void deleteVertex(int ring, int vertex);
  void insertVertex(const Hit& hit);
  QList<QPolygonF> ringsOf(const OverlayPolygon& polygon) const;
  QPointF snapToEdge(QPointF pos, bool* snapped) const;
  // The dragged ring with every edge keeping its direction (Shift held).
  QPolygonF keepingAngles(const Drag& drag, QPointF imagePos) const;
  void updateHoverCursor();

  ImageView* view_;
  std::vector<OverlayPolygon> polygons_;
  int selectedId_ = -1;
  QPolygonF evolving_;
  std::vector<OverlayGuide> guides_;
  QRectF roi_;
  bool snapRightAngles_ = true;
  double rightAngleToleranceDeg_ = 6.0;
  bool snapEdges_ = false;
  cv::Mat edgeMap_;
  double edgeThreshold_ = 1.0;
  double edgeSnapRadius_ = 3.0;
  std::optional<Drag> drag_;
  std::optional<Hit> hover_;
  std::set<std::pair<int, int>> selectedVertices_;
  std::optional<QRectF> band_;  // rubber band in image pixels (start corner, current corner)
};

}  // namespace delineo::widgets
