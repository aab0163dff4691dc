#pragma once
// Raster I/O through GDAL. Every error names the file and the problem (core::Error).
#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

namespace delineo::io {

// Affine pixel → map transform, GDAL order: x = gt[0] + col*gt[1] + row*gt[2],
// y = gt[3] + col*gt[4] + row*gt[5]. Pixel (col, row) is the pixel's top-left corner.
struct GeoReference {
  std::array<double, 6> geoTransform{0, 1, 0, 0, 0, 1};
  std::string crsWkt;  // empty when the raster has no CRS
  bool hasTransform = false;
  bool valid() const { return hasTransform; }
  cv::Point2d pixelToMap(const cv::Point2d& pixel) const;
  cv::Point2d mapToPixel(const cv::Point2d& map) const;
};

struct Raster {
  cv::Mat data;  // rows x cols, CV_8U/CV_16U/CV_32F, 1 or more channels (band order as in file)
  GeoReference geo;
  std::optional<double> nodata;  // from the file's first band, when it declares one
  std::string path;
};

enum class PixelType { Keep, Float32 };

struct ReadOptions {
  // Keep: 8/16-bit stay integer; Float32: converted, and nodata pixels become NaN.
  PixelType type = PixelType::Keep;
  // Any number of bands is accepted when false; when true the result has exactly one channel
  // (grey conversion: 1 band as is, 3+ bands as 0.299 R + 0.587 G + 0.114 B of the first three).
  bool toGrey = false;
  // Largest decoded pixel buffer accepted (bytes, all bands at the decoded depth), checked on
  // the declared size before anything is allocated. Default 4 GiB: 1 Gpx of float32.
  std::uint64_t maxBytes = std::uint64_t{4} << 30;
};

// Reads a raster. Throws FileNotFound, UnreadableFile (truncated / corrupt / not a raster, or an
// uncompressed GeoTIFF declaring more pixel data than the file holds), UnsupportedInput (complex
// or 64-bit types, 2 bands, a declared size above ReadOptions::maxBytes).
Raster readRaster(const std::string& path, const ReadOptions& options = {});

// What a raster's header says, without reading its pixels: its size, bands and georeferencing.
// Throws like readRaster for a file it would refuse by its header.
struct RasterInfo {
  cv::Size size;
  int bands = 0;
  GeoReference geo;
};
RasterInfo readRasterInfo(const std::string& path);

// Reads a raster as a single-band float32 image ready for matching (grey, NaN for nodata).
cv::Mat readGreyFloat(const std::string& path, GeoReference* geo = nullptr);

// Reads an image for its colours: CV_8UC3 BGR for a raster of 3 or more bands (the first three
// read as R, G, B), else CV_8UC1 grey, through stretchTo8Bit(). Throws like readRaster.
cv::Mat readImage8(const std::string& path);

// Share of the finite values left darker than black, and brighter than white, by stretchTo8Bit().
inline constexpr double kStretchLowQuantile = 0.005;
// CV_32F values (any number of bands) as 8-bit for display and radiometry: values within 0..255
// keep their grey levels; deeper ones (an 11- or 12-bit satellite image) are stretched from the
// 0.5th to the 99.5th percentile of the finite values of all bands together (the colours keep
// their balance), so that a few hot pixels do not darken the rest. NaN (nodata) becomes 0.
cv::Mat stretchTo8Bit(const cv::Mat& values);

// Reads a single-band raster as a mask of the given size: CV_8U, 255 where the value is non-zero
// and not nodata, 0 elsewhere (exclusion masks, classifications). Throws like readRaster, and
// MismatchedInputs naming the file when it has several bands or another size.
cv::Mat readMask(const std::string& path, cv::Size expected);

struct WriteOptions {
  std::optional<double> nodata;  // written into the file's band metadata
  bool compress = true;          // DEFLATE
};

// Writes GeoTIFF: CV_8U, CV_16U or CV_32F, 1..4 channels. For float images with `nodata` set,
// NaN pixels are written as that value. Writes `geo` when valid. Throws WriteFailed.
void writeGeoTiff(const std::string& path, const cv::Mat& image, const GeoReference& geo = {},
                  const WriteOptions& options = {});

// Float32 GeoTIFF with NaN kept as NaN and declared as the nodata value (DEM, disparity).
void writeFloatGeoTiff(const std::string& path, const cv::Mat& image, const GeoReference& geo = {});

// Ensures a and b have the same size; throws MismatchedInputs naming both files otherwise.
void requireSameSize(const Raster& a, const Raster& b);

}  // namespace delineo::io
