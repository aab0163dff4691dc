#pragma once
// 3D view of a DEM with VTK: a height-field surface (NaN = holes) coloured by height or draped
// with a grey texture, plus building outlines extruded between a base and a top height.
//
// Two rendering backends, chosen from QGuiApplication::platformName() (see
// docs/qt6-vtk-facts.md): under X, a QOpenGLWidget driving a vtkGenericOpenGLRenderWindow; on
// the "offscreen" platform (where Qt 6.4 crashes with QOpenGLWidget), VTK renders offscreen and
// the pixels are painted by a plain QWidget with Qt events forwarded to the VTK interactor.
// Both need an X server for VTK (run tests under xvfb-run).
//
// Large DEMs are subsampled so that at most ~500 x 500 grid nodes are displayed, and a coarser
// mesh (~160 x 160) is shown while a mouse button is held.
#include <QImage>
#include <QWidget>
#include <memory>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/widgets/colour_maps.hpp"

namespace delineo::widgets {

struct BuildingOutline {
  core::Polygon polygon;  // DEM pixels (x right, y down)
  double baseHeight = 0.0;  // m
  double topHeight = 0.0;   // m
};

class Terrain3DView : public QWidget {
  Q_OBJECT
 public:
  enum class Backend { OpenGLWidget, Offscreen };
  // The backend this platform gets.
  static Backend preferredBackend();
  // Sets the default QSurfaceFormat VTK needs (OpenGL 3.2 core, depth 24, stencil 8). Call it in
  // main() BEFORE the QApplication is created; harmless on the offscreen platform.
  static void setDefaultSurfaceFormat();

  explicit Terrain3DView(QWidget* parent = nullptr);
  ~Terrain3DView() override;
  Backend backend() const { return backend_; }

  // DEM heights (CV_32F or CV_64F, metres, NaN = no data) with ground sample distance `gsd`
  // (m/px). The data is shared, not copied. Resets the camera when the size changes.
  void setDem(const cv::Mat& dem, double gsd);
  // Grey texture (CV_8U, any size; stretched over the DEM extent); empty = colour by height.
  void setTexture(const cv::Mat& grey);
  void setColourMap(ColourMap map);
  void setBuildings(const std::vector<BuildingOutline>& buildings);
  // The blocks shown (one per building, or per roof part), as last set.
  const std::vector<BuildingOutline>& buildings() const;
  void setVerticalExaggeration(double factor);
  double verticalExaggeration() const;
  // A vertical exaggeration that makes the relief readable: 1 when the height range (lowest to
  // highest finite height) is at least a tenth of the DEM's horizontal extent (towns: buildings
  // carry the relief), more for flat terrain (up to 5), in steps of 0.5.
  static double suggestedExaggeration(const cv::Mat& dem, double gsd);
  // Looks at the whole DEM from the south, 40° above the horizon.
  void resetCamera();
  // Same viewing direction, framed on a region of the DEM (pixels) and its heights, e.g. the
  // selected building with some surroundings. An empty or outside region frames the whole DEM.
  void frameRegion(const cv::Rect2d& demPixels);

  // Grid actually displayed (after subsampling); {0, 0} without a DEM.
  cv::Size displayedGridSize() const;
  // Grid shown while interacting (coarser).
  cv::Size interactiveGridSize() const;
  // Renders the current scene and returns it (works with both backends).
  QImage renderImage();

 protected:
  void resizeEvent(QResizeEvent* event) override;

 private:
  class Scene;
  class GLSurface;
  class OffscreenSurface;
  friend class GLSurface;
  friend class OffscreenSurface;
  void setInteracting(bool interacting);
  void sceneChanged();

  Backend backend_;
  std::unique_ptr<Scene> scene_;
  QWidget* surface_ = nullptr;
};

}  // namespace delineo::widgets
