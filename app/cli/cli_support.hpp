#pragma once
// Command-line plumbing shared by every delineo-cli command: option parsing with generated
// --help, binding of algorithm parameter structs to flags, progress on stderr, exit codes.
#include <functional>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "delineo/core/error.hpp"
#include "delineo/core/geometry.hpp"
#include "delineo/core/params.hpp"
#include "delineo/core/progress.hpp"
#include "delineo/io/output_file.hpp"

namespace delineo::cli {

// Exit codes (documented in README and docs/cli.md).
enum ExitCode : int {
  kExitOk = 0,
  kExitUsage = 2,
  kExitBadInput = 3,
  kExitProcessing = 4,
  kExitCanceled = 130,
};

struct UsageError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Thrown by a command that saw its progress object canceled (Ctrl-C).
struct Canceled : std::runtime_error {
  Canceled() : std::runtime_error("canceled") {}
};

class Options {
 public:
  Options(std::string command, std::string summary);

  // A flag taking a value. `metavar` names the value in --help ("FILE", "N").
  Options& value(const std::string& key, const std::string& metavar, const std::string& help,
                 std::optional<std::string> defaultValue = std::nullopt, bool required = false);
  Options& required(const std::string& key, const std::string& metavar, const std::string& help) {
    return value(key, metavar, help, std::nullopt, true);
  }
  // A flag without a value.
  Options& flag(const std::string& key, const std::string& help);

  // Adds one flag per field of a parameter struct (same keys as the project file).
  template <class Params>
  Options& params(Params defaults, const std::string& group = {}) {
    defaults.visit([&](const core::ParamInfo& info, auto& v) {
      using T = std::decay_t<decltype(v)>;
      std::string help(info.help);
      if (!info.unit.empty()) help += " [" + std::string(info.unit) + "]";
      if (!info.choices.empty()) help += " (" + std::string(info.choices) + ")";
      std::string def;
      if constexpr (std::is_same_v<T, bool>) {
        def = v ? "true" : "false";
      } else if constexpr (std::is_same_v<T, std::string>) {
        def = v;
      } else {
        def = formatNumber(static_cast<double>(v));
      }
      value(std::string(info.key), std::is_same_v<T, bool> ? "BOOL" : "X", help, def);
      paramKeys_.push_back(std::string(info.key));
      (void)group;
    });
    return *this;
  }

  // Parses argv after the command name. Throws UsageError. Returns false when --help was given
  // (help already printed to stdout).
  bool parse(const std::vector<std::string>& args);

  bool has(const std::string& key) const;  // given on the command line (or flag set)
  std::string get(const std::string& key) const;  // value or default; UsageError if neither
  double getDouble(const std::string& key) const;
  int getInt(const std::string& key) const;
  // "A:B" or "A,B" → two numbers.
  std::pair<double, double> getPair(const std::string& key) const;
  std::vector<double> getList(const std::string& key) const;  // comma separated

  // Copies the bound flags into a parameter struct, then validates it.
  template <class Params>
  void apply(Params& params) const {
    params.visit([&](const core::ParamInfo& info, auto& v) {
      using T = std::decay_t<decltype(v)>;
      const std::string key(info.key);
      if (!has(key)) return;
      if constexpr (std::is_same_v<T, bool>) {
        const std::string s = get(key);
        if (s == "true" || s == "1" || s == "yes") v = true;
        else if (s == "false" || s == "0" || s == "no") v = false;
        else throw UsageError("--" + key + " expects true or false, got '" + s + "'");
      } else if constexpr (std::is_same_v<T, std::string>) {
        v = get(key);
      } else if constexpr (std::is_integral_v<T>) {
        v = static_cast<T>(getInt(key));
      } else {
        v = static_cast<T>(getDouble(key));
      }
    });
    params.validate();
  }

  std::string help() const;
  const std::string& command() const { return command_; }

 private:
  static std::string formatNumber(double v);
  struct Spec {
    std::string key, metavar, help;
    std::optional<std::string> defaultValue;
    bool required = false;
    bool isFlag = false;
  };
  const Spec* find(const std::string& key) const;
  std::string command_, summary_;
  std::vector<Spec> specs_;
  std::vector<std::string> paramKeys_;
  std::map<std::string, std::string> values_;
};

// Progress printed on stderr: one line per stage change and per 10 % step (log-friendly), or a
// live line when stderr is a terminal.
class StderrProgress : public core::Progress {
 public:
  explicit StderrProgress(bool quiet = false);
  void report(double fraction) override;
  using core::Progress::setStage;
  void setStage(const core::Stage& stage) override;
  void finish();
  // Commands with a --quiet flag switch the shared progress off (or on) before running.
  void setQuiet(bool quiet) { quiet_ = quiet; }

 private:
  bool quiet_;
  bool tty_;
  int lastPercent_ = -1;
  std::string lastStage_;
};

// The progress object of the running command; Ctrl-C cancels it.
StderrProgress& commandProgress();
// Throws Canceled when the progress was canceled (to unwind a command cleanly).
void throwIfCanceled(const core::Progress& p);

// A command's one positional argument (a PROJECT), which may stand anywhere among the options:
// the one argument that is neither an option nor the value of one of `valueOptions` ("--out").
// The options are left in `rest`; empty when there is none. Throws UsageError naming a second one.
std::string positionalArgument(const std::vector<std::string>& args, const std::vector<std::string>& valueOptions,
                               std::vector<std::string>& rest);

// The output policy (io/output_file.hpp) before any work: the files of the `outputs` options
// given, against those of the `inputs` options given.
void checkOutputs(const Options& opts, const std::vector<std::pair<std::string, io::OutputFormat>>& outputs,
                  const std::vector<std::string>& inputs);

// The id of the `index`-th (from 0) feature of `file` (an --init file): its "id" property as a
// number (core::numberProperty, within +-9e15), else its position in the file from 1. Throws
// core::Error(InvalidParameter) naming the feature and the file when the id is not a number.
long long featureId(const core::Feature& feature, size_t index, const std::string& file);

// Reads `read()`, a feature's properties; a malformed one (core::Error) becomes the same error
// with `feature` ("feature 3", "building id 12") before its detail and `file` as its file.
template <class Read>
auto readFeatureProperties(Read&& read, const std::string& feature, const std::string& file) {
  try {
    return read();
  } catch (const core::Error& e) {
    throw core::Error(e.code(), feature + ": " + e.detail(), file);
  }
}

// The rectangle of --roi X,Y,W,H (left-image pixels) as a feature. Throws UsageError when it is
// not four numbers with positive W and H.
core::Feature roiFeature(const Options& opts);

using CommandFn = std::function<int(const std::vector<std::string>& args)>;
struct CommandInfo {
  std::string name;
  std::string summary;
  CommandFn run;
};

// Commands register themselves at static-initialisation time (see commands/*.cpp).
bool registerCommand(CommandInfo info);
const std::vector<CommandInfo>& commands();

// Runs one command with error → exit-code mapping. Used by main and by tests.
int runCommand(const std::vector<std::string>& argv);

}  // namespace delineo::cli
