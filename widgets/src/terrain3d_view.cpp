#include "delineo/widgets/terrain3d_view.hpp"

#include <QGuiApplication>
#include <QMouseEvent>
#include <QOpenGLContext>
#include <QOpenGLExtraFunctions>
#include <QOpenGLWidget>
#include <QPainter>
#include <QSurfaceFormat>
#include <QTimer>
#include <QVBoxLayout>
#include <QWheelEvent>
#include <algorithm>
#include <cmath>
#include <optional>

#include <vtkActor.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkFloatArray.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkGenericRenderWindowInteractor.h>
#include <vtkImageData.h>
#include <vtkInteractorStyleTerrain.h>
#include <vtkLookupTable.h>
#include <vtkNew.h>
#include <vtkOpenGLFramebufferObject.h>
#include <vtkOpenGLState.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkTexture.h>
#include <vtkUnsignedCharArray.h>

#include <opencv2/imgproc.hpp>

namespace delineo::widgets {
namespace {

constexpr int kDisplayGrid = 500;      // max grid nodes per side shown at rest
constexpr int kInteractiveGrid = 160;  // max grid nodes per side while the mouse is held

int stepFor(const cv::Size& size, int maxNodes) {
  const int longest = std::max(size.width, size.height);
  return std::max(1, (longest + maxNodes - 1) / maxNodes);
}

cv::Size gridFor(const cv::Size& size, int step) {
  return {(size.width + step - 1) / step, (size.height + step - 1) / step};
}

}  // namespace

// --- scene: VTK pipeline shared by both backends -----------------------------------------------

class Terrain3DView::Scene {
 public:
  Scene() {
    renderer->SetBackground(0.16, 0.18, 0.22);
    renderer->SetBackground2(0.45, 0.52, 0.62);
    renderer->GradientBackgroundOn();
    surfaceActor->SetMapper(surfaceMapper);
    surfaceActor->GetProperty()->SetAmbient(0.25);
    surfaceActor->GetProperty()->SetDiffuse(0.8);
    renderer->AddActor(surfaceActor);
    wallActor->SetMapper(wallMapper);
    wallActor->GetProperty()->SetColor(0.95, 0.85, 0.6);
    wallActor->GetProperty()->SetOpacity(0.55);
    renderer->AddActor(wallActor);
    outlineActor->SetMapper(outlineMapper);
    outlineActor->GetProperty()->SetColor(1.0, 0.25, 0.1);
    outlineActor->GetProperty()->SetLineWidth(2.5);
    outlineActor->GetProperty()->LightingOff();
    renderer->AddActor(outlineActor);
    surfaceMapper->SetLookupTable(lut);
    surfaceMapper->SetScalarModeToUsePointData();
    surfaceMapper->SetColorModeToMapScalars();
    setColourMap(ColourMap::Terrain);
  }

  void setColourMap(ColourMap map) {
    colourMap = map;
    lut->SetNumberOfTableValues(256);
    for (int i = 0; i < 256; ++i) {
      const QColor c = mapColour(map, i / 255.0);
      lut->SetTableValue(i, c.redF(), c.greenF(), c.blueF(), 1.0);
    }
    lut->Modified();
  }

