// delineo-cli run PROJECT: executes a project's pending steps with the same code as the GUI
// (delineo::project): dense matching when the project has no disparity yet, the outline of every
// pending building with its method (the active polygon, or box-fitting), with --detect first the
// scene analysis and its building proposals, export of the
// delineated outlines (and of their LoD1 blocks on the ground next to each when they have roof
// heights, with --detect's DTM as terrain), then an atomic save of the project. `--sample DIR` first creates (or reuses) the bundled sample project in DIR.
#include <cstdio>

#include "cli_support.hpp"
#include "delineo/core/error.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/project/project.hpp"

namespace {
using namespace delineo;

int run(const std::vector<std::string>& args) {
  cli::Options opts("run",
                    "Executes the pending steps of a project: matching if the disparity is "
                    "missing, the outline of pending buildings with their method (the project's "
                    "or the building's \"method\": active-polygon or box-fitting), export of the "
                    "outlines to <outputDir>/buildings.geojson and, for the buildings with a roof "
                    "height, of their LoD1 blocks (on the ground next to each; with --detect, with the terrain) to "
                    "<outputDir>/buildings.city.json; then saves the project.\n"
                    "Usage: delineo-cli run PROJECT [options]");
  opts.value("project", "FILE", "project file (may also be given as the first argument)", "")
      .value("sample", "DIR", "create (or reuse) the sample project in DIR and run it", "")
      .flag("detect", "first detect buildings (ground, DTM, classes, objects) and add the proposals as pending buildings")
      .flag("no-save", "do not write the project file back (outputs are still written)")
      .flag("quiet", "no progress on stderr");
  // PROJECT may stand anywhere among the options: the one argument that is neither an option
  // nor an option's value.
  std::vector<std::string> rest;
  std::string projectPath = cli::positionalArgument(args, {"--project", "--sample"}, rest);
  if (!opts.parse(rest)) return cli::kExitOk;
  if (!projectPath.empty() && opts.has("project")) throw cli::UsageError("give PROJECT or --project, not both");
  if (projectPath.empty()) projectPath = opts.get("project");
  auto& progress = cli::commandProgress();
  progress.setQuiet(opts.has("quiet"));
  if (!opts.get("sample").empty()) {
    if (!projectPath.empty()) throw cli::UsageError("give either PROJECT or --sample, not both");
    progress.setStage("creating the sample scene");
    projectPath = project::ensureSampleProject(opts.get("sample"), &progress);
  }
  if (projectPath.empty()) throw cli::UsageError("missing PROJECT (see --help)");

  project::Project proj = project::loadProject(projectPath);
  for (const auto& missing : proj.missingFiles()) {
    throw core::Error(core::ErrorCode::FileNotFound, "referenced by the project " + projectPath, missing);
  }
  project::RunOptions runOptions;
  runOptions.detect = opts.has("detect");
  const project::RunSummary summary =
      project::runPendingSteps(proj, project::outputDirectory(proj, projectPath), &progress, runOptions);
  cli::throwIfCanceled(progress);
  if (summary.status == core::RunStatus::Canceled) throw cli::Canceled();
  progress.finish();
  if (summary.rangeEstimated) {
    std::fprintf(stderr, "run: disparity range estimated from %d matches: [%d, %d] px\n",
                 summary.rangeEstimated->matches, summary.rangeEstimated->range.low,
                 summary.rangeEstimated->range.high);
  }
  for (const auto& message : summary.messages) std::fprintf(stderr, "run: %s\n", message.c_str());
  if (runOptions.detect) {
    std::fprintf(stderr, "run: %d above-ground object(s), %d new building(s) proposed\n", summary.objects,
                 summary.proposed);
  }
  if (summary.boxFitted > 0) std::fprintf(stderr, "run: %d building(s) outlined by box-fitting\n", summary.boxFitted);
  if (!opts.has("no-save")) project::saveProject(proj, projectPath);
  std::fprintf(stderr, "run: %s; %d building(s) delineated, %d skipped%s%s\n",
               summary.matched ? "disparity computed" : "disparity already present",
               summary.delineated, summary.skipped,
               summary.exported.empty() ? "" : "; outlines written to ",
               summary.exported.c_str());
  if (!summary.exportedBlocks.empty()) {
    std::fprintf(stderr, "run: LoD1 blocks written to %s", summary.exportedBlocks.c_str());
    if (summary.terrainTriangles > 0) std::fprintf(stderr, " with the terrain (%d triangles)", summary.terrainTriangles);
    std::fprintf(stderr, "\n");
  }
  return summary.skipped > 0 || summary.blocksFailed ? cli::kExitProcessing : cli::kExitOk;
}

const bool registered = cli::registerCommand(
    {"run", "execute a project's pending steps (matching, delineation, export) and save it", run});
}  // namespace
