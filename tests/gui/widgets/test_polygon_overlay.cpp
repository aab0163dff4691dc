#include <QApplication>
#include <QKeyEvent>
#include <QMenu>
#include <QSignalSpy>
#include <QTest>
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/polygon_overlay.hpp"
#include "gui_test_support.hpp"

using namespace delineo::widgets;

namespace {

struct EditFixture : ::testing::Test {
  void SetUp() override {
    view.resize(400, 400);
    view.setImage(cv::Mat(200, 200, CV_8U, cv::Scalar(90)));
    view.setView(QPointF(100, 100), 2.0);  // image (x, y) ↔ widget (2x, 2y)
    OverlayPolygon square;
    square.id = 7;
    square.polygon.outer = {{50, 50}, {150, 50}, {150, 150}, {50, 150}};
    square.polygon.holes = {{{80, 80}, {100, 80}, {100, 100}, {80, 100}}};
    OverlayPolygon other;
    other.id = 9;
    other.status = PolygonStatus::Accepted;
    other.polygon.outer = {{160, 160}, {190, 160}, {190, 190}, {160, 190}};
    view.polygons().setPolygons({square, other});
    view.polygons().setSelectedId(7);
    view.polygons().setSnapToRightAngles(false);
    view.polygons().setSnapToEdges(false);
    view.setInteractionMode(InteractionMode::EditPolygon);
  }
  QPoint w(double x, double y) const {
    const QPointF p = view.imageToWidget(QPointF(x, y));
    return QPoint(static_cast<int>(std::lround(p.x())), static_cast<int>(std::lround(p.y())));
  }
  QPolygonF lastRing(QSignalSpy& spy, int* id = nullptr, int* ring = nullptr) {
    const QList<QVariant> args = spy.takeLast();
    if (id) *id = args.at(0).toInt();
    if (ring) *ring = args.at(1).toInt();
    return args.at(2).value<QPolygonF>();
  }
  ImageView view;
};

}  // namespace

TEST_F(EditFixture, DraggingAVertexEmitsOneEditAtTheEnd) {
  QSignalSpy spy(&view.polygons(), &PolygonOverlay::editRequested);
  QTest::mousePress(&view, Qt::LeftButton, {}, w(50, 50));
  QTest::mouseMove(&view, w(45, 47));
  EXPECT_TRUE(view.polygons().isDragging());
  EXPECT_EQ(spy.count(), 0);  // live preview only
  QTest::mouseMove(&view, w(40, 45));
  QTest::mouseRelease(&view, Qt::LeftButton, {}, w(40, 45));
  ASSERT_EQ(spy.count(), 1);
  int id = 0;
  int ring = -1;
  const QPolygonF edited = lastRing(spy, &id, &ring);
  EXPECT_EQ(id, 7);
  EXPECT_EQ(ring, 0);
  ASSERT_EQ(edited.size(), 4);
  EXPECT_EQ(edited[0], QPointF(40, 45));
  EXPECT_EQ(edited[1], QPointF(150, 50));
  // The model is untouched until the application applies the edit.
  EXPECT_EQ(view.polygons().selectedPolygon()->polygon.outer[0], cv::Point2d(50, 50));
}

TEST_F(EditFixture, HoleVerticesAreEditableWithTheirRingIndex) {
  QSignalSpy spy(&view.polygons(), &PolygonOverlay::editRequested);
  QTest::mousePress(&view, Qt::LeftButton, {}, w(100, 100));
  QTest::mouseMove(&view, w(105, 104));
  QTest::mouseRelease(&view, Qt::LeftButton, {}, w(105, 104));
  ASSERT_EQ(spy.count(), 1);
  int ring = -1;
  const QPolygonF edited = lastRing(spy, nullptr, &ring);
  EXPECT_EQ(ring, 1);
  EXPECT_EQ(edited[2], QPointF(105, 104));
}

