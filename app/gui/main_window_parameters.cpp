// MainWindow's parameters dock: the roof interval on the ROI histogram (with the warning when
// the matched range cuts it), the pair's disparity search range, and the parameter forms, kept
// in step with the document's parameter groups.
#include <QComboBox>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QGroupBox>
#include <QLabel>
#include <QPushButton>
#include <QScrollArea>
#include <QSpinBox>
#include <QStatusBar>
#include <QTabWidget>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>

#include "delineo/core/error.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/project/roof_parts.hpp"
#include "delineo/segmentation/roof_levels.hpp"
#include "delineo/widgets/disparity_histogram.hpp"
#include "delineo/widgets/image_view.hpp"
#include "delineo/widgets/parameter_form.hpp"
#include "delineo/widgets/polygon_overlay.hpp"
#include "document.hpp"
#include "error_text.hpp"
#include "main_window.hpp"

#include "delineo/boxfit/params.hpp"
#include "delineo/delineation/above_ground.hpp"
#include "delineo/delineation/params.hpp"
#include "delineo/dem/enhance.hpp"
#include "delineo/segmentation/classify.hpp"
#include "delineo/segmentation/detect.hpp"
#include "delineo/segmentation/ground.hpp"
#include "delineo/segmentation/objects.hpp"
#include "delineo/stereo/match.hpp"