  // Height field of the DEM sampled every `step` pixels. Points are at pixel centres in metres:
  // x east = column, y north = -row, z up = height x exaggeration.
  vtkSmartPointer<vtkPolyData> buildMesh(int step) const {
    const cv::Size grid = gridFor(dem.size(), step);
    auto points = vtkSmartPointer<vtkPoints>::New();
    points->SetDataTypeToFloat();
    points->SetNumberOfPoints(static_cast<vtkIdType>(grid.area()));
    auto heights = vtkSmartPointer<vtkFloatArray>::New();
    heights->SetName("height");
    heights->SetNumberOfValues(static_cast<vtkIdType>(grid.area()));
    auto tcoords = vtkSmartPointer<vtkFloatArray>::New();
    tcoords->SetNumberOfComponents(2);
    tcoords->SetNumberOfTuples(static_cast<vtkIdType>(grid.area()));
    std::vector<uint8_t> valid(static_cast<size_t>(grid.area()), 0);
    for (int gy = 0; gy < grid.height; ++gy) {
      const int row = std::min(gy * step, dem.rows - 1);
      const float* line = dem.ptr<float>(row);
      for (int gx = 0; gx < grid.width; ++gx) {
        const int col = std::min(gx * step, dem.cols - 1);
        const float h = line[col];
        const vtkIdType id = static_cast<vtkIdType>(gy) * grid.width + gx;
        const bool ok = std::isfinite(h);
        valid[static_cast<size_t>(id)] = ok ? 1 : 0;
        const double z = ok ? h * exaggeration : heightMin * exaggeration;
        points->SetPoint(id, (col + 0.5) * gsd, -(row + 0.5) * gsd, z);
        heights->SetValue(id, ok ? h : static_cast<float>(heightMin));
        tcoords->SetTuple2(id, (col + 0.5) / dem.cols, 1.0 - (row + 0.5) / dem.rows);
      }
    }
    auto triangles = vtkSmartPointer<vtkCellArray>::New();
    for (int gy = 0; gy + 1 < grid.height; ++gy) {
      for (int gx = 0; gx + 1 < grid.width; ++gx) {
        const vtkIdType a = static_cast<vtkIdType>(gy) * grid.width + gx;
        const vtkIdType b = a + 1;
        const vtkIdType c = a + grid.width;
        const vtkIdType d = c + 1;
        // Holes: only triangles whose three corners have data.
        if (valid[a] && valid[c] && valid[b]) {
          const vtkIdType tri[3] = {a, c, b};
          triangles->InsertNextCell(3, tri);
        }
        if (valid[b] && valid[c] && valid[d]) {
          const vtkIdType tri[3] = {b, c, d};
          triangles->InsertNextCell(3, tri);
        }
      }
    }
    auto mesh = vtkSmartPointer<vtkPolyData>::New();
    mesh->SetPoints(points);
    mesh->SetPolys(triangles);
    mesh->GetPointData()->SetScalars(heights);
    mesh->GetPointData()->SetTCoords(tcoords);
    return mesh;
  }

  void rebuildSurface() {
    if (dem.empty()) {
      fineMesh = coarseMesh = nullptr;
      surfaceMapper->SetInputData(vtkSmartPointer<vtkPolyData>::New());
      return;
    }
    fineStep = stepFor(dem.size(), kDisplayGrid);
    coarseStep = stepFor(dem.size(), kInteractiveGrid);
    fineMesh = buildMesh(fineStep);
    coarseMesh = coarseStep == fineStep ? fineMesh : buildMesh(coarseStep);
    surfaceMapper->SetScalarRange(heightMin, heightMax);
    applyMode();
  }

  void applyMode() {
    if (fineMesh == nullptr) return;
    surfaceMapper->SetInputData(interacting ? coarseMesh : fineMesh);
  }

  void setTexture(const cv::Mat& grey) {
    if (grey.empty()) {
      surfaceActor->SetTexture(nullptr);
      surfaceMapper->ScalarVisibilityOn();
      surfaceActor->GetProperty()->SetColor(1, 1, 1);
      return;
    }
    cv::Mat image8;
    if (grey.depth() == CV_8U) {
      image8 = grey.channels() == 1 ? grey : cv::Mat();
      if (grey.channels() == 3) cv::cvtColor(grey, image8, cv::COLOR_BGR2GRAY);
    } else {
      cv::normalize(grey, image8, 0, 255, cv::NORM_MINMAX, CV_8U);
    }
    // Textures wider than the displayed grid only cost memory: cap at 2048 px.
    const int longest = std::max(image8.cols, image8.rows);
    if (longest > 2048) {
      const double s = 2048.0 / longest;
      cv::resize(image8, image8, cv::Size(), s, s, cv::INTER_AREA);
    }
    auto image = vtkSmartPointer<vtkImageData>::New();
    image->SetDimensions(image8.cols, image8.rows, 1);
    image->AllocateScalars(VTK_UNSIGNED_CHAR, 1);
    for (int y = 0; y < image8.rows; ++y) {
      // VTK images start at the bottom row.
      auto* dst = static_cast<unsigned char*>(image->GetScalarPointer(0, image8.rows - 1 - y, 0));
      std::copy_n(image8.ptr<uchar>(y), image8.cols, dst);
    }
    auto texture = vtkSmartPointer<vtkTexture>::New();
    texture->SetInputData(image);
    texture->InterpolateOn();
    surfaceActor->SetTexture(texture);
    surfaceMapper->ScalarVisibilityOff();
    surfaceActor->GetProperty()->SetColor(1, 1, 1);
  }

