#pragma once
/// \file basis.h
/// B-spline basis functions on Blender's knots (Cox-de Boor recursion; Piegl & Tiller, The NURBS
/// Book, A2.1-A2.3), evaluated in double. Used by the §3.3 interpolation (collocation matrix)
/// and by surface evaluation.

#include <vector>

namespace plume {

/// The `order` basis functions that can be non-zero at t, and their first derivatives.
/// N_{first + r}(t) = values[r], r = 0 .. order - 1.
struct BasisValues {
  int first = 0;                  ///< index of the first control point they weight
  std::vector<double> values;     ///< N_{first+r}(t)
  std::vector<double> derivatives;  ///< dN_{first+r}/dt (filled only when asked)
};

/// Knot span index s with knots[s] <= t < knots[s+1], restricted to the drawn domain
/// [knots[order-1], knots[pointCount]] (t is clamped into it; t at the end uses the last span,
/// like basisNurb's closed interval).
int findSpan(const std::vector<float>& knots, int pointCount, int order, double t);

/// Basis functions (and, if `withDerivatives`, first derivatives) at t, clamped to the domain.
BasisValues basisFunctions(const std::vector<float>& knots, int pointCount, int order, double t,
                           bool withDerivatives = false);

}  // namespace plume
