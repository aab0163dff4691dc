#pragma once
// Parameter structs: one per algorithm, bound three times (CLI flags, GUI form, project file).
//
// A parameter struct holds plain fields with defaults and exposes them through
//
//   template <class Visitor> void visit(Visitor&& v) {
//     v(ParamInfo{"edge-weight", "Edge weight", "", "Weight λ of the edge terms", 0, 1000}, edgeWeight);
//   }
//   void validate() const;   // throws core::Error(InvalidParameter)
//
// Visitors receive `(const ParamInfo&, T&)` with T one of double, int, bool, std::string. The
// helpers below use `visit` for range checks and JSON; the CLI and the GUI use it to make flags
// and form fields, so a new field shows up everywhere at once.
#include <cmath>
#include <sstream>
#include <string>
#include <string_view>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "delineo/core/error.hpp"

namespace delineo::core {

struct ParamInfo {
  std::string_view key;    // kebab-case: CLI flag (--key), JSON key, GUI object name
  std::string_view label;  // short English label (the GUI translates it)
  std::string_view unit;   // "px", "%", "m", "" when unitless
  std::string_view help;   // one sentence: what it does, and the paper's value when any
  double min = -1e300;     // inclusive numeric domain (ignored for bool and string)
  double max = 1e300;
  std::string_view choices = {};  // for strings: allowed values separated by '|', empty = any
};

namespace detail {
inline bool choiceAllowed(std::string_view choices, std::string_view value) {
  if (choices.empty()) return true;
  size_t start = 0;
  while (start <= choices.size()) {
    size_t bar = choices.find('|', start);
    if (bar == std::string_view::npos) bar = choices.size();
    if (choices.substr(start, bar - start) == value) return true;
    start = bar + 1;
  }
  return false;
}
}  // namespace detail

// Throws InvalidParameter for the first field outside its declared domain.
template <class Params>
void checkDeclaredRanges(const Params& params) {
  Params copy = params;  // visit() is non-const so that one method serves reading and writing
  copy.visit([](const ParamInfo& info, auto& value) {
    using T = std::decay_t<decltype(value)>;
    if constexpr (std::is_same_v<T, std::string>) {
      if (!detail::choiceAllowed(info.choices, value)) {
        throw Error(ErrorCode::InvalidParameter, std::string(info.key) + " = '" + value +
                                                     "' is not one of " + std::string(info.choices));
      }
    } else if constexpr (!std::is_same_v<T, bool>) {
      const double v = static_cast<double>(value);
      if (!std::isfinite(v) || v < info.min || v > info.max) {
        std::ostringstream msg;
        msg << info.key << " = " << v << " is outside [" << info.min << ", " << info.max << "]";
        if (!info.unit.empty()) msg << " " << info.unit;
        throw Error(ErrorCode::InvalidParameter, msg.str());
      }
    }
  });
}

template <class Params>
nlohmann::json toJson(const Params& params) {
  nlohmann::json out = nlohmann::json::object();
  Params copy = params;
  copy.visit([&](const ParamInfo& info, auto& value) { out[std::string(info.key)] = value; });
  return out;
}

// Reads the keys present in `in` (missing keys keep their current value), rejects unknown keys
// and wrong types, then validates.
template <class Params>
void fromJson(Params& params, const nlohmann::json& in) {
  if (!in.is_object()) throw Error(ErrorCode::InvalidParameter, "parameters must be a JSON object");
  size_t known = 0;
  params.visit([&](const ParamInfo& info, auto& value) {
    using T = std::decay_t<decltype(value)>;
    auto it = in.find(std::string(info.key));
    if (it == in.end()) return;
    ++known;
    const bool ok = std::is_same_v<T, bool>          ? it->is_boolean()
                    : std::is_same_v<T, std::string> ? it->is_string()
                    : std::is_integral_v<T>          ? it->is_number_integer()
                                                     : it->is_number();
    if (!ok) {
      throw Error(ErrorCode::InvalidParameter,
                  "parameter '" + std::string(info.key) + "' has the wrong JSON type");
    }
    value = it->template get<T>();
  });
  if (known != in.size()) {
    for (auto it = in.begin(); it != in.end(); ++it) {
      bool found = false;
      params.visit([&](const ParamInfo& info, auto&) { found = found || info.key == it.key(); });
      if (!found) throw Error(ErrorCode::InvalidParameter, "unknown parameter '" + it.key() + "'");
    }
  }
  params.validate();
}

}  // namespace delineo::core
