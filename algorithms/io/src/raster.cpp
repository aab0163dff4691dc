#include "delineo/io/raster.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <tuple>
#include <utility>
#include <vector>

#include <cpl_conv.h>
#include <cpl_string.h>
#include <cpl_vsi.h>
#include <gdal.h>
#include <opencv2/imgproc.hpp>

#include "delineo/core/error.hpp"
#include "delineo/core/nan_mask.hpp"
#include "delineo/io/output_file.hpp"
#include "gdal_support.hpp"

namespace delineo::io {

using core::Error;
using core::ErrorCode;

cv::Point2d GeoReference::pixelToMap(const cv::Point2d& pixel) const {
  const auto& gt = geoTransform;
  return {gt[0] + pixel.x * gt[1] + pixel.y * gt[2], gt[3] + pixel.x * gt[4] + pixel.y * gt[5]};
}

cv::Point2d GeoReference::mapToPixel(const cv::Point2d& map) const {
  const auto& gt = geoTransform;
  const double det = gt[1] * gt[5] - gt[2] * gt[4];
  if (det == 0.0 || !std::isfinite(det)) {
    throw Error(ErrorCode::InvalidParameter, "geotransform is not invertible (zero pixel size)");
  }
  const double dx = map.x - gt[0];
  const double dy = map.y - gt[3];
  return {(gt[5] * dx - gt[2] * dy) / det, (-gt[4] * dx + gt[1] * dy) / det};
}

namespace {

using DatasetPtr = std::unique_ptr<void, detail::DatasetCloser>;

struct ReadLayout {
  GDALDataType gdalType;
  int depth;  // OpenCV depth of the decoded pixels
};

// Maps the file's pixel type to what Raster holds. Signed and 32-bit integer rasters (e.g. Int16
// DEMs) are decoded as float32, which is exact for 16-bit values.
ReadLayout layoutFor(GDALDataType type, const std::string& path) {
  switch (type) {
    case GDT_Byte: return {GDT_Byte, CV_8U};
    case GDT_UInt16: return {GDT_UInt16, CV_16U};
    case GDT_Float32:
    case GDT_Int16:
    case GDT_Int32:
    case GDT_UInt32: return {GDT_Float32, CV_32F};
    default:
      throw Error(ErrorCode::UnsupportedInput,
                  std::string("pixel type ") + GDALGetDataTypeName(type) +
                      " is not supported (8/16-bit unsigned, 16/32-bit integer or float32 only)",
                  path);
  }
}

// Expands a palette band (e.g. an indexed PNG) into three R, G, B channels of the same depth.
cv::Mat expandPalette(const cv::Mat& indices, GDALColorTableH table) {
  const int entries = GDALGetColorEntryCount(table);
  cv::Mat lut(1, 256, CV_8UC3, cv::Scalar::all(0));
  for (int i = 0; i < std::min(entries, 256); ++i) {
    const GDALColorEntry* entry = GDALGetColorEntry(table, i);
    lut.at<cv::Vec3b>(0, i) = cv::Vec3b(static_cast<uchar>(entry->c1), static_cast<uchar>(entry->c2),
                                        static_cast<uchar>(entry->c3));
  }
  cv::Mat rgbSource;
  cv::cvtColor(indices, rgbSource, cv::COLOR_GRAY2BGR);  // three copies of the index
  cv::Mat rgb;
  cv::LUT(rgbSource, lut, rgb);
  return rgb;
}

// Float copy of `data` where each band's nodata value becomes NaN.
cv::Mat toFloatWithNaN(const cv::Mat& data, const std::vector<std::optional<double>>& bandNodata) {
  cv::Mat asFloat;
  data.convertTo(asFloat, CV_32F);
  const int channels = asFloat.channels();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  bool anyNodata = false;
  for (const auto& value : bandNodata) anyNodata = anyNodata || (value && !std::isnan(*value));
  if (!anyNodata) return asFloat;
  for (int row = 0; row < asFloat.rows; ++row) {
    float* pixel = asFloat.ptr<float>(row);
    for (int col = 0; col < asFloat.cols; ++col) {
      for (int c = 0; c < channels; ++c, ++pixel) {
        const auto& nodata = bandNodata[static_cast<size_t>(c)];
        // Compare in float: the nodata value went through the same conversion as the pixels.
        if (nodata && *pixel == static_cast<float>(*nodata)) *pixel = nan;
      }
    }
  }
  return asFloat;
}

// Single-channel float grey: 1 channel as is, 3+ channels 0.299 R + 0.587 G + 0.114 B.
cv::Mat greyFromFloat(const cv::Mat& asFloat) {
  if (asFloat.channels() == 1) return asFloat;
  std::vector<cv::Mat> planes;
  cv::split(asFloat, planes);
  cv::Mat grey = 0.299 * planes[0] + 0.587 * planes[1] + 0.114 * planes[2];
  return grey;
}

// Refuses a declared size before the pixel buffer is allocated: above `maxBytes` decoded, or,
// for an uncompressed GeoTIFF, more pixel bytes than the whole file holds (a header of a few
// bytes may declare 100000 x 100000 pixels).
void checkDeclaredSize(GDALDatasetH ds, int width, int height, int bands, int decodedDepth,
                       std::uint64_t maxBytes, const std::string& path) {
  const auto pixels = static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height);
  const auto bytesPerPixel = static_cast<std::uint64_t>(bands) *
                             static_cast<std::uint64_t>(CV_ELEM_SIZE1(decodedDepth));
  const std::string size = std::to_string(width) + " x " + std::to_string(height) + " x " +
                           std::to_string(bands) + " band(s)";
  if (pixels > maxBytes / bytesPerPixel) {
    throw Error(ErrorCode::UnsupportedInput,
                "declared size " + size + " needs more than the " + std::to_string(maxBytes >> 20) +
                    " MiB allowed for one raster (io::ReadOptions::maxBytes)",
                path);
  }
  GDALDriverH driver = GDALGetDatasetDriver(ds);
  const bool uncompressedTiff = driver != nullptr && std::string(GDALGetDriverShortName(driver)) == "GTiff" &&
                                GDALGetMetadataItem(ds, "COMPRESSION", "IMAGE_STRUCTURE") == nullptr;
  if (!uncompressedTiff) return;
  VSIStatBufL stat{};
  if (VSIStatL(path.c_str(), &stat) != 0) return;
  // Bits per stored sample: NBITS (1..7 bit TIFFs) or the data type's size.
  GDALRasterBandH first = GDALGetRasterBand(ds, 1);
  const char* nbits = GDALGetMetadataItem(first, "NBITS", "IMAGE_STRUCTURE");
  const int bits = nbits != nullptr ? std::atoi(nbits) : GDALGetDataTypeSizeBits(GDALGetRasterDataType(first));
  // A sparse GeoTIFF (GDAL's SPARSE_OK) leaves blocks out of the file; they read as zeros.
  if (bits <= 0 || GDALGetMetadataItem(first, "BLOCK_OFFSET_0_0", "TIFF") == nullptr) return;
  // A lower bound for every layout (rows may be padded to whole bytes, bands interleaved or not).
  const std::uint64_t rowBytes = static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(bands) *
                                 static_cast<std::uint64_t>(bits) / 8;
  const std::uint64_t needed = rowBytes * static_cast<std::uint64_t>(height);
  if (needed > static_cast<std::uint64_t>(stat.st_size)) {
    throw Error(ErrorCode::UnreadableFile,
                "declared size " + size + " needs " + std::to_string(needed) +
                    " bytes of uncompressed pixels but the file holds only " +
                    std::to_string(stat.st_size) + " bytes (truncated or corrupt)",
                path);
  }
}

// A path on disk must name a file; GDAL's virtual paths (/vsizip/...) are left to GDAL.
void requireFileOnDisk(const std::string& path) {
  if (detail::isVirtualPath(path)) return;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw Error(ErrorCode::FileNotFound, "no such file", path);
  if (std::filesystem::is_directory(path, ec)) {
    throw Error(ErrorCode::UnreadableFile, "is a directory, not a raster file", path);
  }
}

// What the file declares: its size, its band count and how its pixels are decoded.
struct RasterShape {
  int width = 0, height = 0, bands = 0;
  ReadLayout layout{};
};

// The file's shape; throws on what readRaster refuses: no band, 2 bands, more than OpenCV's
// channels, a pixel type it does not decode in the first band or a complex or 64-bit one in
// another.
RasterShape checkedShape(GDALDatasetH ds, const std::string& path) {
  const int width = GDALGetRasterXSize(ds);
  const int height = GDALGetRasterYSize(ds);
  const int bands = GDALGetRasterCount(ds);
  if (bands == 0 || width <= 0 || height <= 0) {
    throw Error(ErrorCode::UnreadableFile, "the file holds no raster band", path);
  }
  if (bands == 2) {
    throw Error(ErrorCode::UnsupportedInput,
                "2-band rasters are not supported (expected 1 grey band or 3+ colour bands)", path);
  }
  if (bands > CV_CN_MAX) {
    throw Error(ErrorCode::UnsupportedInput, "too many bands (" + std::to_string(bands) + ")", path);
  }
  GDALRasterBandH first = GDALGetRasterBand(ds, 1);
  const ReadLayout layout = layoutFor(GDALGetRasterDataType(first), path);
  for (int b = 2; b <= bands; ++b) {
    const GDALDataType type = GDALGetRasterDataType(GDALGetRasterBand(ds, b));
    if (GDALDataTypeIsComplex(type) || GDALGetDataTypeSizeBytes(type) > 4) layoutFor(type, path);
  }
  return {width, height, bands, layout};
}

// Every band's pixels, interleaved, decoded as `shape.layout` says.
cv::Mat readPixels(GDALDatasetH ds, const RasterShape& shape, detail::ScopedGdalErrors& errors,
                   const std::string& path) {
  const int width = shape.width, height = shape.height, bands = shape.bands;
  cv::Mat data(height, width, CV_MAKETYPE(shape.layout.depth, bands));
  const auto elementBytes = static_cast<GSpacing>(data.elemSize1());
  errors.reset();
  const CPLErr readStatus = GDALDatasetRasterIOEx(
      ds, GF_Read, 0, 0, width, height, data.data, width, height, shape.layout.gdalType, bands,
      nullptr, elementBytes * bands, static_cast<GSpacing>(data.step[0]), elementBytes, nullptr);
  // A truncated TIFF often opens fine (the header is intact) and only fails here.
  if (readStatus != CE_None || errors.failed()) {
    throw Error(ErrorCode::UnreadableFile, errors.describe("pixel data cannot be read (truncated or corrupt)"),
                path);
  }
  return data;
}

// Each band's declared nodata value, if any.
std::vector<std::optional<double>> bandNodataOf(GDALDatasetH ds, int bands) {
  std::vector<std::optional<double>> bandNodata(static_cast<size_t>(bands));
  for (int b = 1; b <= bands; ++b) {
    int hasNodata = 0;
    const double value = GDALGetRasterNoDataValue(GDALGetRasterBand(ds, b), &hasNodata);
    if (hasNodata) bandNodata[static_cast<size_t>(b - 1)] = value;
  }
  return bandNodata;
}

GeoReference georeferenceOf(GDALDatasetH ds) {
  GeoReference geo;
  double geoTransform[6];
  if (GDALGetGeoTransform(ds, geoTransform) == CE_None) {
    std::copy(geoTransform, geoTransform + 6, geo.geoTransform.begin());
    geo.hasTransform = true;
  }
  if (const char* wkt = GDALGetProjectionRef(ds); wkt != nullptr) geo.crsWkt = wkt;
  return geo;
}

// An indexed-colour band only means something as colours when converting to grey; kept as
// indices otherwise (label images and masks are often paletted). When expanded, the three
// channels have no nodata value.
void expandPaletteForGrey(GDALDatasetH ds, const RasterShape& shape, const ReadOptions& options,
                          cv::Mat& data, std::vector<std::optional<double>>& bandNodata) {
  GDALRasterBandH first = GDALGetRasterBand(ds, 1);
  if (options.toGrey && shape.bands == 1 && shape.layout.depth == CV_8U &&
      GDALGetRasterColorInterpretation(first) == GCI_PaletteIndex) {
    if (GDALColorTableH table = GDALGetRasterColorTable(first); table != nullptr) {
      data = expandPalette(data, table);
      bandNodata.assign(3, std::nullopt);
    }
  }
}

// The decoded pixels as `options` asks: as they are, as float (each band's nodata as NaN), or as
// grey (float, or at the source depth).
cv::Mat convertedPixels(const cv::Mat& data, const std::vector<std::optional<double>>& bandNodata,
                        const std::optional<double>& nodata, const ReadOptions& options,
                        int depth) {
  const bool wantFloat = options.type == PixelType::Float32;
  const bool needsGrey = options.toGrey && data.channels() > 1;
  if (!wantFloat && !needsGrey) return data;
  cv::Mat asFloat = toFloatWithNaN(data, bandNodata);
  if (needsGrey) asFloat = greyFromFloat(asFloat);
  if (wantFloat) return asFloat;
  // Keep the source depth for grey output: nodata pixels get the nodata value back.
  if (nodata && !std::isnan(*nodata)) {
    asFloat.setTo(*nodata, core::nanMask(asFloat));
  }
  cv::Mat grey;
  asFloat.convertTo(grey, depth);
  return grey;
}

}  // namespace

