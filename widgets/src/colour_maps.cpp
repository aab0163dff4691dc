#include "delineo/widgets/colour_maps.hpp"

#include <QFontMetrics>
#include <QLinearGradient>
#include <QPainter>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <opencv2/imgproc.hpp>

namespace delineo::widgets {
namespace {

struct Stop {
  double t;
  unsigned char r, g, b;
};

// Control points sampled from the published viridis map; linear interpolation between them is
// visually indistinguishable at legend sizes.
constexpr std::array<Stop, 9> kViridis{{{0.000, 68, 1, 84},
                                        {0.125, 71, 44, 122},
                                        {0.250, 59, 81, 139},
                                        {0.375, 44, 113, 142},
                                        {0.500, 33, 144, 141},
                                        {0.625, 39, 173, 129},
                                        {0.750, 92, 200, 99},
                                        {0.875, 170, 220, 50},
                                        {1.000, 253, 231, 37}}};

constexpr std::array<Stop, 6> kTerrain{{{0.00, 51, 102, 179},
                                        {0.15, 0, 153, 204},
                                        {0.25, 0, 178, 102},
                                        {0.50, 230, 217, 128},
                                        {0.75, 128, 92, 84},
                                        {1.00, 255, 255, 255}}};

constexpr std::array<Stop, 2> kGrey{{{0.0, 0, 0, 0}, {1.0, 255, 255, 255}}};

template <size_t N>
cv::Vec3b interpolate(const std::array<Stop, N>& stops, double t) {
  t = std::clamp(t, 0.0, 1.0);
  size_t i = 1;
  while (i + 1 < N && stops[i].t < t) ++i;
  const Stop& lo = stops[i - 1];
  const Stop& hi = stops[i];
  const double w = (t - lo.t) / std::max(hi.t - lo.t, 1e-12);
  auto mix = [w](unsigned char a, unsigned char b) {
    return static_cast<unsigned char>(std::lround(a + (b - a) * w));
  };
  return {mix(lo.r, hi.r), mix(lo.g, hi.g), mix(lo.b, hi.b)};
}

cv::Vec3b mapRgb(ColourMap map, double t) {
  switch (map) {
    case ColourMap::Viridis: return interpolate(kViridis, t);
    case ColourMap::Terrain: return interpolate(kTerrain, t);
    case ColourMap::Grey: break;
  }
  return interpolate(kGrey, t);
}

// 256-entry lookup table so colourising is one multiply and one fetch per pixel.
std::array<cv::Vec4b, 256> lookupTable(ColourMap map) {
  std::array<cv::Vec4b, 256> lut{};
  for (int i = 0; i < 256; ++i) {
    const cv::Vec3b c = mapRgb(map, i / 255.0);
    lut[i] = cv::Vec4b(c[0], c[1], c[2], 255);
  }
  return lut;
}

constexpr int kCheckerSize = 8;

}  // namespace

QColor mapColour(ColourMap map, double t) {
  const cv::Vec3b c = mapRgb(map, t);
  return QColor(c[0], c[1], c[2]);
}

QColor noDataColour(int x, int y) {
  const bool dark = ((x / kCheckerSize) + (y / kCheckerSize)) % 2 != 0;
  return dark ? QColor(150, 150, 150) : QColor(195, 195, 195);
}

cv::Mat colourise(const cv::Mat& values, double min, double max, ColourMap map, cv::Point origin) {
  CV_Assert(values.channels() == 1);
  cv::Mat asFloat;
  if (values.depth() == CV_32F) {
    asFloat = values;
  } else {
    values.convertTo(asFloat, CV_32F);
  }
  const auto lut = lookupTable(map);
  const QColor light = noDataColour(0, 0);
  const QColor dark = noDataColour(kCheckerSize, 0);
  const cv::Vec4b lightPx(light.red(), light.green(), light.blue(), 255);
  const cv::Vec4b darkPx(dark.red(), dark.green(), dark.blue(), 255);
  const double span = max - min;
  const float scale = span > 0 ? static_cast<float>(255.0 / span) : 0.0f;
  const float offset = static_cast<float>(min);
  cv::Mat out(asFloat.size(), CV_8UC4);
  for (int y = 0; y < asFloat.rows; ++y) {
    const float* in = asFloat.ptr<float>(y);
    auto* dst = out.ptr<cv::Vec4b>(y);
    const int gy = (y + origin.y) / kCheckerSize;
    for (int x = 0; x < asFloat.cols; ++x) {
      const float v = in[x];
      if (std::isnan(v)) {
        dst[x] = (((x + origin.x) / kCheckerSize + gy) % 2 != 0) ? darkPx : lightPx;
        continue;
      }
      const float s = (v - offset) * scale;
      const int index = s <= 0.0f ? 0 : s >= 255.0f ? 255 : static_cast<int>(s + 0.5f);
      dst[x] = lut[index];
    }
  }
  return out;
}

QImage colouriseToImage(const cv::Mat& values, double min, double max, ColourMap map) {
  const cv::Mat rgba = colourise(values, min, max, map);
  QImage image(rgba.cols, rgba.rows, QImage::Format_RGBA8888);
  for (int y = 0; y < rgba.rows; ++y) {
    std::copy_n(rgba.ptr<uchar>(y), rgba.cols * 4, image.scanLine(y));
  }
  return image;
}

std::pair<double, double> finiteRange(const cv::Mat& values) {
  CV_Assert(values.channels() == 1);
  if (values.depth() != CV_32F && values.depth() != CV_64F) {
    double lo = 0;
    double hi = 0;
    if (values.empty()) return {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
    cv::minMaxLoc(values, &lo, &hi);
    return {lo, hi};
  }
  cv::Mat asFloat;
  values.convertTo(asFloat, CV_32F);
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  for (int y = 0; y < asFloat.rows; ++y) {
    const float* row = asFloat.ptr<float>(y);
    for (int x = 0; x < asFloat.cols; ++x) {
      if (std::isfinite(row[x])) {
        lo = std::min(lo, static_cast<double>(row[x]));
        hi = std::max(hi, static_cast<double>(row[x]));
      }
    }
  }
  if (lo > hi) return {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::quiet_NaN()};
  return {lo, hi};
}

cv::Mat hillshade(const cv::Mat& dem, double gsd, double azimuthDeg, double altitudeDeg) {
  CV_Assert(dem.channels() == 1 && gsd > 0);
  cv::Mat z;
  dem.convertTo(z, CV_32F);
  const double zenith = (90.0 - altitudeDeg) * CV_PI / 180.0;
  // Azimuth is clockwise from north (image up); convert to the mathematical angle of the light
  // direction in the image frame (x right, y down).
  const double az = azimuthDeg * CV_PI / 180.0;
  const double lightX = std::sin(az);
  const double lightY = -std::cos(az);  // north = -y
  cv::Mat out(z.size(), CV_8U, cv::Scalar(0));
  auto at = [&](int y, int x) -> float {
    x = std::clamp(x, 0, z.cols - 1);
    y = std::clamp(y, 0, z.rows - 1);
    return z.at<float>(y, x);
  };
  for (int y = 0; y < z.rows; ++y) {
    for (int x = 0; x < z.cols; ++x) {
      const float centre = z.at<float>(y, x);
      if (!std::isfinite(centre)) continue;
      // Central differences, falling back to the centre value next to holes.
      auto sample = [&](int yy, int xx) {
        const float v = at(yy, xx);
        return std::isfinite(v) ? v : centre;
      };
      const double dzdx = (sample(y, x + 1) - sample(y, x - 1)) / (2.0 * gsd);
      const double dzdy = (sample(y + 1, x) - sample(y - 1, x)) / (2.0 * gsd);
      // Surface normal (-dz/dx, -dz/dy, 1) normalised; light (sinZ*lx, sinZ*ly, cosZ).
      const double norm = std::sqrt(dzdx * dzdx + dzdy * dzdy + 1.0);
      const double shade = (-dzdx * std::sin(zenith) * lightX - dzdy * std::sin(zenith) * lightY +
                            std::cos(zenith)) /
                           norm;
      out.at<uchar>(y, x) = cv::saturate_cast<uchar>(1.0 + 254.0 * std::max(shade, 0.0));
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------------

ColourLegend::ColourLegend(QWidget* parent) : QWidget(parent) {
  setSizePolicy(QSizePolicy::Fixed, QSizePolicy::Expanding);
}

void ColourLegend::setColourMap(ColourMap map) {
  map_ = map;
  update();
}

void ColourLegend::setRange(double min, double max) {
  min_ = min;
  max_ = max;
  update();
}

void ColourLegend::setUnit(const QString& unit) {
  unit_ = unit;
  updateGeometry();
  update();
}

void ColourLegend::setTitle(const QString& title) {
  title_ = title;
  updateGeometry();
  update();
}

void ColourLegend::setNoDataVisible(bool visible) {
  noDataVisible_ = visible;
  update();
}

QSize ColourLegend::sizeHint() const {
  const QFontMetrics fm(font());
  const int labelWidth = fm.horizontalAdvance(QStringLiteral("-00000.0 ") + unit_);
  const int width = std::max(18 + 8 + labelWidth + 8, fm.horizontalAdvance(title_) + 8);
  return {width, 220};
}

QSize ColourLegend::minimumSizeHint() const { return {sizeHint().width(), 120}; }

namespace {
// Round step (1, 2 or 5 times a power of ten) giving about `count` ticks over `span`.
double niceStep(double span, int count) {
  if (!(span > 0)) return 1.0;
  const double raw = span / std::max(count, 1);
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * p >= raw) return m * p;
  }
  return 10.0 * p;
}
}  // namespace

void ColourLegend::paintEvent(QPaintEvent*) {
  QPainter painter(this);
  painter.setRenderHint(QPainter::Antialiasing, false);
  const QFontMetrics fm(font());
  const int margin = 4;
  int top = margin + fm.height() / 2;
  if (!title_.isEmpty()) {
    painter.setPen(palette().color(QPalette::WindowText));
    painter.drawText(QPoint(margin, margin + fm.ascent()), title_);
    top += fm.height() + 2;
  }
  int bottom = height() - margin - fm.height() / 2;
  const int swatch = 14;
  if (noDataVisible_) bottom -= swatch + 6;
  const QRect bar(margin, top, 18, std::max(bottom - top, 10));

  // Gradient: high values at the top.
  QImage strip(1, bar.height(), QImage::Format_RGB32);
  for (int y = 0; y < bar.height(); ++y) {
    const double t = 1.0 - static_cast<double>(y) / std::max(bar.height() - 1, 1);
    strip.setPixel(0, y, mapColour(map_, t).rgb());
  }
  painter.drawImage(bar, strip);
  painter.setPen(palette().color(QPalette::WindowText));
  painter.drawRect(bar.adjusted(0, 0, -1, -1));

  // Ticks with labels.
  const double span = max_ - min_;
  if (span > 0 && std::isfinite(span)) {
    const int maxTicks = std::max(2, bar.height() / (fm.height() + 6));
    const double step = niceStep(span, maxTicks);
    const int decimals = step >= 1.0 ? 0 : static_cast<int>(std::ceil(-std::log10(step)));
    for (double v = std::ceil(min_ / step) * step; v <= max_ + step * 1e-6; v += step) {
      const double t = (v - min_) / span;
      const int y = bar.bottom() - static_cast<int>(std::lround(t * (bar.height() - 1)));
      painter.drawLine(bar.right() + 1, y, bar.right() + 5, y);
      QString text = QString::number(v, 'f', decimals);
      if (!unit_.isEmpty()) text += QLatin1Char(' ') + unit_;
      painter.drawText(QPoint(bar.right() + 8, y + fm.ascent() / 2 - 1), text);
    }
  } else {
    QString text = QString::number(min_);
    if (!unit_.isEmpty()) text += QLatin1Char(' ') + unit_;
    painter.drawText(QPoint(bar.right() + 8, bar.center().y()), text);
  }

  if (noDataVisible_) {
    const QRect box(margin, bar.bottom() + 8, swatch, swatch);
    for (int y = 0; y < swatch; ++y) {
      for (int x = 0; x < swatch; ++x) {
        painter.setPen(noDataColour(x * 2, y * 2));
        painter.drawPoint(box.left() + x, box.top() + y);
      }
    }
    painter.setPen(palette().color(QPalette::WindowText));
    painter.drawRect(box.adjusted(0, 0, -1, -1));
    painter.drawText(QPoint(box.right() + 6, box.top() + fm.ascent() - 1), tr("no data"));
  }
}

}  // namespace delineo::widgets
