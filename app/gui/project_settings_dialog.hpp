#pragma once
// The project's settings an operator sets once per pair: where outputs go, and the height model
// that turns disparities into heights (the DEM, the 3D view and every roof height follow it).
#include <QDialog>
#include <optional>

#include "delineo/project/project.hpp"

class QButtonGroup;
class QDoubleSpinBox;
class QFormLayout;
class QGroupBox;
class QLabel;
class QLineEdit;
class QPushButton;
class QRadioButton;

namespace delineo::gui {

// Metres of height per pixel of disparity for a near-nadir pair taken from flying height H (m)
// above the ground with base B (m) and focal length f (px): k = H² / (B·f) (first order in
// height / H). 0 when an input is not positive.
double metresPerPixelFromCamera(double base, double flyingHeight, double focalPx);

class ProjectSettingsDialog : public QDialog {
  Q_OBJECT
 public:
  // `groundSuggestion`: the ground disparity read from the disparity map (offered by a button).
  ProjectSettingsDialog(const project::Project& project, const QString& projectFolder,
                        std::optional<double> groundSuggestion, QWidget* parent = nullptr);

  std::string outputDir() const;
  project::HeightModel heightModel() const;

  // The camera inputs (the second way of giving the model); for tests.
  void setCamera(double base, double flyingHeight, double focalPx);

 private:
  QGroupBox* createOutputBox(const project::Project& project);
  QGroupBox* createHeightModelBox(const project::Project& project, std::optional<double> groundSuggestion);
  QFormLayout* createGroundDisparityForm(const project::Project& project, std::optional<double> groundSuggestion);
  QFormLayout* createCameraForm();
  void updateCameraResult();
  void updateEnabled();

  QString projectFolder_;
  QLineEdit* outputDir_ = nullptr;
  QRadioButton* direct_ = nullptr;
  QRadioButton* camera_ = nullptr;
  QDoubleSpinBox* groundDisparity_ = nullptr;
  QDoubleSpinBox* metresPerPixel_ = nullptr;
  QDoubleSpinBox* base_ = nullptr;
  QDoubleSpinBox* flyingHeight_ = nullptr;
  QDoubleSpinBox* focal_ = nullptr;
  QLabel* cameraResult_ = nullptr;
  QDoubleSpinBox* gsd_ = nullptr;
  QDoubleSpinBox* groundElevation_ = nullptr;
};

}  // namespace delineo::gui
