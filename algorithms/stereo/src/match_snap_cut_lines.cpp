#include "match_snap_cut_lines.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "workers.hpp"

namespace delineo::stereo::detail {

namespace {
using CutRows = std::vector<std::vector<NearSideCut>>;

// The row's own best cut (the first of equal ones), among the candidates it may take alone.
int argminCut(const NearSideCut& cut) {
  const auto end = cut.cost.begin() + (cut.ownLast - cut.eFirst + 1);
  return cut.eFirst + static_cast<int>(std::min_element(cut.cost.begin(), end) - cut.cost.begin());
}

// Whether the candidate ranges of two cuts overlap (or lie within 2 px of each other).
bool overlaps(const NearSideCut& p, const NearSideCut& c) {
  const int pLast = p.eFirst + static_cast<int>(p.cost.size()) - 1;
  const int cLast = c.eFirst + static_cast<int>(c.cost.size()) - 1;
  return std::min(pLast, cLast) + 2 >= std::max(p.eFirst, c.eFirst);
}

// Links each cut of `row` to the cut of the same step in the row `above` (near and far
// disparities within `link`, candidate ranges overlapping, not linked yet) whose own best is
// nearest its own.
void linkToRowAbove(std::vector<NearSideCut>& row, std::vector<NearSideCut>& above, float link) {
  for (size_t i = 0; i < row.size(); ++i) {
    NearSideCut& c = row[i];
    int bestJ = -1, bestDistance = std::numeric_limits<int>::max();
    for (size_t j = 0; j < above.size(); ++j) {
      const NearSideCut& p = above[j];
      if (p.next >= 0 || std::abs(p.dNear - c.dNear) > link || std::abs(p.dFar - c.dFar) > link ||
          !overlaps(p, c)) {
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

// Each cut's costs relative to its own best, capped: a row far off the line costs at most
// lineCap (`cap`), whatever its error. Candidates past the row's own range (over far pixels) cost
// at least as much as its own best: a line takes them only where the neighbouring rows put it.
// (The links read only the costs' count.)
void capRelativeToBest(std::vector<NearSideCut>& row, float cap) {
  for (NearSideCut& cut : row) {
    const float best = cut.cost[static_cast<size_t>(cut.rowBest - cut.eFirst)];
    for (float& c : cut.cost) c = std::min(cap, std::max(0.0F, c - best));
  }
}

// The line's offset from e0 in row y + k, round(slope · k), for each slope tried (index
// si · (2 lineRows + 1) + k + lineRows): computed once, not in the innermost loop (lround was a
// tenth of the snapping's instructions).
std::vector<int> lineOffsets(const StepSnapSettings& settings) {
  const int slopes = 2 * settings.slopeSteps + 1;
  const int span = 2 * settings.lineRows + 1;
  std::vector<int> lineOffset(static_cast<size_t>(slopes) * static_cast<size_t>(span));
  for (int si = 0; si < slopes; ++si) {
    const double slope =
        settings.maxSlope * static_cast<double>(si - settings.slopeSteps) / settings.slopeSteps;
    for (int k = -settings.lineRows; k <= settings.lineRows; ++k) {
      lineOffset[static_cast<size_t>(si * span + k + settings.lineRows)] =
          static_cast<int>(std::lround(slope * k));
    }
  }
  return lineOffset;
}

// The cuts of one step through rows y ± lineRows (collect) and the lines tried through them
// (lineCut).
class CutChain {
 public:
  CutChain(const CutRows& rows, const StepSnapSettings& settings,
           const std::vector<int>& lineOffset)
      : rows_(rows),
        settings_(settings),
        lineOffset_(lineOffset),
        cap_(static_cast<float>(settings.lineCap)),
        slopes_(2 * settings.slopeSteps + 1),
        span_(2 * settings.lineRows + 1) {}

  // The chain of cut c, following its links up and down; returns the number of rows linked.
  int collect(const NearSideCut& c) {
    chain_.assign(static_cast<size_t>(2 * settings_.lineRows + 1), nullptr);
    chain_[static_cast<size_t>(settings_.lineRows)] = &c;
    int linked = 0;
    const NearSideCut* p = &c;
    for (int k = 1; k <= settings_.lineRows && p->prev >= 0; ++k, ++linked) {
      p = &rows_[static_cast<size_t>(p->y - 1)][static_cast<size_t>(p->prev)];
      chain_[static_cast<size_t>(settings_.lineRows - k)] = p;
    }
    p = &c;
    for (int k = 1; k <= settings_.lineRows && p->next >= 0; ++k, ++linked) {
      p = &rows_[static_cast<size_t>(p->y + 1)][static_cast<size_t>(p->next)];
      chain_[static_cast<size_t>(settings_.lineRows + k)] = p;
    }
    return linked;
  }

  // The cut the collected chain's line puts row c at: the line e(k) = e0 + slope * k through the
  // row's candidate e0 of least summed cost, the first in the order (e0, then slope) of the lines
  // of least sum. The least sum first, from the row's own best outwards (a tight bound early
  // prunes most lines); then the first line in order that reaches it exactly (the same sums,
  // summed the same way).
  int lineCut(const NearSideCut& c) const {
    const int count = static_cast<int>(c.cost.size());
    const int own = c.rowBest - c.eFirst;
    double least = std::numeric_limits<double>::infinity();
    for (int step = 0; step < 2 * count; ++step) {
      const int i = own + (step % 2 == 0 ? step / 2 : -(step + 1) / 2);
      if (i < 0 || i >= count || static_cast<double>(c.cost[static_cast<size_t>(i)]) >= least) {
        continue;
      }
      for (int si = 0; si < slopes_; ++si) {
        least = std::min(least, lineSum(c.eFirst + i, si, least, false));
      }
    }
    int bestE = c.chosen, bestSlope = 0;
    bool found = false;
    for (int i = 0; i < count && !found; ++i) {
      if (static_cast<double>(c.cost[static_cast<size_t>(i)]) > least) continue;
      for (int si = 0; si < slopes_; ++si) {
        if (lineSum(c.eFirst + i, si, least, true) == least) {
          bestE = c.eFirst + i;
          bestSlope = si - settings_.slopeSteps;
          found = true;
          break;
        }
      }
    }
    // A line at the steepest slope tried is likely steeper still (a near-horizontal edge, whose
    // rows the chain links loosely): the row alone decides there.
    return std::abs(bestSlope) < settings_.slopeSteps ? bestE : c.chosen;
  }

 private:
  // The chain's costs along the line through e0 at slope index si, summed in row order (lineCap
  // where the line misses a row's candidates), given up once the sum passes `bound` (the costs
  // are ≥ 0: a sum never falls below a partial sum, nor below the row's own cost at e0).
  double lineSum(int e0, int si, double bound, bool orEqual) const {
    const int* offsets = &lineOffset_[static_cast<size_t>(si * span_)];
    double sum = 0;
    for (int k = -settings_.lineRows;
         k <= settings_.lineRows && (sum < bound || (orEqual && sum == bound)); ++k) {
      const NearSideCut* q = chain_[static_cast<size_t>(k + settings_.lineRows)];
      if (q == nullptr) continue;
      const int e = e0 + offsets[k + settings_.lineRows];
      const int j = e - q->eFirst;
      sum +=
          j >= 0 && j < static_cast<int>(q->cost.size()) ? q->cost[static_cast<size_t>(j)] : cap_;
    }
    return sum;
  }

  const CutRows& rows_;
  const StepSnapSettings& settings_;
  const std::vector<int>& lineOffset_;
  const float cap_;
  const int slopes_, span_;
  // The chain's cuts in rows y − lineRows .. y + lineRows (nullptr: no cut of this step).
  std::vector<const NearSideCut*> chain_;
};
}  // namespace

void chooseCuts(std::vector<std::vector<NearSideCut>>& rows, const StepSnapSettings& settings) {
  const int h = static_cast<int>(rows.size());
  // Each row's own best.
  forRowBands(h, settings.threads, [&](int rowStart, int rowEnd) {
    for (int y = rowStart; y < rowEnd; ++y) {
      for (NearSideCut& cut : rows[static_cast<size_t>(y)]) {
        cut.chosen = cut.rowBest = argminCut(cut);
      }
    }
  });
  if (settings.lineRows <= 0) return;
  // The rows' cuts linked, then their costs made relative to their own best.
  const float link = static_cast<float>(settings.linkDisparity);
  const float cap = static_cast<float>(settings.lineCap);
  forRowBands(h, settings.threads, [&](int rowStart, int rowEnd) {
    for (int y = std::max(1, rowStart); y < rowEnd; ++y) {
      linkToRowAbove(rows[static_cast<size_t>(y)], rows[static_cast<size_t>(y - 1)], link);
    }
    for (int y = rowStart; y < rowEnd; ++y) capRelativeToBest(rows[static_cast<size_t>(y)], cap);
  });
  // Each cut with at least lineRows linked rows above and below together taken on its line; in
  // a shorter chain (too short to be a line) the row decides.
  const std::vector<int> lineOffset = lineOffsets(settings);
  forRowBands(h, settings.threads, [&](int rowStart, int rowEnd) {
    CutChain chain(rows, settings, lineOffset);
    for (int y = rowStart; y < rowEnd; ++y) {
      for (NearSideCut& c : rows[static_cast<size_t>(y)]) {
        if (chain.collect(c) >= settings.lineRows) c.chosen = chain.lineCut(c);
      }
    }
  });
}

}  // namespace delineo::stereo::detail
