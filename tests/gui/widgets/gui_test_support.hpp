#pragma once
#include <QDir>
#include <QImage>
#include <QString>
#include <QWidget>

namespace delineo::widgets::test {

// Saves a rendering of `widget` when DELINEO_SCREENSHOT_DIR is set (for a human to look at).
inline void saveScreenshot(QWidget& widget, const QString& name) {
  const QString dir = qEnvironmentVariable("DELINEO_SCREENSHOT_DIR");
  if (dir.isEmpty()) return;
  QDir().mkpath(dir);
  widget.grab().save(dir + QLatin1Char('/') + name + QStringLiteral(".png"));
}

inline void saveImage(const QImage& image, const QString& name) {
  const QString dir = qEnvironmentVariable("DELINEO_SCREENSHOT_DIR");
  if (dir.isEmpty()) return;
  QDir().mkpath(dir);
  image.save(dir + QLatin1Char('/') + name + QStringLiteral(".png"));
}

}  // namespace delineo::widgets::test