  void rebuildBuildings() {
    auto points = vtkSmartPointer<vtkPoints>::New();
    auto walls = vtkSmartPointer<vtkCellArray>::New();
    auto lines = vtkSmartPointer<vtkCellArray>::New();
    auto addRing = [&](const core::Ring& ring, double base, double top) {
      const size_t n = ring.size();
      if (n < 2) return;
      std::vector<vtkIdType> bottomIds(n);
      std::vector<vtkIdType> topIds(n);
      for (size_t i = 0; i < n; ++i) {
        const double x = ring[i].x * gsd;
        const double y = -ring[i].y * gsd;
        bottomIds[i] = points->InsertNextPoint(x, y, base * exaggeration);
        topIds[i] = points->InsertNextPoint(x, y, top * exaggeration);
      }
      for (size_t i = 0; i < n; ++i) {
        const size_t j = (i + 1) % n;
        const vtkIdType quad[4] = {bottomIds[i], bottomIds[j], topIds[j], topIds[i]};
        walls->InsertNextCell(4, quad);
      }
      std::vector<vtkIdType> loop(topIds);
      loop.push_back(topIds.front());
      lines->InsertNextCell(static_cast<vtkIdType>(loop.size()), loop.data());
    };
    for (const BuildingOutline& b : buildings) {
      addRing(b.polygon.outer, b.baseHeight, b.topHeight);
      for (const core::Ring& hole : b.polygon.holes) addRing(hole, b.baseHeight, b.topHeight);
    }
    auto wallData = vtkSmartPointer<vtkPolyData>::New();
    wallData->SetPoints(points);
    wallData->SetPolys(walls);
    wallMapper->SetInputData(wallData);
    auto lineData = vtkSmartPointer<vtkPolyData>::New();
    lineData->SetPoints(points);
    lineData->SetLines(lines);
    outlineMapper->SetInputData(lineData);
  }

  void resetCamera() { frameRegion(cv::Rect2d(0, 0, dem.cols, dem.rows)); }

