// Strings of the parameter forms (ParameterForm translates labels and help sentences in the
// "Parameters" context at run time; they come from the parameter structs' visit(), which
// lupdate cannot see). Listed here so that they reach translations/*.ts.
#include <QtGlobal>

namespace {
[[maybe_unused]] const char* const kParameterStrings[] = {
    QT_TRANSLATE_NOOP("Parameters", "on"),
    QT_TRANSLATE_NOOP("Parameters", "off"),
    QT_TRANSLATE_NOOP("Parameters", "Unit: %1"),
    QT_TRANSLATE_NOOP("Parameters", "Default: %1"),
    // delineation::DelineationParams
    QT_TRANSLATE_NOOP("Parameters", "Occlusion"),
    QT_TRANSLATE_NOOP("Parameters", "Percentage p of ROI pixels taken as unmatched; NoMatchCost is the (100-p)% quantile of the best costs (paper: 10)"),
    QT_TRANSLATE_NOOP("Parameters", "Edge weight"),
    QT_TRANSLATE_NOOP("Parameters", "Weight lambda of the left and right image edge terms (paper: 5)"),
    QT_TRANSLATE_NOOP("Parameters", "Rigidity"),
    QT_TRANSLATE_NOOP("Parameters", "Weight beta of the vertex angle prior R (paper: 15)"),
    QT_TRANSLATE_NOOP("Parameters", "Initial spacing"),
    QT_TRANSLATE_NOOP("Parameters", "Refined spacing"),
    QT_TRANSLATE_NOOP("Parameters", "Move radius"),
    QT_TRANSLATE_NOOP("Parameters", "Max iterations"),
    QT_TRANSLATE_NOOP("Parameters", "ROI margin"),
    QT_TRANSLATE_NOOP("Parameters", "Cost window"),
    QT_TRANSLATE_NOOP("Parameters", "Ground tolerance"),
    QT_TRANSLATE_NOOP("Parameters", "Ground search"),
    QT_TRANSLATE_NOOP("Parameters", "Ring width"),
    QT_TRANSLATE_NOOP("Parameters", "Edge moves"),
    QT_TRANSLATE_NOOP("Parameters", "Courtyards"),
    QT_TRANSLATE_NOOP("Parameters", "Min courtyard area"),
    // stereo::MatchParams
    QT_TRANSLATE_NOOP("Parameters", "Method"),
    QT_TRANSLATE_NOOP("Parameters", "Minimum disparity"),
    QT_TRANSLATE_NOOP("Parameters", "Maximum disparity"),
    QT_TRANSLATE_NOOP("Parameters", "Pyramid levels"),
    QT_TRANSLATE_NOOP("Parameters", "Template size"),
    QT_TRANSLATE_NOOP("Parameters", "Validation tolerance"),
    QT_TRANSLATE_NOOP("Parameters", "Edge low threshold"),
    QT_TRANSLATE_NOOP("Parameters", "Edge high threshold"),
    QT_TRANSLATE_NOOP("Parameters", "Edge smoothing"),
    QT_TRANSLATE_NOOP("Parameters", "Minimal shape"),
    QT_TRANSLATE_NOOP("Parameters", "Interval margin"),
    QT_TRANSLATE_NOOP("Parameters", "Line shift"),
    QT_TRANSLATE_NOOP("Parameters", "Minimal score"),
    QT_TRANSLATE_NOOP("Parameters", "Sub-pixel"),
    QT_TRANSLATE_NOOP("Parameters", "Adaptive shapes"),
    QT_TRANSLATE_NOOP("Parameters", "Threads"),
};
}  // namespace
