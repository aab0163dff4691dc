#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <thread>
#include <vector>

#include <cpl_conv.h>
#include <gdal.h>
#include <gtest/gtest.h>
#include <ogr_srs_api.h>

#include "delineo/core/error.hpp"
#include "delineo/core/nan_mask.hpp"
#include "delineo/io/raster.hpp"
#include "epsg_wkt.hpp"
#include "temp_dir.hpp"

namespace delineo::io {
namespace {

using core::ErrorCode;
using testing::TempDir;

using testing::captureError;

cv::Mat randomImage(int rows, int cols, int type, double low, double high, int seed) {
  cv::Mat image(rows, cols, type);
  cv::RNG rng(static_cast<uint64>(seed));
  rng.fill(image, cv::RNG::UNIFORM, low, high);
  return image;
}

bool sameBits(const cv::Mat& a, const cv::Mat& b) {
  if (a.size() != b.size() || a.type() != b.type()) return false;
  return cv::norm(a, b, cv::NORM_INF) == 0.0;
}

// Writes a raster with arbitrary GDAL type/band count through GDAL itself, for inputs the
// library refuses to write (2 bands, complex, float64, int16).
void writeWithGdal(const std::string& path, int width, int height, int bands, GDALDataType type) {
  GDALAllRegister();
  GDALDatasetH ds = GDALCreate(GDALGetDriverByName("GTiff"), path.c_str(), width, height, bands, type, nullptr);
  ASSERT_NE(ds, nullptr);
  for (int b = 1; b <= bands; ++b) GDALFillRaster(GDALGetRasterBand(ds, b), 7.0, 0.0);
  GDALClose(ds);
}

TEST(RasterIo, EightBitRoundTrip) {
  TempDir dir;
  const cv::Mat image = randomImage(37, 53, CV_8UC1, 0, 256, 1);
  writeGeoTiff(dir.file("a.tif"), image);
  const Raster raster = readRaster(dir.file("a.tif"));
  EXPECT_TRUE(sameBits(raster.data, image));
  EXPECT_FALSE(raster.geo.valid());
  EXPECT_TRUE(raster.geo.crsWkt.empty());
  EXPECT_FALSE(raster.nodata.has_value());
  EXPECT_EQ(raster.path, dir.file("a.tif"));
}

TEST(RasterIo, SixteenBitRoundTripUncompressed) {
  TempDir dir;
  const cv::Mat image = randomImage(20, 31, CV_16UC1, 0, 65536, 2);
  WriteOptions options;
  options.compress = false;
  writeGeoTiff(dir.file("a.tif"), image, {}, options);
  const Raster raster = readRaster(dir.file("a.tif"));
  ASSERT_EQ(raster.data.type(), CV_16UC1);
  EXPECT_TRUE(sameBits(raster.data, image));
  double maxValue = 0;
  cv::minMaxLoc(raster.data, nullptr, &maxValue);
  EXPECT_GT(maxValue, 255.0);
}

TEST(RasterIo, FloatWithNaNRoundTripDeclaresNaNNodata) {
  TempDir dir;
  cv::Mat image = randomImage(16, 24, CV_32FC1, -50, 300, 3);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  image.at<float>(0, 0) = nan;
  image.at<float>(5, 7) = nan;
  writeFloatGeoTiff(dir.file("dem.tif"), image);
  const Raster raster = readRaster(dir.file("dem.tif"));
  ASSERT_EQ(raster.data.type(), CV_32FC1);
  ASSERT_TRUE(raster.nodata.has_value());
  EXPECT_TRUE(std::isnan(*raster.nodata));
  for (int r = 0; r < image.rows; ++r) {
    for (int c = 0; c < image.cols; ++c) {
      const float expected = image.at<float>(r, c);
      const float actual = raster.data.at<float>(r, c);
      if (std::isnan(expected)) {
        EXPECT_TRUE(std::isnan(actual)) << r << "," << c;
      } else {
        EXPECT_EQ(actual, expected) << r << "," << c;
      }
    }
  }
}

TEST(RasterIo, FiniteNodataBecomesNaNOnlyWhenReadingAsFloat) {
  TempDir dir;
  cv::Mat image(4, 5, CV_32FC1, cv::Scalar(12.5f));
  image.at<float>(1, 2) = std::numeric_limits<float>::quiet_NaN();
  WriteOptions options;
  options.nodata = -9999.0;
  writeGeoTiff(dir.file("a.tif"), image, {}, options);

  const Raster kept = readRaster(dir.file("a.tif"));
  ASSERT_TRUE(kept.nodata.has_value());
  EXPECT_EQ(*kept.nodata, -9999.0);
  EXPECT_EQ(kept.data.at<float>(1, 2), -9999.0f);  // NaN was written as the nodata value

  ReadOptions asFloat;
  asFloat.type = PixelType::Float32;
  const Raster converted = readRaster(dir.file("a.tif"), asFloat);
  EXPECT_TRUE(std::isnan(converted.data.at<float>(1, 2)));
  EXPECT_EQ(converted.data.at<float>(0, 0), 12.5f);
  EXPECT_EQ(cv::countNonZero(delineo::core::nanMask(converted.data)), 1);
}

TEST(RasterIo, EightBitNodataMapsToNaNInFloat32) {
  TempDir dir;
  cv::Mat mask(6, 6, CV_8UC1, cv::Scalar(200));
  mask.at<uchar>(3, 4) = 0;
  WriteOptions options;
  options.nodata = 0;
  writeGeoTiff(dir.file("m.tif"), mask, {}, options);
  ReadOptions asFloat;
  asFloat.type = PixelType::Float32;
  const Raster raster = readRaster(dir.file("m.tif"), asFloat);
  ASSERT_EQ(raster.data.type(), CV_32FC1);
  EXPECT_TRUE(std::isnan(raster.data.at<float>(3, 4)));
  EXPECT_EQ(raster.data.at<float>(0, 0), 200.0f);
}

TEST(RasterIo, MaskIsNonZeroAndNotNodata) {
  TempDir dir;
  cv::Mat values(4, 5, CV_32FC1, cv::Scalar(0.0f));
  values.at<float>(0, 1) = 2.0f;                                     // a class code
  values.at<float>(2, 3) = -1.0f;                                    // any non-zero value
  values.at<float>(3, 4) = std::numeric_limits<float>::quiet_NaN();  // nodata: not masked
  WriteOptions options;
  options.nodata = -9999.0;
  writeGeoTiff(dir.file("mask.tif"), values, {}, options);
  const cv::Mat mask = readMask(dir.file("mask.tif"), {5, 4});
  ASSERT_EQ(mask.type(), CV_8UC1);
  EXPECT_EQ(cv::countNonZero(mask), 2);
  EXPECT_EQ(mask.at<uchar>(0, 1), 255);
  EXPECT_EQ(mask.at<uchar>(2, 3), 255);
  EXPECT_EQ(mask.at<uchar>(3, 4), 0);
  const core::Error error = captureError([&] { readMask(dir.file("mask.tif"), {6, 4}); });
  EXPECT_EQ(error.code(), ErrorCode::MismatchedInputs);
  EXPECT_NE(std::string(error.what()).find("mask.tif"), std::string::npos);
  EXPECT_NE(std::string(error.what()).find("6x4"), std::string::npos);
}

TEST(RasterIo, ThreeBandsKeptOrConvertedToGrey) {
  TempDir dir;
  const cv::Mat rgb = randomImage(10, 12, CV_8UC3, 0, 256, 4);
  writeGeoTiff(dir.file("rgb.tif"), rgb);

  const Raster kept = readRaster(dir.file("rgb.tif"));
  ASSERT_EQ(kept.data.type(), CV_8UC3);
  EXPECT_TRUE(sameBits(kept.data, rgb));

  ReadOptions greyOptions;
  greyOptions.toGrey = true;
  const Raster grey8 = readRaster(dir.file("rgb.tif"), greyOptions);
  ASSERT_EQ(grey8.data.type(), CV_8UC1);

  GeoReference geo;
  const cv::Mat greyFloat = readGreyFloat(dir.file("rgb.tif"), &geo);
  ASSERT_EQ(greyFloat.type(), CV_32FC1);
  for (int r = 0; r < rgb.rows; ++r) {
    for (int c = 0; c < rgb.cols; ++c) {
      const cv::Vec3b px = rgb.at<cv::Vec3b>(r, c);  // band order as written: R, G, B
      const double expected = 0.299 * px[0] + 0.587 * px[1] + 0.114 * px[2];
      EXPECT_NEAR(greyFloat.at<float>(r, c), expected, 1e-3);
      EXPECT_NEAR(grey8.data.at<uchar>(r, c), expected, 0.5 + 1e-3);
    }
  }
}

// A wide image, so the NaN search runs through OpenCV's vectorised paths too.
TEST(RasterIo, ThreeBandsToGreyKeepTheNodataValueEverywhere) {
  TempDir dir;
  cv::Mat rgb(33, 70, CV_8UC3, cv::Scalar(40, 90, 160));
  int holes = 0;
  for (int r = 0; r < rgb.rows; r += 4) {
    for (int c = r % 3; c < rgb.cols; c += 9) {
      rgb.at<cv::Vec3b>(r, c) = cv::Vec3b(200, 200, 200);
      ++holes;
    }
  }
  WriteOptions options;
  options.nodata = 200.0;
  writeGeoTiff(dir.file("rgb.tif"), rgb, {}, options);

  ReadOptions greyOptions;
  greyOptions.toGrey = true;
  const Raster grey8 = readRaster(dir.file("rgb.tif"), greyOptions);
  ASSERT_EQ(grey8.data.type(), CV_8UC1);
  EXPECT_EQ(cv::countNonZero(grey8.data == 200), holes);
  EXPECT_EQ(grey8.data.at<uchar>(0, 0), 200);
  EXPECT_NEAR(grey8.data.at<uchar>(0, 1), 0.299 * 40 + 0.587 * 90 + 0.114 * 160, 0.5 + 1e-3);
}

TEST(RasterIo, GeoTransformAndCrsPreserved) {
  TempDir dir;
  GeoReference geo;
  geo.geoTransform = {741000.5, 0.5, 0.0, 3737000.25, 0.0, -0.5};
  geo.hasTransform = true;
  geo.crsWkt = testing::wktOfEpsg(32616);
  writeFloatGeoTiff(dir.file("geo.tif"), cv::Mat(8, 9, CV_32FC1, cv::Scalar(1.0f)), geo);
  GeoReference readBack;
  readGreyFloat(dir.file("geo.tif"), &readBack);
  ASSERT_TRUE(readBack.valid());
  for (size_t i = 0; i < 6; ++i) EXPECT_DOUBLE_EQ(readBack.geoTransform[i], geo.geoTransform[i]) << i;
  ASSERT_FALSE(readBack.crsWkt.empty());
  OGRSpatialReferenceH expected = OSRNewSpatialReference(geo.crsWkt.c_str());
  OGRSpatialReferenceH actual = OSRNewSpatialReference(readBack.crsWkt.c_str());
  EXPECT_TRUE(OSRIsSame(expected, actual)) << readBack.crsWkt;
  EXPECT_EQ(std::string(OSRGetAuthorityCode(actual, nullptr)), "32616");
  OSRDestroySpatialReference(expected);
  OSRDestroySpatialReference(actual);
}

TEST(RasterIo, PixelMapConversions) {
  GeoReference geo;
  geo.geoTransform = {1000.0, 2.0, 0.0, 5000.0, 0.0, -2.0};
  geo.hasTransform = true;
  const cv::Point2d map = geo.pixelToMap({10.0, 20.0});
  EXPECT_DOUBLE_EQ(map.x, 1020.0);
  EXPECT_DOUBLE_EQ(map.y, 4960.0);
  const cv::Point2d pixel = geo.mapToPixel({1020.0, 4960.0});
  EXPECT_NEAR(pixel.x, 10.0, 1e-12);
  EXPECT_NEAR(pixel.y, 20.0, 1e-12);

  GeoReference rotated;
  rotated.geoTransform = {500.0, 0.8, 0.3, 900.0, 0.2, -0.7};
  rotated.hasTransform = true;
  const cv::Point2d back = rotated.mapToPixel(rotated.pixelToMap({123.25, -4.5}));
  EXPECT_NEAR(back.x, 123.25, 1e-9);
  EXPECT_NEAR(back.y, -4.5, 1e-9);

  GeoReference identity;  // default: pixel coordinates are map coordinates
  EXPECT_EQ(identity.pixelToMap({3.0, 4.0}), cv::Point2d(3.0, 4.0));

  GeoReference singular;
  singular.geoTransform = {0, 0, 0, 0, 0, 0};
  singular.hasTransform = true;
  EXPECT_EQ(captureError([&] { singular.mapToPixel({1, 1}); }).code(), ErrorCode::InvalidParameter);
}

TEST(RasterIo, ReadsPngAndJpegThroughGdal) {
  TempDir dir;
  const cv::Mat image = randomImage(16, 16, CV_8UC1, 0, 256, 5);
  writeGeoTiff(dir.file("src.tif"), image, {}, WriteOptions{std::nullopt, false});
  GDALDatasetH source = GDALOpen(dir.file("src.tif").c_str(), GA_ReadOnly);
  ASSERT_NE(source, nullptr);
  for (const char* driverName : {"PNG", "JPEG"}) {
    const std::string path = dir.file(std::string("copy.") + (std::string(driverName) == "PNG" ? "png" : "jpg"));
    GDALDatasetH copy = GDALCreateCopy(GDALGetDriverByName(driverName), path.c_str(), source, FALSE, nullptr,
                                       nullptr, nullptr);
    ASSERT_NE(copy, nullptr) << driverName;
    GDALClose(copy);
    const Raster raster = readRaster(path);
    ASSERT_EQ(raster.data.type(), CV_8UC1) << driverName;
    if (std::string(driverName) == "PNG") {
      EXPECT_TRUE(sameBits(raster.data, image));
    } else {
      EXPECT_LT(cv::norm(raster.data, image, cv::NORM_L1) / image.total(), 40.0);  // lossy
    }
  }
  GDALClose(source);
}

TEST(RasterIo, SignedSixteenBitReadAsFloat) {
  TempDir dir;
  writeWithGdal(dir.file("i16.tif"), 4, 3, 1, GDT_Int16);
  const Raster raster = readRaster(dir.file("i16.tif"));
  ASSERT_EQ(raster.data.type(), CV_32FC1);
  EXPECT_EQ(raster.data.at<float>(2, 3), 7.0f);
}

std::string numberedTiff(const TempDir& dir, int index) {
  std::string name = std::to_string(index);
  name.insert(0, "t");
  name += ".tif";
  return dir.file(name);
}

TEST(RasterIo, ConcurrentReadsOfSeparateFiles) {
  TempDir dir;
  const int count = 4;
  std::vector<cv::Mat> images;
  for (int i = 0; i < count; ++i) {
    images.push_back(randomImage(64, 64, CV_16UC1, 0, 60000, 10 + i));
    writeGeoTiff(numberedTiff(dir, i), images.back());
  }
  std::vector<int> matches(count, 0);
  std::vector<std::thread> threads;
  for (int i = 0; i < count; ++i) {
    threads.emplace_back([&, i] {
      for (int repeat = 0; repeat < 5; ++repeat) {
        matches[static_cast<size_t>(i)] += sameBits(readRaster(numberedTiff(dir, i)).data,
                                                    images[static_cast<size_t>(i)]);
      }
    });
  }
  for (auto& thread : threads) thread.join();
  for (int i = 0; i < count; ++i) EXPECT_EQ(matches[static_cast<size_t>(i)], 5);
}

// ---- bad inputs ----

TEST(RasterIoErrors, MissingFile) {
  TempDir dir;
  const std::string path = dir.file("absent.tif");
  const core::Error error = captureError([&] { readRaster(path); });
  EXPECT_EQ(error.code(), ErrorCode::FileNotFound);
  EXPECT_EQ(error.path(), path);
  EXPECT_NE(std::string(error.what()).find(path), std::string::npos);
}

void truncateToHalf(const std::string& path) {
  const auto size = std::filesystem::file_size(path);
  std::filesystem::resize_file(path, size / 2);
}

TEST(RasterIoErrors, TruncatedTiffCompressedAndUncompressed) {
  TempDir dir;
  const cv::Mat image = randomImage(300, 300, CV_8UC1, 0, 256, 6);
  for (bool compress : {true, false}) {
    const std::string path = dir.file(compress ? "deflate.tif" : "raw.tif");
    writeGeoTiff(path, image, {}, WriteOptions{std::nullopt, compress});
    truncateToHalf(path);
    const core::Error error = captureError([&] { readRaster(path); });
    EXPECT_EQ(error.code(), ErrorCode::UnreadableFile) << error.what();
    EXPECT_NE(std::string(error.what()).find(path), std::string::npos);
  }
}

// A classic little-endian TIFF of ~130 bytes declaring width x height 8-bit grey pixels in one
// uncompressed strip, of which it holds 8 bytes.
void writeTinyTiffDeclaring(const std::string& path, uint32_t width, uint32_t height) {
  std::vector<unsigned char> bytes{'I', 'I', 42, 0, 8, 0, 0, 0};
  auto put = [&](uint64_t value, int size) {
    for (int i = 0; i < size; ++i) bytes.push_back(static_cast<unsigned char>(value >> (8 * i)));
  };
  // (tag, type: 3 SHORT / 4 LONG, value); the strip starts after the directory.
  const std::vector<std::array<uint32_t, 3>> entries{
      {256, 4, width}, {257, 4, height}, {258, 3, 8}, {259, 3, 1}, {262, 3, 1},
      {273, 4, 8 + 2 + 9 * 12 + 4}, {277, 3, 1}, {278, 4, height}, {279, 4, 8}};
  put(entries.size(), 2);
  for (const auto& [tag, type, value] : entries) {
    put(tag, 2);
    put(type, 2);
    put(1, 4);
    put(value, 4);
  }
  put(0, 4);  // no next directory
  put(0x0101010101010101ULL, 8);
  std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()),
                                              static_cast<std::streamsize>(bytes.size()));
}