  // Frames the box of `region` (DEM pixels) between the lowest and highest finite height in it.
  void frameRegion(cv::Rect2d region) {
    if (dem.empty()) return;
    region &= cv::Rect2d(0, 0, dem.cols, dem.rows);
    if (region.width < 1 || region.height < 1) region = cv::Rect2d(0, 0, dem.cols, dem.rows);
    const cv::Rect pixels = cv::Rect(static_cast<int>(region.x), static_cast<int>(region.y),
                                     std::max(1, static_cast<int>(std::ceil(region.width))),
                                     std::max(1, static_cast<int>(std::ceil(region.height)))) &
                            cv::Rect(0, 0, dem.cols, dem.rows);
    auto [lo, hi] = finiteRange(dem(pixels));
    if (std::isnan(lo)) {
      lo = heightMin;
      hi = heightMax;
    }
    for (const BuildingOutline& b : buildings) {
      const cv::Rect2d box = core::boundingBox(b.polygon.outer);
      if ((box & region).area() > 0) hi = std::max(hi, b.topHeight);
    }
    const double bounds[6] = {region.x * gsd, (region.x + region.width) * gsd,
                              -(region.y + region.height) * gsd, -region.y * gsd,
                              lo * exaggeration, hi * exaggeration};
    const double cx = 0.5 * (bounds[0] + bounds[1]);
    const double cy = 0.5 * (bounds[2] + bounds[3]);
    const double cz = 0.5 * (bounds[4] + bounds[5]);
    vtkCamera* camera = renderer->GetActiveCamera();
    // Looking north from the south, 40° above the horizon: relief reads well with Z up.
    camera->SetFocalPoint(cx, cy, cz);
    camera->SetPosition(cx, cy - std::cos(kElevation), cz + std::sin(kElevation));
    camera->SetViewUp(0, 0, 1);
    // Fits the box's bounding sphere (VTK accounts for the aspect ratio); the sphere is loose
    // around a flat box, so come a little closer.
    renderer->ResetCamera(bounds);
    camera->Dolly(1.2);
    framed = region;
    renderer->ResetCameraClippingRange();
  }
  static constexpr double kElevation = 40.0 * 3.14159265358979323846 / 180.0;

  vtkNew<vtkRenderer> renderer;
  vtkNew<vtkActor> surfaceActor;
  vtkNew<vtkPolyDataMapper> surfaceMapper;
  vtkNew<vtkActor> wallActor;
  vtkNew<vtkPolyDataMapper> wallMapper;
  vtkNew<vtkActor> outlineActor;
  vtkNew<vtkPolyDataMapper> outlineMapper;
  vtkNew<vtkLookupTable> lut;
  vtkSmartPointer<vtkPolyData> fineMesh;
  vtkSmartPointer<vtkPolyData> coarseMesh;
  int fineStep = 1;
  int coarseStep = 1;
  cv::Mat dem;  // CV_32F
  double gsd = 1.0;
  double heightMin = 0.0;
  double heightMax = 1.0;
  double exaggeration = 1.0;
  bool interacting = false;
  // The region last framed, until the operator moves the camera: a resize frames it again (the
  // first framing often happens before the widget has its final size).
  std::optional<cv::Rect2d> framed;
  ColourMap colourMap = ColourMap::Terrain;
  std::vector<BuildingOutline> buildings;
};

// --- event forwarding shared by both surfaces --------------------------------------------------

namespace {

void forwardMouse(vtkRenderWindowInteractor* iren, QWidget* w, QMouseEvent* e, bool press, bool release) {
  const double dpr = w->devicePixelRatioF();
  const int ctrl = (e->modifiers() & Qt::ControlModifier) ? 1 : 0;
  const int shift = (e->modifiers() & Qt::ShiftModifier) ? 1 : 0;
  iren->SetEventInformationFlipY(static_cast<int>(e->position().x() * dpr),
                                 static_cast<int>(e->position().y() * dpr), ctrl, shift, 0,
                                 e->type() == QEvent::MouseButtonDblClick ? 1 : 0);
  if (press) {
    switch (e->button()) {
      case Qt::LeftButton: iren->LeftButtonPressEvent(); break;
      case Qt::MiddleButton: iren->MiddleButtonPressEvent(); break;
      case Qt::RightButton: iren->RightButtonPressEvent(); break;
      default: break;
    }
  } else if (release) {
    switch (e->button()) {
      case Qt::LeftButton: iren->LeftButtonReleaseEvent(); break;
      case Qt::MiddleButton: iren->MiddleButtonReleaseEvent(); break;
      case Qt::RightButton: iren->RightButtonReleaseEvent(); break;
      default: break;
    }
  } else {
    iren->MouseMoveEvent();
  }
}

void forwardWheel(vtkRenderWindowInteractor* iren, QWidget* w, QWheelEvent* e) {
  const double dpr = w->devicePixelRatioF();
  iren->SetEventInformationFlipY(static_cast<int>(e->position().x() * dpr),
                                 static_cast<int>(e->position().y() * dpr),
                                 (e->modifiers() & Qt::ControlModifier) ? 1 : 0,
                                 (e->modifiers() & Qt::ShiftModifier) ? 1 : 0);
  if (e->angleDelta().y() > 0) iren->MouseWheelForwardEvent();
  if (e->angleDelta().y() < 0) iren->MouseWheelBackwardEvent();
}

}  // namespace

// --- backend 1: QOpenGLWidget + vtkGenericOpenGLRenderWindow (X/GLX) ----------------------------

class Terrain3DView::GLSurface : public QOpenGLWidget {
 public:
  GLSurface(Terrain3DView* owner, Scene* scene) : QOpenGLWidget(owner), owner_(owner) {
    window_->SetOwnContext(false);
    window_->SetFrameBlitModeToNoBlit();
    window_->SetMultiSamples(0);
    window_->AddRenderer(scene->renderer);
    interactor_->SetRenderWindow(window_);
    interactor_->SetInteractorStyle(style_);
    interactor_->EnableRenderOff();  // renders go through paintGL
    addObserver(interactor_, vtkCommand::RenderEvent);
    addObserver(window_, vtkCommand::WindowMakeCurrentEvent);
    addObserver(window_, vtkCommand::WindowIsCurrentEvent);
    addObserver(window_, vtkCommand::WindowSupportsOpenGLEvent);
    addObserver(window_, vtkCommand::WindowIsDirectEvent);
    addObserver(window_, vtkCommand::WindowFrameEvent);
    setFocusPolicy(Qt::StrongFocus);
    setMouseTracking(false);
  }

