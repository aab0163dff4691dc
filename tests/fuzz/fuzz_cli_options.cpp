// libFuzzer target: the CLI's option parser (cli::Options::parse) and the typed getters and
// parameter binding every command uses after it. The bytes are split at '\n' into arguments.
// Expected outcomes: parsed values, cli::UsageError, or core::Error(InvalidParameter) from a
// parameter struct's validate(). Seeds: corpus/cli_options.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "cli_support.hpp"
#include "delineo/core/error.hpp"
#include "delineo/core/params.hpp"

namespace {

// A parameter struct with one field of each type a visitor sees (int, double, bool, string
// with choices), bound to flags like every algorithm's.
struct FuzzParams {
  int count = 4;
  double weight = 1.5;
  bool enabled = true;
  std::string mode = "fast";
  template <class V>
  void visit(V&& v) {
    v(delineo::core::ParamInfo{"count", "Count", "px", "An integer.", 1, 64}, count);
    v(delineo::core::ParamInfo{"weight", "Weight", "", "A real number.", 0, 1000}, weight);
    v(delineo::core::ParamInfo{"enabled", "Enabled", "", "A switch."}, enabled);
    v(delineo::core::ParamInfo{"mode", "Mode", "", "A choice.", 0, 0, "fast|exact"}, mode);
  }
  void validate() const { delineo::core::checkDeclaredRanges(*this); }
};

std::vector<std::string> splitLines(const uint8_t* data, size_t size) {
  std::vector<std::string> args;
  std::string current;
  for (size_t i = 0; i < size; ++i) {
    if (data[i] == '\n') {
      args.push_back(current);
      current.clear();
    } else {
      current.push_back(static_cast<char>(data[i]));
    }
  }
  if (!current.empty()) args.push_back(current);
  return args;
}

delineo::cli::Options makeOptions() {
  delineo::cli::Options options("fuzz", "Every kind of option a command declares.");
  options.required("left", "FILE", "Left image")
      .value("range", "A:B", "Disparity range", "0:16")
      .value("threads", "N", "Threads", "2")
      .value("scale", "X", "Scale")
      .value("weights", "LIST", "Weights", "1,2,3")
      .flag("quiet", "No progress")
      .params(FuzzParams{});
  return options;
}

template <class Get>
void tryGet(Get&& get) {
  try {
    get();
  } catch (const delineo::cli::UsageError&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  std::freopen("/dev/null", "w", stdout);  // --help prints there
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  auto options = makeOptions();
  try {
    if (!options.parse(splitLines(data, size))) return 0;
  } catch (const delineo::cli::UsageError&) {
    return 0;
  }
  tryGet([&] { (void)options.get("left"); });
  tryGet([&] { (void)options.getPair("range"); });
  tryGet([&] { (void)options.getInt("threads"); });
  tryGet([&] { (void)options.getDouble("scale"); });
  tryGet([&] { (void)options.getList("weights"); });
  (void)options.has("quiet");
  try {
    FuzzParams params;
    options.apply(params);
  } catch (const delineo::cli::UsageError&) {
  } catch (const delineo::core::Error& error) {
    if (error.code() != delineo::core::ErrorCode::InvalidParameter) __builtin_trap();
  }
  return 0;
}
