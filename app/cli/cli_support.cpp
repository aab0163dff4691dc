#include "cli_support.hpp"

#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

#include "delineo/core/error.hpp"

namespace delineo::cli {

Options::Options(std::string command, std::string summary)
    : command_(std::move(command)), summary_(std::move(summary)) {}

Options& Options::value(const std::string& key, const std::string& metavar, const std::string& help,
                        std::optional<std::string> defaultValue, bool required) {
  specs_.push_back(Spec{key, metavar, help, std::move(defaultValue), required, false});
  return *this;
}

Options& Options::flag(const std::string& key, const std::string& help) {
  specs_.push_back(Spec{key, "", help, std::nullopt, false, true});
  return *this;
}

const Options::Spec* Options::find(const std::string& key) const {
  for (const auto& s : specs_) {
    if (s.key == key) return &s;
  }
  return nullptr;
}

bool Options::parse(const std::vector<std::string>& args) {
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    if (a == "--help" || a == "-h") {
      std::cout << help();
      return false;
    }
    if (a.rfind("--", 0) != 0) throw UsageError("unexpected argument '" + a + "'");
    std::string key = a.substr(2);
    std::optional<std::string> inlineValue;
    if (auto eq = key.find('='); eq != std::string::npos) {
      inlineValue = key.substr(eq + 1);
      key = key.substr(0, eq);
    }
    const Spec* spec = find(key);
    if (spec == nullptr) throw UsageError("unknown option --" + key + " (see --help)");
    if (spec->isFlag) {
      if (inlineValue) throw UsageError("--" + key + " takes no value");
      values_[key] = "true";
      continue;
    }
    if (inlineValue) {
      values_[key] = *inlineValue;
    } else {
      if (i + 1 >= args.size()) throw UsageError("--" + key + " needs a value " + spec->metavar);
      values_[key] = args[++i];
    }
  }
  for (const auto& s : specs_) {
    if (s.required && !values_.count(s.key)) {
      throw UsageError("missing required option --" + s.key + " " + s.metavar);
    }
  }
  return true;
}

bool Options::has(const std::string& key) const { return values_.count(key) > 0; }

std::string Options::get(const std::string& key) const {
  if (auto it = values_.find(key); it != values_.end()) return it->second;
  const Spec* spec = find(key);
  if (spec != nullptr && spec->defaultValue) return *spec->defaultValue;
  throw UsageError("option --" + key + " is needed here");
}

double Options::getDouble(const std::string& key) const {
  const std::string s = get(key);
  try {
    size_t used = 0;
    const double v = std::stod(s, &used);
    if (used != s.size() || !std::isfinite(v)) throw std::invalid_argument(s);
    return v;
  } catch (const std::exception&) {
    throw UsageError("--" + key + " expects a finite number, got '" + s + "'");
  }
}

int Options::getInt(const std::string& key) const {
  const std::string s = get(key);
  int v = 0;
  auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || ptr != s.data() + s.size()) {
    throw UsageError("--" + key + " expects an integer, got '" + s + "'");
  }
  return v;
}

std::vector<double> Options::getList(const std::string& key) const {
  std::string s = get(key);
  std::vector<double> out;
  std::replace(s.begin(), s.end(), ':', ',');
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    try {
      size_t used = 0;
      out.push_back(std::stod(item, &used));
      if (used != item.size() || !std::isfinite(out.back())) throw std::invalid_argument(item);
    } catch (const std::exception&) {
      throw UsageError("--" + key + ": '" + item + "' is not a finite number");
    }
  }
  return out;
}

std::pair<double, double> Options::getPair(const std::string& key) const {
  const auto v = getList(key);
  if (v.size() != 2) throw UsageError("--" + key + " expects A:B, got '" + get(key) + "'");
  return {v[0], v[1]};
}

std::string Options::formatNumber(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

std::string Options::help() const {
  std::ostringstream out;
  out << "usage: delineo-cli " << command_;
  for (const auto& s : specs_) {
    if (s.required) out << " --" << s.key << " " << s.metavar;
  }
  out << " [options]\n\n" << summary_ << "\n\noptions:\n";
  for (const auto& s : specs_) {
    std::string left = "  --" + s.key + (s.isFlag ? "" : " " + s.metavar);
    out << left;
    if (left.size() < 28) out << std::string(28 - left.size(), ' ');
    else out << "\n" << std::string(28, ' ');
    out << s.help;
    if (s.required) out << " (required)";
    else if (s.defaultValue && !s.defaultValue->empty()) out << " (default " << *s.defaultValue << ")";
    out << "\n";
  }
  out << "  --help                    show this help\n";
  return out.str();
}

StderrProgress::StderrProgress(bool quiet) : quiet_(quiet), tty_(isatty(STDERR_FILENO) != 0) {}

void StderrProgress::report(double fraction) {
  core::Progress::report(fraction);
  if (quiet_) return;
  const int pct = static_cast<int>(this->fraction() * 100.0);
  const int step = tty_ ? 1 : 10;
  if (pct / step == lastPercent_ / step) return;
  lastPercent_ = pct;
  if (tty_) {
    std::fprintf(stderr, "\r%-40s %3d%%", lastStage_.c_str(), pct);
  } else {
    std::fprintf(stderr, "%s %d%%\n", lastStage_.c_str(), pct);
  }
  std::fflush(stderr);
}

void StderrProgress::setStage(const core::Stage& info) {
  core::Progress::setStage(info);
  const std::string stage = info.english();
  if (quiet_ || stage == lastStage_) return;
  if (tty_ && !lastStage_.empty()) std::fprintf(stderr, "\n");
  lastStage_ = stage;
  // On a terminal each stage redraws its own line; in a log, one line per 10 % of the run.
  if (tty_) lastPercent_ = -1;
}

void StderrProgress::finish() {
  if (!quiet_ && tty_ && !lastStage_.empty()) std::fprintf(stderr, "\n");
}

StderrProgress& commandProgress() {
  static StderrProgress progress;
  return progress;
}

std::string positionalArgument(const std::vector<std::string>& args, const std::vector<std::string>& valueOptions,
                               std::vector<std::string>& rest) {
  std::string positional;
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string& a = args[i];
    const bool takesValue =
        std::find(valueOptions.begin(), valueOptions.end(), a) != valueOptions.end() && i + 1 < args.size();
    if (a.rfind("-", 0) == 0) {
      rest.push_back(a);
      if (takesValue) rest.push_back(args[++i]);
    } else if (positional.empty()) {
      positional = a;
    } else {
      throw UsageError("unexpected argument '" + a + "': give one PROJECT");
    }
  }
  return positional;
}

