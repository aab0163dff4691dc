#pragma once
// The stereo code's worker model (internal to delineo_stereo): work is split into independent
// tasks or bands of rows, handed out from an atomic counter to `threads` workers, the calling
// thread one of them (threads == 1 runs everything inline, no pool). Each task writes only its
// own outputs, so results never depend on the number of threads.
#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <set>
#include <thread>
#include <utility>
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

// Tasks 0 .. n−1 whose result must be that of running them in this order, where task k reads and
// writes only the rows rows[k] = [first, end) of the outputs they share: task k starts once every
// earlier task whose rows overlap its own has finished; tasks on disjoint rows run side by side
// (they touch disjoint data, so their order does not matter).
// The owner calls run(); up to `helpers` other threads may each call help() once, at any time
// (before, during or after run()). run() returns once every task has finished and every helper
// has called help() and left it: the owner may then destroy this object.
class RowOrderedTasks {
 public:
  RowOrderedTasks(const std::vector<std::pair<int, int>>& rows, std::function<void(size_t)> task,
                  int helpers)
      : RowOrderedTasks(rows.size(), std::move(task), helpers) {
    int end = 0;
    for (const auto& span : rows) end = std::max(end, span.second);
    std::vector<size_t> lastOn(static_cast<size_t>(end), kNone);
    std::vector<int> cells;
    for (size_t k = 0; k < rows.size(); ++k) {
      cells.clear();
      for (int y = std::max(0, rows[k].first); y < rows[k].second; ++y) cells.push_back(y);
      link(k, cells, lastOn);
    }
  }

  // The same order where task k reads and writes only the cells cells[k] (ids 0 .. cellCount − 1,
  // e.g. the tiles of an image a rectangle covers): it waits for every earlier task sharing one.
  RowOrderedTasks(const std::vector<std::vector<int>>& cells, int cellCount,
                  std::function<void(size_t)> task, int helpers)
      : RowOrderedTasks(cells.size(), std::move(task), helpers) {
    std::vector<size_t> lastOn(static_cast<size_t>(cellCount), kNone);
    for (size_t k = 0; k < cells.size(); ++k) link(k, cells[k], lastOn);
  }

  // run() on this thread with the `helpers` given at construction each calling help() from a
  // thread of their own: for an owner that has no workers at hand.
  void runWithHelpers() {
    const int helpers = helpersToCome_;  // (read before any helper runs: they decrement it)
    std::vector<std::thread> pool;
    for (int h = 0; h < helpers; ++h) pool.emplace_back([this] { help(); });
    run();
    for (auto& t : pool) t.join();
  }

  void run() {
    std::unique_lock<std::mutex> lock(mutex_);
    workUntilAllFinished(lock);
    changed_.wait(lock, [&] { return helpersToCome_ == 0; });
  }

  void help() {
    std::unique_lock<std::mutex> lock(mutex_);
    workUntilAllFinished(lock);
    --helpersToCome_;
    changed_.notify_all();  // (under the lock: run() cannot return before it is released)
  }

 private:
  void workUntilAllFinished(std::unique_lock<std::mutex>& lock) {
    while (unfinished_ > 0) {
      if (ready_.empty()) {
        changed_.wait(lock);
        continue;
      }
      const size_t k = *ready_.begin();  // the earliest ready task
      ready_.erase(ready_.begin());
      lock.unlock();
      task_(k);
      lock.lock();
      for (const size_t next : after_[k]) {
        if (--waitingOn_[next] == 0) ready_.insert(next);
      }
      --unfinished_;
      changed_.notify_all();
    }
  }

  RowOrderedTasks(size_t tasks, std::function<void(size_t)> task, int helpers)
      : task_(std::move(task)),
        waitingOn_(tasks, 0),
        after_(tasks),
        unfinished_(tasks),
        helpersToCome_(helpers) {}

  // Task k waits for the last earlier task on each of its cells only: that one waits in turn for
  // the earlier ones there. (Σ of the tasks' cell counts, not n² pairs: a large image has many
  // thousands of regions.)
  void link(size_t k, const std::vector<int>& cells, std::vector<size_t>& lastOn) {
    std::vector<size_t> before;
    for (const int c : cells) {
      size_t& last = lastOn[static_cast<size_t>(c)];
      if (last != kNone && last != k) before.push_back(last);
      last = k;
    }
    std::sort(before.begin(), before.end());
    before.erase(std::unique(before.begin(), before.end()), before.end());
    for (const size_t j : before) after_[j].push_back(k);
    waitingOn_[k] = static_cast<int>(before.size());
    if (before.empty()) ready_.insert(k);
  }

  static constexpr size_t kNone = static_cast<size_t>(-1);
  std::function<void(size_t)> task_;
  std::vector<int> waitingOn_;              // unfinished earlier tasks it waits for
  std::vector<std::vector<size_t>> after_;  // the later tasks waiting for it
  std::set<size_t> ready_;                  // not started, nothing left to wait for
  size_t unfinished_;
  int helpersToCome_;  // helpers that have not left help() yet
  std::mutex mutex_;
  std::condition_variable changed_;
};

}  // namespace delineo::stereo::detail
