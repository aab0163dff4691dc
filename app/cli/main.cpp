// delineo-cli: headless entry point. Ctrl-C cancels the running command's progress object; the
// command unwinds and the process exits with 130 (no partial output is presented as complete).
#include <csignal>
#include <string>
#include <vector>

#include "cli_support.hpp"
#include "delineo/core/allocator.hpp"

namespace {
extern "C" void onInterrupt(int) {
  // Only an atomic store: async-signal-safe.
  delineo::cli::commandProgress().cancel();
}
}  // namespace

int main(int argc, char** argv) {
  delineo::core::tuneAllocatorForLargeImages();  // before any image is allocated
  delineo::cli::commandProgress();  // construct before any signal can arrive
  std::signal(SIGINT, onInterrupt);
  std::signal(SIGTERM, onInterrupt);
  std::vector<std::string> args(argv + 1, argv + argc);
  return delineo::cli::runCommand(args);
}