TEST_F(EditFixture, RightAngleSnapProjectsOntoThePerpendicular) {
  view.polygons().setSnapToRightAngles(true);
  QSignalSpy spy(&view.polygons(), &PolygonOverlay::editRequested);
  // Vertex 1 towards (170, 48): the angle at vertex 0 is ~91° → snapped back onto y = 50.
  QTest::mousePress(&view, Qt::LeftButton, {}, w(150, 50));
  QTest::mouseMove(&view, w(170, 48));
  QTest::mouseRelease(&view, Qt::LeftButton, {}, w(170, 48));
  ASSERT_EQ(spy.count(), 1);
  const QPolygonF edited = lastRing(spy);
  EXPECT_NEAR(edited[1].x(), 170.0, 1e-9);
  EXPECT_NEAR(edited[1].y(), 50.0, 1e-9);
  // Far from any right angle: no snapping.
  const QPolygonF ring = toQPolygon(view.polygons().selectedPolygon()->polygon.outer);
  EXPECT_EQ(view.polygons().snapVertex(ring, 1, QPointF(200, 90)), QPointF(200, 90));
  // Near a rectangle corner: both neighbours' perpendiculars meet at the corner.
  EXPECT_EQ(view.polygons().snapVertex(ring, 1, QPointF(152, 48)), QPointF(150, 50));
}

TEST_F(EditFixture, EdgeSnapMovesToTheNearestStrongEdgePixel) {
  cv::Mat edges(200, 200, CV_8U, cv::Scalar(0));
  edges.col(60).setTo(255);
  view.polygons().setEdgeMap(edges, 128);
  view.polygons().setEdgeSnapRadius(3);
  view.polygons().setSnapToEdges(true);
  QSignalSpy spy(&view.polygons(), &PolygonOverlay::editRequested);
  QTest::mousePress(&view, Qt::LeftButton, {}, w(50, 50));
  QTest::mouseMove(&view, w(58, 50.5));
  QTest::mouseRelease(&view, Qt::LeftButton, {}, w(58, 50.5));
  ASSERT_EQ(spy.count(), 1);
  const QPolygonF edited = lastRing(spy);
  EXPECT_EQ(edited[0], QPointF(60.5, 50.5));
  // Out of the radius: unchanged.
  const QPolygonF ring = toQPolygon(view.polygons().selectedPolygon()->polygon.outer);
  EXPECT_EQ(view.polygons().snapVertex(ring, 0, QPointF(52, 50)), QPointF(52, 50));
}

TEST_F(EditFixture, DoubleClickOnAnEdgeInsertsAVertex) {
  QSignalSpy spy(&view.polygons(), &PolygonOverlay::editRequested);
  QTest::mouseDClick(&view, Qt::LeftButton, {}, w(100, 50));
  ASSERT_EQ(spy.count(), 1);
  const QList<QVariant> args = spy.takeLast();
  const QPolygonF edited = args.at(2).value<QPolygonF>();
  ASSERT_EQ(edited.size(), 5);
  EXPECT_EQ(edited[1], QPointF(100, 50));
  EXPECT_EQ(args.at(3).toString(), QStringLiteral("Insert vertex"));
}

TEST_F(EditFixture, DeleteKeyRemovesTheHoveredVertex) {
  QSignalSpy spy(&view.polygons(), &PolygonOverlay::editRequested);
  QTest::mouseMove(&view, w(150, 150));
  QTest::keyClick(&view, Qt::Key_Delete);
  ASSERT_EQ(spy.count(), 1);
  const QPolygonF edited = lastRing(spy);
  ASSERT_EQ(edited.size(), 3);
  EXPECT_FALSE(edited.contains(QPointF(150, 150)));
}

TEST_F(EditFixture, ShiftDragMovesAWholeEdgeAlongItsNormalToo) {
  view.polygons().setSnapToRightAngles(true);
  QSignalSpy spy(&view.polygons(), &PolygonOverlay::editRequested);
  QTest::mousePress(&view, Qt::LeftButton, Qt::ShiftModifier, w(100, 50));
  QTest::mouseMove(&view, w(103, 40));
  QTest::mouseRelease(&view, Qt::LeftButton, Qt::ShiftModifier, w(103, 40));
  ASSERT_EQ(spy.count(), 1);
  const QList<QVariant> args = spy.takeLast();
  const QPolygonF edited = args.at(2).value<QPolygonF>();
  EXPECT_EQ(edited[0], QPointF(50, 40));
  EXPECT_EQ(edited[1], QPointF(150, 40));
  EXPECT_EQ(edited[2], QPointF(150, 150));
  EXPECT_EQ(args.at(3).toString(), QStringLiteral("Move edge"));
}

