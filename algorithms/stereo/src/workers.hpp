#pragma once
// The stereo code's worker model (internal to delineo_stereo): work is split into independent
// tasks or bands of rows, handed out from an atomic counter to `threads` workers, the calling
// thread one of them (threads == 1 runs everything inline, no pool). Each task writes only its
// own outputs, so results never depend on the number of threads.
#include <algorithm>
#include <atomic>
#include <functional>
#include <thread>
#include <vector>

namespace delineo::stereo::detail {

inline void runTasks(const std::vector<std::function<void()>>& tasks, int threads) {
  std::atomic<size_t> next{0};
  auto worker = [&] {
    for (size_t i = next++; i < tasks.size(); i = next++) tasks[i]();
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < std::min<int>(threads, static_cast<int>(tasks.size())); ++t) {
    pool.emplace_back(worker);
  }
  worker();
  for (auto& t : pool) t.join();
}

// band(rowStart, rowEnd) over rows 0..rows−1 in bands of `bandRows`.
template <class BandFn>
void forRowBands(int rows, int threads, const BandFn& band, int bandRows = 16) {
  const int bands = (rows + bandRows - 1) / bandRows;
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int b = next++; b < bands; b = next++) {
      band(b * bandRows, std::min(rows, (b + 1) * bandRows));
    }
  };
  const int workers = std::max(1, std::min(threads, bands));
  std::vector<std::thread> pool;
  for (int t = 1; t < workers; ++t) pool.emplace_back(worker);
  worker();
  for (auto& t : pool) t.join();
}

}  // namespace delineo::stereo::detail
