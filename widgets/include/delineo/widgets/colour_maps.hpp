#pragma once
// Colour maps for float rasters (disparity, DEM), the matching legend widget and hillshading.
//
// Conventions: colourised images are CV_8UC4 with bytes in R, G, B, A order, so that a row maps
// directly onto QImage::Format_RGBA8888. NaN (no data) is shown as a neutral grey checkerboard
// that no colour map uses, so holes are never mistaken for a value.
#include <QColor>
#include <QImage>
#include <QString>
#include <QWidget>

#include <opencv2/core.hpp>

namespace delineo::widgets {

enum class ColourMap {
  Grey,     // black → white
  Viridis,  // perceptually uniform dark blue → green → yellow (disparities, errors)
  Terrain,  // sea-blue → green → brown → white (heights)
};

// Colour of map `map` at t in [0, 1] (clamped).
QColor mapColour(ColourMap map, double t);

// The two grey levels of the no-data checkerboard; (x, y) pick the square (8 px squares).
QColor noDataColour(int x = 0, int y = 0);

// Colourises a single-channel raster (any depth; converted to float) between `min` and `max`
// (values outside are clamped). NaN → no-data checkerboard. `origin` is the position of
// values(0, 0) in the full image so that tiles of one image share one checkerboard phase.
cv::Mat colourise(const cv::Mat& values, double min, double max, ColourMap map,
                  cv::Point origin = {0, 0});

// Same, wrapped as a QImage that owns its pixels.
QImage colouriseToImage(const cv::Mat& values, double min, double max, ColourMap map);

// Finite minimum and maximum of a single-channel raster; {NaN, NaN} when it has no finite value.
std::pair<double, double> finiteRange(const cv::Mat& values);

// Lambertian hillshade of a DEM (CV_32F/CV_64F heights in metres, NaN = no data) with ground
// sample distance `gsd` (m/px), sun azimuth (degrees clockwise from north = image up) and
// altitude (degrees above the horizon). Returns CV_8U; no-data pixels are 0.
cv::Mat hillshade(const cv::Mat& dem, double gsd, double azimuthDeg = 315.0,
                  double altitudeDeg = 45.0);

// A vertical gradient bar with labelled ticks, a unit and a no-data swatch.
class ColourLegend : public QWidget {
  Q_OBJECT
 public:
  explicit ColourLegend(QWidget* parent = nullptr);

  void setColourMap(ColourMap map);
  void setRange(double min, double max);
  void setUnit(const QString& unit);    // e.g. "m", "px"; shown after the tick values
  void setTitle(const QString& title);  // e.g. tr("Height")
  void setNoDataVisible(bool visible);  // shows the "no data" swatch under the bar

  ColourMap colourMap() const { return map_; }
  double minimum() const { return min_; }
  double maximum() const { return max_; }

  QSize sizeHint() const override;
  QSize minimumSizeHint() const override;

 protected:
  void paintEvent(QPaintEvent* event) override;

 private:
  ColourMap map_ = ColourMap::Viridis;
  double min_ = 0.0;
  double max_ = 1.0;
  QString unit_;
  QString title_;
  bool noDataVisible_ = true;
};

}  // namespace delineo::widgets
