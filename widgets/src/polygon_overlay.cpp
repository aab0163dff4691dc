#include "delineo/widgets/polygon_overlay.hpp"

#include "delineo/core/error.hpp"

#include <QContextMenuEvent>
#include <QKeyEvent>
#include <QMenu>
#include <QMouseEvent>
#include <QPainter>
#include <QPainterPath>
#include <algorithm>
#include <cmath>

#include <opencv2/core.hpp>

#include "delineo/widgets/image_view.hpp"

namespace delineo::widgets {
namespace {

constexpr double kVertexHitPx = 7.0;  // widget pixels
constexpr double kEdgeHitPx = 5.0;

double dot(QPointF a, QPointF b) { return a.x() * b.x() + a.y() * b.y(); }
double length(QPointF a) { return std::hypot(a.x(), a.y()); }

// Distance from p to segment [a, b] and the parameter t of the closest point.
double segmentDistance(QPointF p, QPointF a, QPointF b, double* t) {
  const QPointF ab = b - a;
  const double len2 = dot(ab, ab);
  double s = len2 > 0 ? dot(p - a, ab) / len2 : 0.0;
  s = std::clamp(s, 0.0, 1.0);
  if (t != nullptr) *t = s;
  return length(p - (a + ab * s));
}

// Angle between two vectors in degrees, in [0, 180].
double angleBetween(QPointF u, QPointF w) {
  const double lu = length(u);
  const double lw = length(w);
  if (lu < 1e-12 || lw < 1e-12) return 0.0;
  return std::acos(std::clamp(dot(u, w) / (lu * lw), -1.0, 1.0)) * 180.0 / M_PI;
}

// Projection of p onto the line through `origin` with direction `dir`.
QPointF projectOntoLine(QPointF p, QPointF origin, QPointF dir) {
  const double d2 = dot(dir, dir);
  if (d2 < 1e-24) return p;
  return origin + dir * (dot(p - origin, dir) / d2);
}

bool intersectLines(QPointF p, QPointF d, QPointF q, QPointF e, QPointF* out) {
  const double cross = d.x() * e.y() - d.y() * e.x();
  if (std::abs(cross) < 1e-9 * length(d) * length(e)) return false;
  const QPointF w = q - p;
  const double s = (w.x() * e.y() - w.y() * e.x()) / cross;
  *out = p + d * s;
  return true;
}

QPointF perpendicular(QPointF v) { return {-v.y(), v.x()}; }

// True when an edge of ring `a` meets an edge of ring `b` (two rings of one polygon must not).
bool ringsMeet(const QPolygonF& a, const QPolygonF& b) {
  for (int i = 0; i < a.size(); ++i) {
    const cv::Point2d p1(a[i].x(), a[i].y());
    const cv::Point2d p2(a[(i + 1) % a.size()].x(), a[(i + 1) % a.size()].y());
    for (int j = 0; j < b.size(); ++j) {
      const cv::Point2d p3(b[j].x(), b[j].y());
      const cv::Point2d p4(b[(j + 1) % b.size()].x(), b[(j + 1) % b.size()].y());
      if (core::segmentsIntersect(p1, p2, p3, p4)) return true;
    }
  }
  return false;
}

// A valid polygon: every ring simple, no two rings meeting, every hole inside the outer ring.
bool validRings(const QList<QPolygonF>& rings) {
  for (const QPolygonF& ring : rings) {
    if (!core::isSimple(toRing(ring))) return false;
  }
  for (int r = 1; r < rings.size(); ++r) {
    if (!rings[0].containsPoint(rings[r].first(), Qt::OddEvenFill)) return false;
    for (int k = 0; k < r; ++k) {
      if (ringsMeet(rings[r], rings[k])) return false;
    }
  }
  return true;
}

}  // namespace

QPolygonF toQPolygon(const core::Ring& ring) {
  QPolygonF out;
  out.reserve(static_cast<qsizetype>(ring.size()));
  for (const cv::Point2d& p : ring) out << QPointF(p.x, p.y);
  return out;
}

core::Ring toRing(const QPolygonF& polygon) {
  core::Ring out;
  out.reserve(static_cast<size_t>(polygon.size()));
  for (const QPointF& p : polygon) out.emplace_back(p.x(), p.y());
  // QPolygonF may repeat the first point to close itself; core rings are implicitly closed.
  if (out.size() > 1 && out.front() == out.back()) out.pop_back();
  return out;
}

core::Polygon toPolygon(const QList<QPolygonF>& rings) {
  core::Polygon out;
  if (rings.isEmpty()) return out;
  out.outer = toRing(rings.first());
  for (qsizetype k = 1; k < rings.size(); ++k) out.holes.push_back(toRing(rings[k]));
  return out;
}

QColor statusColour(PolygonStatus status) {
  switch (status) {
    case PolygonStatus::Candidate: return QColor(0, 200, 255);    // cyan
    case PolygonStatus::Accepted: return QColor(40, 220, 90);     // green
    case PolygonStatus::Rejected: return QColor(150, 150, 150);   // grey
    case PolygonStatus::Edited: return QColor(255, 170, 0);       // orange
    case PolygonStatus::Failed: return QColor(235, 60, 60);       // red
  }
  return QColor(0, 200, 255);
}

PolygonOverlay::PolygonOverlay(ImageView* view) : QObject(view), view_(view) {}

void PolygonOverlay::setPolygons(std::vector<OverlayPolygon> polygons) {
  const OverlayPolygon* before = selectedPolygon();
  const QList<QPolygonF> ringsBefore = before != nullptr ? ringsOf(*before) : QList<QPolygonF>();
  polygons_ = std::move(polygons);
  drag_.reset();
  hover_.reset();
  band_.reset();
  const OverlayPolygon* after = selectedPolygon();
  // Vertex indices only mean something on the same geometry.
  if (after == nullptr || ringsOf(*after) != ringsBefore) selectedVertices_.clear();
  if (selectedId_ >= 0 && after == nullptr) {
    selectedId_ = -1;
    emit selectionChanged(-1);
  }
  emit changed();
}

void PolygonOverlay::clearPolygons() { setPolygons({}); }

void PolygonOverlay::setSelectedId(int id) {
  if (id == selectedId_) return;
  selectedId_ = id;
  drag_.reset();
  hover_.reset();
  band_.reset();
  selectedVertices_.clear();
  emit selectionChanged(id);
  emit changed();
}

const OverlayPolygon* PolygonOverlay::selectedPolygon() const {
  for (const OverlayPolygon& p : polygons_) {
    if (p.id == selectedId_) return &p;
  }
  return nullptr;
}

void PolygonOverlay::setEvolvingContour(const QPolygonF& contour) {
  evolving_ = contour;
  emit changed();
}

void PolygonOverlay::clearEvolvingContour() { setEvolvingContour({}); }

void PolygonOverlay::setGuides(std::vector<OverlayGuide> guides) {
  guides_ = std::move(guides);
  emit changed();
}

void PolygonOverlay::setRoi(const QRectF& roi) {
  roi_ = roi;
  emit changed();
}

void PolygonOverlay::setEdgeMap(const cv::Mat& edgeStrength, double threshold) {
  CV_Assert(edgeStrength.empty() || edgeStrength.channels() == 1);
  if (edgeStrength.empty() || edgeStrength.depth() == CV_32F) {
    edgeMap_ = edgeStrength;
  } else {
    edgeStrength.convertTo(edgeMap_, CV_32F);
  }
  edgeThreshold_ = threshold;
}

QPolygonF PolygonOverlay::ringOf(const OverlayPolygon& polygon, int ringIndex) const {
  if (drag_ && polygon.id == selectedId_ && drag_->ring == ringIndex) return drag_->preview;
  if (ringIndex == 0) return toQPolygon(polygon.polygon.outer);
  const size_t hole = static_cast<size_t>(ringIndex - 1);
  return hole < polygon.polygon.holes.size() ? toQPolygon(polygon.polygon.holes[hole]) : QPolygonF();
}

QList<QPolygonF> PolygonOverlay::ringsOf(const OverlayPolygon& polygon) const {
  QList<QPolygonF> rings{toQPolygon(polygon.polygon.outer)};
  for (const core::Ring& hole : polygon.polygon.holes) rings << toQPolygon(hole);
  return rings;
}

// --- snapping --------------------------------------------------------------------------------

QPointF PolygonOverlay::snapToEdge(QPointF pos, bool* snapped) const {
  *snapped = false;
  if (edgeMap_.empty()) return pos;
  const int r = static_cast<int>(std::ceil(edgeSnapRadius_));
  const int cx = static_cast<int>(std::floor(pos.x()));
  const int cy = static_cast<int>(std::floor(pos.y()));
  double best = edgeSnapRadius_ * edgeSnapRadius_ + 1e-9;
  QPointF bestPos = pos;
  for (int y = std::max(cy - r, 0); y <= std::min(cy + r, edgeMap_.rows - 1); ++y) {
    const float* row = edgeMap_.ptr<float>(y);
    for (int x = std::max(cx - r, 0); x <= std::min(cx + r, edgeMap_.cols - 1); ++x) {
      if (!(row[x] >= edgeThreshold_)) continue;
      const QPointF centre(x + 0.5, y + 0.5);
      const QPointF d = centre - pos;
      const double d2 = dot(d, d);
      if (d2 < best) {
        best = d2;
        bestPos = centre;
        *snapped = true;
      }
    }
  }
  return bestPos;
}

QPointF PolygonOverlay::snapVertex(const QPolygonF& ring, int vertex, QPointF pos) const {
  const int n = static_cast<int>(ring.size());
  if (snapEdges_) {
    bool snapped = false;
    const QPointF onEdge = snapToEdge(pos, &snapped);
    if (snapped) return onEdge;
  }
  if (!snapRightAngles_ || n < 3) return pos;
  auto at = [&](int i) { return ring[((i % n) + n) % n]; };
  const QPointF prev = at(vertex - 1);
  const QPointF next = at(vertex + 1);
  const double tol = rightAngleToleranceDeg_;

  // Right angle at the previous vertex: pos on the line through prev perpendicular to the edge
  // arriving there. Likewise at the next vertex. Both → their intersection (a rectangle corner).
  bool havePrevLine = false;
  bool haveNextLine = false;
  QPointF prevDir;
  QPointF nextDir;
  if (n >= 4) {
    const QPointF prevEdge = prev - at(vertex - 2);
    if (std::abs(angleBetween(at(vertex - 2) - prev, pos - prev) - 90.0) <= tol) {
      havePrevLine = true;
      prevDir = perpendicular(prevEdge);
    }
    const QPointF nextEdge = at(vertex + 2) - next;
    if (std::abs(angleBetween(at(vertex + 2) - next, pos - next) - 90.0) <= tol) {
      haveNextLine = true;
      nextDir = perpendicular(nextEdge);
    }
  }
  if (havePrevLine && haveNextLine) {
    QPointF corner;
    if (intersectLines(prev, prevDir, next, nextDir, &corner)) return corner;
  }
  if (havePrevLine) return projectOntoLine(pos, prev, prevDir);
  if (haveNextLine) return projectOntoLine(pos, next, nextDir);

  // Right angle at the vertex itself: pos on the circle whose diameter is prev-next (Thales).
  if (std::abs(angleBetween(prev - pos, next - pos) - 90.0) <= tol) {
    const QPointF centre = (prev + next) / 2.0;
    const double radius = length(next - prev) / 2.0;
    const QPointF d = pos - centre;
    const double dl = length(d);
    if (dl > 1e-12) return centre + d * (radius / dl);
  }
  return pos;
}

// --- hit testing -----------------------------------------------------------------------------

std::optional<PolygonOverlay::Hit> PolygonOverlay::hitTest(QPointF widgetPos) const {
  const OverlayPolygon* selected = selectedPolygon();
  if (selected == nullptr) return std::nullopt;
  const int rings = 1 + static_cast<int>(selected->polygon.holes.size());
  std::optional<Hit> best;
  double bestVertex = kVertexHitPx;
  for (int r = 0; r < rings; ++r) {
    const QPolygonF ring = ringOf(*selected, r);
    for (int i = 0; i < ring.size(); ++i) {
      const double d = length(view_->imageToWidget(ring[i]) - widgetPos);
      if (d <= bestVertex) {
        bestVertex = d;
        best = Hit{r, i, -1, view_->widgetToImage(widgetPos)};
      }
    }
  }
  if (best) return best;
  double bestEdge = kEdgeHitPx;
  for (int r = 0; r < rings; ++r) {
    const QPolygonF ring = ringOf(*selected, r);
    const int n = static_cast<int>(ring.size());
    for (int i = 0; i < n; ++i) {
      double t = 0;
      const double d = segmentDistance(widgetPos, view_->imageToWidget(ring[i]),
                                       view_->imageToWidget(ring[(i + 1) % n]), &t);
      if (d <= bestEdge) {
        bestEdge = d;
        best = Hit{r, -1, i, view_->widgetToImage(widgetPos)};
      }
    }
  }
  return best;
}

int PolygonOverlay::polygonAt(QPointF widgetPos) const {
  const QPointF p = view_->widgetToImage(widgetPos);
  for (auto it = polygons_.rbegin(); it != polygons_.rend(); ++it) {
    if (!toQPolygon(it->polygon.outer).containsPoint(p, Qt::OddEvenFill)) continue;
    const bool inHole = std::any_of(it->polygon.holes.begin(), it->polygon.holes.end(), [&](const core::Ring& h) {
      return toQPolygon(h).containsPoint(p, Qt::OddEvenFill);
    });
    if (!inHole) return it->id;
  }
  return -1;
}

// --- gestures --------------------------------------------------------------------------------

bool PolygonOverlay::mousePress(QMouseEvent* event) {
  if (event->button() != Qt::LeftButton) return false;
  const OverlayPolygon* selected = selectedPolygon();
  if (selected == nullptr) return false;
  const QPointF imagePos = view_->widgetToImage(event->position());
  if (event->modifiers() & Qt::ControlModifier) {
    // Ctrl: a rubber band selects vertices (a Ctrl+click toggles the vertex under the cursor).
    band_ = QRectF(imagePos, imagePos);
    emit changed();
    return true;
  }
  const std::optional<Hit> hit = hitTest(event->position());
  if (!hit) return false;
  // A vertex moves alone; an edge (highlighted under the cursor) moves with both its vertices.
  const QPolygonF ring = ringOf(*selected, hit->ring);
  const Drag::Kind kind = hit->vertex >= 0 ? Drag::Kind::Vertex : Drag::Kind::Edge;
  drag_ =
      Drag{kind, hit->ring, hit->vertex >= 0 ? hit->vertex : hit->edge, hit->imagePos, ring, ring};
  hover_ = hit;
  emit changed();
  return true;
}

bool PolygonOverlay::mouseMove(QMouseEvent* event) {
  const QPointF imagePos = view_->widgetToImage(event->position());
  if (band_) {
    band_->setBottomRight(imagePos);
    emit changed();
    return true;
  }
  if (!drag_) {
    const std::optional<Hit> hit = hitTest(event->position());
    const bool hoverChanged = hit.has_value() != hover_.has_value() ||
                              (hit && (hit->vertex != hover_->vertex || hit->edge != hover_->edge ||
                                       hit->ring != hover_->ring));
    hover_ = hit;
    if (hoverChanged) {
      updateHoverCursor();
      emit changed();
    }
    return false;
  }
  Drag& d = *drag_;
  const int n = static_cast<int>(d.original.size());
  d.preview = d.original;
  if (event->modifiers() & Qt::ShiftModifier) {
    // Shift keeps every edge's direction: the neighbours slide along the edges beyond them.
    d.preview = keepingAngles(d, imagePos);
  } else if (d.kind == Drag::Kind::Vertex) {
    d.preview[d.index] = snapVertex(d.original, d.index, imagePos);
  } else {
    const int j = (d.index + 1) % n;
    QPointF delta = imagePos - d.pressImagePos;
    const QPointF along = d.original[j] - d.original[d.index];
    const QPointF normal = perpendicular(along);
    if (snapRightAngles_) {
      // Moving along the normal keeps the edge parallel to itself and its neighbours' angles.
      delta = projectOntoLine(delta, QPointF(0, 0), normal);
    }
    if (snapEdges_) {
      bool snapped = false;
      const QPointF mid = (d.original[d.index] + d.original[j]) / 2.0 + delta;
      const QPointF onEdge = snapToEdge(mid, &snapped);
      if (snapped) delta += projectOntoLine(onEdge - mid, QPointF(0, 0), normal);
    }
    d.preview[d.index] = d.original[d.index] + delta;
    d.preview[j] = d.original[j] + delta;
  }
  emit changed();
  return true;
}

QPolygonF PolygonOverlay::keepingAngles(const Drag& d, QPointF imagePos) const {
  const core::Ring ring = toRing(d.original);
  try {
    if (d.kind == Drag::Kind::Vertex) {
      if (ring.size() < 4) return d.original;  // a triangle has no angle-keeping move
      return toQPolygon(core::moveCornerKeepingAngles(ring, d.index, {imagePos.x(), imagePos.y()}));
    }
    const int j = (d.index + 1) % static_cast<int>(d.original.size());
    const QPointF along = d.original[j] - d.original[d.index];
    const double length = std::hypot(along.x(), along.y());
    if (length < 1e-9) return d.original;
    // Offset along the edge's left normal (y down), as moveEdgeKeepingAngles takes it.
    const QPointF delta = imagePos - d.pressImagePos;
    const double offset = (delta.x() * along.y() - delta.y() * along.x()) / length;
    return toQPolygon(core::moveEdgeKeepingAngles(ring, d.index, offset));
  } catch (const core::Error&) {
    return d.original;
  }
}

bool PolygonOverlay::mouseRelease(QMouseEvent* event) {
  if (event->button() != Qt::LeftButton) return false;
  if (band_) {
    band_->setBottomRight(view_->widgetToImage(event->position()));
    const QRectF band = band_->normalized();
    band_.reset();
    const double widgetSize = std::max(band.width(), band.height()) * view_->zoom();
    if (widgetSize < 3.0) {
      // A Ctrl+click: toggle the vertex under the cursor (or clear the selection).
      const std::optional<Hit> hit = hitTest(event->position());
      if (hit && hit->vertex >= 0) {
        const std::pair<int, int> key{hit->ring, hit->vertex};
        if (!selectedVertices_.erase(key)) selectedVertices_.insert(key);
      } else {
        selectedVertices_.clear();
      }
      emit changed();
    } else {
      selectVerticesIn(band);
    }
    return true;
  }
  if (!drag_) return false;
  mouseMove(event);  // the release position is the final one
  const Drag d = *drag_;
  drag_.reset();
  emit changed();
  if (d.preview != d.original) {
    emit editRequested(selectedId_, d.ring, d.preview,
                       d.kind == Drag::Kind::Vertex ? tr("Move vertex") : tr("Move edge"));
  }
  return true;
}

void PolygonOverlay::updateHoverCursor() {
  // Over a vertex or an edge of the edited polygon a drag moves it, elsewhere it pans.
  if (view_->interactionMode() != InteractionMode::EditPolygon) return;
  view_->setCursor(hover_ ? Qt::SizeAllCursor : Qt::ArrowCursor);
}

bool PolygonOverlay::mouseDoubleClick(QMouseEvent* event) {
  if (event->button() != Qt::LeftButton) return false;
  const std::optional<Hit> hit = hitTest(event->position());
  if (selectedPolygon() == nullptr || !hit || hit->edge < 0) return false;
  drag_.reset();
  insertVertex(*hit);
  return true;
}

void PolygonOverlay::insertVertex(const Hit& hit) {
  const OverlayPolygon* selected = selectedPolygon();
  if (selected == nullptr || hit.edge < 0) return;
  QPolygonF ring = ringOf(*selected, hit.ring);
  const int n = static_cast<int>(ring.size());
  const QPointF a = ring[hit.edge];
  const QPointF b = ring[(hit.edge + 1) % n];
  double t = 0.5;
  segmentDistance(hit.imagePos, a, b, &t);
  ring.insert(hit.edge + 1, a + (b - a) * t);
  emit editRequested(selectedId_, hit.ring, ring, tr("Insert vertex"));
}

void PolygonOverlay::deleteVertex(int ringIndex, int vertex) {
  const OverlayPolygon* selected = selectedPolygon();
  if (selected == nullptr) return;
  QPolygonF ring = ringOf(*selected, ringIndex);
  if (ring.size() <= 3 || vertex < 0 || vertex >= ring.size()) return;  // keep a valid polygon
  ring.remove(vertex);
  hover_.reset();
  emit editRequested(selectedId_, ringIndex, ring, tr("Delete vertex"));
}

int PolygonOverlay::selectVerticesIn(const QRectF& imageRect) {
  selectedVertices_.clear();
  if (const OverlayPolygon* selected = selectedPolygon()) {
    const QList<QPolygonF> rings = ringsOf(*selected);
    for (int r = 0; r < rings.size(); ++r) {
      for (int i = 0; i < rings[r].size(); ++i) {
        if (imageRect.contains(rings[r][i])) selectedVertices_.insert({r, i});
      }
    }
  }
  emit changed();
  return static_cast<int>(selectedVertices_.size());
}

void PolygonOverlay::clearVertexSelection() {
  if (selectedVertices_.empty() && !band_) return;
  selectedVertices_.clear();
  band_.reset();
  emit changed();
}

QRectF PolygonOverlay::rubberBand() const {
  return band_ ? band_->normalized() : QRectF();
}

bool PolygonOverlay::deleteSelectedVertices() {
  const OverlayPolygon* selected = selectedPolygon();
  if (selected == nullptr || selectedVertices_.empty()) return false;
  const QList<QPolygonF> before = ringsOf(*selected);
  QList<QPolygonF> after;
  for (int r = 0; r < before.size(); ++r) {
    QPolygonF ring;
    for (int i = 0; i < before[r].size(); ++i) {
      if (!selectedVertices_.count({r, i})) ring << before[r][i];
    }
    if (r > 0 && ring.isEmpty()) continue;  // a hole selected whole goes with its vertices
    if (ring.size() < 3) {
      emit editRefused(
          r == 0 ? tr("The outline would keep fewer than 3 vertices; select fewer vertices.")
                 : tr("A hole would keep fewer than 3 vertices; select all of it to delete it, "
                      "or fewer of its vertices."));
      return false;
    }
    after << ring;
  }
  if (!validRings(after)) {
    emit editRefused(
        tr("Deleting these vertices would make the outline cross itself; nothing was deleted."));
    return false;
  }
  const int count = static_cast<int>(selectedVertices_.size());
  selectedVertices_.clear();
  hover_.reset();
  emit changed();
  emit polygonEditRequested(
      selectedId_, after,
      count == 1 ? tr("Delete vertex") : tr("Delete %n vertices", nullptr, count));
  return true;
}

bool PolygonOverlay::deleteHole(int ringIndex) {
  const OverlayPolygon* selected = selectedPolygon();
  if (selected == nullptr || ringIndex < 1 ||
      ringIndex > static_cast<int>(selected->polygon.holes.size())) {
    return false;
  }
  QList<QPolygonF> rings = ringsOf(*selected);
  rings.removeAt(ringIndex);
  selectedVertices_.clear();
  hover_.reset();
  emit polygonEditRequested(selectedId_, rings, tr("Delete hole"));
  return true;
}

bool PolygonOverlay::wantsKey(const QKeyEvent& event) const {
  switch (event.key()) {
    case Qt::Key_Escape:
      return drag_.has_value() || band_.has_value() || !selectedVertices_.empty();
    case Qt::Key_Delete:
    case Qt::Key_Backspace:
      return !drag_ && selectedPolygon() != nullptr &&
             (!selectedVertices_.empty() || (hover_ && hover_->vertex >= 0));
    default:
      return false;
  }
}

bool PolygonOverlay::keyPress(QKeyEvent* event) {
  if (event->key() == Qt::Key_Escape && (drag_ || band_ || !selectedVertices_.empty())) {
    // One gesture back: a drag, else the rubber band, else the selection.
    if (drag_)
      drag_.reset();
    else if (band_)
      band_.reset();
    else
      selectedVertices_.clear();
    emit changed();
    return true;
  }
  if ((event->key() == Qt::Key_Delete || event->key() == Qt::Key_Backspace) && !drag_) {
    if (!selectedVertices_.empty()) {
      deleteSelectedVertices();
      return true;
    }
    if (hover_ && hover_->vertex >= 0) {
      deleteVertex(hover_->ring, hover_->vertex);
      return true;
    }
  }
  return false;
}

bool PolygonOverlay::fillContextMenu(QMenu& menu, QPointF widgetPos) {
  const OverlayPolygon* selected = selectedPolygon();
  const std::optional<Hit> hit = hitTest(widgetPos);
  if (selected == nullptr || !hit) return false;
  const Hit at = *hit;
  if (at.vertex >= 0) {
    QAction* del = menu.addAction(tr("Delete vertex"));
    del->setEnabled(ringOf(*selected, at.ring).size() > 3);
    connect(del, &QAction::triggered, this, [this, at] { deleteVertex(at.ring, at.vertex); });
  } else {
    connect(menu.addAction(tr("Insert vertex here")), &QAction::triggered, this,
            [this, at] { insertVertex(at); });
  }
  if (!selectedVertices_.empty()) {
    const int count = static_cast<int>(selectedVertices_.size());
    const QString text = count == 1 ? tr("Delete the selected vertex")
                                    : tr("Delete %n selected vertices", nullptr, count);
    connect(menu.addAction(text), &QAction::triggered, this, [this] { deleteSelectedVertices(); });
  }
  if (at.ring >= 1) {
    menu.addSeparator();
    connect(menu.addAction(tr("Delete hole")), &QAction::triggered, this,
            [this, at] { deleteHole(at.ring); });
  }
  return true;
}

bool PolygonOverlay::contextMenu(QContextMenuEvent* event) {
  QMenu menu(view_);
  if (!fillContextMenu(menu, event->pos())) return false;
  menu.exec(event->globalPos());
  return true;
}

// --- painting --------------------------------------------------------------------------------

void PolygonOverlay::paint(QPainter& painter) const {
  auto toWidget = [&](const QPolygonF& ring) {
    QPolygonF out;
    out.reserve(ring.size());
    for (const QPointF& p : ring) out << view_->imageToWidget(p);
    return out;
  };

  if (!roi_.isNull()) {
    painter.setBrush(Qt::NoBrush);
    painter.setPen(QPen(QColor(255, 255, 255), 1.0, Qt::SolidLine));
    const QRectF r(view_->imageToWidget(roi_.topLeft()), view_->imageToWidget(roi_.bottomRight()));
    painter.drawRect(r);
    painter.setPen(QPen(QColor(255, 200, 0), 1.0, Qt::DashLine));
    painter.drawRect(r);
  }

  for (const OverlayPolygon& polygon : polygons_) {
    const bool selected = polygon.id == selectedId_;
    QColor colour = polygon.colour.isValid() ? polygon.colour : statusColour(polygon.status);
    QPainterPath path;
    path.setFillRule(Qt::OddEvenFill);
    const int rings = 1 + static_cast<int>(polygon.polygon.holes.size());
    for (int r = 0; r < rings; ++r) {
      const QPolygonF ring = toWidget(ringOf(polygon, r));
      if (ring.size() < 2) continue;
      path.addPolygon(ring);
      path.closeSubpath();
    }
    QColor fill = colour;
    fill.setAlpha(selected ? 60 : 35);
    QPen pen(colour, selected ? 2.5 : 1.5);
    if (polygon.status == PolygonStatus::Rejected) pen.setStyle(Qt::DashLine);
    painter.setPen(pen);
    painter.setBrush(fill);
    painter.drawPath(path);
    if (!polygon.label.isEmpty() && !polygon.polygon.outer.empty()) {
      painter.setPen(colour);
      const QPointF at = view_->imageToWidget(QPointF(polygon.polygon.outer[0].x, polygon.polygon.outer[0].y));
      painter.drawText(at + QPointF(4, -4), polygon.label);
    }
    if (selected && view_->interactionMode() == InteractionMode::EditPolygon) {
      for (int r = 0; r < rings; ++r) {
        const QPolygonF ring = toWidget(ringOf(polygon, r));
        for (int i = 0; i < ring.size(); ++i) {
          const bool hot = (hover_ && hover_->ring == r && hover_->vertex == i) ||
                           (drag_ && drag_->kind == Drag::Kind::Vertex && drag_->ring == r && drag_->index == i);
          // Selected vertices (rubber band) are larger and red, so a deletion shows what it takes.
          const bool picked = selectedVertices_.count({r, i}) > 0;
          painter.setPen(QPen(Qt::black, 1.0));
          painter.setBrush(hot      ? QColor(255, 255, 0)
                           : picked ? QColor(255, 40, 40)
                                    : QColor(255, 255, 255));
          const double s = picked ? 5.0 : hot ? 4.5 : 3.5;
          painter.drawRect(QRectF(ring[i] - QPointF(s, s), ring[i] + QPointF(s, s)));
        }
        const bool edgeHot = (hover_ && hover_->ring == r && hover_->edge >= 0) ||
                             (drag_ && drag_->kind == Drag::Kind::Edge && drag_->ring == r);
        if (edgeHot && ring.size() >= 2) {
          const int e = drag_ ? drag_->index : hover_->edge;
          painter.setPen(QPen(QColor(255, 255, 0), 3.0));
          painter.drawLine(ring[e], ring[(e + 1) % ring.size()]);
        }
      }
    }
  }

  for (const OverlayGuide& guide : guides_) {
    QPainterPath path;
    path.setFillRule(Qt::OddEvenFill);
    path.addPolygon(toWidget(toQPolygon(guide.polygon.outer)));
    path.closeSubpath();
    for (const core::Ring& hole : guide.polygon.holes) {
      path.addPolygon(toWidget(toQPolygon(hole)));
      path.closeSubpath();
    }
    painter.setBrush(Qt::NoBrush);
    painter.setPen(QPen(QColor(0, 0, 0, 160), guide.width + 1.5));
    painter.drawPath(path);
    painter.setPen(QPen(guide.colour, guide.width, guide.style));
    painter.drawPath(path);
  }

  if (band_) {
    const QRectF band = band_->normalized();
    painter.setBrush(QColor(255, 40, 40, 30));
    painter.setPen(QPen(QColor(255, 40, 40), 1.5, Qt::DashLine));
    painter.drawRect(
        QRectF(view_->imageToWidget(band.topLeft()), view_->imageToWidget(band.bottomRight())));
  }

  if (evolving_.size() >= 2) {
    const QPolygonF ring = toWidget(evolving_);
    painter.setBrush(Qt::NoBrush);
    painter.setPen(QPen(QColor(0, 0, 0), 2.5));
    painter.drawPolygon(ring);
    painter.setPen(QPen(QColor(255, 60, 200), 2.0, Qt::DashLine));
    painter.drawPolygon(ring);
  }
}

}  // namespace delineo::widgets