TEST(RasterIoErrors, DeclaredSizeAboveTheLimitIsRefusedBeforeAllocating) {
  // 100000 x 100000 bytes = 9.3 GiB declared by a 130-byte file: refused, nothing allocated.
  TempDir dir;
  const std::string path = dir.file("huge.tif");
  writeTinyTiffDeclaring(path, 100000, 100000);
  ASSERT_LT(std::filesystem::file_size(path), 200U);
  for (const auto type : {PixelType::Keep, PixelType::Float32}) {
    const core::Error error = captureError([&] { readRaster(path, ReadOptions{type, true}); });
    EXPECT_EQ(error.code(), ErrorCode::UnsupportedInput) << error.what();
    EXPECT_EQ(error.path(), path);
    EXPECT_NE(error.detail().find("100000 x 100000"), std::string::npos) << error.detail();
  }
}

TEST(RasterIoErrors, UncompressedTiffDeclaringMoreThanItHoldsIsRefused) {
  // 20000 x 20000 bytes (400 MB, under the limit) declared, 130 bytes in the file.
  TempDir dir;
  const std::string path = dir.file("short.tif");
  writeTinyTiffDeclaring(path, 20000, 20000);
  const core::Error error = captureError([&] { readRaster(path); });
  EXPECT_EQ(error.code(), ErrorCode::UnreadableFile) << error.what();
  EXPECT_EQ(error.path(), path);
  EXPECT_NE(error.detail().find("file holds only"), std::string::npos) << error.detail();
  // The same header declaring what it holds reads.
  writeTinyTiffDeclaring(path, 4, 2);
  EXPECT_EQ(readRaster(path).data.size(), cv::Size(4, 2));
}

