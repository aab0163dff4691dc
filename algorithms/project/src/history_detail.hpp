#pragma once
// The detail of a building's history entry, led by who made it ("delineo-cli run: ...").
#include <string>

namespace delineo::project::detail {

inline std::string withOrigin(const std::string& origin, const std::string& text) {
  return origin.empty() ? text : origin + ": " + text;
}

}  // namespace delineo::project::detail
