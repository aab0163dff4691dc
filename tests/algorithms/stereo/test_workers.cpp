// The worker model (workers.hpp): tasks run in an order fixed by the rows they touch; a cancel
// stops a step's workers and ends it with Canceled.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <thread>
#include <utility>
#include <vector>

#include "workers.hpp"

namespace {

namespace detail = delineo::stereo::detail;

// Tasks over the rows of a 100-row map: each appends its index to the log of every row it
// touches. Whatever the threads do, a row's log must list its tasks in increasing order, each
// task once.
struct RowLogs {
  std::vector<std::pair<int, int>> rows;
  std::vector<std::vector<size_t>> logs = std::vector<std::vector<size_t>>(100);
  std::vector<std::atomic<int>> runs;
  std::vector<std::atomic<bool>> finished;
  std::atomic<int> startedTooEarly{0};
  std::mutex logsMutex;  // so that a broken scheduler shows as a failure, not as a data race
  explicit RowLogs(std::vector<std::pair<int, int>> r)
      : rows(std::move(r)), runs(rows.size()), finished(rows.size()) {}
  bool overlap(size_t j, size_t k) const {
    return rows[j].first < rows[k].second && rows[k].first < rows[j].second;
  }
  void task(size_t k) {
    ++runs[k];
    for (size_t j = 0; j < k; ++j) {
      if (overlap(j, k) && !finished[j]) ++startedTooEarly;
    }
    // Long enough for the other thread to start a task meanwhile.
    std::this_thread::sleep_for(std::chrono::microseconds(200));
    {
      std::lock_guard<std::mutex> lock(logsMutex);
      for (int y = rows[k].first; y < rows[k].second; ++y) logs[static_cast<size_t>(y)].push_back(k);
    }
    finished[k] = true;
  }
  void expectSerialOrderPerRow() const {
    EXPECT_EQ(startedTooEarly.load(), 0) << "tasks started before an earlier overlapping one ended";
    for (size_t k = 0; k < rows.size(); ++k) EXPECT_EQ(runs[k].load(), 1) << "task " << k;
    for (int y = 0; y < 100; ++y) {
      std::vector<size_t> expected;
      for (size_t k = 0; k < rows.size(); ++k) {
        if (rows[k].first <= y && y < rows[k].second) expected.push_back(k);
      }
      EXPECT_EQ(logs[static_cast<size_t>(y)], expected) << "row " << y;
    }
  }
};

std::vector<std::pair<int, int>> someRows() {
  // Overlapping chains and disjoint bands, in no particular row order.
  return {{0, 10}, {50, 60}, {5, 15}, {55, 70}, {90, 100}, {12, 30}, {80, 85}, {0, 100},
          {20, 25}, {60, 95}, {30, 31}, {1, 2}, {40, 45}, {44, 50}, {99, 100}, {10, 90}};
}

TEST(RowOrderedTasks, OverlappingTasksRunInOrderOnOneThread) {
  RowLogs logs(someRows());
  detail::RowOrderedTasks tasks(logs.rows, [&](size_t k) { logs.task(k); }, 0);
  tasks.run();
  logs.expectSerialOrderPerRow();
}

TEST(RowOrderedTasks, AHelperRunsDisjointTasksAlongsideAndOverlappingOnesInOrder) {
  // The helper arrives before, at about the same time as, and after the owner starts.
  for (const int helperDelayMs : {0, 1, 50}) {
    SCOPED_TRACE(helperDelayMs);
    RowLogs logs(someRows());
    std::atomic<int> concurrent{0}, mostConcurrent{0};
    std::atomic<bool> firstTaskSeen{false};
    detail::RowOrderedTasks tasks(
        logs.rows,
        [&](size_t k) {
          const int now = ++concurrent;
          int seen = mostConcurrent.load();
          while (now > seen && !mostConcurrent.compare_exchange_weak(seen, now)) {
          }
          // The first task holds its thread until the other one runs a task beside it (or 2 s
          // pass): on a loaded machine the helper may otherwise be scheduled only once the
          // owner is done, which says nothing about the scheduler.
          if (helperDelayMs == 0 && !firstTaskSeen.exchange(true)) {
            const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
            while (mostConcurrent.load() < 2 && std::chrono::steady_clock::now() < deadline) {
              std::this_thread::sleep_for(std::chrono::microseconds(100));
            }
          }
          logs.task(k);
          --concurrent;
        },
        1);
    std::thread helper([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(helperDelayMs));
      tasks.help();
    });
    tasks.run();
    helper.join();
    logs.expectSerialOrderPerRow();
    if (helperDelayMs == 0) {
      EXPECT_EQ(mostConcurrent.load(), 2);  // the disjoint bands
    }
  }
}

