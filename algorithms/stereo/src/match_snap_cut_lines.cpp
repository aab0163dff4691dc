#include "match_snap_cut_lines.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "workers.hpp"

namespace delineo::stereo::detail {

namespace {
// The row's own best cut (the first of equal ones), among the candidates it may take alone.
int argminCut(const NearSideCut& cut) {
  const auto end = cut.cost.begin() + (cut.ownLast - cut.eFirst + 1);
  return cut.eFirst + static_cast<int>(std::min_element(cut.cost.begin(), end) - cut.cost.begin());
}
}  // namespace

void chooseCuts(std::vector<std::vector<NearSideCut>>& rows, const StepSnapSettings& settings) {
  const int h = static_cast<int>(rows.size());
  forRowBands(h, settings.threads, [&](int rowStart, int rowEnd) {
    for (int y = rowStart; y < rowEnd; ++y) {
      for (NearSideCut& cut : rows[static_cast<size_t>(y)]) {
        cut.chosen = cut.rowBest = argminCut(cut);
      }
    }
  });
  if (settings.lineRows <= 0) return;
  const auto overlaps = [](const NearSideCut& p, const NearSideCut& c) {
    const int pLast = p.eFirst + static_cast<int>(p.cost.size()) - 1;
    const int cLast = c.eFirst + static_cast<int>(c.cost.size()) - 1;
    return std::min(pLast, cLast) + 2 >= std::max(p.eFirst, c.eFirst);
  };
  const float link = static_cast<float>(settings.linkDisparity);
  const float cap = static_cast<float>(settings.lineCap);
  forRowBands(h, settings.threads, [&](int rowStart, int rowEnd) {
    for (int y = std::max(1, rowStart); y < rowEnd; ++y) {
      std::vector<NearSideCut>& row = rows[static_cast<size_t>(y)];
      std::vector<NearSideCut>& above = rows[static_cast<size_t>(y - 1)];
      for (size_t i = 0; i < row.size(); ++i) {
        NearSideCut& c = row[i];
        int bestJ = -1, bestDistance = std::numeric_limits<int>::max();
        for (size_t j = 0; j < above.size(); ++j) {
          const NearSideCut& p = above[j];
          if (p.next >= 0 || std::abs(p.dNear - c.dNear) > link ||
              std::abs(p.dFar - c.dFar) > link || !overlaps(p, c)) {
            continue;
          }
          const int distance = std::abs(p.rowBest - c.rowBest);
          if (distance < bestDistance) {
            bestDistance = distance;
            bestJ = static_cast<int>(j);
          }
        }
        if (bestJ >= 0) {
          c.prev = bestJ;
          above[static_cast<size_t>(bestJ)].next = static_cast<int>(i);
        }
      }
    }
    // Each row's costs relative to its own best, capped: a row far off the line costs at most
    // lineCap, whatever its error. Candidates past the row's own range (over far pixels) cost
    // at least as much as its own best: a line takes them only where the neighbouring rows put
    // it. (The links above read only the costs' count.)
    for (int y = rowStart; y < rowEnd; ++y) {
      for (NearSideCut& cut : rows[static_cast<size_t>(y)]) {
        const float best = cut.cost[static_cast<size_t>(cut.rowBest - cut.eFirst)];
        for (float& c : cut.cost) c = std::min(cap, std::max(0.0F, c - best));
      }
    }
  });
  const int slopes = 2 * settings.slopeSteps + 1;
  const int span = 2 * settings.lineRows + 1;
  // The line's offset from e0 in row y + k, round(slope · k), for each slope tried: computed
  // once here, not in the innermost loop (lround was a tenth of the snapping's instructions).
  std::vector<int> lineOffset(static_cast<size_t>(slopes) * static_cast<size_t>(span));
  for (int si = 0; si < slopes; ++si) {
    const double slope =
        settings.maxSlope * static_cast<double>(si - settings.slopeSteps) / settings.slopeSteps;
    for (int k = -settings.lineRows; k <= settings.lineRows; ++k) {
      lineOffset[static_cast<size_t>(si * span + k + settings.lineRows)] =
          static_cast<int>(std::lround(slope * k));
    }
  }
  forRowBands(h, settings.threads, [&](int rowStart, int rowEnd) {
    std::vector<const NearSideCut*> chain;
    for (int y = rowStart; y < rowEnd; ++y) {
      for (NearSideCut& c : rows[static_cast<size_t>(y)]) {
        // The chain's cuts in rows y - lineRows .. y + lineRows (nullptr: no cut of this step).
        chain.assign(static_cast<size_t>(2 * settings.lineRows + 1), nullptr);
        chain[static_cast<size_t>(settings.lineRows)] = &c;
        int linked = 0;
        const NearSideCut* p = &c;
        for (int k = 1; k <= settings.lineRows && p->prev >= 0; ++k, ++linked) {
          p = &rows[static_cast<size_t>(p->y - 1)][static_cast<size_t>(p->prev)];
          chain[static_cast<size_t>(settings.lineRows - k)] = p;
        }
        p = &c;
        for (int k = 1; k <= settings.lineRows && p->next >= 0; ++k, ++linked) {
          p = &rows[static_cast<size_t>(p->y + 1)][static_cast<size_t>(p->next)];
          chain[static_cast<size_t>(settings.lineRows + k)] = p;
        }
        // Fewer than lineRows linked rows above and below together: too short to be a line,
        // the row decides.
        if (linked < settings.lineRows) continue;
        // The line e(k) = e0 + slope * k through the row's candidate e0 of least summed cost:
        // the first in the order (e0, then slope) of the lines of least sum. Its rows' costs
        // summed in row order, given up once the sum passes `bound` (the costs are ≥ 0: a sum
        // never falls below a partial sum, nor below the row's own cost at e0).
        const auto lineSum = [&](int e0, int si, double bound, bool orEqual) {
          const int* offsets = &lineOffset[static_cast<size_t>(si * span)];
          double sum = 0;
          for (int k = -settings.lineRows;
               k <= settings.lineRows && (sum < bound || (orEqual && sum == bound)); ++k) {
            const NearSideCut* q = chain[static_cast<size_t>(k + settings.lineRows)];
            if (q == nullptr) continue;
            const int e = e0 + offsets[k + settings.lineRows];
            const int j = e - q->eFirst;
            sum += j >= 0 && j < static_cast<int>(q->cost.size()) ? q->cost[static_cast<size_t>(j)]
                                                                  : cap;
          }
          return sum;
        };
        // The least sum first, from the row's own best outwards (a tight bound early prunes
        // most lines); then the first line in order that reaches it exactly (the same sums,
        // summed the same way).
        const int count = static_cast<int>(c.cost.size());
        const int own = c.rowBest - c.eFirst;
        double least = std::numeric_limits<double>::infinity();
        for (int step = 0; step < 2 * count; ++step) {
          const int i = own + (step % 2 == 0 ? step / 2 : -(step + 1) / 2);
          if (i < 0 || i >= count || static_cast<double>(c.cost[static_cast<size_t>(i)]) >= least) {
            continue;
          }
          for (int si = 0; si < slopes; ++si) {
            least = std::min(least, lineSum(c.eFirst + i, si, least, false));
          }
        }
        int bestE = c.chosen, bestSlope = 0;
        bool found = false;
        for (int i = 0; i < count && !found; ++i) {
          if (static_cast<double>(c.cost[static_cast<size_t>(i)]) > least) continue;
          for (int si = 0; si < slopes; ++si) {
            if (lineSum(c.eFirst + i, si, least, true) == least) {
              bestE = c.eFirst + i;
              bestSlope = si - settings.slopeSteps;
              found = true;
              break;
            }
          }
        }
        // A line at the steepest slope tried is likely steeper still (a near-horizontal edge,
        // whose rows the chain links loosely): the row alone decides there.
        if (std::abs(bestSlope) < settings.slopeSteps) c.chosen = bestE;
      }
    }
  });
}

}  // namespace delineo::stereo::detail
