// The output policy: checks before any work, atomic replacement, symlinks and permissions.
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "delineo/core/error.hpp"
#include "delineo/io/output_file.hpp"
#include "delineo/io/raster.hpp"
#include "delineo/io/vector.hpp"
#include "temp_dir.hpp"

namespace {
using namespace delineo;
using io::OutputFormat;
using io::testing::captureError;
using io::testing::TempDir;
namespace fs = std::filesystem;

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

void writeText(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

bool runningAsRoot() { return ::geteuid() == 0; }

TEST(OutputFile, AnOutputEqualToAnInputIsRefusedEvenThroughASymlinkOrAnotherSpelling) {
  TempDir dir;
  writeText(dir.file("left.tif"), "image");
  fs::create_symlink(dir.file("left.tif"), dir.file("link.tif"));
  for (const std::string& out : {dir.file("left.tif"), dir.file("link.tif"), dir.file("sub/../left.tif")}) {
    fs::create_directories(dir.file("sub"));
    const core::Error e = captureError(
        [&] { io::checkOutputs({{out, OutputFormat::GeoTiff}}, {dir.file("left.tif")}); });
    EXPECT_EQ(e.code(), core::ErrorCode::UnusableOutput) << out;
    EXPECT_EQ(e.path(), out);
    EXPECT_NE(e.detail().find("input"), std::string::npos) << e.detail();
  }
  EXPECT_EQ(readText(dir.file("left.tif")), "image");
}

TEST(OutputFile, TwoOutputsOfOneRunMustDiffer) {
  TempDir dir;
  const core::Error e = captureError([&] {
    io::checkOutputs({{dir.file("d.tif"), OutputFormat::GeoTiff}, {dir.file("d.tif"), OutputFormat::GeoTiff}}, {});
  });
  EXPECT_EQ(e.code(), core::ErrorCode::UnusableOutput);
  EXPECT_NE(e.detail().find("two outputs"), std::string::npos);
}

TEST(OutputFile, MissingFolderWrongExtensionEmptyNameAndFolderAreRefused) {
  TempDir dir;
  const std::vector<io::OutputFile> bad{{dir.file("missing/d.tif"), OutputFormat::GeoTiff},
                                        {dir.file("d.png"), OutputFormat::GeoTiff},
                                        {dir.file("d"), OutputFormat::GeoTiff},
                                        {dir.file("o.shp"), OutputFormat::Vector},
                                        {dir.file("r.txt"), OutputFormat::Json},
                                        {"", OutputFormat::Vector}};
  for (const auto& out : bad) {
    const core::Error e = captureError([&] { io::checkOutputs({out}, {}); });
    EXPECT_EQ(e.code(), core::ErrorCode::UnusableOutput) << out.path;
  }
  fs::create_directories(dir.file("folder.tif"));
  EXPECT_EQ(captureError([&] { io::checkOutputs({{dir.file("folder.tif"), OutputFormat::GeoTiff}}, {}); }).code(),
            core::ErrorCode::UnusableOutput);
  EXPECT_NO_THROW(io::checkOutputs({{dir.file("D.TIF"), OutputFormat::GeoTiff},
                                    {dir.file("o.gpkg"), OutputFormat::Vector},
                                    {dir.file("r.json"), OutputFormat::Json}},
                                   {dir.file("left.tif")}));
}

TEST(OutputFile, AReadOnlyFileOrFolderIsNotReplaced) {
  TempDir dir;
  writeText(dir.file("old.json"), "kept");
  fs::permissions(dir.file("old.json"), fs::perms::owner_read);
  EXPECT_EQ(captureError([&] { io::checkOutputs({{dir.file("old.json"), OutputFormat::Json}}, {}); }).code(),
            core::ErrorCode::UnusableOutput);
  if (runningAsRoot()) GTEST_SKIP() << "root may write into a read-only folder";
  fs::create_directories(dir.file("locked"));
  fs::permissions(dir.file("locked"), fs::perms::owner_read | fs::perms::owner_exec);
  EXPECT_EQ(captureError([&] { io::checkOutputs({{dir.file("locked/o.json"), OutputFormat::Json}}, {}); }).code(),
            core::ErrorCode::UnusableOutput);
  fs::permissions(dir.file("locked"), fs::perms::owner_all);
}

TEST(OutputFile, AFailedWriteLeavesThePreviousFileAndNoTemporaryFile) {
  TempDir dir;
  writeText(dir.file("out.json"), "previous");
  EXPECT_THROW(io::writeAtomically(dir.file("out.json"),
                                   [](const std::string& temp) {
                                     writeText(temp, "half");
                                     throw core::Error(core::ErrorCode::WriteFailed, "disk full", temp);
                                   }),
               core::Error);
  EXPECT_EQ(readText(dir.file("out.json")), "previous");
  int files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir.path())) ++files;
  EXPECT_EQ(files, 1);
}

