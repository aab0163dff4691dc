#include "delineo/widgets/parameter_form.hpp"

#include <QCheckBox>
#include <QComboBox>
#include <QCoreApplication>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QLineEdit>
#include <QSpinBox>
#include <cmath>
#include <stdexcept>

namespace delineo::widgets {
namespace {

QString qs(std::string_view text) { return QString::fromUtf8(text.data(), static_cast<qsizetype>(text.size())); }

// Number of decimals that shows `value` and the range limits without loss (2..6).
int decimalsFor(double value, double min, double max) {
  int decimals = 2;
  for (double v : {value, min, max}) {
    if (!std::isfinite(v) || std::abs(v) > 1e12) continue;
    for (int d = decimals; d <= 6; ++d) {
      const double scaled = v * std::pow(10.0, d);
      if (std::abs(scaled - std::round(scaled)) < 1e-6 * std::max(1.0, std::abs(scaled))) break;
      decimals = std::max(decimals, std::min(d + 1, 6));
    }
  }
  return decimals;
}

QString valueText(const ParameterForm::Value& value) {
  return std::visit(
      [](const auto& v) -> QString {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, bool>) {
          return v ? QCoreApplication::translate("Parameters", "on")
                   : QCoreApplication::translate("Parameters", "off");
        } else if constexpr (std::is_same_v<T, std::string>) {
          return QString::fromStdString(v);
        } else if constexpr (std::is_same_v<T, int>) {
          return QString::number(v);
        } else {
          return QString::number(v, 'g', 8);
        }
      },
      value);
}

}  // namespace

ParameterForm::ParameterForm(QWidget* parent) : QWidget(parent), layout_(new QFormLayout(this)) {
  layout_->setFieldGrowthPolicy(QFormLayout::ExpandingFieldsGrow);
}

void ParameterForm::clearRows() {
  while (layout_->rowCount() > 0) layout_->removeRow(0);
  rows_.clear();
}

void ParameterForm::addRow(const core::ParamInfo& info, const Value& value, const Value& defaultValue) {
  const std::string key(info.key);
  const std::string label(info.label);
  const QString unit = qs(info.unit);
  QWidget* editor = nullptr;

  if (const double* d = std::get_if<double>(&value)) {
    auto* spin = new QDoubleSpinBox(this);
    const double lo = std::max(info.min, -1e9);
    const double hi = std::min(info.max, 1e9);
    spin->setDecimals(decimalsFor(*d, lo, hi));
    spin->setRange(lo, hi);
    const double span = hi - lo;
    spin->setSingleStep(span <= 2.0 ? 0.05 : span <= 20.0 ? 0.1 : 1.0);
    if (!unit.isEmpty()) spin->setSuffix(QLatin1Char(' ') + unit);
    spin->setValue(*d);
    connect(spin, &QDoubleSpinBox::valueChanged, this, [this] {
      if (!updating_) emit changed();
    });
    editor = spin;
  } else if (const int* i = std::get_if<int>(&value)) {
    auto* spin = new QSpinBox(this);
    spin->setRange(static_cast<int>(std::max(info.min, -2e9)), static_cast<int>(std::min(info.max, 2e9)));
    if (!unit.isEmpty()) spin->setSuffix(QLatin1Char(' ') + unit);
    spin->setValue(*i);
    connect(spin, &QSpinBox::valueChanged, this, [this] {
      if (!updating_) emit changed();
    });
    editor = spin;
  } else if (const bool* b = std::get_if<bool>(&value)) {
    auto* box = new QCheckBox(this);
    box->setChecked(*b);
    connect(box, &QCheckBox::toggled, this, [this] {
      if (!updating_) emit changed();
    });
    editor = box;
  } else {
    const std::string& text = std::get<std::string>(value);
    if (!info.choices.empty()) {
      auto* combo = new QComboBox(this);
      const QStringList choices = qs(info.choices).split(QLatin1Char('|'));
      for (const QString& choice : choices) {
        // The stored value stays the untranslated key; the shown text is translated.
        combo->addItem(QCoreApplication::translate("Parameters", choice.toUtf8().constData()), choice);
      }
      combo->setCurrentIndex(std::max(0, combo->findData(QString::fromStdString(text))));
      connect(combo, &QComboBox::currentIndexChanged, this, [this] {
        if (!updating_) emit changed();
      });
      editor = combo;
    } else {
      auto* line = new QLineEdit(QString::fromStdString(text), this);
      connect(line, &QLineEdit::textChanged, this, [this] {
        if (!updating_) emit changed();
      });
      editor = line;
    }
  }

  editor->setObjectName(QString::fromStdString(key));
  QString tip = QCoreApplication::translate("Parameters", std::string(info.help).c_str());
  if (!unit.isEmpty()) {
    tip += QLatin1String("\n") + QCoreApplication::translate("Parameters", "Unit: %1").arg(unit);
  }
  tip += QLatin1String("\n") +
         QCoreApplication::translate("Parameters", "Default: %1").arg(valueText(defaultValue));
  editor->setToolTip(tip);
  const QString labelText = QCoreApplication::translate("Parameters", label.c_str());
  layout_->addRow(labelText, editor);
  if (QWidget* labelWidget = layout_->labelForField(editor)) labelWidget->setToolTip(tip);
  rows_[key] = Row{value, editor};
}

ParameterForm::Value ParameterForm::value(std::string_view key) const {
  auto it = rows_.find(key);
  if (it == rows_.end()) throw std::out_of_range("ParameterForm has no row '" + std::string(key) + "'");
  const Row& row = it->second;
  if (std::holds_alternative<double>(row.kind)) {
    return static_cast<QDoubleSpinBox*>(row.editor)->value();
  }
  if (std::holds_alternative<int>(row.kind)) {
    return static_cast<QSpinBox*>(row.editor)->value();
  }
  if (std::holds_alternative<bool>(row.kind)) {
    return static_cast<QCheckBox*>(row.editor)->isChecked();
  }
  if (auto* combo = qobject_cast<QComboBox*>(row.editor)) {
    return combo->currentData().toString().toStdString();
  }
  return static_cast<QLineEdit*>(row.editor)->text().toStdString();
}

void ParameterForm::setValue(std::string_view key, const Value& value) {
  auto it = rows_.find(key);
  if (it == rows_.end() || it->second.kind.index() != value.index()) return;
  QWidget* editor = it->second.editor;
  const Value before = this->value(key);
  updating_ = true;
  if (const double* d = std::get_if<double>(&value)) {
    static_cast<QDoubleSpinBox*>(editor)->setValue(*d);
  } else if (const int* i = std::get_if<int>(&value)) {
    static_cast<QSpinBox*>(editor)->setValue(*i);
  } else if (const bool* b = std::get_if<bool>(&value)) {
    static_cast<QCheckBox*>(editor)->setChecked(*b);
  } else if (auto* combo = qobject_cast<QComboBox*>(editor)) {
    const int index = combo->findData(QString::fromStdString(std::get<std::string>(value)));
    if (index >= 0) combo->setCurrentIndex(index);
  } else {
    static_cast<QLineEdit*>(editor)->setText(QString::fromStdString(std::get<std::string>(value)));
  }
  updating_ = false;
  if (this->value(key) != before) emit changed();
}

QWidget* ParameterForm::editor(std::string_view key) const {
  auto it = rows_.find(key);
  return it == rows_.end() ? nullptr : it->second.editor;
}

}  // namespace delineo::widgets