TEST_F(EditFixture, ShiftDragOfAVertexKeepsEveryEdgesDirection) {
  QSignalSpy spy(&view.polygons(), &PolygonOverlay::editRequested);
  QTest::mousePress(&view, Qt::LeftButton, Qt::ShiftModifier, w(150, 50));
  // A move event with Shift held (QTest's mouseMove carries no modifiers).
  QMouseEvent move(QEvent::MouseMove, w(160, 45), view.mapToGlobal(w(160, 45)), Qt::NoButton, Qt::LeftButton,
                   Qt::ShiftModifier);
  QApplication::sendEvent(&view, &move);
  QTest::mouseRelease(&view, Qt::LeftButton, Qt::ShiftModifier, w(160, 45));
  ASSERT_EQ(spy.count(), 1);
  const QPolygonF edited = lastRing(spy);
  // The corner went where it was dragged and its neighbours slid along the edges beyond them:
  // still a rectangle.
  EXPECT_EQ(edited[1], QPointF(160, 45));
  EXPECT_EQ(edited[0], QPointF(50, 45));
  EXPECT_EQ(edited[2], QPointF(160, 150));
  EXPECT_EQ(edited[3], QPointF(50, 150));
}

TEST_F(EditFixture, ClickingAnotherPolygonSelectsIt) {
  QSignalSpy spy(&view.polygons(), &PolygonOverlay::selectionChanged);
  QTest::mouseClick(&view, Qt::LeftButton, {}, w(175, 175));
  ASSERT_EQ(spy.count(), 1);
  EXPECT_EQ(view.polygons().selectedId(), 9);
}

TEST_F(EditFixture, DrawsPolygonsEvolvingContourAndRoi) {
  view.polygons().setRoi(QRectF(30, 30, 150, 150));
  view.polygons().setEvolvingContour(QPolygonF({QPointF(60, 60), QPointF(140, 62), QPointF(138, 140), QPointF(62, 138)}));
  const QImage shot = view.grab().toImage();
  // Selected outline in the candidate colour, handles at the vertices.
  const QColor edge(shot.pixel(w(100, 50)));
  EXPECT_GT(edge.blue(), 150);
  EXPECT_NE(QColor(shot.pixel(w(50, 50))).rgb(), QColor(90, 90, 90).rgb());
  test::saveScreenshot(view, QStringLiteral("polygon_overlay"));
}

TEST_F(EditFixture, PlainDragOnTheHighlightedEdgeMovesTheEdge) {
  QSignalSpy spy(&view.polygons(), &PolygonOverlay::editRequested);
  QSignalSpy panned(&view, &ImageView::viewChanged);
  QTest::mouseMove(&view, w(100, 150));
  QTest::mousePress(&view, Qt::LeftButton, {}, w(100, 150));
  QTest::mouseMove(&view, w(100, 155));
  QTest::mouseMove(&view, w(100, 160));
  QTest::mouseRelease(&view, Qt::LeftButton, {}, w(100, 160));
  EXPECT_EQ(panned.count(), 0);  // the view did not move
  ASSERT_EQ(spy.count(), 1);
  const QList<QVariant> args = spy.takeLast();
  const QPolygonF edited = args.at(2).value<QPolygonF>();
  EXPECT_EQ(edited[0], QPointF(50, 50));
  EXPECT_EQ(edited[2], QPointF(150, 160));
  EXPECT_EQ(edited[3], QPointF(50, 160));
  EXPECT_EQ(args.at(3).toString(), QStringLiteral("Move edge"));
  // Empty canvas still pans.
  QTest::mousePress(&view, Qt::LeftButton, {}, w(20, 20));
  QTest::mouseMove(&view, w(25, 20));
  QTest::mouseMove(&view, w(30, 20));
  QTest::mouseRelease(&view, Qt::LeftButton, {}, w(30, 20));
  EXPECT_GE(panned.count(), 1);
  EXPECT_EQ(spy.count(), 0);
}

