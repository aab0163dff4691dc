// libFuzzer target: the project file loader (the JSON that project::loadProject parses, then
// project::fromJson), and toJson on whatever loads. Expected outcomes: a project, or core::Error
// (invalid JSON is reported as such by loadProject before fromJson runs). Seeds: corpus/project.
#include <cstddef>
#include <cstdint>

#include <nlohmann/json.hpp>

#include "delineo/core/error.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/project/project.hpp"

// loadProject (in project.cpp, built into this target) validates the parameter groups with the
// algorithm libraries (pipeline.cpp), which this target does not build; it never calls
// loadProject, so that validation is left out here.
void delineo::project::validateParameters(const Project&) {}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const auto document = nlohmann::json::parse(data, data + size, nullptr, /*allow_exceptions=*/false);
  if (document.is_discarded()) return 0;
  try {
    const auto project = delineo::project::fromJson(document, "/fuzz/project");
    // A project that loads can be saved again.
    (void)delineo::project::toJson(project, "/fuzz/project").dump();
    (void)project.pendingBuildings();
  } catch (const delineo::core::Error&) {
  }
  return 0;
}