TEST(RasterIoErrors, SizeLimitIsConfigurable) {
  TempDir dir;
  const std::string path = dir.file("small.tif");
  writeGeoTiff(path, randomImage(32, 64, CV_16UC1, 0, 1000, 9));  // 4096 bytes decoded
  ReadOptions options;
  options.maxBytes = 4095;
  const core::Error error = captureError([&] { readRaster(path, options); });
  EXPECT_EQ(error.code(), ErrorCode::UnsupportedInput) << error.what();
  options.maxBytes = 4096;
  EXPECT_EQ(readRaster(path, options).data.size(), cv::Size(64, 32));
}

TEST(RasterIo, SparseGeoTiffReadsAsZeros) {
  // GDAL's SPARSE_OK leaves unwritten blocks out of the file: not a short file.
  TempDir dir;
  const std::string path = dir.file("sparse.tif");
  GDALAllRegister();
  const char* createOptions[] = {"SPARSE_OK=TRUE", nullptr};
  GDALDatasetH ds = GDALCreate(GDALGetDriverByName("GTiff"), path.c_str(), 2000, 1500, 1, GDT_Byte,
                               const_cast<char**>(createOptions));
  ASSERT_NE(ds, nullptr);
  GDALClose(ds);
  ASSERT_LT(std::filesystem::file_size(path), 100000U);
  const cv::Mat data = readRaster(path).data;
  ASSERT_EQ(data.size(), cv::Size(2000, 1500));
  EXPECT_EQ(cv::countNonZero(data), 0);
}

