// MainWindow's image views: the left image (the central widget, where buildings are picked and
// edited), the right image, the disparity and the DEM; how they follow each other, the outlines
// they draw, and the readout of the pixel under the cursor.
#include <QComboBox>
#include <QLabel>
#include <QScopedValueRollback>
#include <QStatusBar>
#include <algorithm>
#include <cmath>
#include <tuple>
#include <utility>
#include <vector>

#include "delineo/project/pipeline.hpp"
#include "delineo/widgets/colour_maps.hpp"
#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/polygon_overlay.hpp"
#include "document.hpp"
#include "main_window.hpp"

namespace delineo::gui {

using project::Building;
using project::BuildingStatus;
using widgets::ImageView;

namespace {

// How the overlays draw a building in this state.
widgets::PolygonStatus overlayStatus(BuildingStatus status) {
  switch (status) {
    case BuildingStatus::Pending:
    case BuildingStatus::Automatic: return widgets::PolygonStatus::Candidate;
    case BuildingStatus::Corrected: return widgets::PolygonStatus::Edited;
    case BuildingStatus::Accepted: return widgets::PolygonStatus::Accepted;
    case BuildingStatus::Rejected: return widgets::PolygonStatus::Rejected;
  }
  return widgets::PolygonStatus::Candidate;
}

// The outline of a rectangle picked on the left image.
core::Polygon rectanglePolygon(const QRectF& r) {
  core::Polygon p;
  p.outer = {{r.left(), r.top()}, {r.right(), r.top()}, {r.right(), r.bottom()}, {r.left(), r.bottom()}};
  return p;
}

}  // namespace

void MainWindow::createViews() {
  leftView_ = new ImageView;
  leftView_->setObjectName(QStringLiteral("leftView"));
  leftView_->setToolTip(tr("Left image (reference): pick buildings here"));
  setCentralWidget(leftView_);
  rightView_ = new ImageView;
  rightView_->setObjectName(QStringLiteral("rightView"));
  disparityView_ = new ImageView;
  disparityView_->setObjectName(QStringLiteral("disparityView"));
  demView_ = new ImageView;
  demView_->setObjectName(QStringLiteral("demView"));
  for (ImageView* v : {disparityView_, demView_}) widgets::linkViews(leftView_, v);
  // The right view follows with the selected roof's disparity as offset, so the roof under the
  // left view's centre is under the right view's centre too (and the other way round).
  connect(leftView_, &ImageView::viewChanged, this, [this] { syncRightView(); });
  connect(rightView_, &ImageView::viewChanged, this, [this](QPointF center, double zoom) {
    if (linkingRight_) return;
    linkingRight_ = true;
    leftView_->setView(center + QPointF(rightShift_, 0.0), zoom);
    linkingRight_ = false;
  });
  // Clicking an outline in the right view selects that building.
  connect(&rightView_->polygons(), &widgets::PolygonOverlay::selectionChanged, this,
          &MainWindow::onSelectionFromOverlay);

  connect(leftView_, &ImageView::cursorMoved, this, [this](QPointF p) {
    updateReadout(p, true, document_ ? document_->leftGrey() : cv::Mat());
  });
  connect(disparityView_, &ImageView::cursorMoved, this, [this](QPointF p) {
    updateReadout(p, true, document_ ? document_->leftGrey() : cv::Mat());
  });
  connect(demView_, &ImageView::cursorMoved, this, [this](QPointF p) {
    updateReadout(p, true, document_ ? document_->leftGrey() : cv::Mat());
  });
  connect(rightView_, &ImageView::cursorMoved, this, [this](QPointF p) {
    updateReadout(p, false, document_ ? document_->rightGrey() : cv::Mat());
  });
  connect(leftView_, &ImageView::rectanglePicked, this,
          [this](QRectF r) { onPicked(rectanglePolygon(r.normalized())); });
  connect(leftView_, &ImageView::polygonPicked, this, [this](QPolygonF poly) {
    core::Polygon p;
    p.outer = widgets::toRing(poly);
    onPicked(p);
  });
  connect(leftView_, &ImageView::pointPicked, this, &MainWindow::onObjectPicked);
  connect(&leftView_->polygons(), &widgets::PolygonOverlay::editRequested, this, &MainWindow::onEditRequested);
  // Hole and rubber-band deletions: the overlay has checked the result is a valid polygon.
  connect(&leftView_->polygons(), &widgets::PolygonOverlay::polygonEditRequested, this,
          [this](int id, const QList<QPolygonF>& rings, const QString& description) {
            if (document_) document_->setPolygon(id, widgets::toPolygon(rings), description);
          });
  connect(&leftView_->polygons(), &widgets::PolygonOverlay::editRefused, this,
          [this](const QString& reason) { showMessage(tr("Edit outline"), reason); });
  connect(&leftView_->polygons(), &widgets::PolygonOverlay::selectionChanged, this,
          &MainWindow::onSelectionFromOverlay);

  readout_ = new QLabel;
  readout_->setObjectName(QStringLiteral("readout"));
  readout_->setMinimumWidth(420);
  statusBar()->addWidget(readout_, 1);
  statusBar()->addPermanentWidget(createLayerLegend());
  auto* progress = new widgets::JobProgressWidget(jobs_);
  progress->setObjectName(QStringLiteral("jobProgress"));
  statusBar()->addPermanentWidget(progress);
  reviewProgress_ = new QLabel;
  reviewProgress_->setObjectName(QStringLiteral("reviewProgress"));
  statusBar()->addPermanentWidget(reviewProgress_);
}

void MainWindow::refreshRasters() {
  if (!document_) return;
  const cv::Mat& disparity = document_->disparity();
  if (disparity.empty()) {
    disparityView_->clearImage();
  } else {
    const auto [lo, hi] = widgets::finiteRange(disparity);
    disparityView_->setImage(disparity, {widgets::ColourMap::Viridis, lo, hi});
    disparityLegend_->setRange(lo, hi);
  }
  const cv::Mat& dem = demViewRaster();
  if (dem.empty()) {
    demView_->clearImage();
  } else if (demMode_->currentIndex() == 0) {
    demView_->setImage(widgets::hillshade(dem, document_->project().height.gsd));
    demLegend_->hide();
  } else {
    auto [lo, hi] = widgets::finiteRange(dem);
    // Heights above ground from 0, so that the ground has one colour whatever the scene.
    if (demLayer() == DemLayer::Ndsm) std::tie(lo, hi) = std::pair(0.0, std::max(hi, 1.0));
    static const char* const titles[] = {QT_TR_NOOP("Height"), QT_TR_NOOP("Ground height"),
                                         QT_TR_NOOP("Height above ground")};
    demLegend_->setTitle(tr(titles[static_cast<int>(demLayer())]));
    demView_->setImage(dem, {widgets::ColourMap::Terrain, lo, hi});
    demLegend_->setRange(lo, hi);
    demLegend_->show();
  }
  // Views that got their first image fit themselves; keep them on the left view's position.
  for (ImageView* v : {disparityView_, demView_}) {
    if (v->hasImage()) v->setView(leftView_->viewCenter(), leftView_->zoom());
  }
}

void MainWindow::refreshOverlays() {
  // Pushing polygons is no choice of the operator's: a view that does not draw the selected
  // building (the right view before its roof disparity is known) must not deselect it.
  const QScopedValueRollback<bool> pushing(updatingSelection_, true);
  if (!document_) {
    leftView_->polygons().clearPolygons();
    return;
  }
  std::vector<widgets::OverlayPolygon> polygons;
  for (const Building& b : document_->project().buildings) {
    widgets::OverlayPolygon p;
    p.id = b.id;
    p.polygon = b.currentPolygon();
    p.status = overlayStatus(b.status);
    p.label = QStringLiteral("#%1").arg(b.id);
    if (b.status == BuildingStatus::Pending) p.colour = QColor(255, 200, 0);
    polygons.push_back(std::move(p));
  }
  for (ImageView* v : {leftView_, disparityView_, demView_}) {
    v->polygons().setPolygons(polygons);
    v->polygons().setSelectedId(selectedId_);
  }
  // The right view is in its own geometry: a roof point at x_left is seen at x_left - d. Each
  // outline is shifted by its roof disparity so the operator can check it on both images (the
  // walls and the ground then do not line up, by design); editing stays on the left image.
  std::vector<widgets::OverlayPolygon> shifted;
  for (widgets::OverlayPolygon p : polygons) {
    const std::optional<double> d = roofDisparity(p.id);
    if (!d) continue;
    auto shift = [&](core::Ring& ring) {
      for (auto& q : ring) q.x -= *d;
    };
    shift(p.polygon.outer);
    for (auto& hole : p.polygon.holes) shift(hole);
    shifted.push_back(std::move(p));
  }
  rightView_->polygons().setPolygons(std::move(shifted));
  rightView_->polygons().setSelectedId(selectedId_);
}

std::optional<double> MainWindow::roofDisparity(int id) const {
  if (!document_) return std::nullopt;
  const Building* b = document_->project().find(id);
  if (b == nullptr) return std::nullopt;
  std::optional<project::DisparityInterval> interval = b->roofInterval;
  if (!interval && !document_->disparity().empty()) {
    interval = project::suggestRoofInterval(document_->disparity(), b->currentPolygon());
  }
  if (!interval) return std::nullopt;
  return 0.5 * (interval->low + interval->high);
}

void MainWindow::syncRightView() {
  if (linkingRight_ || !rightView_->hasImage()) return;
  linkingRight_ = true;
  rightView_->setView(leftView_->viewCenter() - QPointF(rightShift_, 0.0), leftView_->zoom());
  linkingRight_ = false;
}

void MainWindow::updateReadout(QPointF p, bool leftGeometry, const cv::Mat& ownGrey) {
  if (!document_) return;
  const int x = static_cast<int>(std::floor(p.x()));
  const int y = static_cast<int>(std::floor(p.y()));
  if (ownGrey.empty() || x < 0 || y < 0 || x >= ownGrey.cols || y >= ownGrey.rows) {
    readout_->clear();
    return;
  }
  QString text = tr("x %1  y %2  grey %3").arg(x).arg(y).arg(ownGrey.at<uchar>(y, x));
  if (leftGeometry) {
    const cv::Mat& disparity = document_->disparity();
    if (!disparity.empty()) {
      const float d = disparity.at<float>(y, x);
      text += std::isfinite(d) ? tr("  disparity %1 px").arg(d, 0, 'f', 2) : tr("  disparity –");
    }
    const cv::Mat& dem = shownDem();
    if (!dem.empty()) {
      const float h = dem.at<float>(y, x);
      text += std::isfinite(h) ? tr("  height %1 m").arg(h, 0, 'f', 2) : tr("  height –");
    }
    if (scene_ && !scene_->ndsm.empty()) {
      const float above = scene_->ndsm.at<float>(y, x);
      if (std::isfinite(above)) text += tr("  above ground %1 m").arg(above, 0, 'f', 2);
    }
  } else {
    text += tr("  (right image)");
  }
  readout_->setText(text);
}

}  // namespace delineo::gui
