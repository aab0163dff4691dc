#pragma once
// Where F(truth) and F(result) differ, shared by the benchmarks that compare a delineated outline
// with a reference one (bench_delineation --diag, bench_real_outlines --diag).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/delineation/energy.hpp"

namespace delineo::bench {

using delineation::EnergyImages;
using delineation::IntPolygon;

// --diag: where F(truth) and F(result) differ. Each ROI pixel is labelled ground (E), roof (Ω) or
// band (O) under both outlines, with the same rules as referenceEnergy; the pixels whose label
// differs are split by the pair of labels, by their distance to the true outline (< 2, 2-5,
// > 5 px) and by the side of the true outline they lie on (-x, +x, top/bottom), and each group
// reports its share of F(truth) - F(result) and its mean costs.
enum PixelLabel : uchar { kGround = 0, kRoof = 1, kBand = 2 };
inline cv::Mat labelPixels(const EnergyImages& im, const IntPolygon& polygon) {
  const cv::Size size = im.roofCost.size();
  cv::Mat labels = core::rasterize(toPolygon(polygon), size) / 255;  // 1 inside
  for (int y = 0; y < size.height; ++y) {
    uchar* m = labels.ptr<uchar>(y);
    std::vector<std::pair<int, int>> runs;
    for (int x = 0; x < size.width;) {
      if (m[x] != kRoof) { ++x; continue; }
      int e = x;
      while (e < size.width && m[e] == kRoof) ++e;
      runs.emplace_back(x, e);
      x = e;
    }
    auto widthAt = [&](int x) {
      return im.occlusionWidth.empty() ? 0 : std::max(0, im.occlusionWidth.at<int>(y, std::clamp(x, 0, size.width - 1)));
    };
    for (size_t k = 0; k < runs.size(); ++k) {
      if (im.occlusionSide < 0) {
        const int start = runs[k].first, stop = k == 0 ? 0 : runs[k - 1].second;
        for (int x = std::max(start - widthAt(start), stop); x < start; ++x) m[x] = kBand;
      } else {
        const int end = runs[k].second, stop = k + 1 == runs.size() ? size.width : runs[k + 1].first;
        for (int x = end; x < std::min(end + widthAt(end - 1), stop); ++x) m[x] = kBand;
      }
    }
  }
  return labels;
}

struct DiagCell {
  long long n = 0;
  double dF = 0, cr = 0, cg = 0;
  void add(double d, double r, double g) { ++n; dF += d; cr += r; cg += g; }
};
// key: "truthLabel>resultLabel|group"
using DiagTable = std::map<std::string, DiagCell>;

inline const char* labelName(int l) { return l == kRoof ? "roof" : l == kBand ? "band" : "ground"; }

inline void diagnose(const EnergyImages& im, const cv::Mat& excluded, const IntPolygon& truth,
              const IntPolygon& result, DiagTable& table, cv::Mat* picture) {
  const cv::Mat lt = labelPixels(im, truth), lr = labelPixels(im, result);
  const cv::Mat inside = core::rasterize(toPolygon(truth), lt.size());
  // Distance to the true outline and the direction to its nearest pixel on the other side.
  cv::Mat distOut, labOut, distIn, labIn;
  cv::distanceTransform(~inside, distOut, labOut, cv::DIST_L2, 5, cv::DIST_LABEL_PIXEL);  // to nearest inside px
  cv::distanceTransform(inside, distIn, labIn, cv::DIST_L2, 5, cv::DIST_LABEL_PIXEL);     // to nearest outside px
  std::vector<cv::Point> insideAt(lt.total() + 1), outsideAt(lt.total() + 1);
  for (int y = 0; y < lt.rows; ++y) {
    for (int x = 0; x < lt.cols; ++x) {
      if (inside.at<uchar>(y, x)) insideAt[labOut.at<int>(y, x)] = {x, y};
      else outsideAt[labIn.at<int>(y, x)] = {x, y};
    }
  }
  if (picture) {
    *picture = cv::Mat(lt.size(), CV_8UC3, cv::Scalar(0, 0, 0));
    if (!excluded.empty())
      picture->setTo(cv::Scalar(90, 90, 90), excluded);  // grey: kept out of the roof
  }
  if (!excluded.empty()) {
    std::printf(
        "      diag excluded pixels (mask, intermediate heights): %d inside the truth, %d "
        "outside\n",
        cv::countNonZero(excluded & inside), cv::countNonZero(excluded & ~inside));
  }
  const float nmc = im.noMatchCost;
  {
    // How the truth's own labels are matched: mean cost and share above NoMatchCost per label.
    double sum[3] = {0, 0, 0}, above[3] = {0, 0, 0}, count[3] = {0, 0, 0};
    for (int y = 0; y < lt.rows; ++y) {
      for (int x = 0; x < lt.cols; ++x) {
        const int l = lt.at<uchar>(y, x);
        const double c = l == kRoof ? im.roofCost.at<float>(y, x) : im.groundCost.at<float>(y, x);
        sum[l] += c;
        above[l] += c > nmc;
        ++count[l];
      }
    }
    std::printf("      diag NoMatchCost %.3f; truth labels: roof c_roof %.3f (%.0f%% above NMC), ground c_ground "
                "%.3f (%.0f%%), band c_ground %.3f (%.0f%%)\n",
                nmc, sum[kRoof] / std::max(1.0, count[kRoof]), 100 * above[kRoof] / std::max(1.0, count[kRoof]),
                sum[kGround] / std::max(1.0, count[kGround]), 100 * above[kGround] / std::max(1.0, count[kGround]),
                sum[kBand] / std::max(1.0, count[kBand]), 100 * above[kBand] / std::max(1.0, count[kBand]));
  }
  for (int y = 0; y < lt.rows; ++y) {
    for (int x = 0; x < lt.cols; ++x) {
      const int a = lt.at<uchar>(y, x), b = lr.at<uchar>(y, x);
      if (a == b) continue;
      const double cr = im.roofCost.at<float>(y, x), cg = im.groundCost.at<float>(y, x);
      auto cost = [&](int l) { return l == kRoof ? cr : l == kBand ? nmc : cg; };
      const double d = cost(a) - cost(b);
      const bool in = inside.at<uchar>(y, x) != 0;
      // Distance in px from the pixel centre to the true outline (approx: transform value - 0.5).
      const float dist = in ? distIn.at<float>(y, x) : distOut.at<float>(y, x);
      const cv::Point other = in ? outsideAt[labIn.at<int>(y, x)] : insideAt[labOut.at<int>(y, x)];
      // Side of the true outline: direction from the inside pixel to the outside one.
      const cv::Point dir = in ? other - cv::Point(x, y) : cv::Point(x, y) - other;
      const char* side = std::abs(dir.x) >= std::abs(dir.y) ? (dir.x < 0 ? "-x" : "+x") : "y";
      const char* ring = dist < 2.5 ? "<2" : dist < 5.5 ? "2-5" : ">5";
      const std::string key = std::string(labelName(a)) + ">" + labelName(b);
      table[key + "|all"].add(d, cr, cg);
      table[key + "|d" + ring].add(d, cr, cg);
      table[key + "|s" + side].add(d, cr, cg);
      table[key + "|" + (in ? "in" : "out") + "|s" + side + "|d" + ring].add(d, cr, cg);
      if (picture) {
        // Colour by class; brightness by how much the truth pays more (red) or less (dim).
        static const std::map<std::string, cv::Vec3b> colours{
            {"roof>ground", {0, 0, 255}},   {"roof>band", {0, 160, 255}}, {"ground>roof", {255, 0, 0}},
            {"ground>band", {255, 0, 255}}, {"band>roof", {0, 255, 0}},   {"band>ground", {0, 255, 255}}};
        cv::Vec3b c = colours.at(key);
        if (d <= 0) c = c * 0.4;
        picture->at<cv::Vec3b>(y, x) = c;
      }
    }
  }
}

inline void printDiag(const DiagTable& t, const char* indent, bool detailed) {
  for (const auto& [key, c] : t) {
    const size_t bar = key.find('|');
    const std::string group = key.substr(bar + 1);
    if (!detailed && group.rfind("in|", 0) == 0) continue;
    if (!detailed && group.rfind("out|", 0) == 0) continue;
    std::printf("%s%-12s %-14s n %6lld  dF %+9.1f  mean dF %+.3f  c_roof %.3f c_ground %.3f\n", indent,
                key.substr(0, bar).c_str(), group.c_str(), c.n, c.dF, c.n ? c.dF / c.n : 0.0, c.n ? c.cr / c.n : 0.0,
                c.n ? c.cg / c.n : 0.0);
  }
}

}  // namespace delineo::bench
