// Project files with fields of the wrong JSON type: always core::Error(UnreadableFile) naming
// the field, never a JSON library exception (which the CLI and the GUI do not expect).
// Inputs found by the fuzz_project fuzzer are kept here and in tests/fuzz/corpus/project.
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "delineo/core/error.hpp"
#include "delineo/project/project.hpp"

namespace {

using delineo::core::Error;
using delineo::core::ErrorCode;
using nlohmann::json;

// Runs fromJson and returns the code of the core::Error it throws; any other exception fails.
ErrorCode loadError(const std::string& text) {
  const json document = json::parse(text);
  try {
    (void)delineo::project::fromJson(document, "/projects");
  } catch (const Error& error) {
    return error.code();
  }
  ADD_FAILURE() << "no core::Error for " << text;
  return ErrorCode::ProcessingFailed;
}

TEST(ProjectMalformed, FormatOfTheWrongTypeIsNotAProject) {
  // Found by fuzz_project: a "format" object made json::value() throw type_error.
  EXPECT_EQ(loadError(R"({"format": {"left": "l.tif"}, "version": 1})"), ErrorCode::UnreadableFile);
  EXPECT_EQ(loadError(R"({"format": 1})"), ErrorCode::UnreadableFile);
  EXPECT_EQ(loadError(R"({"format": null})"), ErrorCode::UnreadableFile);
}

TEST(ProjectMalformed, OtherFieldsOfTheWrongTypeNameTheField) {
  const std::string head = R"({"format": "delineo-project", "version": 1, )";
  for (const char* rest : {
           R"("images": {"left": 1, "right": "r.tif"}})",
           R"("images": [], "name": "n"})",
           R"("images": {"left": "l.tif", "right": "r.tif"}, "name": {}})",
           R"("images": {"left": "l.tif", "right": "r.tif"}, "outputDir": 3})",
           R"("images": {"left": "l.tif", "right": "r.tif"}, "buildings": [{"id": "1"}]})",
           R"("images": {"left": "l.tif", "right": "r.tif"}, "heightModel": {"gsd": "1"}})",
       }) {
    EXPECT_EQ(loadError(head + rest), ErrorCode::UnreadableFile) << rest;
  }
}

TEST(ProjectMalformed, IntegerFieldsOutOfRangeAreRefused) {
  // Found by fuzz_project: an id of 1e128 was converted to int (undefined behaviour).
  const std::string head = R"({"format": "delineo-project", "images": {"left": "l", "right": "r"}, )";
  for (const char* rest : {R"("version": 1e128})", R"("version": -1e300})",
                           R"("version": 1, "buildings": [{"id": 1.11e128, "initial": [[[0,0],[4,0],[4,4]]]}]})"}) {
    EXPECT_EQ(loadError(head + rest), ErrorCode::UnreadableFile) << rest;
  }
  // A whole number written as a float still loads, as before.
  const json ok = json::parse(head + R"("version": 1.0, "buildings": [{"id": 3.0, "initial": [[[0,0],[4,0],[4,4]]]}]})");
  EXPECT_EQ(delineo::project::fromJson(ok, "/projects").buildings.at(0).id, 3);
}

TEST(ProjectMalformed, LoadProjectNamesTheFile) {
  const auto path = std::filesystem::temp_directory_path() /
                    ("delineo_malformed_" + std::to_string(::getpid()) + ".delineo.json");
  std::ofstream(path) << R"({"format": {}, "version": 1})";
  try {
    (void)delineo::project::loadProject(path.string());
    ADD_FAILURE() << "loaded";
  } catch (const Error& error) {
    EXPECT_EQ(error.code(), ErrorCode::UnreadableFile);
    EXPECT_EQ(error.path(), path.string());
  }
  std::filesystem::remove(path);
}

}  // namespace
