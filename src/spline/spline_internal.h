#pragma once
// Private helpers shared by the spline module's sources.
#include <vector>

#include "seam/core/bernstein.h"
#include "seam/core/result.h"
#include "seam/core/types.h"
#include "seam/spline/bspline_curve.h"

namespace seam {
class BSplineSurface;
}

namespace seam::detail {

/// Largest degree handled by the allocation-free evaluation paths (higher degrees use the general algorithms).
inline constexpr int kMaxFastBasisDegree = 15;

/// Values, first and second derivatives (rows 0, 1, 2) of the p + 1 non-zero basis functions of degree
/// p <= kMaxFastBasisDegree at t in knot span `span` (NURBS Book A2.3, on the stack).
void basisUpTo2(const std::vector<double>& U, int p, int span, double t, double (*ders)[kMaxFastBasisDegree + 1]);

/// The p + 1 non-zero basis functions at t in `span`, p <= kMaxFastBasisDegree (triangular Cox-de Boor scheme, NURBS
/// Book A2.2, on the stack). kP > 0: the degree known at compile time (the same operations, so the same bits).
/// BSplineCurve::point3 / evaluate and detail::OneSpanCurve (src/continuity/one_span_curve.h) evaluate through it.
template <int kP>
inline void basisValuesImpl(const double* U, int p, int span, double t, double* N) {
  if constexpr (kP > 0) p = kP;
  double left[kMaxFastBasisDegree + 1], right[kMaxFastBasisDegree + 1];
  N[0] = 1.0;
  for (int j = 1; j <= p; ++j) {
    left[j] = t - U[span + 1 - j];
    right[j] = U[span + j] - t;
    double saved = 0.0;
    for (int r = 0; r < j; ++r) {
      const double tmp = N[r] / (right[r + 1] + left[j - r]);
      N[r] = saved + right[r + 1] * tmp;
      saved = left[j - r] * tmp;
    }
    N[j] = saved;
  }
}

/// BSplineSurface::pointAndFirstDerivatives of a 3-D surface of degrees <= kMaxFastBasisDegree, on the stack:
/// with `unrolled`, through instances of its loops for the degrees up to 3 known at compile time (what the method
/// uses), else with the degrees as run-time values. The same operations in the same order either way, so the same
/// bits (bspline_surface_test compares the two).
void pointAndFirstDerivativesFast(const BSplineSurface& s, double u, double v, bool unrolled, Vec3& point, Vec3& du,
                                  Vec3& dv);

/// Makes both domain ends of multiplicity degree+1 and drops control rows outside the domain (same curve).
void clampEnds(int degree, std::vector<double>& knots, Matrix& rows);

/// A B-spline (full-multiplicity interior knots) from Bezier pieces of equal degree on consecutive intervals.
/// Pieces hold homogeneous coefficients (last column = weight) when `rational`.
BSplineCurve curveFromBezierPieces(const std::vector<BernsteinPoly>& pieces, const std::vector<Interval>& spans,
                                   bool rational);

/// Transposes the (i, j) layout of surface rows: in (nu*nv) x d with row i*nv+j -> out row j*nu+i.
Matrix transposeGrid(const Matrix& rows, int nu, int nv);

/// Quotient rule for curves: rows of H are A^(k) | w^(k) (k = 0..order); returns rows C^(k) (NURBS Book A4.2).
Matrix curveQuotientRule(const Matrix& H);
/// Quotient rule for surfaces: H[k][l] = (A_{kl}, w_{kl}) for k + l <= order; returns S[k][l] (NURBS Book A4.4).
std::vector<std::vector<VecX>> surfaceQuotientRule(const std::vector<std::vector<VecX>>& H);

/// Clamps the ends and continues the first and last pieces' polynomials to [lo, hi] (a larger domain; an end that
/// is already beyond is left as it is). Exact: every control point is a blossom of a piece (knot_algorithms.cpp).
void extendDomain(int degree, std::vector<double>& knots, Matrix& rows, double lo, double hi);

/// The same surface over the larger domain u x v (each containing the current one): the polynomials of the end
/// pieces (rational surfaces: of the homogeneous net) continued exactly, as OpenCASCADE evaluates a B-spline surface
/// beyond its bounds. Ends come out clamped. An error when the domain does not contain the surface's, or when the
/// continued net would have a weight that is not positive or a coordinate that is not finite. Used where a trimmed
/// face's pcurves run past its surface's bounds (src/occt/brep_model.cpp).
Result<BSplineSurface> extendedSurface(const BSplineSurface& s, Interval u, Interval v);

}  // namespace seam::detail
