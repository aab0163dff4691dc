#include "delineo/segmentation/ground_model.hpp"

#include <algorithm>
#include <cmath>

namespace delineo::segmentation {

double arcStep(double x, double x0, double sigmaBelow, double sigmaAbove) {
  const double t = x - x0;
  const double s = t < 0 ? sigmaBelow : sigmaAbove;
  if (s <= 0) return t < 0 ? -1.0 : (t > 0 ? 1.0 : 0.0);
  const double v = 1.0 - std::exp(-t * t / (2.0 * s * s));
  return t < 0 ? -v : v;
}

double contextualPotential(GroundLabel n, GroundLabel nOther, double delta, double criticalHeight) {
  const double s = 0.5 * criticalHeight;
  const bool above = n == GroundLabel::Above, otherAbove = nOther == GroundLabel::Above;
  if (above && otherAbove) return -1.0;
  if (!above && !otherAbove) return arcStep(std::abs(delta), criticalHeight, s, s);
  if (above) return -arcStep(delta, criticalHeight, s, s);
  return -arcStep(-delta, criticalHeight, s, s);
}

double dataPotential(GroundLabel n, double height, const GroundUnder& ground, double criticalHeight) {
  const double h0 = ground.average + criticalHeight;
  const double h1 = std::min(ground.lowest + criticalHeight, ground.average);
  const double h2 = std::max(ground.highest + criticalHeight, ground.average + 2.0 * criticalHeight);
  const double v = arcStep(height, h0, 0.5 * (h0 - h1), 0.5 * (h2 - h0));
  return n == GroundLabel::Ground ? v : -v;
}

}  // namespace delineo::segmentation
