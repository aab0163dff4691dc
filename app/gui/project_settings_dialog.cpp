#include "project_settings_dialog.hpp"

#include <QDialogButtonBox>
#include <QDir>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QRadioButton>
#include <QVBoxLayout>
#include <cmath>

namespace delineo::gui {

double metresPerPixelFromCamera(double base, double flyingHeight, double focalPx) {
  if (!(base > 0) || !(flyingHeight > 0) || !(focalPx > 0)) return 0.0;
  return flyingHeight * flyingHeight / (base * focalPx);
}

namespace {
QDoubleSpinBox* spinBox(const QString& name, double min, double max, int decimals,
                        const QString& suffix, const QString& tip) {
  auto* box = new QDoubleSpinBox;
  box->setObjectName(name);
  box->setRange(min, max);
  box->setDecimals(decimals);
  box->setSuffix(suffix);
  box->setToolTip(tip);
  return box;
}
}  // namespace

ProjectSettingsDialog::ProjectSettingsDialog(const project::Project& project,
                                             const QString& projectFolder,
                                             std::optional<double> groundSuggestion,
                                             QWidget* parent)
    : QDialog(parent), projectFolder_(projectFolder) {
  setObjectName(QStringLiteral("projectSettingsDialog"));
  setWindowTitle(tr("Project settings"));
  auto* layout = new QVBoxLayout(this);
  layout->addWidget(createOutputBox(project));
  layout->addWidget(createHeightModelBox(project, groundSuggestion));

  direct_->setChecked(true);
  for (QDoubleSpinBox* box : {base_, flyingHeight_, focal_}) {
    connect(box, &QDoubleSpinBox::valueChanged, this, [this] { updateCameraResult(); });
  }
  connect(direct_, &QRadioButton::toggled, this, [this] { updateEnabled(); });
  updateCameraResult();
  updateEnabled();

  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel);
  connect(buttons, &QDialogButtonBox::accepted, this, &QDialog::accept);
  connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
  layout->addWidget(buttons);
}

QGroupBox* ProjectSettingsDialog::createOutputBox(const project::Project& project) {
  auto* outputBox = new QGroupBox(tr("Outputs"));
  auto* outputRow = new QHBoxLayout(outputBox);
  outputDir_ = new QLineEdit(QString::fromStdString(project.outputDir));
  outputDir_->setObjectName(QStringLiteral("outputDir"));
  outputDir_->setToolTip(
      tr("Folder for the disparity map and exports; a relative folder is relative to the project "
         "file"));
  auto* browse = new QPushButton(tr("Browse…"));
  outputRow->addWidget(new QLabel(tr("Output folder")));
  outputRow->addWidget(outputDir_, 1);
  outputRow->addWidget(browse);
  connect(browse, &QPushButton::clicked, this, [this] {
    const QString chosen =
        QFileDialog::getExistingDirectory(this, tr("Output folder"), projectFolder_);
    if (chosen.isEmpty()) return;
    // Inside the project folder: stored relative, so it moves with the project.
    const QString relative =
        projectFolder_.isEmpty() ? QString() : QDir(projectFolder_).relativeFilePath(chosen);
    outputDir_->setText(!relative.isEmpty() && !relative.startsWith(QStringLiteral("..")) ? relative
                                                                                          : chosen);
  });
  return outputBox;
}

// The height model: the ground disparity, metres per pixel given directly or from the camera,
// then the ground sample distance and the ground level's elevation.
QGroupBox* ProjectSettingsDialog::createHeightModelBox(const project::Project& project,
                                                       std::optional<double> groundSuggestion) {
  auto* heightBox =
      new QGroupBox(tr("Height model: height = (disparity − ground disparity) × metres per pixel"));
  auto* heightLayout = new QVBoxLayout(heightBox);
  heightLayout->addLayout(createGroundDisparityForm(project, groundSuggestion));

  direct_ = new QRadioButton(tr("Metres of height per pixel of disparity"));
  direct_->setObjectName(QStringLiteral("modelDirect"));
  metresPerPixel_ = spinBox(QStringLiteral("metresPerPixel"), 0, 1000, 4, tr(" m/px"),
                            tr("Height difference of one pixel of disparity (0 = unknown)"));
  metresPerPixel_->setValue(project.height.metresPerPixel);
  heightLayout->addWidget(direct_);
  auto* directForm = new QFormLayout;
  directForm->addRow(tr("Metres per pixel"), metresPerPixel_);
  heightLayout->addLayout(directForm);

  camera_ = new QRadioButton(tr("From the camera: k = H² / (B · f)"));
  camera_->setObjectName(QStringLiteral("modelCamera"));
  heightLayout->addWidget(camera_);
  heightLayout->addLayout(createCameraForm());

  auto* gsdForm = new QFormLayout;
  gsd_ = spinBox(QStringLiteral("gsd"), 0.0001, 1000, 4, tr(" m"),
                 tr("Ground size of one image pixel (hillshade and 3D view)"));
  gsd_->setValue(project.height.gsd);
  gsdForm->addRow(tr("Ground sample distance"), gsd_);
  groundElevation_ = spinBox(QStringLiteral("groundElevation"), -10000, 10000, 2, tr(" m"),
                             tr("Elevation of the ground level above the vertical datum, added to the z of the CityJSON export"));
  groundElevation_->setValue(project.height.groundElevation);
  gsdForm->addRow(tr("Ground elevation"), groundElevation_);
  heightLayout->addLayout(gsdForm);
  return heightBox;
}

