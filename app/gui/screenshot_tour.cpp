#include "screenshot_tour.hpp"

#include <QAction>
#include <QApplication>
#include <QComboBox>
#include <QDir>
#include <QDockWidget>
#include <QElapsedTimer>
#include <QEventLoop>
#include <QMouseEvent>
#include <QTimer>
#include <cstdio>

#include <opencv2/imgproc.hpp>

#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/polygon_overlay.hpp"
#include "delineo/widgets/terrain3d_view.hpp"
#include "document.hpp"
#include "main_window.hpp"

namespace delineo::gui {

namespace {

// Runs the event loop until `done()` or the timeout; the tour is a script, not a test, so it
// waits on state rather than on fixed delays.
template <class Predicate>
bool waitUntil(Predicate done, int timeoutMs) {
  QElapsedTimer clock;
  clock.start();
  while (!done()) {
    if (clock.elapsed() > timeoutMs) return false;
    QEventLoop loop;
    QTimer::singleShot(20, &loop, &QEventLoop::quit);
    loop.exec();
  }
  return true;
}

void settle() {
  waitUntil([] { return false; }, 300);  // lets docks lay out and tiles render
}

bool shoot(MainWindow& window, const QString& directory, const QString& name) {
  settle();
  const QString path = QDir(directory).filePath(name + QStringLiteral(".png"));
  const bool ok = window.grab().save(path);
  std::fprintf(stderr, "screenshot %s: %s\n", ok ? "written" : "FAILED", qPrintable(path));
  return ok;
}

// The building of the sample whose ground-truth label component is the largest near the image
// centre: a clear first example. Returns its bounding rectangle grown by `grow` px.
core::Polygon roughPolygonOfABuilding(const cv::Mat& labels, int grow) {
  cv::Mat building = labels == 1;
  cv::Mat components, stats, centroids;
  const int n = cv::connectedComponentsWithStats(building, components, stats, centroids, 4);
  int best = -1;
  double bestScore = -1;
  for (int i = 1; i < n; ++i) {
    const double area = stats.at<int>(i, cv::CC_STAT_AREA);
    const double dx = centroids.at<double>(i, 0) - labels.cols / 2.0;
    const double dy = centroids.at<double>(i, 1) - labels.rows / 2.0;
    const double score = area / (1.0 + std::sqrt(dx * dx + dy * dy) / 100.0);
    if (score > bestScore) {
      bestScore = score;
      best = i;
    }
  }
  core::Polygon p;
  if (best < 0) return p;
  const double x0 = stats.at<int>(best, cv::CC_STAT_LEFT) - grow;
  const double y0 = stats.at<int>(best, cv::CC_STAT_TOP) - grow;
  const double x1 = x0 + stats.at<int>(best, cv::CC_STAT_WIDTH) + 2 * grow;
  const double y1 = y0 + stats.at<int>(best, cv::CC_STAT_HEIGHT) + 2 * grow;
  p.outer = {{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}};
  return p;
}

// Sends a left-button mouse event with `modifiers` to the view at image position `imagePos`.
void sendMouse(widgets::ImageView* view, QEvent::Type type, QPointF imagePos,
               Qt::KeyboardModifiers modifiers) {
  const QPointF at = view->imageToWidget(imagePos);
  const Qt::MouseButtons held = type == QEvent::MouseButtonRelease ? Qt::NoButton : Qt::LeftButton;
  QMouseEvent event(type, at, view->mapToGlobal(at),
                    type == QEvent::MouseMove ? Qt::NoButton : Qt::LeftButton, held, modifiers);
  QApplication::sendEvent(view, &event);
}

}  // namespace

bool runPairScreenshotTour(MainWindow& window, const QString& directory, const QString& left,
                           const QString& right) {
  QDir().mkpath(directory);
  window.resize(1500, 950);
  auto fail = [](const char* what) {
    std::fprintf(stderr, "screenshot tour: %s\n", what);
    return false;
  };
  if (!window.openPair(left, right)) return fail("cannot open the pair");
  if (!waitUntil([&] { return window.jobs()->activeCount() == 0; }, 300000))
    return fail("matching too slow");
  window.showDock(QStringLiteral("rightDock"));
  if (!shoot(window, directory, QStringLiteral("pair-01-opened"))) return false;

  Document* doc = window.document();
  const cv::Size size = doc->leftGrey().size();
  const double half = std::min(size.width, size.height) / 10.0;
  const cv::Point2d c(size.width / 2.0, size.height / 2.0);
  // A rectangle with cut corners: eight vertices, so the selection below takes a few of them
  // even when the active polygon cannot run on this pair.
  const double cut = half / 3.0;
  core::Polygon rough;
  rough.outer = {{c.x - half + cut, c.y - half}, {c.x + half - cut, c.y - half},
                 {c.x + half, c.y - half + cut}, {c.x + half, c.y + half - cut},
                 {c.x + half - cut, c.y + half}, {c.x - half + cut, c.y + half},
                 {c.x - half, c.y + half - cut}, {c.x - half, c.y - half + cut}};
  const int id = doc->addBuilding(rough);
  window.selectBuilding(id);
  if (window.startDelineation(id) != 0 &&
      !waitUntil([&] { return window.jobs()->activeCount() == 0; }, 120000)) {
    return fail("active polygon too slow");
  }
  if (!doc->project().find(id)->hasOutline()) {
    std::fprintf(stderr, "screenshot tour: no outline (%s); the rough polygon is shown\n",
                 qPrintable(window.lastMessage()));
  }
  window.selectBuilding(id);
  window.action(QStringLiteral("actionEdit"))->trigger();
  widgets::ImageView* view = window.leftView();
  const cv::Rect2d box = core::boundingBox(doc->project().find(id)->currentPolygon().outer);
  view->setView(QPointF(box.x + box.width / 2, box.y + box.height / 2),
                0.6 * std::min(view->width() / box.width, view->height() / box.height));
  // A Ctrl+drag over the upper-left part of the outline.
  const QPointF from(box.x - 4, box.y - 4);
  const QPointF to(box.x + 0.55 * box.width, box.y + 0.45 * box.height);
  sendMouse(view, QEvent::MouseButtonPress, from, Qt::ControlModifier);
  sendMouse(view, QEvent::MouseMove, (from + to) / 2, Qt::ControlModifier);
  sendMouse(view, QEvent::MouseMove, to, Qt::ControlModifier);
  if (!shoot(window, directory, QStringLiteral("pair-02-rubber-band"))) return false;
  sendMouse(view, QEvent::MouseButtonRelease, to, Qt::ControlModifier);
  if (view->polygons().selectedVertices().empty())
    return fail("the rubber band selected no vertex");
  return shoot(window, directory, QStringLiteral("pair-03-vertices-selected"));
}

bool runScreenshotTour(MainWindow& window, const QString& directory) {
  QDir().mkpath(directory);
  window.resize(1500, 950);
  auto fail = [](const char* what) {
    std::fprintf(stderr, "screenshot tour: %s\n", what);
    return false;
  };
  if (!window.openSample()) return fail("cannot open the sample project");
  if (!waitUntil([&] { return window.document() != nullptr; }, 120000)) return fail("sample not opened");
  if (!waitUntil([&] { return window.jobs()->activeCount() == 0; }, 300000)) return fail("matching too slow");
  Document* doc = window.document();
  if (doc->disparity().empty()) return fail("no disparity after matching");
  window.leftView()->fitToWindow();
  window.showDock(QStringLiteral("rightDock"));
  if (!shoot(window, directory, QStringLiteral("01-sample-opened"))) return false;

  if (doc->labels().empty()) return fail("the sample has no labels");
  const int id = doc->addBuilding(roughPolygonOfABuilding(doc->labels(), 6));
  window.selectBuilding(id);
  window.leftView()->setZoom(2.5);
  window.showDock(QStringLiteral("disparityDock"));
  if (!shoot(window, directory, QStringLiteral("02-building-picked"))) return false;

  if (window.startDelineation(id) == 0) return fail("cannot start the active polygon");
  if (!waitUntil([&] { return window.jobs()->activeCount() == 0; }, 120000)) return fail("active polygon too slow");
  if (!doc->project().find(id)->hasOutline()) return fail("no outline after the active polygon");
  window.action(QStringLiteral("actionEdit"))->trigger();
  if (!shoot(window, directory, QStringLiteral("03-delineated"))) return false;

  // A manual correction, as the overlay would request it after a vertex drag.
  core::Ring ring = doc->project().find(id)->outline.outer;
  ring[0] += cv::Point2d(-3, -2);
  doc->editRing(id, 0, ring, QStringLiteral("Move vertex 1"));
  window.selectBuilding(id);
  // The right image with the outline shifted by the roof disparity: the same roof on both.
  window.showDock(QStringLiteral("rightDock"));
  if (!shoot(window, directory, QStringLiteral("04-corrected"))) return false;

  window.acceptSelected();
  window.action(QStringLiteral("actionNavigate"))->trigger();
  window.showDock(QStringLiteral("demDock"));
  if (auto* mode = window.findChild<QComboBox*>(QStringLiteral("demMode"))) mode->setCurrentIndex(1);
  if (!shoot(window, directory, QStringLiteral("05-accepted-dem"))) return false;

  // The whole scene in 3D (the view frames the selected building; "Frame" without a selection
  // and resetCamera() show everything).
  window.showDock(QStringLiteral("view3DDock"));
  settle();
  if (window.view3D() != nullptr) window.view3D()->resetCamera();
  if (!shoot(window, directory, QStringLiteral("06-3d-view"))) return false;
  return true;
}

}  // namespace delineo::gui
