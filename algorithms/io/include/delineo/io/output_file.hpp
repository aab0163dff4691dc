#pragma once
// The output policy of every command and of the GUI (docs/conventions.md, "Outputs"):
// - an output is checked before any work: a name, a known extension matching what is written,
//   an existing folder that can be written, not an existing read-only file, never the same file
//   as an input of the run nor as another output (compared after resolving symlinks);
// - it is written to a temporary file in its own folder and renamed over the target only once
//   complete, so that a failure or a cancel leaves the previous file as it was; the existing
//   file's permissions are kept and a symlink is followed to the file it names.
#include <functional>
#include <string>
#include <vector>

namespace delineo::io {

enum class OutputFormat {
  GeoTiff,  // .tif / .tiff
  Vector,   // .geojson / .json / .gpkg
  CityJson, // .city.json / .cityjson (3D blocks, io/cityjson.hpp)
  Json,     // .json (reports)
  Text,     // any name (project files and their autosave copies)
};

struct OutputFile {
  std::string path;
  OutputFormat format = OutputFormat::GeoTiff;
};

// The file a write to `path` replaces: absolute, normalised, symlinks followed when it exists.
std::string resolvedPath(const std::string& path);

// True when a and b name the same file (after resolving; two paths to one existing file count).
bool sameFile(const std::string& a, const std::string& b);

// Checks `outputs` against the policy above. `inputs` are the files the run reads (empty
// entries ignored). Throws core::Error(UnusableOutput) naming the output and the problem.
void checkOutputs(const std::vector<OutputFile>& outputs, const std::vector<std::string>& inputs);

// Writes `path` through a temporary file: `write` receives the temporary path (same folder,
// same extension, ".city.json" whole) and writes the whole file there; on success it replaces the target (the real
// file when `path` is a symlink), keeping the target's permissions; on any exception the
// temporary file is removed, the target is untouched and the exception goes on.
void writeAtomically(const std::string& path, const std::function<void(const std::string&)>& write);

// writeAtomically() of a text file. Throws core::Error(WriteFailed) naming `path`.
void writeTextFile(const std::string& path, const std::string& text);

}  // namespace delineo::io