TEST(RasterIoErrors, CorruptFileAndNotARaster) {
  TempDir dir;
  {
    std::ofstream garbage(dir.file("garbage.tif"), std::ios::binary);
    garbage << "II*\0this is not really a tiff file at all";
  }
  {
    std::ofstream text(dir.file("notes.txt"));
    text << "just some text\n";
  }
  {
    std::ofstream json(dir.file("shapes.geojson"));
    json << R"({"type":"FeatureCollection","features":[]})";
  }
  for (const char* name : {"garbage.tif", "notes.txt", "shapes.geojson"}) {
    const core::Error error = captureError([&] { readRaster(dir.file(name)); });
    EXPECT_EQ(error.code(), ErrorCode::UnreadableFile) << name << ": " << error.what();
    EXPECT_EQ(error.path(), dir.file(name));
  }
  EXPECT_EQ(captureError([&] { readRaster(dir.path().string()); }).code(), ErrorCode::UnreadableFile);
}

TEST(RasterIoErrors, UnsupportedBandCountAndTypes) {
  TempDir dir;
  writeWithGdal(dir.file("two.tif"), 4, 4, 2, GDT_Byte);
  writeWithGdal(dir.file("complex.tif"), 4, 4, 1, GDT_CInt16);
  writeWithGdal(dir.file("double.tif"), 4, 4, 1, GDT_Float64);
  for (const char* name : {"two.tif", "complex.tif", "double.tif"}) {
    const core::Error error = captureError([&] { readRaster(dir.file(name)); });
    EXPECT_EQ(error.code(), ErrorCode::UnsupportedInput) << name << ": " << error.what();
    EXPECT_EQ(error.path(), dir.file(name));
  }
}