QFormLayout* ProjectSettingsDialog::createGroundDisparityForm(const project::Project& project,
                                                              std::optional<double> groundSuggestion) {
  auto* form = new QFormLayout;
  groundDisparity_ = spinBox(QStringLiteral("groundDisparity"), -100000, 100000, 2, tr(" px"),
                             tr("Disparity of the ground (height 0)"));
  groundDisparity_->setValue(project.height.groundDisparity);
  auto* groundRow = new QHBoxLayout;
  groundRow->addWidget(groundDisparity_, 1);
  if (groundSuggestion) {
    auto* fromMap =
        new QPushButton(tr("From the disparity map (%1 px)").arg(*groundSuggestion, 0, 'f', 1));
    fromMap->setObjectName(QStringLiteral("groundFromMap"));
    fromMap->setToolTip(tr("The ground level read from the disparity map"));
    connect(fromMap, &QPushButton::clicked, this,
            [this, g = *groundSuggestion] { groundDisparity_->setValue(g); });
    groundRow->addWidget(fromMap);
  }
  form->addRow(tr("Ground disparity"), groundRow);
  return form;
}

QFormLayout* ProjectSettingsDialog::createCameraForm() {
  base_ = spinBox(QStringLiteral("cameraBase"), 0, 1e6, 2, tr(" m"),
                  tr("Distance between the two exposures"));
  flyingHeight_ = spinBox(QStringLiteral("cameraHeight"), 0, 1e7, 1, tr(" m"),
                          tr("Flying height above the ground"));
  focal_ = spinBox(QStringLiteral("cameraFocal"), 0, 1e7, 1, tr(" px"),
                   tr("Focal length in pixels of the epipolar images"));
  auto* cameraForm = new QFormLayout;
  cameraForm->addRow(tr("Base B"), base_);
  cameraForm->addRow(tr("Flying height H"), flyingHeight_);
  cameraForm->addRow(tr("Focal length f"), focal_);
  cameraResult_ = new QLabel;
  cameraResult_->setObjectName(QStringLiteral("cameraResult"));
  cameraForm->addRow(QString(), cameraResult_);
  return cameraForm;
}

void ProjectSettingsDialog::setCamera(double base, double flyingHeight, double focalPx) {
  camera_->setChecked(true);
  base_->setValue(base);
  flyingHeight_->setValue(flyingHeight);
  focal_->setValue(focalPx);
}

void ProjectSettingsDialog::updateCameraResult() {
  const double k =
      metresPerPixelFromCamera(base_->value(), flyingHeight_->value(), focal_->value());
  if (k <= 0) {
    cameraResult_->setText(tr("Give B, H and f."));
    return;
  }
  const double gsd = flyingHeight_->value() / focal_->value();
  cameraResult_->setText(tr("k = (%1)² / (%2 × %3) = %4 m/px; ground sample distance H / f = %5 m")
                             .arg(flyingHeight_->value())
                             .arg(base_->value())
                             .arg(focal_->value())
                             .arg(k, 0, 'f', 4)
                             .arg(gsd, 0, 'f', 4));
  if (camera_->isChecked()) gsd_->setValue(gsd);
}

void ProjectSettingsDialog::updateEnabled() {
  const bool direct = direct_->isChecked();
  metresPerPixel_->setEnabled(direct);
  for (QDoubleSpinBox* box : {base_, flyingHeight_, focal_}) box->setEnabled(!direct);
  gsd_->setEnabled(direct);
  if (!direct) updateCameraResult();
}

std::string ProjectSettingsDialog::outputDir() const {
  const QString text = outputDir_->text().trimmed();
  return text.isEmpty() ? std::string("output") : text.toStdString();
}

project::HeightModel ProjectSettingsDialog::heightModel() const {
  project::HeightModel model;
  model.groundDisparity = groundDisparity_->value();
  model.metresPerPixel =
      direct_->isChecked()
          ? metresPerPixel_->value()
          : metresPerPixelFromCamera(base_->value(), flyingHeight_->value(), focal_->value());
  model.gsd = gsd_->value();
  model.groundElevation = groundElevation_->value();
  return model;
}

}  // namespace delineo::gui
