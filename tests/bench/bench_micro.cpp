// Micro-benchmarks (Google Benchmark) of the inner operations an operator waits on
// interactively: the roof-interval query of the correlation cost service (runs on every drag of
// the interval in the GUI), polygon rasterisation, and the footprint IoU used by every report.
// Run: bench_micro [--benchmark_filter=...]; ctest runs it once with a tiny minimum time.
#include <benchmark/benchmark.h>

#include <memory>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "delineo/core/geometry.hpp"
#include "delineo/eval/polygon_measures.hpp"
#include "delineo/stereo/cost_service.hpp"

namespace {
using namespace delineo;

// A textured pair with a constant shift of 12 px, big enough for a 300x300 ROI.
struct Pair {
  cv::Mat left, right;
};
Pair makePair(int width, int height, int shift) {
  cv::Mat noise(height, width + shift, CV_32F);
  cv::RNG rng(42);
  rng.fill(noise, cv::RNG::UNIFORM, 0.0, 255.0);
  cv::GaussianBlur(noise, noise, cv::Size(0, 0), 1.2);
  Pair p;
  p.left = noise(cv::Rect(0, 0, width, height)).clone();
  p.right = noise(cv::Rect(shift, 0, width, height)).clone();  // x_right = x_left - shift
  return p;
}

void BM_CostServiceCompute(benchmark::State& state) {
  const int range = static_cast<int>(state.range(0));
  const Pair pair = makePair(400, 400, 12);
  for (auto _ : state) {
    auto service = stereo::CorrelationCostService::compute(pair.left, pair.right,
                                                           cv::Rect(50, 50, 300, 300), 0, range - 1);
    benchmark::DoNotOptimize(service.get());
  }
  state.SetLabel("300x300 ROI");
}
BENCHMARK(BM_CostServiceCompute)->Arg(64)->Arg(256)->Unit(benchmark::kMillisecond);

void BM_CostServiceMinCostQuery(benchmark::State& state) {
  const int range = static_cast<int>(state.range(0));
  const Pair pair = makePair(400, 400, 12);
  auto service = stereo::CorrelationCostService::compute(pair.left, pair.right,
                                                         cv::Rect(50, 50, 300, 300), 0, range - 1);
  int a = 3;
  for (auto _ : state) {
    // A different interval each time, as while dragging: no caching can help.
    cv::Mat c = service->minCost(a, a + range / 3);
    benchmark::DoNotOptimize(c.data);
    a = (a + 7) % (range / 2);
  }
  state.SetLabel("300x300 ROI");
}
BENCHMARK(BM_CostServiceMinCostQuery)->Arg(64)->Arg(256)->Unit(benchmark::kMillisecond);

core::Polygon lShape(double s) {
  core::Polygon p;
  p.outer = {{10, 10}, {10 + 20 * s, 10}, {10 + 20 * s, 10 + 8 * s},
             {10 + 8 * s, 10 + 8 * s}, {10 + 8 * s, 10 + 20 * s}, {10, 10 + 20 * s}};
  return p;
}

void BM_Rasterize(benchmark::State& state) {
  const core::Polygon p = lShape(14.0);
  for (auto _ : state) {
    cv::Mat m = core::rasterize(p, cv::Size(300, 300));
    benchmark::DoNotOptimize(m.data);
  }
}
BENCHMARK(BM_Rasterize)->Unit(benchmark::kMicrosecond);

void BM_FootprintIoU(benchmark::State& state) {
  const core::Polygon a = lShape(10.0);
  core::Polygon b = lShape(10.0);
  for (auto& v : b.outer) v += cv::Point2d(1.5, -0.7);
  for (auto _ : state) benchmark::DoNotOptimize(eval::intersectionOverUnion(a, b));
}
BENCHMARK(BM_FootprintIoU)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