TEST(RasterIoErrors, SizeMismatch) {
  Raster a;
  a.data = cv::Mat(10, 20, CV_8UC1);
  a.path = "left.tif";
  Raster b;
  b.data = cv::Mat(10, 21, CV_8UC1);
  b.path = "right.tif";
  EXPECT_NO_THROW(requireSameSize(a, a));
  const core::Error error = captureError([&] { requireSameSize(a, b); });
  EXPECT_EQ(error.code(), ErrorCode::MismatchedInputs);
  const std::string message = error.what();
  EXPECT_NE(message.find("left.tif"), std::string::npos);
  EXPECT_NE(message.find("right.tif"), std::string::npos);
}

TEST(RasterIoErrors, WriteFailures) {
  TempDir dir;
  const cv::Mat image(4, 4, CV_8UC1, cv::Scalar(1));
  const std::string inMissingDir = dir.file("no/such/dir/out.tif");
  const core::Error missingDir = captureError([&] { writeGeoTiff(inMissingDir, image); });
  EXPECT_EQ(missingDir.code(), ErrorCode::WriteFailed);
  EXPECT_EQ(missingDir.path(), inMissingDir);
  EXPECT_EQ(captureError([&] { writeGeoTiff(dir.path().string(), image); }).code(), ErrorCode::WriteFailed);
  EXPECT_EQ(captureError([&] { writeGeoTiff(dir.file("d.tif"), cv::Mat(4, 4, CV_64FC1)); }).code(),
            ErrorCode::WriteFailed);
  EXPECT_EQ(captureError([&] { writeGeoTiff(dir.file("e.tif"), cv::Mat()); }).code(), ErrorCode::WriteFailed);
}

}  // namespace
}  // namespace delineo::io