TEST(OutputFile, TheTemporaryFileKeepsTheExtensionTheWritersChooseTheFormatBy) {
  TempDir dir;
  std::vector<std::string> temporaries;
  for (const char* name : {"b.city.json", "B.City.JSON", "b.cityjson", "b.geojson"}) {
    io::writeAtomically(dir.file(name), [&](const std::string& temp) {
      temporaries.push_back(fs::path(temp).filename().string());
      writeText(temp, "x");
    });
  }
  ASSERT_EQ(temporaries.size(), 4u);
  EXPECT_TRUE(temporaries[0].starts_with(".b.partial-") && temporaries[0].ends_with(".city.json")) << temporaries[0];
  EXPECT_TRUE(temporaries[1].starts_with(".B.partial-") && temporaries[1].ends_with(".City.JSON")) << temporaries[1];
  EXPECT_TRUE(temporaries[2].starts_with(".b.partial-") && temporaries[2].ends_with(".cityjson")) << temporaries[2];
  EXPECT_TRUE(temporaries[3].starts_with(".b.partial-") && temporaries[3].ends_with(".geojson")) << temporaries[3];
  EXPECT_EQ(readText(dir.file("b.city.json")), "x");
}

TEST(OutputFile, TheErrorOfAFailedWriteNamesTheRequestedFileNotTheTemporaryOne) {
  TempDir dir;
  const core::Error e = captureError([&] {
    io::writeAtomically(dir.file("out.tif"), [](const std::string& temp) {
      throw core::Error(core::ErrorCode::WriteFailed, "cannot write", temp);
    });
  });
  EXPECT_EQ(e.path(), dir.file("out.tif"));
}

TEST(OutputFile, ReplacingAFileKeepsItsModeAndWritesThroughASymlink) {
  TempDir dir;
  writeText(dir.file("real.json"), "old");
  fs::permissions(dir.file("real.json"), fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
  fs::create_symlink("real.json", dir.file("link.json"));
  io::writeTextFile(dir.file("link.json"), "new");
  EXPECT_TRUE(fs::is_symlink(dir.file("link.json")));
  EXPECT_EQ(readText(dir.file("real.json")), "new");
  EXPECT_EQ(fs::status(dir.file("real.json")).permissions(),
            fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read);
}

TEST(OutputFile, GeoTiffAndVectorWritersReplaceAtomically) {
  TempDir dir;
  const std::string tif = dir.file("d.tif");
  io::writeFloatGeoTiff(tif, cv::Mat(4, 5, CV_32F, cv::Scalar(2.0f)));
  // An empty image is refused during the write: the previous file stays whole.
  EXPECT_THROW(io::writeFloatGeoTiff(tif, cv::Mat()), core::Error);
  EXPECT_EQ(io::readGreyFloat(tif).cols, 5);

  core::Feature f;
  f.polygon.outer = {{0, 0}, {4, 0}, {4, 3}};
  io::writeFeatures(dir.file("o.geojson"), {f});
  io::writeFeatures(dir.file("o.geojson"), {f, f});
  EXPECT_EQ(io::readFeatures(dir.file("o.geojson")).size(), 2u);
  int files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(dir.path())) ++files;
  EXPECT_EQ(files, 2);
}

}  // namespace
