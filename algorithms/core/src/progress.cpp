#include "delineo/core/progress.hpp"

#include <algorithm>

namespace delineo::core {

void Progress::report(double fraction) {
  fraction = std::clamp(fraction, 0.0, 1.0);
  double prev = fraction_.load();
  while (fraction > prev && !fraction_.compare_exchange_weak(prev, fraction)) {
  }
  const int n = reports_.fetch_add(1) + 1;
  const int limit = cancelAfter_.load();
  if (limit >= 0 && n >= limit) cancel();
  if (listener_) listener_(fraction_.load(), stage());
}

void Progress::setStage(const std::string& stage) {
  std::lock_guard lock(stageMutex_);
  stage_ = stage;
}

std::string Progress::stage() const {
  std::lock_guard lock(stageMutex_);
  return stage_;
}

Progress::Range::Range(Progress* parent, double begin, double end)
    : parent_(parent), begin_(std::clamp(begin, 0.0, 1.0)), end_(std::clamp(end, begin, 1.0)) {}

void Progress::Range::report(double fraction) {
  Progress::report(fraction);
  if (parent_ != nullptr) parent_->report(begin_ + (end_ - begin_) * std::clamp(fraction, 0.0, 1.0));
}

void Progress::Range::setStage(const std::string& stage) {
  Progress::setStage(stage);
  if (parent_ != nullptr) parent_->setStage(stage);
}

void Progress::Range::cancel() noexcept {
  Progress::cancel();
  if (parent_ != nullptr) parent_->cancel();
}

bool Progress::Range::canceled() const noexcept {
  return Progress::canceled() || (parent_ != nullptr && parent_->canceled());
}

}  // namespace delineo::core