Raster readRaster(const std::string& path, const ReadOptions& options) {
  detail::ensureGdalRegistered();
  requireFileOnDisk(path);
  detail::ScopedGdalErrors errors;
  DatasetPtr dataset(GDALOpenEx(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY | GDAL_OF_VERBOSE_ERROR, nullptr, nullptr, nullptr));
  if (!dataset) throw Error(ErrorCode::UnreadableFile, errors.describe("not a readable raster"), path);
  GDALDatasetH ds = dataset.get();
  const RasterShape shape = checkedShape(ds, path);
  checkDeclaredSize(ds, shape.width, shape.height, shape.bands, shape.layout.depth,
                    options.maxBytes, path);

  Raster raster;
  raster.path = path;
  cv::Mat data = readPixels(ds, shape, errors, path);
  std::vector<std::optional<double>> bandNodata = bandNodataOf(ds, shape.bands);
  raster.nodata = bandNodata[0];
  raster.geo = georeferenceOf(ds);
  expandPaletteForGrey(ds, shape, options, data, bandNodata);
  raster.data = convertedPixels(data, bandNodata, raster.nodata, options, shape.layout.depth);
  return raster;
}

RasterInfo readRasterInfo(const std::string& path) {
  detail::ensureGdalRegistered();
  requireFileOnDisk(path);
  detail::ScopedGdalErrors errors;
  DatasetPtr dataset(GDALOpenEx(path.c_str(), GDAL_OF_RASTER | GDAL_OF_READONLY | GDAL_OF_VERBOSE_ERROR, nullptr, nullptr, nullptr));
  if (!dataset) throw Error(ErrorCode::UnreadableFile, errors.describe("not a readable raster"), path);
  const RasterShape shape = checkedShape(dataset.get(), path);
  return {cv::Size(shape.width, shape.height), shape.bands, georeferenceOf(dataset.get())};
}

