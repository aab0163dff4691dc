#include "delineo/core/error.hpp"

namespace delineo::core {

std::string_view toString(ErrorCode code) {
  switch (code) {
    case ErrorCode::InvalidParameter: return "invalid parameter";
    case ErrorCode::FileNotFound: return "file not found";
    case ErrorCode::UnreadableFile: return "unreadable file";
    case ErrorCode::UnsupportedInput: return "unsupported input";
    case ErrorCode::MismatchedInputs: return "mismatched inputs";
    case ErrorCode::WriteFailed: return "write failed";
    case ErrorCode::UnusableOutput: return "unusable output";
    case ErrorCode::ProcessingFailed: return "processing failed";
  }
  return "unknown error";
}

namespace {
std::string compose(ErrorCode code, const std::string& detail, const std::string& path) {
  std::string msg;
  if (!path.empty()) msg += path + ": ";
  msg += std::string(toString(code)) + ": " + detail;
  return msg;
}
}  // namespace

Error::Error(ErrorCode code, const std::string& detail, std::string path)
    : std::runtime_error(compose(code, detail, path)),
      code_(code),
      detail_(detail),
      path_(std::move(path)) {}

bool isInputError(ErrorCode code) {
  return code != ErrorCode::ProcessingFailed && code != ErrorCode::WriteFailed;
}

}  // namespace delineo::core
