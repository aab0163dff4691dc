#include "delineo/widgets/stage_text.hpp"

#include <QCoreApplication>
#include <cstring>
#include <iterator>

namespace delineo::widgets {
namespace {

// The source wording of each StageId, in its order (Text has none): %1 is the number, %2 the
// count. QT_TRANSLATE_NOOP lets lupdate collect them in the "Stages" context.
constexpr const char* kStageWords[] = {
    nullptr,
    QT_TRANSLATE_NOOP("Stages", "preparing pyramids and edges"),
    QT_TRANSLATE_NOOP("Stages", "matching level %1/%2"),
    QT_TRANSLATE_NOOP("Stages", "matching level %1/%2, right view"),
    QT_TRANSLATE_NOOP("Stages", "validating level %1/%2"),
    QT_TRANSLATE_NOOP("Stages", "refining depth steps, level %1/%2"),
    QT_TRANSLATE_NOOP("Stages", "filling flat regions"),
    QT_TRANSLATE_NOOP("Stages", "removing speckles"),
    QT_TRANSLATE_NOOP("Stages", "snapping depth steps to contours"),
    QT_TRANSLATE_NOOP("Stages", "removing speckles left by the snapping"),
    QT_TRANSLATE_NOOP("Stages", "fitting roof planes"),
    QT_TRANSLATE_NOOP("Stages", "matching (SGBM)"),
    QT_TRANSLATE_NOOP("Stages", "simulating: layout"),
    QT_TRANSLATE_NOOP("Stages", "simulating: rendering"),
    QT_TRANSLATE_NOOP("Stages", "simulating: radiometry"),
    QT_TRANSLATE_NOOP("Stages", "correlation costs"),
    QT_TRANSLATE_NOOP("Stages", "active polygon"),
    QT_TRANSLATE_NOOP("Stages", "active polygon: moves"),
    QT_TRANSLATE_NOOP("Stages", "active polygon: deletions"),
    QT_TRANSLATE_NOOP("Stages", "active polygon: insertion"),
    QT_TRANSLATE_NOOP("Stages", "active polygon: notch"),
    QT_TRANSLATE_NOOP("Stages", "active polygon: courtyard"),
    QT_TRANSLATE_NOOP("Stages", "dense matching"),
    QT_TRANSLATE_NOOP("Stages", "delineating building %1"),
    QT_TRANSLATE_NOOP("Stages", "box-fitting: building segment"),
    QT_TRANSLATE_NOOP("Stages", "box-fitting: boxes"),
    QT_TRANSLATE_NOOP("Stages", "box-fitting: outline"),
    QT_TRANSLATE_NOOP("Stages", "box-fitting building %1"),
    QT_TRANSLATE_NOOP("Stages", "enhancing the DEM"),
    QT_TRANSLATE_NOOP("Stages", "ground and terrain model"),
    QT_TRANSLATE_NOOP("Stages", "buildings, vegetation and objects"),
};
static_assert(std::size(kStageWords) == static_cast<size_t>(core::kLastStageId) + 1,
              "one wording per StageId");

}  // namespace

QString stageText(const core::Stage& stage) {
  const auto index = static_cast<size_t>(stage.id);
  if (stage.id == core::StageId::Text || index >= std::size(kStageWords)) {
    return QString::fromStdString(stage.english());
  }
  QString text = QCoreApplication::translate("Stages", kStageWords[index]);
  // The numbers the source wording asks for (a translation keeps the same placeholders).
  const char* source = kStageWords[index];
  if (std::strstr(source, "%2") != nullptr) return text.arg(stage.number).arg(stage.count);
  if (std::strstr(source, "%1") != nullptr) return text.arg(stage.number);
  return text;
}

}  // namespace delineo::widgets