cv::Mat readGreyFloat(const std::string& path, GeoReference* geo) {
  ReadOptions options;
  options.type = PixelType::Float32;
  options.toGrey = true;
  Raster raster = readRaster(path, options);
  if (geo != nullptr) *geo = raster.geo;
  return raster.data;
}

namespace {
// The values at quantiles `low` and `high` of the finite values of every band of `values`
// (CV_32F), read on at most about a million of them taken at a regular stride.
std::pair<double, double> finiteQuantiles(const cv::Mat& values, double low, double high) {
  const cv::Mat flat = values.isContinuous() ? values.reshape(1, 1) : values.clone().reshape(1, 1);
  const size_t total = flat.total();
  const size_t stride = std::max<size_t>(1, total / 1000000);
  std::vector<float> samples;
  samples.reserve(total / stride + 1);
  const float* data = flat.ptr<float>();
  for (size_t i = 0; i < total; i += stride) {
    if (std::isfinite(data[i])) samples.push_back(data[i]);
  }
  if (samples.empty()) return {0.0, 0.0};
  auto at = [&](double q) {
    const auto k = samples.begin() + static_cast<std::ptrdiff_t>(q * static_cast<double>(samples.size() - 1));
    std::nth_element(samples.begin(), k, samples.end());
    return static_cast<double>(*k);
  };
  return {at(low), at(high)};
}
}  // namespace

