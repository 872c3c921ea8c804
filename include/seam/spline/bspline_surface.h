#pragma once
// Tensor-product B-spline and NURBS surfaces of any bi-degree. Control points points(i, j): i along u, j along v,
// stored row i*numV()+j. Rational surfaces are handled in homogeneous coordinates (w P, w).
#include <array>
#include <string>
#include <string_view>
#include <vector>

#include "seam/core/knot_vector.h"
#include "seam/core/result.h"
#include "seam/core/types.h"
#include "seam/spline/bezier.h"
#include "seam/spline/bspline_curve.h"

namespace seam {

/// The four boundary edges of a patch: u = u_min (U0), u = u_max (U1), v = v_min (V0), v = v_max (V1).
enum class Edge { U0, U1, V0, V1 };
inline constexpr std::array<Edge, 4> kAllEdges = {Edge::U0, Edge::U1, Edge::V0, Edge::V1};
/// "u0", "u1", "v0", "v1".
std::string_view edgeName(Edge e);
/// Parses "u0"/"u1"/"v0"/"v1" (case-insensitive).
Result<Edge> parseEdge(std::string_view name);
/// True for U0/U1 (the edge runs along v), false for V0/V1 (runs along u).
inline bool isUEdge(Edge e) { return e == Edge::U0 || e == Edge::U1; }

/// A Bezier patch of a B-spline surface with its parameter box and span indices.
struct BezierPatchPiece {
  BezierPatch patch;
  Interval u;
  Interval v;
  int spanU = 0;  ///< index of the piece along u (0-based)
  int spanV = 0;
};

class BSplineSurface {
 public:
  BSplineSurface() = default;
  /// Validates sizes, finite values, knots and positive weights; the message says what is wrong.
  static Result<BSplineSurface> create(int degreeU, int degreeV, std::vector<double> knotsU,
                                       std::vector<double> knotsV, int numU, int numV, Matrix points,
                                       VecX weights = {});
  /// Unchecked (asserted in debug builds).
  BSplineSurface(int degreeU, int degreeV, KnotVector knotsU, KnotVector knotsV, int numU, int numV,
                 Matrix points, VecX weights = {});
  static BSplineSurface fromHomogeneous(int degreeU, int degreeV, KnotVector knotsU, KnotVector knotsV, int numU,
                                        int numV, const Matrix& homogeneous, bool rational);

  [[nodiscard]] int degreeU() const { return pu_; }
  [[nodiscard]] int degreeV() const { return pv_; }
  [[nodiscard]] const KnotVector& knotsU() const { return ku_; }
  [[nodiscard]] const KnotVector& knotsV() const { return kv_; }
  [[nodiscard]] int numU() const { return nu_; }
  [[nodiscard]] int numV() const { return nv_; }
  [[nodiscard]] int dim() const { return static_cast<int>(points_.cols()); }
  [[nodiscard]] bool isRational() const { return weights_.size() > 0; }
  [[nodiscard]] const Matrix& points() const { return points_; }
  [[nodiscard]] const VecX& weights() const { return weights_; }
  [[nodiscard]] auto point(int i, int j) const { return points_.row(i * nv_ + j); }
  [[nodiscard]] double weight(int i, int j) const { return isRational() ? weights_[i * nv_ + j] : 1.0; }
  [[nodiscard]] Matrix homogeneous() const;
  [[nodiscard]] Interval domainU() const { return ku_.domain(pu_); }
  [[nodiscard]] Interval domainV() const { return kv_.domain(pv_); }

  [[nodiscard]] VecX evaluate(double u, double v) const;
  /// out[k][l] = d^{k+l} S / du^k dv^l for k + l <= order (rational: NURBS Book A4.4).
  [[nodiscard]] std::vector<std::vector<VecX>> derivatives(double u, double v, int order) const;
  /// Point and first partial derivatives without allocation (3-D surfaces; the hot path of dense checks).
  void pointAndFirstDerivatives(double u, double v, Vec3& point, Vec3& du, Vec3& dv) const;
  /// S, S_u, S_v, S_uu, S_uv, S_vv (in that order) without allocation (3-D surfaces).
  void secondOrderDerivatives(double u, double v, std::array<Vec3, 6>& out) const;
  /// Unit normal (S_u x S_v normalised); zero vector where the normal vanishes.
  [[nodiscard]] Vec3 normal(double u, double v) const;