  ~GLSurface() override {
    makeCurrent();
    window_->Finalize();  // releases VTK's GL resources while the context still exists
    doneCurrent();
  }

  QImage grabImage() { return grabFramebuffer(); }

 protected:
  void initializeGL() override {
    window_->SetSize(pixelWidth(), pixelHeight());
    window_->OpenGLInitContext();
    interactor_->UpdateSize(pixelWidth(), pixelHeight());
    interactor_->Enable();
  }

  void resizeGL(int, int) override {
    window_->SetSize(pixelWidth(), pixelHeight());
    interactor_->UpdateSize(pixelWidth(), pixelHeight());
  }

  void paintGL() override {
    vtkOpenGLState* state = window_->GetState();
    state->Reset();
    state->Push();
    state->vtkglDepthFunc(GL_LEQUAL);  // Qt leaves GL_LESS; VTK expects LEQUAL
    window_->Render();
    state->Pop();

    QOpenGLExtraFunctions* f = context()->extraFunctions();
    const int w = pixelWidth();
    const int h = pixelHeight();
    state->PushFramebufferBindings();
    window_->GetDisplayFramebuffer()->Bind(GL_READ_FRAMEBUFFER);
    window_->GetDisplayFramebuffer()->ActivateReadBuffer(0);
    f->glBindFramebuffer(GL_DRAW_FRAMEBUFFER, defaultFramebufferObject());
    f->glBlitFramebuffer(0, 0, w, h, 0, 0, w, h, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    state->PopFramebufferBindings();
    // Qt composites the widget with its alpha: force it opaque.
    f->glBindFramebuffer(GL_FRAMEBUFFER, defaultFramebufferObject());
    f->glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_TRUE);
    f->glClearColor(0, 0, 0, 1);
    f->glClear(GL_COLOR_BUFFER_BIT);
    f->glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  }

  void mousePressEvent(QMouseEvent* e) override {
    owner_->setInteracting(true);
    forwardMouse(interactor_, this, e, true, false);
  }
  void mouseReleaseEvent(QMouseEvent* e) override {
    forwardMouse(interactor_, this, e, false, true);
    if (e->buttons() == Qt::NoButton) owner_->setInteracting(false);
  }
  void mouseMoveEvent(QMouseEvent* e) override { forwardMouse(interactor_, this, e, false, false); }
  void wheelEvent(QWheelEvent* e) override { forwardWheel(interactor_, this, e); }