cv::Mat stretchTo8Bit(const cv::Mat& values) {
  CV_Assert(values.depth() == CV_32F);
  const cv::Mat finiteBands = (values == values);  // NaN != NaN, per band
  double lo = 0.0, hi = 255.0;
  cv::minMaxLoc(values.reshape(1), &lo, &hi, nullptr, nullptr, finiteBands.reshape(1));
  if (lo >= 0.0 && hi <= 255.0) {
    lo = 0.0, hi = 255.0;  // 8-bit values keep their grey levels
  } else {
    std::tie(lo, hi) = finiteQuantiles(values, kStretchLowQuantile, 1.0 - kStretchLowQuantile);
    if (!(hi > lo)) hi = lo + 1.0;
  }
  cv::Mat finiteAll = finiteBands;
  if (finiteAll.channels() > 1) {
    std::vector<cv::Mat> parts;
    cv::split(finiteAll, parts);
    finiteAll = parts[0];
    for (size_t b = 1; b < parts.size(); ++b) finiteAll &= parts[b];
  }
  const double scale = 255.0 / (hi - lo);
  cv::Mat out;
  values.convertTo(out, CV_8U, scale, -lo * scale);  // saturates outside lo..hi
  out.setTo(cv::Scalar::all(0), finiteAll == 0);
  return out;
}