TEST_F(EditFixture, ContextMenuOfAHoleDeletesTheHole) {
  QSignalSpy spy(&view.polygons(), &PolygonOverlay::polygonEditRequested);
  // Right-click on the hole's edge: the menu has "Delete hole".
  QMenu menu;
  ASSERT_TRUE(view.polygons().fillContextMenu(menu, w(90, 80)));
  QAction* deleteHole = nullptr;
  for (QAction* a : menu.actions()) {
    if (a->text() == QStringLiteral("Delete hole")) deleteHole = a;
  }
  ASSERT_NE(deleteHole, nullptr);
  // The outer ring's menu has no such entry.
  QMenu outerMenu;
  ASSERT_TRUE(view.polygons().fillContextMenu(outerMenu, w(100, 50)));
  for (QAction* a : outerMenu.actions()) EXPECT_NE(a->text(), QStringLiteral("Delete hole"));
  deleteHole->trigger();
  ASSERT_EQ(spy.count(), 1);
  const QList<QVariant> args = spy.takeLast();
  EXPECT_EQ(args.at(0).toInt(), 7);
  const auto rings = args.at(1).value<QList<QPolygonF>>();
  ASSERT_EQ(rings.size(), 1);  // the outer ring only
  EXPECT_EQ(rings[0].size(), 4);
  EXPECT_EQ(args.at(2).toString(), QStringLiteral("Delete hole"));
  const delineo::core::Polygon polygon = toPolygon(rings);
  EXPECT_TRUE(polygon.holes.empty());
  EXPECT_EQ(polygon.outer.size(), size_t(4));
}

TEST_F(EditFixture, CtrlDragSelectsVerticesAndDeleteRemovesThemAsOneEdit) {
  // A square with two extra vertices on its top edge.
  OverlayPolygon p;
  p.id = 3;
  p.polygon.outer = {{50, 50}, {80, 48}, {120, 52}, {150, 50}, {150, 150}, {50, 150}};
  view.polygons().setPolygons({p});
  view.polygons().setSelectedId(3);
  QSignalSpy spy(&view.polygons(), &PolygonOverlay::polygonEditRequested);
  QSignalSpy panned(&view, &ImageView::viewChanged);
  QTest::mousePress(&view, Qt::LeftButton, Qt::ControlModifier, w(70, 35));
  QTest::mouseMove(&view, w(100, 50));
  EXPECT_FALSE(view.polygons().rubberBand().isNull());
  QTest::mouseMove(&view, w(130, 60));
  QTest::mouseRelease(&view, Qt::LeftButton, Qt::ControlModifier, w(130, 60));
  EXPECT_EQ(panned.count(), 0);
  EXPECT_TRUE(view.polygons().rubberBand().isNull());
  const std::set<std::pair<int, int>> expected{{0, 1}, {0, 2}};
  EXPECT_EQ(view.polygons().selectedVertices(), expected);
  // The selection is drawn: the selected handles are red.
  const QImage shot = view.grab().toImage().convertToFormat(QImage::Format_RGB32);
  const QColor handle(shot.pixel(w(80, 48)));
  EXPECT_GT(handle.red(), 200);
  EXPECT_LT(handle.green(), 80);
  test::saveScreenshot(view, QStringLiteral("polygon_overlay_vertex_selection"));
  // Delete claims the key before any window shortcut, then removes both vertices at once.
  QKeyEvent override(QEvent::ShortcutOverride, Qt::Key_Delete, Qt::NoModifier);
  QApplication::sendEvent(&view, &override);
  EXPECT_TRUE(override.isAccepted());
  QTest::keyClick(&view, Qt::Key_Delete);
  ASSERT_EQ(spy.count(), 1);
  const QList<QVariant> args = spy.takeLast();
  const auto rings = args.at(1).value<QList<QPolygonF>>();
  ASSERT_EQ(rings.size(), 1);
  EXPECT_EQ(rings[0],
            QPolygonF({QPointF(50, 50), QPointF(150, 50), QPointF(150, 150), QPointF(50, 150)}));
  EXPECT_EQ(args.at(2).toString(), QStringLiteral("Delete 2 vertices"));
  EXPECT_TRUE(view.polygons().selectedVertices().empty());
}

