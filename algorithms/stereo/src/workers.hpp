#pragma once
// The stereo code's worker model (internal to delineo_stereo): work is split into independent
// tasks or bands of rows, handed out from an atomic counter to `threads` workers, the calling
// thread one of them (threads == 1 runs everything inline), the others a match's parked helpers
// (WorkerPool) or threads started for the step. Each task writes only its own outputs, so
// results never depend on the number of threads nor on which runs what.
//
// Cancellation: a match makes its progress current on its thread (CancelScope) and its helpers
// see it too. forRowBands polls it before each band, runTasks and RowOrderedTasks before each
// task; once it is canceled they take no more work and, when every worker has returned, throw
// Canceled on the calling thread, which the match catches (status Canceled, no maps): nothing
// made after the cancel is read. Outside a match (no scope) nothing is polled. An exception of a
// helper is rethrown on the calling thread once all workers have returned.
#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <set>
#include <thread>
#include <utility>
#include <vector>

#include "delineo/core/progress.hpp"

namespace delineo::stereo::detail {

// Thrown by a step of a canceled match (see above); never leaves the match.
struct Canceled {};

// The progress whose cancel the steps run on this thread poll while the scope lives.
class CancelScope {
 public:
  explicit CancelScope(const core::Progress* progress) : previous_(current_) {
    current_ = progress;
  }
  ~CancelScope() { current_ = previous_; }
  CancelScope(const CancelScope&) = delete;
  CancelScope& operator=(const CancelScope&) = delete;
  static const core::Progress* current() { return current_; }

 private:
  const core::Progress* previous_;
  static inline thread_local const core::Progress* current_ = nullptr;
};

inline bool cancelRequested() { return core::isCanceled(CancelScope::current()); }
inline void throwIfCanceled() {
  if (cancelRequested()) throw Canceled{};
}

// Helper threads parked between the many short parallel steps of a match (a few hundred a run
// at 1 Mpx), lent to them instead of a thread started and joined for each (~38 us a start and
// join on the development machine). A match makes one for its duration and makes it current on
// its own thread (Scope): the steps called there borrow its helpers when all are idle; anywhere
// else (on the helpers themselves, or while they are lent) threads are started as before. Which
// thread runs a task never changes a result (see above).
class WorkerPool {
 public:
  explicit WorkerPool(int helpers) {
    for (int h = 0; h < helpers; ++h) threads_.emplace_back([this, h] { park(h); });
  }
  ~WorkerPool() {
    post(kStop);
    for (auto& t : threads_) t.join();
  }
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  int helpers() const { return static_cast<int>(threads_.size()); }
  std::vector<std::thread::id> helperIds() const {
    std::vector<std::thread::id> ids;
    for (const auto& t : threads_) ids.push_back(t.get_id());
    return ids;
  }

  // Runs work() once on each of `count` helpers (count ≤ helpers()) when none is lent: returns
  // false, doing nothing, otherwise. Then waitLent() before `work` goes.
  bool lend(const std::function<void()>& work, int count) {
    if (count <= 0 || count > helpers() || lent_.exchange(true)) return false;
    work_ = &work;
    pending_.store(count);
    post(static_cast<uint64_t>(count));
    return true;
  }
  void waitLent() {
    // Briefly spinning first: the helpers mostly finish within microseconds of the caller.
    for (int spin = 0; spin < kSpins && pending_.load() != 0; ++spin) pause();
    for (int left = pending_.load(); left != 0; left = pending_.load()) pending_.wait(left);
    lent_.store(false);
  }

  // The pool current on the constructing thread while the Scope lives (the only state the
  // workers keep outside their calls).
  class Scope {
   public:
    explicit Scope(WorkerPool& pool) : previous_(current_) { current_ = &pool; }
    ~Scope() { current_ = previous_; }
    Scope(const Scope&) = delete;
    Scope& operator=(const Scope&) = delete;

   private:
    WorkerPool* previous_;
  };
  static WorkerPool* current() { return current_; }

 private:
  // The posted word: a sequence number above, the helper count of the post (or kStop) below,
  // read together so that a helper never pairs one post's number with another's count.
  static constexpr uint64_t kCountBits = 16, kCountMask = (uint64_t{1} << kCountBits) - 1;
  static constexpr uint64_t kStop = kCountMask;
  static constexpr int kSpins = 4000;  // ~20-60 us