TEST(RowOrderedTasks, RunWithHelpersStartsTheHelpersItself) {
  RowLogs logs(someRows());
  std::atomic<int> concurrent{0}, mostConcurrent{0};
  detail::RowOrderedTasks tasks(
      logs.rows,
      [&](size_t k) {
        const int now = ++concurrent;
        int seen = mostConcurrent.load();
        while (now > seen && !mostConcurrent.compare_exchange_weak(seen, now)) {
        }
        logs.task(k);
        --concurrent;
      },
      2);
  tasks.runWithHelpers();
  logs.expectSerialOrderPerRow();
  EXPECT_GE(mostConcurrent.load(), 2);
}

// Tasks over the 10 x 10 tiles of an image, each on a rectangle of tiles (given as its tile ids):
// a tile's log must list its tasks in increasing order, each task once, and tasks on disjoint
// rectangles that share rows run side by side.
TEST(RowOrderedTasks, TasksOnTilesRunInOrderWhereTheyShareOne) {
  struct Box {
    int x0, y0, x1, y1;  // tiles [x0, x1) x [y0, y1)
  };
  // Left and right halves of the same rows (disjoint), overlapping chains, one over everything.
  const std::vector<Box> boxes{{0, 0, 4, 5},   {6, 0, 10, 5},  {3, 2, 7, 4}, {0, 5, 5, 10},
                               {5, 5, 10, 10}, {0, 0, 10, 10}, {1, 1, 2, 2}, {8, 8, 10, 10},
                               {4, 0, 6, 10},  {0, 9, 10, 10}};
  std::vector<std::vector<int>> cells;
  for (const Box& b : boxes) {
    auto& c = cells.emplace_back();
    for (int y = b.y0; y < b.y1; ++y) {
      for (int x = b.x0; x < b.x1; ++x) c.push_back(10 * y + x);
    }
  }
  for (const int helpers : {0, 1}) {
    SCOPED_TRACE(helpers);
    std::vector<std::vector<size_t>> logs(100);
    std::vector<std::atomic<int>> runs(boxes.size());
    std::vector<std::atomic<bool>> finished(boxes.size());
    std::atomic<int> startedTooEarly{0}, concurrent{0}, mostConcurrent{0};
    std::mutex logsMutex;
    const auto shares = [&](size_t j, size_t k) {
      for (const int a : cells[j]) {
        for (const int b : cells[k]) {
          if (a == b) return true;
        }
      }
      return false;
    };
    detail::RowOrderedTasks tasks(
        cells, 100,
        [&](size_t k) {
          ++runs[k];
          const int now = ++concurrent;
          int seen = mostConcurrent.load();
          while (now > seen && !mostConcurrent.compare_exchange_weak(seen, now)) {
          }
          for (size_t j = 0; j < k; ++j) {
            if (shares(j, k) && !finished[j]) ++startedTooEarly;
          }
          // The first task waits (up to 2 s) for the second, which shares no tile with it, to
          // start on the other thread: a loaded machine may start the helper late.
          const auto start = std::chrono::steady_clock::now();
          while (k == 0 && helpers > 0 && concurrent.load() < 2 &&
                 std::chrono::steady_clock::now() - start < std::chrono::seconds(2)) {
            std::this_thread::yield();
          }
          std::this_thread::sleep_for(std::chrono::microseconds(500));
          {
            std::lock_guard<std::mutex> lock(logsMutex);
            for (const int c : cells[k]) logs[static_cast<size_t>(c)].push_back(k);
          }
          finished[k] = true;
          --concurrent;
        },
        helpers);
    std::thread helper([&] {
      if (helpers > 0) tasks.help();
    });
    tasks.run();
    helper.join();
    EXPECT_EQ(startedTooEarly.load(), 0);
    for (size_t k = 0; k < boxes.size(); ++k) EXPECT_EQ(runs[k].load(), 1) << "task " << k;
    for (int c = 0; c < 100; ++c) {
      std::vector<size_t> expected;
      for (size_t k = 0; k < boxes.size(); ++k) {
        for (const int own : cells[k]) {
          if (own == c) expected.push_back(k);
        }
      }
      EXPECT_EQ(logs[static_cast<size_t>(c)], expected) << "tile " << c;
    }
    // The first two share rows but no tile.
    EXPECT_EQ(mostConcurrent.load(), helpers + 1);
  }
}

}  // namespace

