#pragma once
// A form built from any parameter struct (see core/params.hpp) through its visit():
// double → QDoubleSpinBox (range, unit suffix), int → QSpinBox, bool → QCheckBox,
// string with choices → QComboBox (free string → QLineEdit). Labels are translated in the
// "Parameters" context; tooltips give the help sentence, the unit and the default value.
//
//   ParameterForm form;
//   form.setParams(DelineationParams{});    // builds the rows
//   ...
//   DelineationParams p; form.readInto(p);  // reads back
#include <QString>
#include <QWidget>
#include <map>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "delineo/core/params.hpp"

class QFormLayout;

namespace delineo::widgets {

class ParameterForm : public QWidget {
  Q_OBJECT
 public:
  using Value = std::variant<double, int, bool, std::string>;

  explicit ParameterForm(QWidget* parent = nullptr);

  // Rebuilds the form for `params` (defaults are taken from Params{}).
  template <class Params>
  void setParams(const Params& params) {
    std::vector<Value> defaults;
    Params defaultParams{};
    defaultParams.visit([&](const core::ParamInfo&, auto& value) { defaults.emplace_back(Value(value)); });
    clearRows();
    Params copy = params;
    size_t index = 0;
    copy.visit([&](const core::ParamInfo& info, auto& value) {
      addRow(info, Value(value), index < defaults.size() ? defaults[index] : Value(value));
      ++index;
    });
  }

  // Updates the editors from `params` without rebuilding (changed() for each field that changes).
  template <class Params>
  void setValues(const Params& params) {
    Params copy = params;
    copy.visit([&](const core::ParamInfo& info, auto& value) { setValue(info.key, Value(value)); });
  }

  // Copies the editor values into `params` (fields without an editor are left unchanged).
  template <class Params>
  void readInto(Params& params) const {
    params.visit([&](const core::ParamInfo& info, auto& value) {
      using T = std::decay_t<decltype(value)>;
      Value v = this->value(info.key);
      if (const T* typed = std::get_if<T>(&v)) value = *typed;
    });
  }

  // Value of the editor for `key`, of the row's type; throws std::out_of_range when there is no
  // such row.
  Value value(std::string_view key) const;
  void setValue(std::string_view key, const Value& value);
  // The editor widget of a row (objectName = key), or nullptr.
  QWidget* editor(std::string_view key) const;
  int rowCount() const { return static_cast<int>(rows_.size()); }

 signals:
  // Any editor changed by the user or by setValue()/setValues() (not by setParams()).
  void changed();

 private:
  struct Row {
    Value kind;  // holds the type of the field
    QWidget* editor = nullptr;
  };
  void clearRows();
  void addRow(const core::ParamInfo& info, const Value& value, const Value& defaultValue);

  QFormLayout* layout_;
  std::map<std::string, Row, std::less<>> rows_;
  bool updating_ = false;
};

}  // namespace delineo::widgets