TEST(StretchTo8Bit, EightBitValuesKeepTheirGreyLevels) {
  cv::Mat values(4, 4, CV_32F);
  for (int i = 0; i < 16; ++i) values.at<float>(i / 4, i % 4) = static_cast<float>(i * 17);
  values.at<float>(0, 0) = std::numeric_limits<float>::quiet_NaN();
  const cv::Mat out = delineo::io::stretchTo8Bit(values);
  ASSERT_EQ(out.type(), CV_8UC1);
  EXPECT_EQ(out.at<uchar>(0, 0), 0) << "nodata is black";
  EXPECT_EQ(out.at<uchar>(3, 3), 255);
  EXPECT_EQ(out.at<uchar>(1, 2), 6 * 17);
}

TEST(StretchTo8Bit, AFewHotPixelsOfADeepImageDoNotDarkenTheRest) {
  // An 11-bit image spread over 100..1100, with 0.1 % of its pixels at 2047 (saturated sensor).
  cv::Mat values(100, 100, CV_32F);
  cv::randu(values, 100.0f, 1100.0f);
  for (int i = 0; i < 10; ++i) values.at<float>(i * 7, i * 9) = 2047.0f;
  const cv::Mat out = delineo::io::stretchTo8Bit(values);
  cv::Mat inside = values < 1100.0f;
  // Within the bulk the stretch spans nearly the whole 8-bit range: the mid value lands mid-grey.
  EXPECT_NEAR(cv::mean(out, inside)[0], 127.5, 6.0);
  EXPECT_EQ(out.at<uchar>(0, 0), 255) << "a hot pixel saturates";
  double lo = 0, hi = 0;
  cv::minMaxLoc(out, &lo, &hi, nullptr, nullptr, inside);
  EXPECT_LE(lo, 2);
  EXPECT_GE(hi, 250);
}

