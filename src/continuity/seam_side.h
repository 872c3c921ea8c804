#pragma once
// Private (continuity/seam*.cpp): one side of a patch seam seen from its edge, its derivative jets along the edge and
// the pointwise measures of the sampled route. docs/algorithms/seam-measures.md.
#include <Eigen/Dense>
#include <array>
#include <vector>

#include "seam/core/types.h"
#include "seam/model/model.h"
#include "seam/spline/bspline_curve.h"
#include "seam/spline/bspline_surface.h"

namespace seam::detail {

// ------------------------------------------------------------------------------------------------------------
// One side of the seam, seen from its edge as by BSplineSurface::orientedFrom (the edge becomes u = 0, v runs along
// it, u into the surface).
struct Side {
  const Patch* patch = nullptr;
  Edge edge = Edge::U0;
  bool rational = false;
  int degree = 0;                               // degree along the edge
  Interval dom;                                 // parameter domain along the edge
  BSplineCurve curve;                           // Cartesian boundary curve
  std::vector<Interval> spans;                  // Bezier spans along the edge
  // Homogeneous k-th cross derivatives (k = 0, 1, 2), all spans in one matrix (no allocation per span): span i,
  // order k is the block of rows i * degree .. i * degree + degree, columns k * hd .. k * hd + hd - 1.
  Matrix rows;
  int hd = 0;  // homogeneous dimension (3, or 4 when rational)
  [[nodiscard]] Interval domain() const { return dom; }
  /// Coefficient j of span i of the k-th cross derivative: hd values; coefficient j + 1 is rowStride() further.
  [[nodiscard]] const double* coeff(size_t k, size_t i, int j) const {
    return rows.data() + (static_cast<Eigen::Index>(i) * degree + j) * rows.cols() + static_cast<Eigen::Index>(k) * hd;
  }
  [[nodiscard]] Eigen::Index rowStride() const { return rows.cols(); }
  /// The k-th cross derivative on span i as a polynomial (a copy; the general route's products and restrictions).
  [[nodiscard]] BernsteinPoly poly(size_t k, size_t i) const {
    return BernsteinPoly(Matrix(rows.block(static_cast<Eigen::Index>(i) * degree, static_cast<Eigen::Index>(k) * hd,
                                           degree + 1, hd)));
  }
};

/// BSplineSurface::crossDerivativeRows(e, 2) written into `out`, whose storage is reused when its size does not
/// change (the same bits as the surface's function).
void crossDerivativeRowsInto(const BSplineSurface& surf, Edge e, Matrix& out);
/// Makes `s` the side of patch p seen from edge e, reusing the storage of its rows and spans.
void makeSideInto(Side& s, const Patch& p, Edge e);
Side makeSide(const Patch& p, Edge e);
/// The index of the span of s containing t (the last span beyond its end).
int spanIndex(const Side& s, double t);

/// Largest Bezier degree evaluated by edgeJet on the stack (higher degrees use a heap buffer).
constexpr int kJetStackDegree = 15;

/// S, S_u, S_v, S_uu, S_uv, S_vv of the oriented surface at (u = edge, v = t) from the cross-derivative Bezier pieces
/// of the side (homogeneous; the quotient rule for rational sides). `fromRight`: the limit from the right at a
/// breakpoint; `fused` false: always the generic route (the test hook detail::sideJet compares the two).
void edgeJet(const Side& s, double t, std::array<Vec3, 6>& out, bool fromRight = false, bool fused = true);
/// The boundary point of a side at t (row 0 only), with the span chosen as edgeJet chooses it: the same bits as
/// edgeJet's value.
Vec3 edgePoint(const Side& s, double t, bool fromRight);

// ------------------------------------------------------------------------------------------------------------
// Pointwise measures from the surfaces' own derivatives (the sampled route).
struct PointMeasures {
  double g0 = 0.0;        // |a(t) - b(s)|
  double g1 = 0.0;        // radians
  double g2 = 0.0;        // spectral norm of the shape-operator difference
  double curvature = 0.0; // larger curvature of the two sides (spectral norms)
  double lambda = 0.0, kappa = 0.0;
  double residual = 0.0;  // normal component of the Lemma 2 residual
  double c1 = 0.0, c2 = 0.0, c1Scale = 0.0, c2Scale = 0.0;
  Vec3 point = Vec3::Zero();
  bool normalsOk = true;    // the G1 angle was measured (normals or their one-sided limits exist)
  bool curvatureOk = true;  // the chart is well conditioned: curvatures, lambda, kappa were measured
};

/// The pointwise measures at t on A and s on B (sgn = +1 when B's edge parameter s increases with A's t, -1
/// otherwise). Seams that share their control rows take measureSharedAt instead, except for the plots' samples.
/// `g2Only`: only g2 and curvatureOk are measured (the same bits as the full measure; the G2 refinement).
PointMeasures measureAt(const Side& A, double t, const Side& B, double s, double sgn, bool g2Only = false);
/// measureAt on a seam whose rows sharedRowBounds certified (B_0 = A_0, B_1 = lambda A_out, B_2 = lambda^2 A_oo up
/// to rounding): B's derivatives are not evaluated; `sameBoundary` (identicalBoundaryRows): B's boundary point is A's.
PointMeasures measureSharedAt(const Side& A, double t, const Side& B, double s, double sgn, double lambda,
                              bool sameBoundary);
/// True when B's boundary rows are A's, value for value, in the same direction (the sampled gap is exactly 0).
bool identicalBoundaryRows(const Side& A, const Side& B, bool reversed);

/// The diagonal of the control box of a surface: the scale of a seam on it.
double controlDiagonal(const BSplineSurface& s);

}  // namespace seam::detail
