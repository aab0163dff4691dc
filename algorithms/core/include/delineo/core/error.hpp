#pragma once
// Typed errors for every algorithm and I/O routine. The CLI maps codes to exit codes and the
// GUI maps them to translated sentences; `what()` carries the developer detail.
#include <stdexcept>
#include <string>
#include <string_view>

namespace delineo::core {

enum class ErrorCode {
  InvalidParameter,  // a parameter value outside its documented domain
  FileNotFound,      // a named input file does not exist
  UnreadableFile,    // the file exists but cannot be decoded (truncated, corrupt, wrong format)
  UnsupportedInput,  // decodable but not supported (band count, data type, geometry type)
  MismatchedInputs,  // inputs that must agree do not (sizes, CRS)
  WriteFailed,       // an output could not be written
  UnusableOutput,    // an output path refused before any work (no folder, wrong extension, an input, read-only)
  ProcessingFailed,  // the algorithm could not produce a result from valid input
};

std::string_view toString(ErrorCode code);

class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, const std::string& detail, std::string path = {});
  ErrorCode code() const noexcept { return code_; }
  // The file the error is about, empty when none.
  const std::string& path() const noexcept { return path_; }
  // The detail without the path prefix.
  const std::string& detail() const noexcept { return detail_; }

 private:
  ErrorCode code_;
  std::string detail_;
  std::string path_;
};

// True for errors caused by the user's input (files or parameter values), as opposed to a
// failure of the processing itself.
bool isInputError(ErrorCode code);

}  // namespace delineo::core