  [[nodiscard]] BSplineSurface withKnotInsertedU(double u, int times = 1) const;
  [[nodiscard]] BSplineSurface withKnotInsertedV(double v, int times = 1) const;
  [[nodiscard]] BSplineSurface refinedU(const std::vector<double>& newKnots) const;
  [[nodiscard]] BSplineSurface refinedV(const std::vector<double>& newKnots) const;
  [[nodiscard]] std::vector<BezierPatchPiece> bezierPatches() const;
  /// Bernstein form, span by span, of the homogeneous partial derivative d^{ku+kv} (wP, w) / du^ku dv^kv (per unit
  /// of the surface's own parameters), computed from the differenced control net and only then cut into spans, so
  /// that a short span keeps the derivatives' relative accuracy (differencing a short span's Bezier points loses
  /// it: they agree to many digits). Index spanU * (v spans) + spanV, the spans of bezierPatches(); derivatives
  /// above the degree are zero. A knot of full multiplicity in the derivative (a C^0 knot of S) cuts the net there.
  [[nodiscard]] std::vector<BernsteinPatch> homogeneousDerivativePatches(int ku, int kv) const;
  [[nodiscard]] BSplineSurface degreeElevated(int byU, int byV) const;
  [[nodiscard]] BSplineSurface reversedU() const;
  [[nodiscard]] BSplineSurface reversedV() const;
  /// S*(u,v) = S(v,u).
  [[nodiscard]] BSplineSurface swappedUV() const;
  [[nodiscard]] BSplineSurface reparametrized(Interval u, Interval v) const;

  /// The boundary curve of an edge, exactly, parametrised along the edge by the surface's own parameter
  /// (v for U0/U1, u for V0/V1), in increasing parameter order.
  [[nodiscard]] BSplineCurve boundaryCurve(Edge e) const;
  /// The cross-boundary derivative d^k S / dn^k (n = u for U0/U1, v for V0/V1, in the increasing-parameter
  /// sense) along the edge, as an exact B-spline curve, k = 0, 1, 2 (k = 0 is the boundary curve). For rational
  /// surfaces the result is rational (denominator w^{k+1}) with full-multiplicity knots.
  [[nodiscard]] BSplineCurve crossDerivativeCurve(Edge e, int order) const;
  /// Homogeneous cross-boundary derivative d^k (wP, w) / dn^k along the edge (exact polynomial B-spline).
  [[nodiscard]] BSplineCurve homogeneousCrossDerivative(Edge e, int order) const;
  /// Control rows of the homogeneous cross-boundary derivatives of orders 0..maxOrder along edge e, as seen by
  /// orientedFrom(e) (derivative into the surface, edge parameter running as the original one), in one pass without
  /// copying the surface: an n x ((maxOrder + 1) h) matrix, h = dim() + (isRational() ? 1 : 0), whose column block k
  /// holds the B-spline control rows (w P, w) of order k over the along-edge knots (knotsV() for U edges, knotsU()
  /// for V edges). Orders above the cross degree are zero.
  [[nodiscard]] Matrix crossDerivativeRows(Edge e, int maxOrder) const;
  /// The surface seen from edge e: reoriented (swap/reverse) so that e becomes U0 and parameters increase
  /// along the same direction as the original edge parameter.
  [[nodiscard]] BSplineSurface orientedFrom(Edge e) const;

 private:
  int pu_ = 0, pv_ = 0;
  KnotVector ku_, kv_;
  int nu_ = 0, nv_ = 0;
  Matrix points_;
  VecX weights_;
};

/// Batch evaluation on a tensor grid: basis values are precomputed once per grid line, then every point costs
/// only the (p+1)(q+1) blend. Use for dense checks, reports and tessellation.
class GridEvaluator {
 public:
  GridEvaluator(const BSplineSurface& surface, std::vector<double> us, std::vector<double> vs);
  [[nodiscard]] int numU() const { return static_cast<int>(us_.size()); }
  [[nodiscard]] int numV() const { return static_cast<int>(vs_.size()); }
  /// Points and first partial derivatives at every (us[a], vs[b]); outputs are numU*numV x 3, row a*numV+b.
  /// Any output pointer may be null to skip it.
  void evaluate(Matrix* points, Matrix* du, Matrix* dv) const;

 private:
  const BSplineSurface* s_;
  std::vector<double> us_, vs_;
  std::vector<int> spanU_, spanV_;
  Matrix basisU_, basisV_;  // per grid line: value and first derivative of the p+1 non-zero functions
};

}  // namespace seam