void throwIfCanceled(const core::Progress& p) {
  if (p.canceled()) throw Canceled();
}

void checkOutputs(const Options& opts, const std::vector<std::pair<std::string, io::OutputFormat>>& outputs,
                  const std::vector<std::string>& inputs) {
  std::vector<io::OutputFile> files;
  for (const auto& [key, format] : outputs) {
    if (opts.has(key)) files.push_back({opts.get(key), format});
  }
  std::vector<std::string> inputFiles;
  for (const auto& key : inputs) {
    if (opts.has(key)) inputFiles.push_back(opts.get(key));
  }
  io::checkOutputs(files, inputFiles);
}

long long featureId(const core::Feature& feature, size_t index, const std::string& file) {
  const auto id = readFeatureProperties([&] { return core::numberProperty(feature, "id", 9e15); },
                                        "feature " + std::to_string(index + 1), file);
  return id ? static_cast<long long>(*id) : static_cast<long long>(index + 1);
}

core::Feature roiFeature(const Options& opts) {
  const auto v = opts.getList("roi");
  if (v.size() != 4 || v[2] <= 0 || v[3] <= 0) throw UsageError("--roi expects X,Y,W,H with positive W and H");
  core::Feature f;
  f.polygon.outer = {{v[0], v[1]}, {v[0] + v[2], v[1]}, {v[0] + v[2], v[1] + v[3]}, {v[0], v[1] + v[3]}};
  return f;
}

namespace {
std::vector<CommandInfo>& registry() {
  static std::vector<CommandInfo> r;
  return r;
}
}  // namespace

bool registerCommand(CommandInfo info) {
  registry().push_back(std::move(info));
  std::sort(registry().begin(), registry().end(),
            [](const CommandInfo& a, const CommandInfo& b) { return a.name < b.name; });
  return true;
}

const std::vector<CommandInfo>& commands() { return registry(); }

namespace {
void printTopHelp(std::ostream& out) {
  out << "usage: delineo-cli COMMAND [options]   (delineo-cli COMMAND --help for details)\n\n"
         "commands:\n";
  for (const auto& c : commands()) {
    std::string left = "  " + c.name;
    out << left << std::string(left.size() < 20 ? 20 - left.size() : 1, ' ') << c.summary << "\n";
  }
  out << "\nexit codes: 0 ok, 2 usage, 3 bad input, 4 processing failure, 130 canceled\n";
}
}  // namespace

int runCommand(const std::vector<std::string>& argv) {
  if (argv.empty() || argv[0] == "--help" || argv[0] == "-h" || argv[0] == "help") {
    printTopHelp(argv.empty() ? std::cerr : std::cout);
    return argv.empty() ? kExitUsage : kExitOk;
  }
  const auto& cmds = commands();
  auto it = std::find_if(cmds.begin(), cmds.end(),
                         [&](const CommandInfo& c) { return c.name == argv[0]; });
  if (it == cmds.end()) {
    std::cerr << "delineo-cli: unknown command '" << argv[0] << "'\n";
    printTopHelp(std::cerr);
    return kExitUsage;
  }
  const std::vector<std::string> rest(argv.begin() + 1, argv.end());
  try {
    const int rc = it->run(rest);
    commandProgress().finish();
    return rc;
  } catch (const UsageError& e) {
    commandProgress().finish();
    std::cerr << "delineo-cli " << it->name << ": " << e.what() << "\n";
    return kExitUsage;
  } catch (const Canceled&) {
    commandProgress().finish();
    std::cerr << "delineo-cli " << it->name << ": canceled\n";
    return kExitCanceled;
  } catch (const core::Error& e) {
    commandProgress().finish();
    std::cerr << "delineo-cli " << it->name << ": error: " << e.what() << "\n";
    return core::isInputError(e.code()) ? kExitBadInput : kExitProcessing;
  } catch (const std::exception& e) {
    commandProgress().finish();
    std::cerr << "delineo-cli " << it->name << ": processing failed: " << e.what() << "\n";
    return kExitProcessing;
  }
}

}  // namespace delineo::cli