namespace delineo::gui {

using project::Building;
using project::BuildingStatus;

// The parameters dock: the selected building's roof interval on the histogram of its region of
// interest, above the tabs of the parameter forms.
void MainWindow::createParametersDock() {
  auto* paramsPage = new QWidget;
  auto* paramsLayout = new QVBoxLayout(paramsPage);
  paramsLayout->addWidget(createMethodChoice());
  auto* intervalTitle = new QLabel(tr("<b>Roof disparity interval</b> (drag on the histogram of the ROI; the line marks the ground)"));
  intervalTitle->setWordWrap(true);
  paramsLayout->addWidget(intervalTitle);
  histogram_ = new widgets::DisparityHistogramWidget;
  histogram_->setObjectName(QStringLiteral("histogram"));
  histogram_->setToolTip(tr("Disparities inside the region of interest of the selected building. "
                            "Drag the band or its handles to choose the roof interval [px]."));
  paramsLayout->addWidget(histogram_);
  intervalLabel_ = new QLabel;
  intervalLabel_->setObjectName(QStringLiteral("intervalLabel"));
  paramsLayout->addWidget(intervalLabel_);
  connect(histogram_, &widgets::DisparityHistogramWidget::intervalChanged, this, [this](int a, int b) {
    intervalLabel_->setText(tr("Roof: %1 .. %2 px").arg(a).arg(b));
  });
  connect(histogram_, &widgets::DisparityHistogramWidget::intervalEditingFinished, this, [this](int a, int b) {
    if (!document_ || selectedId_ <= 0) return;
    document_->setRoofInterval(selectedId_, {a, b});
    // A new interval for an outline nobody has edited yet: the active polygon runs again with it
    // (box-fitting does not read the interval).
    const Building* building = document_->project().find(selectedId_);
    if (building != nullptr && action(QStringLiteral("actionDelineateOnPick"))->isChecked() &&
        document_->project().methodOf(*building) == project::kActivePolygon &&
        (building->status == BuildingStatus::Pending || building->status == BuildingStatus::Automatic)) {
      startDelineation(selectedId_);
    }
  });
  paramsLayout->addWidget(createParameterTabs(), 1);
  addDock(QStringLiteral("parametersDock"), tr("Parameters"), paramsPage, Qt::LeftDockWidgetArea);
}

// The parameter forms, one tab per algorithm; the Matching tab starts with the pair's range.
QTabWidget* MainWindow::createParameterTabs() {
  auto* tabs = new QTabWidget;
  tabs->setObjectName(QStringLiteral("parameterTabs"));
  tabs->setUsesScrollButtons(true);
  addParameterGroup<delineation::DelineationParams>(tabs, "delineation", tr("Active polygon"), {});
  addParameterGroup<stereo::MatchParams>(tabs, "matching", tr("Matching"), {});
  addParameterGroup<boxfit::BoxFitParams>(
      tabs, "boxfit", tr("Box-fitting"),
      tr("Building → Box-fitting: the building's region from the DEM, boxes grown on the left image's edges."));
  addParameterGroup<dem::EnhanceParams>(
      tabs, "enhance", tr("Enhanced DEM"),
      tr("View → Enhanced DEM: vertical walls at the outlines and filtered roofs."));
  addParameterGroup<delineation::AboveGroundParams>(
      tabs, "pick", tr("Object pick"),
      tr("Pick an above-ground object: the raised object under a click, above the ground beside it."));
  addParameterGroup<segmentation::GroundParams>(
      tabs, project::kSegmentGroup, tr("Ground"),
      tr("Processing → Analyse the scene: regions of even height, ground or above ground, and the DTM under them."));
  addParameterGroup<segmentation::ClassifyParams>(
      tabs, project::kClassifyGroup, tr("Classes"),
      tr("The above-ground pieces as building or vegetation, from the left image's texture and colour."));
  addParameterGroup<segmentation::ObjectParams>(
      tabs, project::kObjectsGroup, tr("Objects"),
      tr("The above-ground objects of one class and their outlines (View → Objects)."));
  addParameterGroup<segmentation::DetectParams>(
      tabs, project::kDetectGroup, tr("Detection"),
      tr("Building → Detect buildings: which building objects become pending buildings."));
  addParameterGroup<segmentation::RoofLevelParams>(
      tabs, project::kRoofLevelsGroup, tr("Roof levels"),
      tr("A roof with several levels as one block per level in the 3D view and the CityJSON export."));
  return tabs;
}

// A tab with the form of one parameter group (the Matching tab has the pair's range above it).
// Each edit is written to the document at once, as one undoable step.
template <class Params>
void MainWindow::addParameterGroup(QTabWidget* tabs, const std::string& group, const QString& title,
                                   const QString& description) {
  auto* form = new widgets::ParameterForm;
  form->setObjectName(QString::fromStdString(group) + QStringLiteral("Form"));
  form->setParams(Params{});
  connect(form, &widgets::ParameterForm::changed, this, [this, group] {
    if (!updatingForms_) writeFormIntoDocument(group);
  });
  ParameterGroup entry{group, form,
                       [form, group](const project::Project& p) { form->setValues(project::parameters<Params>(p, group)); },
                       [form, group](Document& doc) {
                         auto params = project::parameters<Params>(doc.project(), group);
                         form->readInto(params);
                         doc.setParameters(group, core::toJson(params));
                       }};
  parameterGroups_.push_back(std::move(entry));

  auto* page = new QWidget;
  auto* layout = new QVBoxLayout(page);
  layout->setContentsMargins(0, 0, 0, 0);
  if (group == "matching") layout->addWidget(createRangeEditor());
  if (!description.isEmpty()) {
    auto* label = new QLabel(description);
    label->setWordWrap(true);
    label->setContentsMargins(6, 4, 6, 0);
    layout->addWidget(label);
  }
  layout->addWidget(form);
  layout->addStretch(1);
  auto* scroll = new QScrollArea;
  scroll->setWidget(page);
  scroll->setWidgetResizable(true);
  tabs->addTab(scroll, title);
}

widgets::ParameterForm* MainWindow::parameterForm(const std::string& group) const {
  for (const ParameterGroup& g : parameterGroups_) {
    if (g.group == group) return g.form;
  }
  return nullptr;
}

// The method that outlines a picked building (the project's `method`): the active polygon or
// box-fitting. Buildings that already name their method keep it.
QWidget* MainWindow::createMethodChoice() {
  auto* row = new QWidget;
  auto* layout = new QHBoxLayout(row);
  layout->setContentsMargins(0, 0, 0, 0);
  auto* label = new QLabel(tr("Outline with"));
  methodChoice_ = new QComboBox;
  methodChoice_->setObjectName(QStringLiteral("methodChoice"));
  methodChoice_->addItem(tr("active polygon"), QString::fromLatin1(project::kActivePolygon));
  methodChoice_->addItem(tr("box-fitting"), QString::fromLatin1(project::kBoxFitting));
  methodChoice_->setToolTip(tr("The method that outlines a picked building; box-fitting needs the DEM."));
  label->setBuddy(methodChoice_);
  layout->addWidget(label);
  layout->addWidget(methodChoice_, 1);
  connect(methodChoice_, &QComboBox::currentIndexChanged, this, [this] {
    if (!document_ || updatingForms_) return;
    document_->setMethod(methodChoice_->currentData().toString().toStdString());
  });
  return row;
}

void MainWindow::refreshHistogram() {
  histogram_->setValues({});
  histogram_->clearGroundLevel();
  intervalLabel_->clear();
  leftView_->polygons().setRoi({});
  const Building* b = document_ && selectedId_ > 0 ? document_->project().find(selectedId_) : nullptr;
  histogram_->setPlaceholder(b == nullptr ? tr("Select a building to see the disparities around it.") : QString());
  if (b == nullptr) return;
  const cv::Rect2d box = core::boundingBox(b->initial.outer);
  const int margin = project::parameters<delineation::DelineationParams>(document_->project(), "delineation").roiMargin;
  QRectF roi(box.x - margin, box.y - margin, box.width + 2 * margin, box.height + 2 * margin);
  roi &= QRectF(0, 0, document_->leftGrey().cols, document_->leftGrey().rows);
  leftView_->polygons().setRoi(roi);
  const cv::Mat& disparity = document_->disparity();
  if (disparity.empty()) {
    intervalLabel_->setText(tr("Compute the disparity to see the histogram."));
    return;
  }
  const cv::Rect r(static_cast<int>(roi.left()), static_cast<int>(roi.top()), static_cast<int>(roi.width()),
                   static_cast<int>(roi.height()));
  const cv::Mat roiDisparities = disparity(r & cv::Rect(0, 0, disparity.cols, disparity.rows));
  histogram_->setDisparities(roiDisparities);
  if (auto ground = project::suggestGroundLevel(disparity, b->initial)) histogram_->setGroundLevel(*ground);
  std::optional<project::DisparityInterval> interval = b->roofInterval;
  if (!interval) interval = project::suggestRoofInterval(disparity, b->initial);
  QString text;
  if (interval) {
    histogram_->setInterval(interval->low, interval->high);
    text = tr("Roof: %1 .. %2 px").arg(interval->low).arg(interval->high);
  }
  const QString warning = rangeEndWarning(roiDisparities);
  if (!warning.isEmpty()) {
    text += QStringLiteral("<br><span style=\"color:#b00000\">%1</span>").arg(warning.toHtmlEscaped());
    statusBar()->showMessage(warning, 15000);
  }
  intervalLabel_->setText(text);
}

QString MainWindow::rangeEndWarning(const cv::Mat& roiDisparities) const {
  const auto& range = document_->project().disparityRange;
  if (!range || roiDisparities.empty()) return {};
  // Matches piled up against an end of the searched range stand for disparities beyond it
  // (the matcher cannot return what it did not search).
  int finite = 0, atEnd = 0;
  for (int y = 0; y < roiDisparities.rows; ++y) {
    const float* row = roiDisparities.ptr<float>(y);
    for (int x = 0; x < roiDisparities.cols; ++x) {
      if (!std::isfinite(row[x])) continue;
      ++finite;
      if (row[x] >= static_cast<float>(range->high) - 1.0f || row[x] <= static_cast<float>(range->low) + 1.0f) ++atEnd;
    }
  }
  const double total = static_cast<double>(roiDisparities.total());
  if (finite > 0 && atEnd >= std::max(20.0, 0.02 * finite)) {
    return tr("%1 % of the disparities here lie at an end of the matched range (%2..%3 px): the roof may lie "
              "beyond it. Widen the range on the Matching tab and compute the disparity again.")
        .arg(100.0 * atEnd / finite, 0, 'f', 0)
        .arg(range->low)
        .arg(range->high);
  }
  if (finite < 0.5 * total) {
    return tr("Most of this region has no disparity: the roof may lie outside the matched range (%1..%2 px).")
        .arg(range->low)
        .arg(range->high);
  }
  return {};
}

QWidget* MainWindow::createRangeEditor() {
  auto* box = new QGroupBox(tr("Disparity search range of the pair"));
  box->setObjectName(QStringLiteral("rangeEditor"));
  auto* layout = new QGridLayout(box);
  rangeMin_ = new QSpinBox;
  rangeMin_->setObjectName(QStringLiteral("rangeMin"));
  rangeMax_ = new QSpinBox;
  rangeMax_->setObjectName(QStringLiteral("rangeMax"));
  for (QSpinBox* spin : {rangeMin_, rangeMax_}) {
    spin->setRange(-100000, 100000);
    spin->setSuffix(tr(" px"));
    spin->setKeyboardTracking(false);
  }
  rangeMin_->setToolTip(tr("Smallest disparity searched (x_right = x_left − d)"));
  rangeMax_->setToolTip(tr("Largest disparity searched; the roofs' disparities must lie below it"));
  layout->addWidget(new QLabel(tr("Minimum")), 0, 0);
  layout->addWidget(rangeMin_, 0, 1);
  layout->addWidget(new QLabel(tr("Maximum")), 0, 2);
  layout->addWidget(rangeMax_, 0, 3);
  auto* estimate = new QPushButton(tr("Estimate from the images"));
  estimate->setObjectName(QStringLiteral("estimateRange"));
  estimate->setToolTip(tr("Read the range from feature matches between the two images"));
  connect(estimate, &QPushButton::clicked, this, [this] { startRangeEstimate(false); });
  layout->addWidget(estimate, 1, 0, 1, 4);
  rangeNote_ = new QLabel;
  rangeNote_->setObjectName(QStringLiteral("rangeNote"));
  rangeNote_->setWordWrap(true);
  layout->addWidget(rangeNote_, 2, 0, 1, 4);
  auto commit = [this] {
    if (!document_ || updatingForms_) return;
    const int lo = rangeMin_->value(), hi = rangeMax_->value();
    if (lo > hi) {
      showMessage(tr("Disparity range"), tr("The minimum disparity must not exceed the maximum."));
      loadRangeFromDocument();
      return;
    }
    rangeSource_.clear();
    document_->setDisparityRange(project::DisparityInterval{lo, hi}, tr("Disparity range %1..%2 px").arg(lo).arg(hi));
  };
  connect(rangeMin_, &QSpinBox::valueChanged, this, commit);
  connect(rangeMax_, &QSpinBox::valueChanged, this, commit);
  return box;
}

void MainWindow::loadRangeFromDocument() {
  if (!document_) return;
  updatingForms_ = true;
  const auto& range = document_->project().disparityRange;
  rangeMin_->setValue(range ? range->low : 0);
  rangeMax_->setValue(range ? range->high : 0);
  updatingForms_ = false;
  const QString use = tr("Every computation (matching, the active polygon) searches this range; compute the "
                         "disparity again after changing it.");
  rangeNote_->setText(!range ? tr("Not set yet: estimated from the images when the disparity is computed.")
                             : rangeSource_.isEmpty() ? use : rangeSource_ + QLatin1Char(' ') + use);
}

void MainWindow::writeFormIntoDocument(const std::string& group) {
  if (!document_) return;
  // Only the edited form's group is written: one edit, one undo entry. Writing a group reloads
  // every form from the project; the others show their stored groups already (each edit is
  // written at once), so nothing of them is lost.
  for (const ParameterGroup& g : parameterGroups_) {
    if (g.group == group) g.write(*document_);
  }
}

void MainWindow::loadFormsFromDocument() {
  if (!document_) return;
  updatingForms_ = true;
  try {
    for (const ParameterGroup& g : parameterGroups_) g.load(document_->project());
  } catch (const core::Error& e) {
    showMessage(tr("Parameters"), errorMessage(e));
  }
  const int method = methodChoice_->findData(QString::fromStdString(document_->project().method));
  methodChoice_->setCurrentIndex(std::max(0, method));
  updatingForms_ = false;
}

}  // namespace delineo::gui