 private:
  int pixelWidth() const { return std::max(1, static_cast<int>(width() * devicePixelRatioF())); }
  int pixelHeight() const { return std::max(1, static_cast<int>(height() * devicePixelRatioF())); }

  void addObserver(vtkObject* object, unsigned long event) {
    vtkNew<vtkCallbackCommand> command;
    command->SetClientData(this);
    command->SetCallback(&GLSurface::onVtkEvent);
    object->AddObserver(event, command);
  }

  static void onVtkEvent(vtkObject*, unsigned long event, void* clientData, void* callData) {
    auto* self = static_cast<GLSurface*>(clientData);
    switch (event) {
      case vtkCommand::RenderEvent: self->update(); break;
      case vtkCommand::WindowMakeCurrentEvent:
        // Re-binding when already current would redirect VTK's framebuffer set-up into Qt's
        // framebuffer (GL error 0x506, black view): only make current when needed.
        if (QOpenGLContext::currentContext() != self->context()) self->makeCurrent();
        break;
      case vtkCommand::WindowIsCurrentEvent:
        *static_cast<bool*>(callData) = QOpenGLContext::currentContext() == self->context();
        break;
      case vtkCommand::WindowSupportsOpenGLEvent: *static_cast<int*>(callData) = 1; break;
      case vtkCommand::WindowIsDirectEvent: *static_cast<int*>(callData) = 1; break;
      case vtkCommand::WindowFrameEvent: break;  // Qt swaps buffers itself
      default: break;
    }
  }

  Terrain3DView* owner_;
  vtkNew<vtkGenericOpenGLRenderWindow> window_;
  vtkNew<vtkGenericRenderWindowInteractor> interactor_;
  vtkNew<vtkInteractorStyleTerrain> style_;
};

// --- backend 2: VTK offscreen → QImage in a plain QWidget (Qt "offscreen" platform) -----------

class Terrain3DView::OffscreenSurface : public QWidget {
 public:
  OffscreenSurface(Terrain3DView* owner, Scene* scene) : QWidget(owner), owner_(owner) {
    window_->SetOffScreenRendering(1);
    window_->SetMultiSamples(0);
    window_->AddRenderer(scene->renderer);
    window_->SetSize(320, 240);
    interactor_->SetRenderWindow(window_);
    interactor_->SetInteractorStyle(style_);
    interactor_->EnableRenderOff();
    vtkNew<vtkCallbackCommand> command;
    command->SetClientData(this);
    command->SetCallback([](vtkObject*, unsigned long, void* clientData, void*) {
      auto* self = static_cast<OffscreenSurface*>(clientData);
      self->dirty_ = true;
      self->update();
    });
    interactor_->AddObserver(vtkCommand::RenderEvent, command);
    interactor_->UpdateSize(320, 240);
    interactor_->Enable();
    setAttribute(Qt::WA_OpaquePaintEvent);
    setFocusPolicy(Qt::StrongFocus);
  }

  ~OffscreenSurface() override { window_->Finalize(); }

  void markDirty() {
    dirty_ = true;
    update();
  }

  QImage renderNow() {
    const int w = std::max(1, static_cast<int>(width() * devicePixelRatioF()));
    const int h = std::max(1, static_cast<int>(height() * devicePixelRatioF()));
    window_->SetSize(w, h);
    interactor_->UpdateSize(w, h);
    window_->Render();
    vtkNew<vtkUnsignedCharArray> pixels;
    window_->GetRGBACharPixelData(0, 0, w - 1, h - 1, 0, pixels);
    QImage image(w, h, QImage::Format_RGBA8888);
    const unsigned char* src = pixels->GetPointer(0);
    for (int y = 0; y < h; ++y) {
      // VTK rows start at the bottom.
      std::copy_n(src + static_cast<size_t>(h - 1 - y) * w * 4, static_cast<size_t>(w) * 4, image.scanLine(y));
    }
    // Qt paints with the alpha; the rendered scene is opaque.
    for (int y = 0; y < h; ++y) {
      uchar* line = image.scanLine(y);
      for (int x = 0; x < w; ++x) line[4 * x + 3] = 255;
    }
    image.setDevicePixelRatio(devicePixelRatioF());
    image_ = image;
    dirty_ = false;
    return image_;
  }

