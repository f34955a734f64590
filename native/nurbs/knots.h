#pragma once
/// \file knots.h
/// Blender 3.4's own knot vectors and parameter rules for one NURBS direction
/// ([Smoke Surfaces] §3.3: "each particle in the streaklines serves as a knot" — we interpolate
/// the particles on Blender's knots so that the surface Blender draws is the one we compute).
///
/// Read from blender/source/blender/blenkernel/intern/curve.cc (3.4):
///  - calcknots(): with CU_NURB_ENDPOINT the first `order` knots are 0, then 1, 2, ..., and the
///    last `order` knots are n - order + 1; otherwise (uniform) knot a = a, a = 0 .. n + order - 1.
///  - makeknots() / BKE_nurb_knot_calc_u/v(): n + order knots, only when BKE_nurb_check_valid_u/v
///    holds (n > 1 and order <= n), else no knots and nothing is drawn.
///  - BKE_nurb_makeFaces(): draws u in [knots[order - 1], knots[n]] (non-cyclic) with
///    tot = n * resolution samples, step = (end - start) / (tot - 1) in float, u += step
///    accumulated in float; basisNurb() clamps t to [knots[0], knots[n + order - 1]].

#include <vector>

namespace plume {

/// Orders Blender accepts for a NURBS direction (rna_curve.cc: order_u/order_v in [2, 6]).
constexpr int kMinBlenderOrder = 2;
constexpr int kMaxBlenderOrder = 6;
/// Largest spline resolution Blender's UI offers (resolution_u/v).
constexpr int kMaxBlenderResolution = 1024;

/// Knot vector of calcknots() (curve.cc) for `pointCount` points of order `order`: endpoint
/// (clamped, "endpoint-uniform") or uniform. Size pointCount + order. Throws
/// std::invalid_argument unless 1 <= order <= pointCount and order <= 6.
std::vector<float> blenderKnots(int pointCount, int order, bool endpoint);

/// The parameter interval Blender tessellates (BKE_nurb_makeFaces, non-cyclic):
/// [knots[order - 1], knots[pointCount]]. Endpoint: [0, n - k + 1]; uniform: [k - 1, n].
struct KnotDomain {
  float start = 0.f;
  float end = 0.f;
};
KnotDomain blenderDomain(const std::vector<float>& knots, int pointCount, int order);

/// The `pointCount * resolution` parameters BKE_nurb_makeFaces samples in one direction,
/// reproduced bit for bit: float step (end - start) / (count - 1), accumulated in float.
std::vector<float> blenderSamples(int pointCount, int order, bool endpoint, int resolution);

/// Greville abscissae ḡ_i = (t_{i+1} + ... + t_{i+k-1}) / (k - 1), i = 0 .. n - 1 (de Boor,
/// A Practical Guide to Splines, ch. XIII); order 1: the span midpoints (t_i + t_{i+1}) / 2.
std::vector<double> grevilleAbscissae(const std::vector<float>& knots, int pointCount, int order);

/// Parameters at which the particles are interpolated (§3.3), inside the drawn interval
/// blenderDomain(): the Greville abscissae of Blender's knots. For endpoint knots they already
/// span it (ḡ_0 = 0, ḡ_{n-1} = n - k + 1). For uniform knots the outer ones (ḡ_0 = k/2 < k - 1)
/// lie outside what Blender draws, so those and the first/last inside one are spread evenly
/// between the domain end and the next Greville point; with too few points (n < outside + 3)
/// all are spread evenly over the domain. Both satisfy Schoenberg-Whitney (t_i < τ_i < t_{i+k}),
/// so the collocation system is non-singular, and the first and last particles lie on the
/// surface's edges.
std::vector<double> interpolationParameters(int pointCount, int order, bool endpoint);

}  // namespace plume
