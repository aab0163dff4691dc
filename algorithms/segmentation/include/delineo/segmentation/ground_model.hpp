#pragma once
// The potentials of the ground/above-ground labelling (Baillard and Maître, section 3.2), built
// from arcs of Gaussians. The paper shows their shape and the properties they keep; the exact
// curves are not printed, so these are ours:
//
//   arcStep(x; x0, s-, s+) = -(1 - exp(-(x-x0)²/2s-²)) below x0, +(1 - exp(-(x-x0)²/2s+²)) above:
//   0 at x0 with a zero slope there, tending to -1 below and +1 above.
//
// Contextual potential V_c(n, n'; δ), δ = h(s) - h(s') (m), critical height δ0:
//   V(ground, ground) = arcStep(|δ|; δ0, δ0/2, δ0/2)     low for close heights, high for a step
//   V(above, ground)  = -arcStep(δ; δ0, δ0/2, δ0/2)      low when s stands δ0 or more above s'
//   V(ground, above)  = V(above, ground) at -δ             (symmetry: V(n,n';δ) = V(n',n;-δ))
//   V(above, above)   = -1                                  adjacent objects of any heights
// so that V(ground, ground) <= V(above, ground) exactly when δ <= δ0 (the paper's eq. 3).
//
// Data potential V_d(n; h) with the ground's average, lowest and highest height under the site:
//   h0 = avg + δ0, h1 = min(min + δ0, avg), h2 = max(max + δ0, avg + 2 δ0)
//   V_d(ground; h) = arcStep(h; h0, (h0-h1)/2, (h2-h0)/2),  V_d(above; h) = -V_d(ground; h)
// increasing with h for ground, decreasing for above, crossing at h0; h1 and h2 set the widths
// of the two arcs (a region over varied ground gets a softer data term).
namespace delineo::segmentation {

enum class GroundLabel : unsigned char { Ground = 0, Above = 1 };

double arcStep(double x, double x0, double sigmaBelow, double sigmaAbove);

// V_c(n, n'; δ) with the critical height `criticalHeight` (δ0, m).
double contextualPotential(GroundLabel n, GroundLabel nOther, double delta, double criticalHeight);

// The ground under a site: average, lowest and highest DTM height over its pixels (m).
struct GroundUnder {
  double average = 0.0, lowest = 0.0, highest = 0.0;
};

// V_d(n; h) of a site of height `height` (m) over `ground`.
double dataPotential(GroundLabel n, double height, const GroundUnder& ground, double criticalHeight);

}  // namespace delineo::segmentation