 protected:
  void paintEvent(QPaintEvent*) override {
    if (dirty_ || image_.size() != size() * devicePixelRatioF()) renderNow();
    QPainter painter(this);
    painter.drawImage(QPointF(0, 0), image_);
  }
  void resizeEvent(QResizeEvent*) override { markDirty(); }
  void mousePressEvent(QMouseEvent* e) override {
    owner_->setInteracting(true);
    syncSize();
    forwardMouse(interactor_, this, e, true, false);
  }
  void mouseReleaseEvent(QMouseEvent* e) override {
    forwardMouse(interactor_, this, e, false, true);
    if (e->buttons() == Qt::NoButton) owner_->setInteracting(false);
  }
  void mouseMoveEvent(QMouseEvent* e) override { forwardMouse(interactor_, this, e, false, false); }
  void wheelEvent(QWheelEvent* e) override {
    syncSize();
    forwardWheel(interactor_, this, e);
  }

 private:
  void syncSize() {
    const int w = std::max(1, static_cast<int>(width() * devicePixelRatioF()));
    const int h = std::max(1, static_cast<int>(height() * devicePixelRatioF()));
    window_->SetSize(w, h);
    interactor_->UpdateSize(w, h);
  }

  Terrain3DView* owner_;
  vtkNew<vtkRenderWindow> window_;
  vtkNew<vtkGenericRenderWindowInteractor> interactor_;
  vtkNew<vtkInteractorStyleTerrain> style_;
  QImage image_;
  bool dirty_ = true;
};

// --- the view ----------------------------------------------------------------------------------

Terrain3DView::Backend Terrain3DView::preferredBackend() {
  return QGuiApplication::platformName() == QLatin1String("offscreen") ? Backend::Offscreen
                                                                       : Backend::OpenGLWidget;
}

void Terrain3DView::setDefaultSurfaceFormat() {
  QSurfaceFormat format;
  format.setRenderableType(QSurfaceFormat::OpenGL);
  format.setVersion(3, 2);
  format.setProfile(QSurfaceFormat::CoreProfile);
  format.setDepthBufferSize(24);
  format.setStencilBufferSize(8);
  format.setSamples(0);
  QSurfaceFormat::setDefaultFormat(format);
}

Terrain3DView::Terrain3DView(QWidget* parent)
    : QWidget(parent), backend_(preferredBackend()), scene_(std::make_unique<Scene>()) {
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  if (backend_ == Backend::OpenGLWidget) {
    surface_ = new GLSurface(this, scene_.get());
  } else {
    surface_ = new OffscreenSurface(this, scene_.get());
  }
  layout->addWidget(surface_);
  setMinimumSize(160, 120);
}

Terrain3DView::~Terrain3DView() {
  // The surfaces hold render windows that reference the scene's renderer: delete them first.
  delete surface_;
  surface_ = nullptr;
}

void Terrain3DView::sceneChanged() {
  if (backend_ == Backend::Offscreen) {
    static_cast<OffscreenSurface*>(surface_)->markDirty();
  } else {
    surface_->update();
  }
}

void Terrain3DView::setDem(const cv::Mat& dem, double gsd) {
  const cv::Size previous = scene_->dem.size();
  if (dem.empty()) {
    scene_->dem = cv::Mat();
  } else {
    CV_Assert(dem.channels() == 1);
    if (dem.depth() == CV_32F) {
      scene_->dem = dem;
    } else {
      dem.convertTo(scene_->dem, CV_32F);
    }
  }
  scene_->gsd = gsd > 0 ? gsd : 1.0;
  const auto [lo, hi] = finiteRange(scene_->dem.empty() ? cv::Mat(1, 1, CV_32F, cv::Scalar(0)) : scene_->dem);
  scene_->heightMin = std::isnan(lo) ? 0.0 : lo;
  scene_->heightMax = std::isnan(hi) ? 1.0 : std::max(hi, lo + 1e-6);
  scene_->rebuildSurface();
  scene_->rebuildBuildings();
  if (previous != scene_->dem.size()) scene_->resetCamera();
  sceneChanged();
}

void Terrain3DView::setTexture(const cv::Mat& grey) {
  scene_->setTexture(grey);
  sceneChanged();
}

void Terrain3DView::setColourMap(ColourMap map) {
  scene_->setColourMap(map);
  sceneChanged();
}

void Terrain3DView::setBuildings(const std::vector<BuildingOutline>& buildings) {
  scene_->buildings = buildings;
  scene_->rebuildBuildings();
  sceneChanged();
}

const std::vector<BuildingOutline>& Terrain3DView::buildings() const { return scene_->buildings; }

void Terrain3DView::setVerticalExaggeration(double factor) {
  scene_->exaggeration = factor > 0 ? factor : 1.0;
  scene_->rebuildSurface();
  scene_->rebuildBuildings();
  scene_->resetCamera();
  sceneChanged();
}

void Terrain3DView::resetCamera() {
  scene_->resetCamera();
  sceneChanged();
}

void Terrain3DView::frameRegion(const cv::Rect2d& demPixels) {
  scene_->frameRegion(demPixels);
  sceneChanged();
}

double Terrain3DView::verticalExaggeration() const { return scene_->exaggeration; }

double Terrain3DView::suggestedExaggeration(const cv::Mat& dem, double gsd) {
  if (dem.empty() || gsd <= 0) return 1.0;
  cv::Mat heights;
  dem.convertTo(heights, CV_32F);
  std::vector<float> values;
  const int step = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(dem.total()) / 40000.0)));
  for (int y = 0; y < heights.rows; y += step) {
    const float* row = heights.ptr<float>(y);
    for (int x = 0; x < heights.cols; x += step) {
      if (std::isfinite(row[x])) values.push_back(row[x]);
    }
  }
  if (values.size() < 2) return 1.0;
  // The full range: a few buildings are a small share of a DEM, but they are the relief.
  const auto [lowest, highest] = std::minmax_element(values.begin(), values.end());
  const double relief = *highest - *lowest;
  const double extent = std::max(dem.cols, dem.rows) * gsd;
  if (relief <= 0) return 5.0;
  const double factor = std::clamp(0.1 * extent / relief, 1.0, 5.0);
  return std::round(factor * 2.0) / 2.0;
}

cv::Size Terrain3DView::displayedGridSize() const {
  return scene_->dem.empty() ? cv::Size() : gridFor(scene_->dem.size(), scene_->fineStep);
}

cv::Size Terrain3DView::interactiveGridSize() const {
  return scene_->dem.empty() ? cv::Size() : gridFor(scene_->dem.size(), scene_->coarseStep);
}

QImage Terrain3DView::renderImage() {
  if (backend_ == Backend::Offscreen) return static_cast<OffscreenSurface*>(surface_)->renderNow();
  return static_cast<GLSurface*>(surface_)->grabImage();
}

void Terrain3DView::setInteracting(bool interacting) {
  if (scene_->interacting == interacting) return;
  scene_->interacting = interacting;
  if (interacting) scene_->framed.reset();
  scene_->applyMode();
  sceneChanged();
}

void Terrain3DView::resizeEvent(QResizeEvent* event) {
  QWidget::resizeEvent(event);
  if (scene_->framed) {
    // The surface gets its new size in the same layout pass; frame once it has it.
    QTimer::singleShot(0, this, [this] {
      if (!scene_->framed) return;
      scene_->frameRegion(*scene_->framed);
      sceneChanged();
    });
  }
}

}  // namespace delineo::widgets
