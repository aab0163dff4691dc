// delineo-cli import PROJECT --outlines FILE: the outlines of another source (a cadastre,
// OpenStreetMap, another project's export, detect's proposals) added to a project as pending
// buildings (project::importOutlinesFile); `run` then outlines them.
#include <cstdio>

#include "cli_support.hpp"
#include "delineo/project/pipeline.hpp"
#include "delineo/project/project.hpp"

namespace {
using namespace delineo;

void printSummary(const project::ImportSummary& summary, const std::string& path) {
  for (const auto& line : summary.problems) std::fprintf(stderr, "import: %s\n", line.c_str());
  std::printf("import: %d of %d polygon(s) of %s added as pending buildings", static_cast<int>(summary.added.size()),
              summary.read, path.c_str());
  if (summary.clipped > 0) std::printf(" (%d cut at the image border)", summary.clipped);
  if (summary.alreadyThere > 0) std::printf("; %d already buildings of the project", summary.alreadyThere);
  if (summary.outsideImage > 0) std::printf("; %d outside the left image", summary.outsideImage);
  std::printf("\n");
  if (summary.read > 0 && summary.outsideImage == summary.read) {
    std::fprintf(stderr,
                 "import: no polygon lies on the left image: are its coordinates in the CRS the file declares, "
                 "else the image's (pixels when the image has no georeferencing)?\n");
  }
}

int run(const std::vector<std::string>& args) {
  cli::Options opts("import",
                    "Adds the polygons of a vector file to a project as pending buildings, then saves it.\n"
                    "Usage: delineo-cli import PROJECT --outlines FILE [options]");
  opts.required("outlines", "FILE",
                "polygons to import (.geojson, .gpkg, .shp): in the CRS the file declares (transformed into the "
                "left image's), else in the image's CRS, or pixels when the image has no georeferencing")
      .value("id-field", "NAME", "attribute kept as each building's source id (exported as source_id)")
      .flag("no-save", "do not write the project file back (print what would be added)");
  std::vector<std::string> rest;
  const std::string projectPath = cli::positionalArgument(args, {"--outlines", "--id-field"}, rest);
  if (!opts.parse(rest)) return cli::kExitOk;
  if (projectPath.empty()) throw cli::UsageError("missing PROJECT (see --help)");

  project::Project proj = project::loadProject(projectPath);
  project::ImportOptions options;
  options.idField = opts.has("id-field") ? opts.get("id-field") : std::string();
  options.origin = "delineo-cli import";
  const std::string path = opts.get("outlines");
  const project::ImportSummary summary = project::importOutlinesFile(proj, path, options);
  if (!opts.has("no-save") && !summary.added.empty()) project::saveProject(proj, projectPath);
  printSummary(summary, path);
  return cli::kExitOk;
}

const bool registered = cli::registerCommand(
    {"import", "add the outlines of a vector file (cadastre, OpenStreetMap, an export) to a project as pending buildings",
     run});
}  // namespace