namespace {

// The ids of the threads that ran a parallel step's workers.
struct ThreadsSeen {
  std::mutex mutex;
  std::vector<std::thread::id> ids;
  void add() {
    std::lock_guard<std::mutex> lock(mutex);
    ids.push_back(std::this_thread::get_id());
  }
};

}  // namespace

TEST(WorkerPool, LendsItsHelpersToTheStepsOnItsScopesThread) {
  detail::WorkerPool pool(2);
  const detail::WorkerPool::Scope scope(pool);
  ASSERT_EQ(detail::WorkerPool::current(), &pool);
  // Many short steps in a row, as in a match: every task runs once, on the caller or the pool's
  // two helpers (no thread is started per step).
  const std::vector<std::thread::id> poolIds = pool.helperIds();
  const std::set<std::thread::id> allowed(poolIds.begin(), poolIds.end());
  std::set<std::thread::id> helpers;
  for (int step = 0; step < 200; ++step) {
    std::vector<std::atomic<int>> runs(6);
    ThreadsSeen seen;
    std::vector<std::function<void()>> tasks;
    for (size_t k = 0; k < runs.size(); ++k) {
      tasks.emplace_back([&, k] {
        ++runs[k];
        seen.add();
        std::this_thread::sleep_for(std::chrono::microseconds(50));
      });
    }
    detail::runTasks(tasks, 3);
    for (const auto& r : runs) ASSERT_EQ(r.load(), 1);
    for (const auto& id : seen.ids) {
      if (id != std::this_thread::get_id()) helpers.insert(id);
    }
  }
  EXPECT_GE(helpers.size(), 1U);
  for (const auto& id : helpers) EXPECT_EQ(allowed.count(id), 1U);
}

TEST(WorkerPool, StepsNestedInALentStepStartThreadsAndFinish) {
  detail::WorkerPool pool(1);
  const detail::WorkerPool::Scope scope(pool);
  // Two tasks that wait for each other (as the fill's two workers do) while each runs a parallel
  // step of its own: the outer step has the pool's helper, the inner ones must start threads
  // (the helper is lent; on the helper no pool is current) rather than wait for it.
  std::atomic<int> arrived{0};
  std::atomic<int> innerRuns{0};
  const auto task = [&] {
    ++arrived;
    while (arrived.load() < 2) std::this_thread::yield();
    detail::forRowBands(64, 2, [&](int, int) { ++innerRuns; });
  };
  detail::runTasks({task, task}, 2);
  EXPECT_EQ(arrived.load(), 2);
  EXPECT_EQ(innerRuns.load(), 2 * 4);  // 64 rows in bands of 16, twice
}

TEST(WorkerPool, ScopeRestoresThePreviousPoolAndOtherThreadsSeeNone) {
  EXPECT_EQ(detail::WorkerPool::current(), nullptr);
  detail::WorkerPool outer(1), inner(1);
  {
    const detail::WorkerPool::Scope a(outer);
    {
      const detail::WorkerPool::Scope b(inner);
      EXPECT_EQ(detail::WorkerPool::current(), &inner);
      detail::WorkerPool* elsewhere = &inner;
      std::thread([&] { elsewhere = detail::WorkerPool::current(); }).join();
      EXPECT_EQ(elsewhere, nullptr);
    }
    EXPECT_EQ(detail::WorkerPool::current(), &outer);
  }
  EXPECT_EQ(detail::WorkerPool::current(), nullptr);
}