cv::Mat readImage8(const std::string& path) {
  ReadOptions options;
  options.type = PixelType::Float32;
  const Raster raster = readRaster(path, options);
  if (raster.data.channels() < 3) return stretchTo8Bit(raster.data);  // two-band rasters are refused by readRaster
  std::vector<cv::Mat> bands;
  cv::split(raster.data, bands);
  cv::Mat bgr;
  cv::merge(std::vector<cv::Mat>{bands[2], bands[1], bands[0]}, bgr);  // a fourth band is not read
  return stretchTo8Bit(bgr);
}

cv::Mat readMask(const std::string& path, cv::Size expected) {
  ReadOptions options;
  options.type = PixelType::Float32;  // nodata becomes NaN
  cv::Mat values = readRaster(path, options).data;
  if (values.channels() != 1 || values.size() != expected) {
    throw Error(ErrorCode::MismatchedInputs,
                "a mask must be single-band of the left image's size (" +
                    std::to_string(expected.width) + "x" + std::to_string(expected.height) +
                    "), not " + std::to_string(values.channels()) + "-band " +
                    std::to_string(values.cols) + "x" + std::to_string(values.rows),
                path);
  }
  cv::patchNaNs(values, 0.0);
  return values != 0;
}

namespace {
// Writes the GeoTIFF at `path` itself; writeGeoTiff() points it at a temporary file.
void writeGeoTiffAt(const std::string& path, const cv::Mat& image, const GeoReference& geo,
                    const WriteOptions& options) {
  detail::ensureGdalRegistered();
  if (image.empty()) throw Error(ErrorCode::WriteFailed, "the image to write is empty", path);
  GDALDataType gdalType = GDT_Unknown;
  switch (image.depth()) {
    case CV_8U: gdalType = GDT_Byte; break;
    case CV_16U: gdalType = GDT_UInt16; break;
    case CV_32F: gdalType = GDT_Float32; break;
    default:
      throw Error(ErrorCode::WriteFailed, "only 8-bit, 16-bit unsigned and float32 images can be written",
                  path);
  }
  const int bands = image.channels();
  if (bands < 1 || bands > 4) {
    throw Error(ErrorCode::WriteFailed, "only 1 to 4 channels can be written (got " + std::to_string(bands) + ")",
                path);
  }

  cv::Mat pixels = image;
  if (image.depth() == CV_32F && options.nodata && !std::isnan(*options.nodata)) {
    pixels = image.clone();
    cv::patchNaNs(pixels, *options.nodata);
  }

  detail::ScopedGdalErrors errors;
  GDALDriverH driver = GDALGetDriverByName("GTiff");
  if (driver == nullptr) throw Error(ErrorCode::WriteFailed, "GDAL has no GTiff driver", path);
  CPLStringList createOptions;
  createOptions.SetNameValue("BIGTIFF", "IF_SAFER");
  if (options.compress) {
    createOptions.SetNameValue("COMPRESS", "DEFLATE");
    createOptions.SetNameValue("PREDICTOR", gdalType == GDT_Float32 ? "3" : "2");
  }
  if (bands == 3) createOptions.SetNameValue("PHOTOMETRIC", "RGB");

  DatasetPtr dataset(GDALCreate(driver, path.c_str(), pixels.cols, pixels.rows, bands, gdalType,
                                createOptions.List()));
  if (!dataset) throw Error(ErrorCode::WriteFailed, errors.describe("cannot create the GeoTIFF"), path);
  GDALDatasetH ds = dataset.get();

  auto failAndRemove = [&](const std::string& what) {
    const std::string message = errors.describe(what);
    dataset.reset();
    VSIUnlink(path.c_str());
    throw Error(ErrorCode::WriteFailed, message, path);
  };

  if (geo.valid()) {
    double geoTransform[6];
    std::copy(geo.geoTransform.begin(), geo.geoTransform.end(), geoTransform);
    if (GDALSetGeoTransform(ds, geoTransform) != CE_None) failAndRemove("cannot write the geotransform");
    if (!geo.crsWkt.empty() && GDALSetProjection(ds, geo.crsWkt.c_str()) != CE_None) {
      failAndRemove("cannot write the CRS");
    }
  }
  if (options.nodata) {
    for (int b = 1; b <= bands; ++b) {
      if (GDALSetRasterNoDataValue(GDALGetRasterBand(ds, b), *options.nodata) != CE_None) {
        failAndRemove("cannot write the nodata value");
      }
    }
  }
  const auto elementBytes = static_cast<GSpacing>(pixels.elemSize1());
  if (GDALDatasetRasterIOEx(ds, GF_Write, 0, 0, pixels.cols, pixels.rows, pixels.data, pixels.cols,
                            pixels.rows, gdalType, bands, nullptr, elementBytes * bands,
                            static_cast<GSpacing>(pixels.step[0]), elementBytes, nullptr) != CE_None) {
    failAndRemove("cannot write the pixels");
  }
  GDALFlushCache(ds);
  if (errors.failed()) failAndRemove("cannot write the pixels");
  // Closing writes the TIFF directory; GDALClose reports failures only through CPLError.
  dataset.reset();
  if (errors.failed()) {
    const std::string message = errors.describe("cannot finish the GeoTIFF");
    VSIUnlink(path.c_str());
    throw Error(ErrorCode::WriteFailed, message, path);
  }
}

}  // namespace

void writeGeoTiff(const std::string& path, const cv::Mat& image, const GeoReference& geo,
                  const WriteOptions& options) {
  writeAtomically(path, [&](const std::string& file) { writeGeoTiffAt(file, image, geo, options); });
}

void writeFloatGeoTiff(const std::string& path, const cv::Mat& image, const GeoReference& geo) {
  cv::Mat asFloat = image;
  if (!image.empty() && image.depth() != CV_32F) image.convertTo(asFloat, CV_32F);
  WriteOptions options;
  options.nodata = std::numeric_limits<double>::quiet_NaN();
  writeGeoTiff(path, asFloat, geo, options);
}

void requireSameSize(const Raster& a, const Raster& b) {
  if (a.data.size() == b.data.size()) return;
  auto describe = [](const Raster& r) {
    return (r.path.empty() ? std::string("<in memory>") : r.path) + " is " + std::to_string(r.data.cols) + "x" +
           std::to_string(r.data.rows);
  };
  throw Error(ErrorCode::MismatchedInputs, "sizes differ: " + describe(a) + ", " + describe(b), a.path);
}

}  // namespace delineo::io