  void post(uint64_t count) {
    posts_ += uint64_t{1} << kCountBits;
    state_.store(posts_ | count);
    state_.notify_all();
  }
  static void pause() {
#if defined(__x86_64__) || defined(__i386__)
    __builtin_ia32_pause();
#endif
  }
  void park(int index) {
    uint64_t seen = 0;
    for (;;) {
      // Spinning a little before sleeping: the next step mostly follows within microseconds.
      for (int spin = 0; spin < kSpins && state_.load() == seen; ++spin) pause();
      state_.wait(seen);
      seen = state_.load();
      const uint64_t count = seen & kCountMask;
      if (count == kStop) return;
      // A helper counted in a post is waited for before the next post: `work_` is this one's.
      if (static_cast<uint64_t>(index) < count) {
        (*work_)();
        if (pending_.fetch_sub(1) == 1) pending_.notify_one();
      }
    }
  }

  static inline thread_local WorkerPool* current_ = nullptr;
  std::vector<std::thread> threads_;
  std::atomic<uint64_t> state_{0};
  uint64_t posts_ = 0;  // (the posting thread's only)
  std::atomic<int> pending_{0};
  std::atomic<bool> lent_{false};
  const std::function<void()>* work_ = nullptr;
};

// worker() on the calling thread and on `helpers` more: the current pool's when it can lend
// them, threads started for the call otherwise. Returns once every call has returned; then
// rethrows the calling thread's exception, else the first of a helper's.
template <class Worker>
void runOnWorkers(const Worker& worker, int helpers) {
  if (helpers <= 0) {
    worker();
    return;
  }
  const core::Progress* cancelSource = CancelScope::current();
  std::exception_ptr helperError;
  std::mutex errorMutex;
  const std::function<void()> helper = [&] {
    const CancelScope scope(cancelSource);
    try {
      worker();
    } catch (...) {
      const std::lock_guard lock(errorMutex);
      if (!helperError) helperError = std::current_exception();
    }
  };
  WorkerPool* pool = WorkerPool::current();
  if (pool != nullptr && pool->lend(helper, helpers)) {
    try {
      worker();
    } catch (...) {
      pool->waitLent();  // the helpers still read `helper`
      throw;
    }
    pool->waitLent();
  } else {
    std::vector<std::thread> started;
    for (int t = 0; t < helpers; ++t) started.emplace_back(helper);
    try {
      worker();
    } catch (...) {
      for (auto& t : started) t.join();
      throw;
    }
    for (auto& t : started) t.join();
  }
  if (helperError) std::rethrow_exception(helperError);
}

// Whether the tasks of a runTasks() call may wait for one another's results.
enum class TaskDependence { Independent, MayWait };

// Once canceled, no more independent tasks start; tasks that may wait for another all run (each
// polls the cancel within its own steps).
inline void runTasks(const std::vector<std::function<void()>>& tasks, int threads,
                     TaskDependence dependence = TaskDependence::Independent) {
  const bool skipOnCancel = dependence == TaskDependence::Independent;
  std::atomic<size_t> next{0};
  auto worker = [&] {
    for (size_t i = next++; i < tasks.size(); i = next++) {
      if (skipOnCancel && cancelRequested()) return;
      tasks[i]();
    }
  };
  runOnWorkers(worker, std::min<int>(threads, static_cast<int>(tasks.size())) - 1);
  throwIfCanceled();
}

// band(rowStart, rowEnd) over rows 0..rows−1 in bands of `bandRows`.
template <class BandFn>
void forRowBands(int rows, int threads, const BandFn& band, int bandRows = 16) {
  const int bands = (rows + bandRows - 1) / bandRows;
  std::atomic<int> next{0};
  auto worker = [&] {
    for (int b = next++; b < bands && !cancelRequested(); b = next++) {
      band(b * bandRows, std::min(rows, (b + 1) * bandRows));
    }
  };
  runOnWorkers(worker, std::max(1, std::min(threads, bands)) - 1);
  throwIfCanceled();
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
    // The owner's run() and the helpers' help() as one worker, told apart by a counter.
    std::atomic<int> arrived{0};
    runOnWorkers(
        [&] {
          if (arrived++ == 0) {
            run();
          } else {
            help();
          }
        },
        helpers);
  }

  // Rethrows the first exception of a task (a task not run after it or after a cancel counts as
  // finished), then throws Canceled when canceled.
  void run() {
    std::unique_lock<std::mutex> lock(mutex_);
    workUntilAllFinished(lock);
    changed_.wait(lock, [&] { return helpersToCome_ == 0; });
    if (error_) std::rethrow_exception(error_);
    lock.unlock();
    throwIfCanceled();
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
      const bool skip = error_ != nullptr;
      lock.unlock();
      if (!skip && !cancelRequested()) {
        try {
          task_(k);
        } catch (...) {
          lock.lock();
          if (!error_) error_ = std::current_exception();
          lock.unlock();
        }
      }
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
  std::exception_ptr error_;  // the first task's exception
  std::mutex mutex_;
  std::condition_variable changed_;
};

}  // namespace delineo::stereo::detail