TEST(WorkerPool, OrderedTasksGiveTheSameLogsWithThePoolsHelpers) {
  detail::WorkerPool pool(2);
  const detail::WorkerPool::Scope scope(pool);
  for (int round = 0; round < 20; ++round) {
    RowLogs logs(someRows());
    detail::RowOrderedTasks tasks(
        logs.rows, [&](size_t k) { logs.task(k); }, 2);
    tasks.runWithHelpers();
    logs.expectSerialOrderPerRow();
  }
}

// Cancellation (workers.hpp): under a CancelScope a step stops taking work once canceled and
// throws Canceled on the calling thread after every worker has returned.
TEST(WorkerCancel, BandsStopOnceCanceledAndTheCallerThrows) {
  detail::WorkerPool pool(1);
  for (const bool withPool : {false, true}) {
    for (const int threads : {1, 2, 3}) {
      std::optional<detail::WorkerPool::Scope> poolScope;
      if (withPool) poolScope.emplace(pool);
      delineo::core::Progress progress;
      const detail::CancelScope scope(&progress);
      std::atomic<int> bands{0};
      // 100 bands; the 5th cancels: each other worker finishes at most the band it is in.
      EXPECT_THROW(detail::forRowBands(1600, threads,
                                       [&](int, int) {
                                         if (++bands == 5) progress.cancel();
                                         std::this_thread::sleep_for(std::chrono::microseconds(200));
                                       }),
                   detail::Canceled);
      EXPECT_LE(bands.load(), 5 + threads - 1) << threads << " threads";
    }
  }
}

TEST(WorkerCancel, WithoutAScopeNothingIsPolled) {
  delineo::core::Progress progress;
  progress.cancel();
  std::atomic<int> bands{0};
  detail::forRowBands(160, 2, [&](int, int) { ++bands; });
  EXPECT_EQ(bands.load(), 10);
  // A scope is this thread's only: another thread's steps do not see it.
  const detail::CancelScope scope(&progress);
  std::thread([&] {
    EXPECT_EQ(detail::CancelScope::current(), nullptr);
    detail::forRowBands(160, 2, [&](int, int) { ++bands; });
  }).join();
  EXPECT_EQ(bands.load(), 20);
}

TEST(WorkerCancel, HelpersPollTheCallersScopeAndTheirExceptionsReachTheCaller) {
  delineo::core::Progress progress;
  const detail::CancelScope scope(&progress);
  std::atomic<int> sawScope{0};
  std::atomic<int> arrived{0};
  // Two tasks on two threads (each waits for the other, so one runs on the helper): the helper
  // sees the caller's scope; its exception is rethrown here once both have returned.
  const auto task = [&] {
    sawScope += detail::CancelScope::current() == &progress ? 1 : 0;
    ++arrived;
    while (arrived.load() < 2) std::this_thread::yield();
  };
  const std::thread::id caller = std::this_thread::get_id();
  const auto failing = [&] {
    task();
    if (std::this_thread::get_id() != caller) throw std::runtime_error("helper failed");
  };
  EXPECT_THROW(detail::runTasks({failing, failing}, 2), std::runtime_error);
  EXPECT_EQ(sawScope.load(), 2);
}

TEST(WorkerCancel, OrderedTasksAreSkippedOnceCanceled) {
  for (const int helpers : {0, 1, 2}) {
    delineo::core::Progress progress;
    const detail::CancelScope scope(&progress);
    const auto rows = someRows();
    std::atomic<int> runs{0};
    detail::RowOrderedTasks tasks(
        rows,
        [&](size_t) {
          if (++runs == 3) progress.cancel();
          std::this_thread::sleep_for(std::chrono::microseconds(200));
        },
        helpers);
    EXPECT_THROW(tasks.runWithHelpers(), detail::Canceled);
    EXPECT_LE(runs.load(), 3 + helpers) << helpers << " helpers";
  }
}

TEST(WorkerCancel, AnOrderedTasksExceptionStopsTheRestAndReachesTheOwner) {
  const auto rows = someRows();
  std::atomic<int> runs{0};
  detail::RowOrderedTasks tasks(
      rows,
      [&](size_t k) {
        ++runs;
        if (k == 0) throw std::runtime_error("task 0 failed");
      },
      1);
  EXPECT_THROW(tasks.runWithHelpers(), std::runtime_error);
  EXPECT_LT(runs.load(), static_cast<int>(rows.size()));
}
