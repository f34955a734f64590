#pragma once
/// \file breakaway.h
/// Flickering and separation as a statistical process ([Structural Flames] §4.3).
///
/// The text: "From its creation a flame develops until it reaches H_i. At that point we
/// periodically test a random number against the probability function D(h) [eq. 3] ... The
/// frequency f is the approximate breakaway rate in Hz ... D(h) = 1 for h > H_max." Read here as:
///  - a flame is *eligible* while its length L (arc length of its spine) exceeds H_i;
///  - breakaways form a Poisson process of rate f on the flame's eligible time: each flame keeps
///    a budget of eligible time drawn from Exp(f); every step it is eligible the step is taken
///    from the budget, and when the budget is spent the flame breaks and a new Exp(f) draw is
///    *added* (the overshoot carries over, so the long-run count is exactly f per eligible second
///    even when 1/f is close to the step);
///  - a flame longer than H_max breaks at once (D = 1), a *forced* breakaway that does not use the
///    budget;
///  - the break point h (arc length from the flame's base) is D's variable: eq. 3 is printed with
///    its exponent's square lost and deviation (H_i − H_p)/2, while the prose gives the normal of
///    mean H_p + (H_i − H_p)/2 and deviation (H_i − H_p)/4; the prose is used, with the square,
///    D(h) = exp(−(h − μ)² / 2σ²) / (σ √2π), and h clamped to [H_p, H_i] (±2σ);
///  - the piece above h separates and lives A·i³ (i uniform in [0, 1]: mean A/4).
/// The measured rate is therefore (statistical breakaways) / (eligible flame-seconds).

#include "core/rng.h"
#include "flames/flame.h"

#include <vector>

namespace plume {

/// Heights of the regions of Figure 2 for one flame (m), the source's height scale applied.
struct FlameHeights {
  double persistent = 0.0;    ///< H_p
  double intermittent = 0.0;  ///< H_i
  double max = 0.0;           ///< H_max
};

/// What the process decided for one flame after a step.
struct BreakawayDecision {
  bool eligible = false;  ///< L > H_i: the step counted as eligible time
  bool split = false;     ///< the flame breaks at `height`
  bool forced = false;    ///< L > H_max (D = 1)
  double height = 0.0;    ///< h, arc length of the break point from the base (m)
};

/// Exp(f) waiting time (s) of the Poisson process; +inf when f = 0.
double drawWaitingTime(double frequency, Rng& rng);

/// h ~ N(H_p + (H_i − H_p)/2, ((H_i − H_p)/4)²) clamped to [H_p, H_i], and kept above 1% of H_i so
/// that the part left attached has a length.
double drawSplitHeight(const FlameHeights& heights, Rng& rng);

/// A·i³, i uniform in [0, 1) (§4.3).
double drawLifespan(double lifespanScale, Rng& rng);

/// One step of the process for a flame of length L (m) over dt (s): updates `budget` (eligible
/// seconds left before the next statistical breakaway) and draws h when the flame breaks.
BreakawayDecision testBreakaway(double length, const FlameHeights& heights, double frequency, double dt,
                                double& budget, Rng& rng);

/// Splits a spine at arc length h (§4.3): `lower` gets `lowerCount` points evenly spaced over
/// [0, h] (base kept) — an attached flame keeps n — or, for lowerCount <= 0, the number of input
/// points below h plus one (a separated flame is not refilled); `upper` the piece over [h, L]
/// (tip kept) re-sampled to the number of input points above h plus one — "the number of points
/// split off is not increased back to n". Each piece has at least 2 points.
void splitSpine(const std::vector<SpinePoint>& points, double height, int lowerCount,
                std::vector<SpinePoint>& lower, std::vector<SpinePoint>& upper);

}  // namespace plume