TEST(StretchTo8Bit, BandsShareOneRangeSoColoursKeepTheirBalance) {
  cv::Mat values(10, 10, CV_32FC3, cv::Scalar(1000, 2000, 3000));
  values.at<cv::Vec3f>(0, 0) = cv::Vec3f(500, 500, 500);
  values.at<cv::Vec3f>(1, 1) = cv::Vec3f(3500, 3500, 3500);
  const cv::Vec3b pixel = delineo::io::stretchTo8Bit(values).at<cv::Vec3b>(5, 5);
  EXPECT_LT(pixel[0], pixel[1]);
  EXPECT_LT(pixel[1], pixel[2]);
}

TEST(ReadRasterInfo, TheHeaderGivesWhatReadRasterGivesWithoutThePixels) {
  delineo::io::testing::TempDir dir;
  delineo::io::GeoReference geo;
  geo.geoTransform = {500000.0, 0.5, 0.0, 4000000.0, 0.0, -0.5};
  geo.hasTransform = true;
  geo.crsWkt = delineo::io::testing::wktOfEpsg(32631);
  const std::string path = dir.file("rgb.tif");
  delineo::io::writeGeoTiff(path, cv::Mat(30, 40, CV_8UC3, cv::Scalar(1, 2, 3)), geo);
  const delineo::io::RasterInfo info = delineo::io::readRasterInfo(path);
  const delineo::io::Raster raster = delineo::io::readRaster(path);
  EXPECT_EQ(info.size, raster.data.size());
  EXPECT_EQ(info.bands, 3);
  EXPECT_EQ(info.geo.geoTransform, raster.geo.geoTransform);
  EXPECT_EQ(info.geo.crsWkt, raster.geo.crsWkt);
  EXPECT_THROW(delineo::io::readRasterInfo(dir.file("missing.tif")), delineo::core::Error);
}
