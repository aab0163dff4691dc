// MainWindow's background jobs: the disparity range, dense matching, the active polygon, the
// pending buildings outlined in turn, the energy and the regularization of an outline, the edge
// map. Each copies its inputs into a job of the window's JobRunner and applies the result on the
// GUI thread, provided the document it was started on is still the open one.
#include <QDockWidget>
#include <QLabel>
#include <QMetaObject>
#include <QPointer>
#include <QSpinBox>
#include <QStatusBar>
#include <QTabWidget>
#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <utility>

#include "delineo/core/error.hpp"
#include "delineo/project/edge_map.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/widgets/disparity_histogram.hpp"
#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/polygon_overlay.hpp"
#include "document.hpp"
#include "error_text.hpp"
#include "main_window.hpp"

namespace delineo::gui {

using project::Building;
using project::BuildingStatus;

namespace {

// The listener handed to the active polygon's worker: it streams intermediate contours to the
// left view's evolving contour. Only the latest is kept and at most one repaint request is
// queued at a time, so a fast optimiser cannot flood the event loop.
project::ContourListener evolvingContourListener(MainWindow* window) {
  struct ContourMailbox {
    std::mutex mutex;
    core::Polygon latest;
    bool queued = false;
  };
  auto mailbox = std::make_shared<ContourMailbox>();
  QPointer<MainWindow> self(window);
  return [mailbox, self](const core::Polygon& contour) {
    std::lock_guard lock(mailbox->mutex);
    mailbox->latest = contour;
    if (mailbox->queued || !self) return;
    mailbox->queued = true;
    QMetaObject::invokeMethod(self.data(), [mailbox, self] {
      core::Polygon latest;
      {
        std::lock_guard inner(mailbox->mutex);
        latest = mailbox->latest;
        mailbox->queued = false;
      }
      if (self) self->leftView()->polygons().setEvolvingContour(widgets::toQPolygon(latest.outer));
    }, Qt::QueuedConnection);
  };
}

}  // namespace

widgets::JobId MainWindow::startRangeEstimate(bool thenMatch) {
  if (!document_) return 0;
  const project::Project projectCopy = document_->project();
  const project::StereoPair pair = document_->pair();
  QPointer<Document> doc(document_.get());
  rangeNote_->setText(tr("Estimating the range from feature matches…"));
  rangeJob_ = jobs_->run<project::RangeOutcome>(
      tr("Disparity range"),
      [projectCopy, pair](core::Progress& p) { return project::estimateDisparityRange(projectCopy, pair, &p); },
      [this, doc, thenMatch](project::RangeOutcome outcome) {
        if (!doc || doc != document_.get() || outcome.status != core::RunStatus::Completed) return;
        doc->setDisparityRange(outcome.range, tr("Disparity range %1..%2 px, estimated from %3 feature matches")
                                                  .arg(outcome.range.low)
                                                  .arg(outcome.range.high)
                                                  .arg(outcome.matches));
        rangeSource_ = tr("Estimated from %n feature match(es) between the two images.", nullptr, outcome.matches);
        loadRangeFromDocument();
        statusBar()->showMessage(
            tr("Disparity range %1..%2 px (from %3 feature matches).").arg(outcome.range.low).arg(outcome.range.high).arg(outcome.matches),
            8000);
        emit rangeEstimated();
        if (thenMatch) startMatching();
      },
      QStringLiteral("range"));
  return rangeJob_;
}

void MainWindow::onRangeEstimateFailed(const QString& message) {
  loadRangeFromDocument();
  rangeNote_->setText(tr("Not estimated: %1. Enter the range above, then compute the disparity (Ctrl+M).").arg(message));
  // The Matching tab of the Parameters dock, its range in view and focused.
  if (auto* dock = findChild<QDockWidget*>(QStringLiteral("parametersDock"))) {
    dock->show();
    dock->raise();
  }
  for (QWidget* w = rangeMin_; w != nullptr; w = w->parentWidget()) {
    if (auto* tabs = qobject_cast<QTabWidget*>(w->parentWidget() ? w->parentWidget()->parentWidget() : nullptr)) {
      tabs->setCurrentWidget(w);
      break;
    }
  }
  rangeMin_->setFocus();
  showMessage(tr("Disparity range"),
              tr("The disparity range could not be estimated from the images: %1.\n\nEnter the smallest and largest "
                 "disparity of the pair (x_right = x_left − d) on the Matching tab of the Parameters dock, then "
                 "compute the disparity (Ctrl+M).").arg(message));
}

widgets::JobId MainWindow::startMatching() {
  if (!document_) return 0;
  // The range comes first: estimated from the images when the project has none.
  if (!document_->project().disparityRange) return startRangeEstimate(true);
  const project::Project projectCopy = document_->project();
  const project::StereoPair pair = document_->pair();
  QPointer<Document> doc(document_.get());
  matchingJob_ = jobs_->run<project::MatchingOutcome>(
      tr("Dense matching"),
      [projectCopy, pair](core::Progress& p) {
        return project::computeDisparity(projectCopy, pair.left, pair.right, &p);
      },
      [this, doc](project::MatchingOutcome outcome) {
        if (!doc || doc != document_.get() || outcome.status != core::RunStatus::Completed) return;
        doc->setDisparity(outcome.disparity);
        statusBar()->showMessage(tr("Disparity computed."), 5000);
        const int waiting = std::exchange(awaitingDisparity_, -1);
        const Building* b = doc->project().find(waiting);
        if (b != nullptr && b->status == BuildingStatus::Pending) outlineBuilding(waiting);
        emit matchingFinished();
      },
      QStringLiteral("matching"));
  return matchingJob_;
}

widgets::JobId MainWindow::startDelineation(int id) {
  if (!document_) return 0;
  const Building* current = document_->project().find(id);
  if (current == nullptr) {
    showMessage(tr("Active polygon"), tr("Select a building first."));
    return 0;
  }
  if (document_->disparity().empty() && !current->roofInterval) {
    showMessage(tr("Active polygon"), tr("Compute the disparity (or choose a roof interval) first."));
    return 0;
  }
  writeFormIntoDocument("delineation");
  Building building = *current;
  if (id == selectedId_ && histogram_->sampleCount() > 0) {
    building.roofInterval = project::DisparityInterval{histogram_->lowerBound(), histogram_->upperBound()};
    document_->setRoofInterval(id, *building.roofInterval);
  }
  if (!building.roofInterval) building.roofInterval = project::suggestRoofInterval(document_->disparity(), building.initial);
  if (!building.roofInterval) {
    showMessage(tr("Active polygon"), tr("Choose the roof disparity interval on the histogram first."));
    return 0;
  }
  const project::Project projectCopy = document_->project();
  const project::StereoPair pair = document_->pair();
  QPointer<Document> doc(document_.get());

  const project::ContourListener onContour = evolvingContourListener(this);
  leftView_->polygons().setEvolvingContour(widgets::toQPolygon(building.initial.outer));
  const widgets::JobId job = jobs_->run<project::DelineationOutcome>(
      tr("Active polygon, building %1").arg(id),
      [projectCopy, building, pair, onContour](core::Progress& p) {
        return project::delineateBuilding(projectCopy, building, pair, &p, onContour);
      },
      [this, doc, id](project::DelineationOutcome outcome) {
        if (!doc || doc != document_.get() || outcome.status != core::RunStatus::Completed) return;
        doc->setDelineationResult(id, outcome);
        emit delineationFinished(id);
      },
      QStringLiteral("delineate-%1").arg(id));
  return job;
}

widgets::JobId MainWindow::outlinePendingBuildings() {
  if (!document_) return 0;
  const QString title = tr("Outline the pending buildings");
  const std::vector<int> pending = document_->project().pendingBuildings();
  if (pending.empty()) {
    showMessage(title, tr("No building is pending."));
    return 0;
  }
  const bool withoutInterval = std::any_of(pending.begin(), pending.end(), [this](int id) {
    return !document_->project().find(id)->roofInterval;
  });
  if (document_->disparity().empty() && withoutInterval) {
    showMessage(title, tr("Compute the disparity first: it gives the buildings their roof intervals."));
    return 0;
  }
  const project::Project projectCopy = document_->project();
  const project::StereoPair pair = document_->pair();
  QPointer<Document> doc(document_.get());
  QPointer<MainWindow> self(this);
  struct Batch {
    std::vector<std::pair<int, core::Error>> skipped;  // building id, why
  };
  // Each result goes to the GUI thread as soon as it is there: a cancel loses none of them. A
  // building the operator changed meanwhile keeps the change (Document::setOutlinedPending).
  auto applied = std::make_shared<int>(0);  // read and written on the GUI thread only
  auto deliver = [self, doc, applied](const Building& after) {
    QMetaObject::invokeMethod(self.data(), [self, doc, applied, after] {
      if (self && doc && doc == self->document_.get() && doc->setOutlinedPending(after)) ++*applied;
    }, Qt::QueuedConnection);
  };
  return jobs_->run<Batch>(
      title,
      [projectCopy, pair, pending, deliver](core::Progress& p) {
        Batch batch;
        cv::Mat heights;  // read once, by the first building outlined by box-fitting
        const double n = static_cast<double>(pending.size());
        for (size_t i = 0; i < pending.size(); ++i) {
          core::Progress::Range range(&p, static_cast<double>(i) / n, static_cast<double>(i + 1) / n);
          const Building& building = *projectCopy.find(pending[i]);
          try {
            const std::optional<Building> after =
                project::outlinePendingBuilding(projectCopy, building, pair, heights, &range, "all pending");
            if (!after) return batch;  // canceled
            deliver(*after);
          } catch (const core::Error& e) {
            // This building cannot be outlined (a degenerate proposal, no heights for box-fitting):
            // the others still are. Anything else ends the job as failed.
            if (core::isInputError(e.code()) && e.code() != core::ErrorCode::InvalidParameter) throw;
            batch.skipped.emplace_back(building.id, e);
          }
        }
        return batch;
      },
      [this, doc, title, applied](Batch batch) {
        // The results were queued before this: every one of them has been applied or refused.
        if (!doc || doc != document_.get()) return;
        const int skipped = static_cast<int>(batch.skipped.size());
        QString text = *applied == 1 ? tr("1 building outlined.") : tr("%1 buildings outlined.").arg(*applied);
        if (skipped > 0) text += QLatin1Char(' ') + (skipped == 1 ? tr("1 stays pending.") : tr("%1 stay pending.").arg(skipped));
        statusBar()->showMessage(text, 8000);
        if (skipped > 0) {
          QStringList lines;
          for (const auto& [id, error] : batch.skipped) lines << tr("Building %1: %2").arg(id).arg(errorMessage(error));
          showMessage(title, tr("These buildings could not be outlined and stay pending:") + QLatin1Char('\n') +
                                 lines.join(QLatin1Char('\n')));
        }
        emit pendingOutlined(*applied, skipped);
      },
      QStringLiteral("outline-pending"));
}

widgets::JobId MainWindow::startEnergyUpdate(int id) {
  if (!document_) return 0;
  const Building* b = document_->project().find(id);
  if (b == nullptr || !b->hasOutline() || std::isfinite(b->energy) || !b->roofInterval) return 0;
  const auto asked = energyAsked_.find(id);
  if (asked != energyAsked_.end() && asked->second.outer == b->outline.outer && asked->second.holes == b->outline.holes) {
    return 0;
  }
  energyAsked_[id] = b->outline;
  const project::Project projectCopy = document_->project();
  const Building building = *b;
  const project::StereoPair pair = document_->pair();
  QPointer<Document> doc(document_.get());
  struct Scored {
    core::Polygon outline;
    std::optional<project::EnergyOutcome> outcome;  // none: the outline cannot be scored
  };
  return jobs_->run<Scored>(
      tr("Energy of building %1").arg(id),
      [projectCopy, building, pair](core::Progress& p) {
        Scored scored{building.outline, std::nullopt};
        try {
          scored.outcome = project::outlineEnergy(projectCopy, building, pair, building.outline, &p);
        } catch (const core::Error&) {
          // An outline the energy cannot score (degenerate on the pixel grid): shown as unknown.
        }
        return scored;
      },
      [this, doc, id](Scored scored) {
        if (!doc || doc != document_.get()) return;
        if (scored.outcome && scored.outcome->status != core::RunStatus::Completed) return;
        if (scored.outcome) {
          // Scored: asked again should an undo or redo bring this outline back without its energy.
          energyAsked_.erase(id);
          doc->setOutlineEnergy(id, scored.outline, scored.outcome->energy, scored.outcome->terms);
        }
        emit energyUpdated(id);
      },
      QStringLiteral("energy-%1").arg(id));
}

widgets::JobId MainWindow::startRegularization(int id) {
  if (!document_) return 0;
  const Building* b = document_->project().find(id);
  if (b == nullptr || !b->hasOutline()) return 0;
  if (!b->roofInterval) {
    showMessage(tr("Regularize outline"), tr("Choose the roof disparity interval on the histogram first."));
    return 0;
  }
  const project::Project projectCopy = document_->project();
  const Building building = *b;
  const project::StereoPair pair = document_->pair();
  QPointer<Document> doc(document_.get());
  return jobs_->run<project::RegularizationOutcome>(
      tr("Regularize building %1").arg(id),
      [projectCopy, building, pair](core::Progress& p) {
        return project::regularizeOutline(projectCopy, building, pair, building.outline, &p);
      },
      [this, doc, id, before = building.outline](project::RegularizationOutcome outcome) {
        if (!doc || doc != document_.get()) return;
        const Building* now = doc->project().find(id);
        // The outline changed meanwhile (an edit, an undo): this result is about another one.
        if (now == nullptr || !(now->outline.outer == before.outer && now->outline.holes == before.holes)) return;
        if (outcome.regularization == "regularized") {
          doc->setPolygon(id, outcome.outline,
                          tr("Regularize building %1 (%2 → %3 vertices)")
                              .arg(id)
                              .arg(outcome.verticesBefore)
                              .arg(outcome.verticesAfter));
          statusBar()->showMessage(tr("Building %1 regularized: %2 → %3 vertices.")
                                       .arg(id)
                                       .arg(outcome.verticesBefore)
                                       .arg(outcome.verticesAfter),
                                   8000);
        } else if (outcome.regularization == "kept-raw") {
          showMessage(tr("Regularize outline"), tr("The outline of building %1 was kept as it is: %2")
                                                    .arg(id)
                                                    .arg(QString::fromStdString(outcome.regularizationNote)));
        }
        emit regularizationFinished(id);
      },
      QStringLiteral("regularize-%1").arg(id));
}

void MainWindow::startEdgeMap() {
  if (!document_) return;
  const cv::Mat grey = document_->leftGrey();
  QPointer<Document> doc(document_.get());
  jobs_->run<cv::Mat>(
      tr("Image edges"),
      [grey](core::Progress&) { return project::edgeMap(grey); },
      [this, doc](cv::Mat edges) {
        if (!doc || doc != document_.get()) return;
        edgeMap_ = edges;
        leftView_->polygons().setEdgeMap(edgeMap_, 128.0);
      },
      QStringLiteral("edges"));
}

}  // namespace delineo::gui