TEST_F(EditFixture, VertexDeletionThatBreaksThePolygonIsRefused) {
  QSignalSpy edits(&view.polygons(), &PolygonOverlay::polygonEditRequested);
  QSignalSpy refused(&view.polygons(), &PolygonOverlay::editRefused);
  // Two vertices of the 4-vertex outer ring: 2 would be left.
  EXPECT_EQ(view.polygons().selectVerticesIn(QRectF(40, 40, 120, 20)), 2);
  EXPECT_FALSE(view.polygons().deleteSelectedVertices());
  EXPECT_EQ(edits.count(), 0);
  ASSERT_EQ(refused.count(), 1);
  EXPECT_TRUE(refused.takeLast().at(0).toString().contains(QStringLiteral("fewer than 3")));
  EXPECT_EQ(view.polygons().selectedVertices().size(), size_t(2));  // kept, to adjust it
  // A corner whose removal makes the new edge cut through a notch.
  OverlayPolygon p;
  p.id = 4;
  p.polygon.outer = {{50, 50},  {150, 50}, {150, 150}, {110, 150},
                     {110, 70}, {90, 70},  {90, 150},  {50, 150}};
  view.polygons().setPolygons({p});
  view.polygons().setSelectedId(4);
  EXPECT_EQ(view.polygons().selectVerticesIn(QRectF(140, 40, 20, 20)), 1);
  EXPECT_FALSE(view.polygons().deleteSelectedVertices());
  ASSERT_EQ(refused.count(), 1);
  EXPECT_TRUE(refused.takeLast().at(0).toString().contains(QStringLiteral("cross itself")));
  EXPECT_EQ(edits.count(), 0);
  // A hole selected whole goes with its vertices, in the same single edit.
  view.polygons().setPolygons({});
  OverlayPolygon q;
  q.id = 5;
  q.polygon.outer = {{50, 50}, {150, 50}, {150, 150}, {50, 150}};
  q.polygon.holes = {{{80, 80}, {100, 80}, {100, 100}, {80, 100}}};
  view.polygons().setPolygons({q});
  view.polygons().setSelectedId(5);
  EXPECT_EQ(view.polygons().selectVerticesIn(QRectF(75, 75, 30, 30)), 4);
  EXPECT_TRUE(view.polygons().deleteSelectedVertices());
  ASSERT_EQ(edits.count(), 1);
  EXPECT_EQ(edits.takeLast().at(1).value<QList<QPolygonF>>().size(), 1);
}

TEST_F(EditFixture, EscapeAndAClickClearTheVertexSelection) {
  view.polygons().selectVerticesIn(QRectF(40, 40, 20, 20));
  ASSERT_EQ(view.polygons().selectedVertices().size(), size_t(1));
  QKeyEvent override(QEvent::ShortcutOverride, Qt::Key_Escape, Qt::NoModifier);
  QApplication::sendEvent(&view, &override);
  EXPECT_TRUE(override.isAccepted());
  QTest::keyClick(&view, Qt::Key_Escape);
  EXPECT_TRUE(view.polygons().selectedVertices().empty());
  // Nothing to cancel or delete: the keys are left to the window's shortcuts.
  QKeyEvent idle(QEvent::ShortcutOverride, Qt::Key_Escape, Qt::NoModifier);
  QApplication::sendEvent(&view, &idle);
  EXPECT_FALSE(idle.isAccepted());
  QKeyEvent del(QEvent::ShortcutOverride, Qt::Key_Delete, Qt::NoModifier);
  QApplication::sendEvent(&view, &del);
  EXPECT_FALSE(del.isAccepted());
  view.polygons().selectVerticesIn(QRectF(40, 40, 20, 20));
  QTest::mouseClick(&view, Qt::LeftButton, {}, w(20, 20));
  EXPECT_TRUE(view.polygons().selectedVertices().empty());
  EXPECT_EQ(view.polygons().selectedId(), 7);  // the polygon stays selected
}
