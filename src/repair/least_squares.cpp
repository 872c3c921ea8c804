// The general least-squares join (see join_internal.h and docs/algorithms/lai-lian-cassidy.md).
#include <fmt/format.h>

#include <Eigen/QR>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <Eigen/SparseQR>
#include <Eigen/OrderingMethods>
#include <algorithm>
#include <cmath>
#include <array>
#include <limits>
#include <map>
#include <optional>

#include "repair/frame_internal.h"
#include "repair/join_internal.h"
#include "seam/core/tolerances.h"

namespace seam::detail {

int SeamTarget::degree() const {
  int d = 0;
  for (const TargetPiece& p : pieces) d = std::max(d, p.point.degree());
  return d;
}
int SeamTarget::degreeCross1() const {
  int d = -1;
  for (const TargetPiece& p : pieces)
    if (!p.cross1.empty()) d = std::max(d, p.cross1.degree());
  return d;
}
int SeamTarget::degreeCross2() const {
  int d = -1;
  for (const TargetPiece& p : pieces)
    if (!p.cross2.empty()) d = std::max(d, p.cross2.degree());
  return d;
}

BernsteinPoly reducedToEffectiveDegree(const BernsteinPoly& p) {
  if (p.empty()) return p;
  BernsteinPoly cur = p;
  const double scale = std::max(p.maxAbsCoeff(), std::numeric_limits<double>::min());
  while (cur.degree() >= 1) {
    const int n = cur.degree();
    const Matrix& c = cur.coeffs();
    // n-th forward difference: the coefficient of t^n is C(n,n) times it; zero iff the degree is below n.
    Eigen::RowVectorXd diff = Eigen::RowVectorXd::Zero(c.cols());
    double mag = 0.0;
    for (int k = 0; k <= n; ++k) {
      const double b = binomial(n, k) * (((n - k) % 2) ? -1.0 : 1.0);
      diff += b * c.row(k);
      mag += std::abs(b);
    }
    if (diff.cwiseAbs().maxCoeff() > kIdentityRelTol * mag * scale) break;
    // c_i = (i/n) r_{i-1} + (1 - i/n) r_i  =>  r_i = (n c_i - i r_{i-1}) / (n - i), from both ends for stability.
    Matrix r(n, c.cols());
    const int half = n / 2;
    r.row(0) = c.row(0);
    for (int i = 1; i < half; ++i) r.row(i) = (n * c.row(i) - i * r.row(i - 1)) / static_cast<double>(n - i);
    r.row(n - 1) = c.row(n);
    for (int i = n - 2; i >= half; --i)  // c_{i+1} = ((i+1)/n) r_i + (1 - (i+1)/n) r_{i+1}
      r.row(i) = (n * c.row(i + 1) - (n - i - 1) * r.row(i + 1)) / static_cast<double>(i + 1);
    cur = BernsteinPoly(std::move(r));
  }
  return cur;
}

namespace {

/// x + Z z for the z that minimises |W (x + Z z - x0)| (W = diag(weight)), the least-norm z where that leaves a
/// choice (zero weights): the weighted closest point to x0 in x + span(Z), for Z an orthonormal nullspace basis.
/// The last step of every route of constrainedLeastSquares(QR); Mat and Vec as in nullspaceLeastSquares.
template <class Mat, class Vec>
Vec closestInNullspace(const Mat& Z, const Vec& x, const Vec& x0, const Vec& weight) {
  const Mat A = weight.asDiagonal() * Z;
  const Vec b = weight.asDiagonal() * (x0 - x);
  Eigen::CompleteOrthogonalDecomposition<Mat> cod(A);
  cod.setThreshold(kIdentityRelTol);
  return x + Z * cod.solve(b);
}

/// Systems up to this many unknowns and equations are solved without heap allocation (constrainedLeastSquaresQR);
/// constrainedLeastSquares takes its sparse route only above this size.
constexpr int kSmallSystem = 48;

/// Smallest estimated ratio of the extreme eigenvalues of C^T C (the squared singular values of C) for which
/// fullColumnRankSolution takes C to have full column rank: 1e-8, a condition number of C of about 1e4, six orders of
/// magnitude inside the rank decision of the dense route (kIdentityRelTol = 1e-10 on the pivots of R, 1e-20 on their
/// squares). Two estimates must both pass: the smallest LDL^T pivot (each pivot lies between the smallest and the
/// largest eigenvalue) and kInverseIterations steps of inverse iteration (which converge to the smallest eigenvalue
/// from above). Below it the dense route decides.
constexpr double kNormalEquationsMinPivotRatio = 1e-8;
constexpr int kInverseIterations = 3;
/// sparseQRSolution keeps its rank decision only where the smallest singular value of R11 (the kept columns) is at
/// least this fraction of the largest column norm: two orders of magnitude inside the dense route's rank threshold
/// (kIdentityRelTol = 1e-10), so that no direction the dense route would drop is kept. Below it the dense route
/// decides. Measured on the 29 rank-deficient systems of the strict heal of sunglasses_lens.igs (2026-12-02): in
/// the columns' own order the smallest is 8.4e-7 (inverse iteration within 1 % of the SVD after 3 steps); COLAMD's
/// order had kept directions of 7.5e-17 on 4 of them (solutions amplified by 1e16) and 6.8e-9 on another.
constexpr double kSparseQRMinSigmaRel = 1e-8;
/// The sparse routes are taken when at most one entry in kSparseRouteDensity of C is non-zero.
constexpr Eigen::Index kSparseRouteDensity = 8;

/// Whether the smallest eigenvalue of a symmetric positive definite matrix A of order n stays above `floor` through
/// kInverseIterations steps of inverse iteration (`solveA(v)` = A^-1 v): for a unit v, 1 / |A^-1 v| bounds the
/// smallest eigenvalue from above and converges to it. False as soon as an estimate is below the floor or not finite.
template <typename SolveA>
bool smallestEigenvalueStaysAbove(Eigen::Index n, const SolveA& solveA, double floor) {
  Eigen::VectorXd v = Eigen::VectorXd::LinSpaced(n, 1.0, 2.0).normalized();  // not orthogonal to any eigenvector
  for (int k = 0; k < kInverseIterations; ++k) {
    const Eigen::VectorXd y = solveA(v);
    const double growth = y.norm();
    if (!(growth > 0.0) || !std::isfinite(growth) || growth * floor > 1.0) return false;
    v = y / growth;
  }
  return true;
}

/// The least-squares solution of C x = d when C (m >= n) has full column rank: then it is unique, whatever x0 and the
/// weights, and it is what the dense route returns. Sparse LDL^T of C^T C (the seams' rows touch a few control
/// points each: 0.7 % of the entries of a sunglasses_lens.igs system of 1404 x 747) and one step of iterative
/// refinement on the residual (the corrected semi-normal equations, Björck, Numerical Methods for Least Squares
/// Problems, §2.5.4), which brings the error to that of a QR solution at these condition numbers. Empty when the
/// pivots or the inverse iteration do not show full column rank well inside the tolerance: the caller then takes
/// sparseQRSolution.
std::optional<Eigen::VectorXd> fullColumnRankSolution(const Eigen::SparseMatrix<double>& S, const Eigen::VectorXd& d) {
  const Eigen::Index n = S.cols();
  const Eigen::SparseMatrix<double> N = S.transpose() * S;
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(N);
  if (ldlt.info() != Eigen::Success) return std::nullopt;
  const Eigen::VectorXd D = ldlt.vectorD();
  const double largest = std::max(D.maxCoeff(), Eigen::VectorXd(N.diagonal()).maxCoeff());  // <= lambda_max
  if (!(largest > 0.0) || !(D.minCoeff() >= kNormalEquationsMinPivotRatio * largest)) return std::nullopt;
  const auto solveNormal = [&](const Eigen::VectorXd& v) { return Eigen::VectorXd(ldlt.solve(v)); };
  if (!smallestEigenvalueStaysAbove(n, solveNormal, kNormalEquationsMinPivotRatio * largest))
    return std::nullopt;
  Eigen::VectorXd x = ldlt.solve(S.transpose() * d);
  x += ldlt.solve(S.transpose() * (d - S * x));
  if (!x.allFinite()) return std::nullopt;
  return x;
}

/// The rank-deficient or ill-conditioned tall sparse system, by a sparse QR of C in its own column order, whose rank
/// decision is the dense route's: a column whose remaining norm is below kIdentityRelTol times the largest column
/// norm counts as dependent. A QR without column pivoting reveals the rank only when the directions it keeps are
/// well inside the threshold: where the smallest singular value of R11 (estimated by inverse iteration) is below
/// kSparseQRMinSigmaRel of the largest column norm, the decision is left to the dense route (empty). The columns
/// keep their order (the seams' unknowns, patch by patch): on the 29 rank-deficient systems of the strict heal of
/// sunglasses_lens.igs, COLAMD's fill-reducing order gave a factor twice as full, took 5x as long, and kept a
/// direction of singular value 0 on 4 of them (rank 499 where the SVD says 498; measured 2026-12-02,
/// docs/performance.md "The sparse QR's column order"); the own order agreed with the SVD's rank on those and on
/// the 15 of the teaspoon and example heals. C Pi = Q [R11 R12; 0 0] gives the least-squares solutions
/// x = Pi [R11^-1 (Q^T d)_r; 0] + Z y with the nullspace Z = Pi [-R11^-1 R12; I]; as on the dense route, the
/// particular solution is made orthogonal to the nullspace (minimum norm) and the nullspace part minimises
/// |W (x - x0)| (minimum norm where the weights vanish). Empty when the factorisation fails.
std::optional<Eigen::VectorXd> sparseQRSolution(const Eigen::SparseMatrix<double>& S, const Eigen::VectorXd& d,
                                                const Eigen::VectorXd& x0, const Eigen::VectorXd& weight) {
  const Eigen::Index n = S.cols();
  double largestColumn = 0.0;
  for (Eigen::Index j = 0; j < n; ++j) largestColumn = std::max(largestColumn, S.col(j).norm());
  Eigen::SparseQR<Eigen::SparseMatrix<double>, Eigen::NaturalOrdering<int>> qr;
  qr.setPivotThreshold(kIdentityRelTol * largestColumn);
  qr.compute(S);
  if (qr.info() != Eigen::Success) return std::nullopt;
  const Eigen::Index r = qr.rank();
  const Eigen::SparseMatrix<double> R = qr.matrixR();
  const Eigen::MatrixXd R11 = Eigen::MatrixXd(R.topLeftCorner(r, r));
  const auto T = R11.triangularView<Eigen::Upper>();
  // sigma_min(R11)^2 is the smallest eigenvalue of R11^T R11.
  const double sigmaFloor = kSparseQRMinSigmaRel * largestColumn;
  const auto solveNormal = [&](const Eigen::VectorXd& v) { return Eigen::VectorXd(T.solve(T.transpose().solve(v))); };
  if (r > 0 && !smallestEigenvalueStaysAbove(r, solveNormal, sigmaFloor * sigmaFloor)) return std::nullopt;
  const Eigen::VectorXd qd = qr.matrixQ().transpose() * d;
  Eigen::VectorXd y = Eigen::VectorXd::Zero(n);
  y.head(r) = T.solve(qd.head(r));
  Eigen::VectorXd x = qr.colsPermutation() * y;
  if (r < n) {
    Eigen::MatrixXd Zy(n, n - r);
    Zy.topRows(r) = -T.solve(Eigen::MatrixXd(R.block(0, r, r, n - r)));
    Zy.bottomRows(n - r).setIdentity();
    const Eigen::MatrixXd Z = qr.colsPermutation() * Zy;
    const Eigen::MatrixXd Zo =
        Eigen::HouseholderQR<Eigen::MatrixXd>(Z).householderQ() * Eigen::MatrixXd::Identity(n, n - r);
    x -= Zo * (Zo.transpose() * x);
    x = closestInNullspace<Eigen::MatrixXd, Eigen::VectorXd>(Zo, x, x0, weight);
  }
  if (!x.allFinite()) return std::nullopt;
  return x;
}

/// Tall sparse systems (the joins of many seams at once, as the patch route's heal of a whole model makes them): the
/// sparse routes, which give the dense route's solution (same rank decision, same objective) in milliseconds instead
/// of seconds (docs/performance.md, "Heal of sunglasses_lens.igs"). Empty when the system is small, not tall, not
/// sparse enough, or both sparse routes fail: the caller takes the dense route.
std::optional<Eigen::VectorXd> sparseRoutes(const Eigen::SparseMatrix<double>& S, const Eigen::VectorXd& d,
                                            const Eigen::VectorXd& x0, const Eigen::VectorXd& weight,
                                            double* residual) {
  const Eigen::Index m = S.rows(), n = S.cols();
  if (!(m >= n && n > kSmallSystem && S.nonZeros() * kSparseRouteDensity <= m * n)) return std::nullopt;
  std::optional<Eigen::VectorXd> x = fullColumnRankSolution(S, d);
  if (!x) x = sparseQRSolution(S, d, x0, weight);
  if (x && residual) *residual = (S * *x - d).cwiseAbs().maxCoeff();
  return x;
}

/// The dense route of constrainedLeastSquares (C with rows and columns).
Eigen::VectorXd denseLeastSquares(const Eigen::MatrixXd& C, const Eigen::VectorXd& d, const Eigen::VectorXd& x0,
                                  const Eigen::VectorXd& weight, double* residual) {
  const Eigen::Index n = C.cols();
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(C.transpose());
  qr.setThreshold(kIdentityRelTol);
  const Eigen::Index rank = qr.rank();
  const Eigen::MatrixXd Q = qr.householderQ();
  const Eigen::MatrixXd Z = Q.rightCols(n - rank);
  Eigen::VectorXd x = C.completeOrthogonalDecomposition().solve(d);
  if (n - rank > 0) {
    x = closestInNullspace<Eigen::MatrixXd, Eigen::VectorXd>(Z, x, x0, weight);
  }
  if (residual) *residual = (C * x - d).cwiseAbs().maxCoeff();
  return x;
}

/// Nothing to meet, or nothing free (every point locked): x0 and what it misses.
bool trivialSystem(Eigen::Index rows, Eigen::Index cols, const Eigen::VectorXd& d, double* residual) {
  if (rows > 0 && cols > 0) return false;
  if (residual) *residual = rows == 0 ? 0.0 : d.cwiseAbs().maxCoeff();
  return true;
}

}  // namespace

Eigen::VectorXd constrainedLeastSquares(const Eigen::MatrixXd& C, const Eigen::VectorXd& d, const Eigen::VectorXd& x0,
                                        const Eigen::VectorXd& weight, double* residual) {
  if (trivialSystem(C.rows(), C.cols(), d, residual)) return x0;
  if (C.rows() >= C.cols() && C.cols() > kSmallSystem) {
    if (std::optional<Eigen::VectorXd> x = sparseRoutes(C.sparseView(), d, x0, weight, residual)) return *x;
  }
  return denseLeastSquares(C, d, x0, weight, residual);
}

namespace {

/// constrainedLeastSquaresQR on matrices of type Mat (dynamic, or with a fixed largest size: no heap allocation).
template <class Mat>
Eigen::VectorXd nullspaceLeastSquares(const Eigen::MatrixXd& Cin, const Eigen::VectorXd& din,
                                      const Eigen::VectorXd& x0in, const Eigen::VectorXd& weight, double* residual) {
  using Vec = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, Mat::MaxRowsAtCompileTime, 1>;
  const Eigen::Index n = Cin.cols(), m = Cin.rows();
  // C^T Pi = Q R (n x m), rank r at kIdentityRelTol: Pi^T C = R^T Q^T. The minimum-norm solution lies in the span of
  // Q's first r columns, x = Q [y; 0], where R(0:r, :)^T y = Pi^T d (in the least-squares sense when r < m); the
  // nullspace of C is spanned by Q's last n - r columns.
  const Mat Ct = Cin.transpose();
  Eigen::ColPivHouseholderQR<Mat> qr(Ct);
  qr.setThreshold(kIdentityRelTol);
  const Eigen::Index rank = qr.rank();
  const Vec pd = qr.colsPermutation().transpose() * Vec(din);
  Vec y = Vec::Zero(n);
  if (rank == m) {
    y.head(rank) = qr.matrixR().topLeftCorner(rank, rank).template triangularView<Eigen::Upper>().transpose().solve(pd);
  } else if (rank > 0) {
    const Mat Rt = qr.matrixR().topRows(rank).template triangularView<Eigen::Upper>().toDenseMatrix().transpose();
    y.head(rank) = Eigen::HouseholderQR<Mat>(Rt).solve(pd);
  }
  Vec x = qr.householderQ() * y;
  if (n - rank > 0) {
    Mat Z = Mat::Zero(n, n - rank);
    Z.bottomRows(n - rank).setIdentity();
    Z.applyOnTheLeft(qr.householderQ());
    x = closestInNullspace<Mat, Vec>(Z, x, Vec(x0in), Vec(weight));
  }
  Eigen::VectorXd out = x;
  if (residual) *residual = (Cin * out - din).cwiseAbs().maxCoeff();
  return out;
}

}  // namespace

Eigen::VectorXd constrainedLeastSquaresQR(const Eigen::MatrixXd& C, const Eigen::VectorXd& d, const Eigen::VectorXd& x0,
                                          const Eigen::VectorXd& weight, double* residual) {
  if (C.rows() == 0 || C.cols() == 0) {  // nothing to meet, or nothing free: x0 and what it misses
    if (residual) *residual = C.rows() == 0 ? 0.0 : d.cwiseAbs().maxCoeff();
    return x0;
  }
  if (C.rows() <= kSmallSystem && C.cols() <= kSmallSystem)
    return nullspaceLeastSquares<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kSmallSystem, kSmallSystem>>(
        C, d, x0, weight, residual);
  return nullspaceLeastSquares<Eigen::MatrixXd>(C, d, x0, weight, residual);
}

namespace {

/// The Bezier pieces of a polynomial B-spline curve (homogeneous coefficients stay as they are).
std::vector<std::pair<Interval, BernsteinPoly>> piecesOf(const BSplineCurve& c) {
  std::vector<double> k = c.knots().values();
  Matrix rows = c.points();
  const std::vector<Interval> spans = decompose(c.degree(), k, rows);
  std::vector<std::pair<Interval, BernsteinPoly>> out;
  for (size_t s = 0; s < spans.size(); ++s)
    out.emplace_back(spans[s], BernsteinPoly(Matrix(rows.middleRows(static_cast<Eigen::Index>(s) * c.degree(),
                                                                    c.degree() + 1))));
  return out;
}

BernsteinPoly restrictedTo(const BernsteinPoly& p, Interval whole, double lo, double hi) {
  const double L = whole.length();
  return p.restricted((lo - whole.lo) / L, (hi - whole.lo) / L);
}

/// Adds a zero (or one, for the point) weight column: a polynomial target seen in homogeneous coordinates.
BernsteinPoly homogenizedPoly(const BernsteinPoly& p, double w) {
  if (p.empty()) return p;
  Matrix c(p.coeffs().rows(), p.coeffs().cols() + 1);
  c.leftCols(p.coeffs().cols()) = p.coeffs();
  c.col(p.coeffs().cols()).setConstant(w);
  return BernsteinPoly(std::move(c));
}

SeamTarget homogenized(const SeamTarget& t) {
  if (t.rational) return t;
  SeamTarget h = t;
  h.rational = true;
  h.dimH = t.dimH + 1;
  for (TargetPiece& p : h.pieces) {
    p.point = homogenizedPoly(p.point, 1.0);
    p.cross1 = homogenizedPoly(p.cross1, 0.0);
    p.cross2 = homogenizedPoly(p.cross2, 0.0);
  }
  return h;
}

/// Euclidean point, derivative and weight from homogeneous values (w P, w) and their derivative; plain 3-D values
/// when the data are not homogeneous (weight 1).
struct EuclidDerivative {
  Vec3 point, derivative;
  double weight = 1.0;
};
EuclidDerivative euclidean(const VecX& h, const VecX& dh, bool homogeneous) {
  if (!homogeneous) return {h.head<3>(), dh.head<3>(), 1.0};
  const double w = h[3];
  const Vec3 p = h.head<3>() / w;
  return {p, (dh.head<3>() - dh[3] * p) / w, w};
}

/// lambda0 of kLambdaFloorRel: the mean over the seam of |S_n,perp| / |T_n,perp| (Euclidean cross derivatives,
/// components normal to the seam tangent) times w_S / w_T, which converts the Euclidean ratio to the homogeneous
/// equation's lambda (S^h = rho T^h with rho = w_S / w_T). `frame` is the moving patch's edge frame (edge V0, the
/// derivative in v points into it), `target` the (homogenized when `homogeneous`) target. 1 when undefined.
double geometricLambda(const BSplineSurface& frame, const SeamTarget& target, bool homogeneous) {
  const BSplineCurve P = frame.homogeneousCrossDerivative(Edge::V0, 0);
  const BSplineCurve N = frame.homogeneousCrossDerivative(Edge::V0, 1);
  const bool frameH = frame.isRational();
  const Interval rg = target.range();
  constexpr int kSamples = 33;
  double sum = 0.0;
  int count = 0;
  for (int k = 0; k < kSamples; ++k) {
    const double u = rg.lo + rg.length() * (k + 0.5) / kSamples;
    const TargetPiece* tp = &target.pieces.back();
    for (const TargetPiece& p : target.pieces)
      if (u >= p.u.lo && u <= p.u.hi) { tp = &p; break; }
    const double t = (u - tp->u.lo) / tp->u.length();
    const EuclidDerivative tn = euclidean(tp->point(t), tp->cross1(t), homogeneous);
    const EuclidDerivative tt = euclidean(tp->point(t), tp->point.derivative()(t), homogeneous);
    const EuclidDerivative sn = euclidean(P.evaluate(u), N.evaluate(u), frameH);
    const double tl = tt.derivative.norm();
    if (!(tl > 0.0)) continue;
    const Vec3 e = tt.derivative / tl;
    const double tPerp = (tn.derivative - tn.derivative.dot(e) * e).norm();
    const double sPerp = (sn.derivative - sn.derivative.dot(e) * e).norm();
    if (!(tPerp > 0.0)) continue;
    sum += sPerp / tPerp * (sn.weight / tn.weight);
    ++count;
  }
  const double l0 = count > 0 ? sum / count : 1.0;
  return l0 > 0.0 && std::isfinite(l0) ? l0 : 1.0;
}

/// The local Bernstein coefficients of a global polynomial of degree d on [range] restricted to [lo, hi], as a
/// (d+1) x (d+1) matrix acting on the global coefficient vector.
Eigen::MatrixXd restrictionMatrix(int d, Interval range, double lo, double hi) {
  Eigen::MatrixXd R(d + 1, d + 1);
  for (int k = 0; k <= d; ++k) {
    Matrix e = Matrix::Zero(d + 1, 1);
    e(k, 0) = 1.0;
    const BernsteinPoly loc = restrictedTo(BernsteinPoly(std::move(e)), range, lo, hi);
    R.col(k) = loc.coeffs().col(0);
  }
  return R;
}

BernsteinPoly polyFromCoeffs(const Eigen::VectorXd& c) {
  Matrix m(c.size(), 1);
  m.col(0) = c;
  return BernsteinPoly(std::move(m));
}

/// Derivative weights w[k][j] = d^k N_j / dv^k at the edge v = v_min of a frame's across knot vector, j = 0..K.
Result<std::vector<std::vector<double>>> acrossWeights(const BSplineSurface& frame, int K) {
  const KnotVector& kv = frame.knotsV();
  const int q = frame.degreeV();
  const double v0 = kv.domain(q).lo;
  if (kv.multiplicity(v0) < q + 1)
    return Status(ErrorCode::kUnsupported, "the edge's across knot vector is not clamped at the edge");
  const int span = kv.findSpan(q, v0);
  const Matrix N = basisFunctionDerivatives(kv, q, span, v0, std::min(K, q));
  std::vector<std::vector<double>> w(static_cast<size_t>(K) + 1, std::vector<double>(static_cast<size_t>(K) + 1, 0.0));
  const int first = span - q;  // index of the first non-zero function: 0 for a clamped edge
  if (first != 0) return Status(ErrorCode::kUnsupported, "the edge's across knot vector is not clamped at the edge");
  for (int k = 0; k <= std::min(K, q); ++k)
    for (int j = 0; j <= q; ++j) {
      if (j <= K) {
        w[static_cast<size_t>(k)][static_cast<size_t>(j)] = N(k, j);
      } else if (std::abs(N(k, j)) > kRoundoff * N.row(k).cwiseAbs().maxCoeff()) {
        return Status(ErrorCode::kUnsupported, "the edge's across knot vector is not clamped at the edge");
      }
    }
  return w;
}

// Dense linear constraint system: rows of coefficients over the unknowns, and right-hand sides.
/// One equation's coefficients as (unknown, value) in the order they were added; an unknown may come more than once
/// (its values are summed in that order, as `row[j] += v` on a dense row would). A row touches a few control points
/// and scalars out of thousands of unknowns: a dense row per equation was most of a large heal's memory traffic.
using SparseRow = std::vector<std::pair<int, double>>;

struct System {
  int n = 0;  // unknowns
  std::vector<Eigen::Triplet<double>> entries;  // the rows, each scaled by its largest coefficient
  std::vector<double> rhs;
  /// Adds the equation row . x = r, scaled so that its largest coefficient is 1 (a row without a non-zero
  /// coefficient, e.g. every point locked, is kept as a zero row with its right-hand side).
  void add(SparseRow row, double r) {
    std::stable_sort(row.begin(), row.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    size_t kept = 0;
    for (size_t i = 0; i < row.size();) {
      double v = 0.0;
      const int j = row[i].first;
      for (; i < row.size() && row[i].first == j; ++i) v += row[i].second;
      if (v != 0.0) row[kept++] = {j, v};  // an exact zero is no entry (as Eigen's sparseView of a dense row)
    }
    row.resize(kept);
    double s = 0.0;
    for (const auto& [j, v] : row) s = std::max(s, std::abs(v));
    const int i = static_cast<int>(rhs.size());
    if (!(s > 0.0)) {
      rhs.push_back(r);
      return;
    }
    for (const auto& [j, v] : row) entries.emplace_back(i, j, v / s);
    rhs.push_back(r / s);
  }
};

struct Solution {
  Eigen::VectorXd x;
  double residual = 0.0;
};

/// The system assembled sparse: the sparse routes where they apply, else the dense matrix for the dense route (the
/// same matrix either way, so the same solution as assembling it dense).
Solution solveConstrained(const System& sys, const Eigen::VectorXd& x0, const Eigen::VectorXd& weight) {
  const auto m = static_cast<Eigen::Index>(sys.rhs.size());
  const Eigen::Index n = sys.n;
  Solution sol;
  if (m == 0) {
    sol.x = x0;
    return sol;
  }
  const Eigen::VectorXd d = Eigen::Map<const Eigen::VectorXd>(sys.rhs.data(), m);
  if (trivialSystem(m, n, d, &sol.residual)) {
    sol.x = x0;
    return sol;
  }
  Eigen::SparseMatrix<double> S(m, n);
  S.setFromTriplets(sys.entries.begin(), sys.entries.end());
  if (std::optional<Eigen::VectorXd> x = sparseRoutes(S, d, x0, weight, &sol.residual)) {
    sol.x = std::move(*x);
    return sol;
  }
  sol.x = denseLeastSquares(Eigen::MatrixXd(S), d, x0, weight, &sol.residual);
  return sol;
}

// ------------------------------------------------------------------------------------------------------------------
// The moving patch during the solve.
struct Mover {
  BSplineSurface s;
  bool rational = false;
  int dimH = 3;
  Matrix H;  // homogeneous (or plain) control points, row i * numV + j
};

/// Grid index of frame point (a along, b across) of edge e (own along direction).
int gridIndex(const BSplineSurface& s, Edge e, int a, int b) { return originalIndex(s, e, false, a, b); }

struct ScalarBlock {
  int offset = 0;
  int degree = -1;  // -1: absent
  [[nodiscard]] int size() const { return degree + 1; }
};

}  // namespace

SeamTarget targetFromFrame(const BSplineSurface& tf, Interval range, double c0, double c1, int order) {
  SeamTarget t;
  t.rational = tf.isRational();
  t.dimH = tf.dim() + (t.rational ? 1 : 0);
  const auto P = piecesOf(tf.homogeneousCrossDerivative(Edge::V0, 0));
  const auto N1 = piecesOf(tf.homogeneousCrossDerivative(Edge::V0, 1));
  const auto N2 = order >= 2 ? piecesOf(tf.homogeneousCrossDerivative(Edge::V0, 2)) : decltype(P){};
  const double tLo = c0, tHi = c0 + c1 * range.length();
  const double tol = kKnotRelTol * (tf.knotsU().values().back() - tf.knotsU().values().front());
  auto uOf = [&](double s) { return range.lo + (s - c0) / c1; };
  for (size_t k = 0; k < P.size(); ++k) {
    const Interval sp = P[k].first;
    const double lo = std::max(sp.lo, tLo), hi = std::min(sp.hi, tHi);
    if (!(hi - lo > tol)) continue;
    TargetPiece piece;
    piece.u = {uOf(lo), uOf(hi)};
    piece.point = reducedToEffectiveDegree(restrictedTo(P[k].second, sp, lo, hi));
    piece.cross1 = reducedToEffectiveDegree(restrictedTo(N1[k].second, sp, lo, hi));
    if (!N2.empty()) piece.cross2 = reducedToEffectiveDegree(restrictedTo(N2[k].second, sp, lo, hi));
    if (!t.pieces.empty()) {
      const int c = tf.degreeU() - tf.knotsU().multiplicity(lo);
      t.breaks.emplace_back(piece.u.lo, c);
      piece.u.lo = t.pieces.back().u.hi;
    }
    t.pieces.push_back(std::move(piece));
  }
  if (!t.pieces.empty()) {
    t.pieces.front().u.lo = range.lo;
    t.pieces.back().u.hi = range.hi;
  }
  return t;
}

SeamTarget mappedTarget(const SeamTarget& t, double a, double b) {
  SeamTarget r = t;
  r.pieces.clear();
  r.breaks.clear();
  for (const TargetPiece& p : t.pieces) {
    TargetPiece q = p;
    const double x0 = a + b * p.u.lo, x1 = a + b * p.u.hi;
    q.u = {std::min(x0, x1), std::max(x0, x1)};
    if (b < 0.0) {
      q.point = p.point.reversed();
      q.cross1 = p.cross1.reversed();
      if (!p.cross2.empty()) q.cross2 = p.cross2.reversed();
    }
    r.pieces.push_back(std::move(q));
  }
  for (const auto& [u, c] : t.breaks) r.breaks.emplace_back(a + b * u, c);
  if (b < 0.0) {
    std::reverse(r.pieces.begin(), r.pieces.end());
    std::reverse(r.breaks.begin(), r.breaks.end());
  }
  return r;
}

SeamTarget averagedTarget(const SeamTarget& own0, const SeamTarget& other0, double lambda0) {
  const bool rational = own0.rational || other0.rational;
  const SeamTarget own = rational ? homogenized(own0) : own0;
  const SeamTarget other = rational ? homogenized(other0) : other0;
  // Union of the breakpoints, with the smaller continuity where both break.
  std::map<double, int> br;
  for (const auto& [u, c] : own.breaks) br[u] = c;
  const double tol = kKnotRelTol * std::max(own.range().length(), 1.0) * 1e3;
  for (const auto& [u, c] : other.breaks) {
    auto it = br.lower_bound(u - tol);
    if (it != br.end() && std::abs(it->first - u) <= tol) it->second = std::min(it->second, c);
    else br[u] = c;
  }
  SeamTarget r;
  r.rational = rational;
  r.dimH = own.dimH;
  std::vector<double> cuts{own.range().lo};
  for (const auto& [u, c] : br) {
    cuts.push_back(u);
    r.breaks.emplace_back(u, c);
  }
  cuts.push_back(own.range().hi);
  auto pieceAt = [](const SeamTarget& t, double mid) -> const TargetPiece& {
    for (const TargetPiece& p : t.pieces)
      if (mid >= p.u.lo && mid <= p.u.hi) return p;
    return mid < t.pieces.front().u.lo ? t.pieces.front() : t.pieces.back();
  };
  for (size_t k = 0; k + 1 < cuts.size(); ++k) {
    const double lo = cuts[k], hi = cuts[k + 1], mid = 0.5 * (lo + hi);
    const TargetPiece& a = pieceAt(own, mid);
    const TargetPiece& b = pieceAt(other, mid);
    TargetPiece p;
    p.u = {lo, hi};
    p.point = reducedToEffectiveDegree(0.5 * (restrictedTo(a.point, a.u, lo, hi) + restrictedTo(b.point, b.u, lo, hi)));
    p.cross1 = reducedToEffectiveDegree(
        0.5 * (lambda0 * restrictedTo(b.cross1, b.u, lo, hi) - restrictedTo(a.cross1, a.u, lo, hi)));
    r.pieces.push_back(std::move(p));
  }
  return r;
}

JoinOverlap cornerSnappedOverlap(const BSplineSurface& s, Edge es, const BSplineSurface& t, Edge et, Interval overlapS,
                                 Interval overlapT, bool reversed, double maxGap) {
  const Interval ds = isUEdge(es) ? s.domainV() : s.domainU();
  const Interval dt = isUEdge(et) ? t.domainV() : t.domainU();
  auto corner = [](const BSplineSurface& x, Edge e, double along) -> Vec3 {
    switch (e) {
      case Edge::U0: return x.evaluate(x.domainU().lo, along).head<3>();
      case Edge::U1: return x.evaluate(x.domainU().hi, along).head<3>();
      case Edge::V0: return x.evaluate(along, x.domainV().lo).head<3>();
      case Edge::V1: return x.evaluate(along, x.domainV().hi).head<3>();
    }
    return Vec3::Zero();
  };
  JoinOverlap o{overlapS, overlapT};
  // S's start pairs with T's start (T's end when the seam is reversed), S's end with the other one.
  const double tAtSLo = reversed ? dt.hi : dt.lo, tAtSHi = reversed ? dt.lo : dt.hi;
  if ((corner(s, es, ds.lo) - corner(t, et, tAtSLo)).norm() <= maxGap) {
    o.s.lo = ds.lo;
    (reversed ? o.t.hi : o.t.lo) = tAtSLo;
  }
  if ((corner(s, es, ds.hi) - corner(t, et, tAtSHi)).norm() <= maxGap) {
    o.s.hi = ds.hi;
    (reversed ? o.t.lo : o.t.hi) = tAtSHi;
  }
  return o;
}

BSplineSurface expressedLike(const BSplineSurface& s, const BSplineSurface& like) {
  BSplineSurface r = s.degreeElevated(like.degreeU() - s.degreeU(), like.degreeV() - s.degreeV());
  auto missing = [](const KnotVector& have, const KnotVector& want) {
    std::vector<double> out;
    std::map<double, int> cnt;
    for (double t : have.values()) ++cnt[t];
    std::map<double, int> wc;
    for (double t : want.values()) ++wc[t];
    for (const auto& [t, c] : wc) {
      const int h = cnt.count(t) ? cnt[t] : 0;
      for (int i = h; i < c; ++i) out.push_back(t);
    }
    return out;
  };
  const auto mu = missing(r.knotsU(), like.knotsU());
  if (!mu.empty()) r = r.refinedU(mu);
  const auto mv = missing(r.knotsV(), like.knotsV());
  if (!mv.empty()) r = r.refinedV(mv);
  return r;
}

Result<LsJoinOutcome> leastSquaresJoin(const BSplineSurface& s0, const std::vector<EdgeConstraint>& constraints,
                                       const LsJoinOptions& opt) {
  if (constraints.empty()) return invalidInput("no edge to join");
  for (const EdgeConstraint& c : constraints)
    if (c.target.pieces.empty()) return invalidInput(fmt::format("edge {}: the seam is empty", edgeName(c.edge)));
  const int K = opt.continuity == GeometricClass::kG2 ? 2 : (opt.continuity == GeometricClass::kG1 ? 1 : 0);
  LsJoinOutcome out;
  bool rational = s0.isRational();
  for (const EdgeConstraint& c : constraints) rational = rational || c.target.rational;

  // ---- degree elevation and knot refinement so that the target data lie in the patch's spline space.
  BSplineSurface s = s0;
  {
    int needU = s.degreeU() + std::max(opt.elevate, 0), needV = s.degreeV() + std::max(opt.elevate, 0);
    for (const EdgeConstraint& c : constraints) {
      int q = c.target.degree();
      if (K >= 1) q = std::max(q, c.target.degreeCross1());
      if (K >= 2) q = std::max(q, c.target.degreeCross2());
      if (isUEdge(c.edge)) needV = std::max(needV, q);
      else needU = std::max(needU, q);
    }
    out.elevatedU = needU - s.degreeU();
    out.elevatedV = needV - s.degreeV();
    if (out.elevatedU > 0 || out.elevatedV > 0) {
      s = s.degreeElevated(out.elevatedU, out.elevatedV);
      out.notes.push_back(fmt::format("degree raised by ({}, {}) so that the target edge fits (exact)", out.elevatedU,
                                      out.elevatedV));
    }
  }
  for (const EdgeConstraint& c : constraints) {
    const bool alongV = isUEdge(c.edge);
    const KnotVector& kn = alongV ? s.knotsV() : s.knotsU();
    const int p = alongV ? s.degreeV() : s.degreeU();
    const Interval dom = kn.domain(p);
    std::vector<std::pair<double, int>> need;  // (u, multiplicity)
    for (const auto& [u, cont] : c.target.breaks) need.emplace_back(u, p - cont);
    const Interval rg = c.target.range();
    need.emplace_back(rg.lo, 1);
    need.emplace_back(rg.hi, 1);
    std::vector<double> ins;
    for (auto [u, mult] : need) {
      const double us = snapToKnot(kn, u);
      if (!(us > dom.lo && us < dom.hi)) continue;  // the domain ends are knots already
      const int have = static_cast<int>(std::count(kn.values().begin(), kn.values().end(), us));
      for (int i = have; i < std::min(mult, p); ++i) ins.push_back(us);
    }
    std::sort(ins.begin(), ins.end());
    if (!ins.empty()) {
      s = alongV ? s.refinedV(ins) : s.refinedU(ins);
      auto& dst = alongV ? out.insertedKnotsV : out.insertedKnotsU;
      dst.insert(dst.end(), ins.begin(), ins.end());
    }
  }
  // Enough rows across each edge that the opposite edge stays put: insert knots in the first across span.
  for (const EdgeConstraint& c : constraints) {
    for (int guard = 0; guard < 8; ++guard) {
      const bool acrossU = isUEdge(c.edge);
      const int rows = acrossU ? s.numU() : s.numV();
      if (rows - 1 > K) break;
      const KnotVector& kn = acrossU ? s.knotsU() : s.knotsV();
      const int q = acrossU ? s.degreeU() : s.degreeV();
      const Interval dom = kn.domain(q);
      const std::vector<double> bp = kn.breakpoints();
      const bool atLo = c.edge == Edge::U0 || c.edge == Edge::V0;
      double t;
      if (atLo) {
        const auto it = std::upper_bound(bp.begin(), bp.end(), dom.lo);
        t = 0.5 * (dom.lo + *it);
      } else {
        const auto it = std::lower_bound(bp.begin(), bp.end(), dom.hi);
        t = 0.5 * (*(it - 1) + dom.hi);
      }
      s = acrossU ? s.withKnotInsertedU(t) : s.withKnotInsertedV(t);
      (acrossU ? out.insertedKnotsU : out.insertedKnotsV).push_back(t);
      out.notes.push_back(fmt::format("knot {} inserted across edge {} so that the opposite edge keeps its place", t,
                                      edgeName(c.edge)));
    }
  }

  Mover mv;
  mv.s = s;
  mv.rational = rational;
  mv.dimH = s.dim() + (rational ? 1 : 0);
  mv.H = rational ? s.homogeneous() : s.points();
  if (rational && !s.isRational()) {
    mv.H.conservativeResize(mv.H.rows(), s.dim() + 1);
    mv.H.col(s.dim()).setOnes();
  }
  const int dimH = mv.dimH;
  std::vector<SeamTarget> targets;
  for (const EdgeConstraint& c : constraints) targets.push_back(rational ? homogenized(c.target) : c.target);

  // Frames (for the along knots and the across weights) and the extraction operators.
  struct EdgeData {
    BSplineSurface frame;
    int p = 0, q = 0;  // along degree of the patch, target degree (point)
    int qn = 0, qnn = 0;  // target degrees of T_n, T_nn
    std::vector<std::vector<double>> w;
    std::vector<std::pair<Interval, Matrix>> spans;  // the patch's Bezier spans inside the seam range, extraction
    std::vector<int> alongPoints;                    // frame along indices whose support meets the range
  };
  std::vector<EdgeData> ed(constraints.size());
  for (size_t c = 0; c < constraints.size(); ++c) {
    EdgeData& e = ed[c];
    e.frame = toEdgeFrame(s, constraints[c].edge, false);
    e.p = e.frame.degreeU();
    e.q = targets[c].degree();
    e.qn = std::max(targets[c].degreeCross1(), 0);
    e.qnn = std::max(targets[c].degreeCross2(), 0);
    auto w = acrossWeights(e.frame, K);
    if (!w) return w.status().withContext(fmt::format("edge {}", edgeName(constraints[c].edge)));
    e.w = *w;
    const int na = e.frame.numU();
    const BSplineCurve basis(e.p, e.frame.knotsU(), Matrix::Identity(na, na));
    const Interval rg = targets[c].range();
    const double tol = kKnotRelTol * (e.frame.knotsU().values().back() - e.frame.knotsU().values().front());
    for (const BezierCurvePiece& pc : basis.bezierPieces())
      if (pc.interval.lo >= rg.lo - tol && pc.interval.hi <= rg.hi + tol) e.spans.emplace_back(pc.interval, pc.curve.points());
    const std::vector<double>& U = e.frame.knotsU().values();
    for (int a = 0; a < na; ++a)
      if (U[static_cast<size_t>(a)] < rg.hi - tol && U[static_cast<size_t>(a + e.p + 1)] > rg.lo + tol)
        e.alongPoints.push_back(a);
  }

  // Locked points.
  std::vector<char> locked(static_cast<size_t>(mv.H.rows()), 0);
  for (Edge le : opt.lockedEdges) {
    const BSplineSurface f = toEdgeFrame(s, le, false);
    for (int a = 0; a < f.numU(); ++a)
      for (int b = 0; b < std::min(opt.lockedRows, f.numV()); ++b) locked[static_cast<size_t>(gridIndex(s, le, a, b))] = 1;
  }

  auto targetPieceFor = [](const SeamTarget& t, const Interval& sp) -> const TargetPiece& {
    const double mid = 0.5 * (sp.lo + sp.hi);
    for (const TargetPiece& p : t.pieces)
      if (mid >= p.u.lo && mid <= p.u.hi) return p;
    return mid < t.pieces.front().u.lo ? t.pieces.front() : t.pieces.back();
  };

  // ---- one stage: rows [rowLo, rowHi] of every edge are unknown; order-k equations for k in [kLo, kHi].
  std::vector<Eigen::VectorXd> lambdaC(constraints.size()), kappaC(constraints.size());
  // Rational: the G0 factor rho of S^h = rho T^h along each edge (its global Bernstein coefficients).
  std::vector<Eigen::VectorXd> rhoC(constraints.size());
  // Per constraint: lambda fixed to these global coefficients (empty: lambda is an unknown).
  std::vector<Eigen::VectorXd> fixedLambda(constraints.size());
  // Rational G2: the seam's rho varies along it (non-constant G0 factor). Then the order-2 equations are multiplied
  // through by rho, which keeps them linear (docs/algorithms/zheng-wang-liang.md, "Rational G2 joins").
  std::vector<char> rhoVaries(constraints.size(), 0);
  // Rational: the moving rows' weights are known (not unknowns); the equations stay linear in the Cartesian points.
  bool weightsFixed = false;
  auto stage = [&](int rowLo, int rowHi, int kLo, int kHi, std::vector<char> fixedMask) -> Result<double> {
    std::vector<int> slot(static_cast<size_t>(mv.H.rows()), -1);
    std::vector<int> points;
    for (size_t c = 0; c < constraints.size(); ++c)
      for (int a : ed[c].alongPoints)
        for (int b = rowLo; b <= rowHi; ++b) {
          const int g = gridIndex(s, constraints[c].edge, a, b);
          if (locked[static_cast<size_t>(g)] || fixedMask[static_cast<size_t>(g)] || slot[static_cast<size_t>(g)] >= 0)
            continue;
          slot[static_cast<size_t>(g)] = static_cast<int>(points.size());
          points.push_back(g);
        }
    // Unknown coordinates per moved point: all homogeneous ones, or (weights fixed) w P only, the weight known.
    const int perPt = (rational && weightsFixed) ? dimH - 1 : dimH;
    int n = static_cast<int>(points.size()) * perPt;
    // Scalar blocks per constraint: 0 rho, 1 lambda, 2 kappa, 3 nu (stage G0/G1); 4 mu, 5 nu2, 6 eta (G2; eta,
    // the coefficient of T^h, only for rational data).
    std::vector<std::array<ScalarBlock, 7>> sb(constraints.size());
    for (size_t c = 0; c < constraints.size(); ++c) {
      // Degrees of the connecting functions: as high as the patch's degree p allows for each product term
      // (T of degree q, T_t of q - 1, T_n of qn; G2 adds lambda^2 T_nn, lambda kappa T_nt, kappa^2 T_tt).
      const int p = ed[c].p, q = ed[c].q, qn = ed[c].qn, qnn = ed[c].qnn;
      auto& b = sb[c];
      if (kLo == 0 && rational) b[0].degree = p - q;
      if (kHi >= 1 && kLo <= 1) {
        int dl = p - qn, dk = p - (q - 1);
        if (K == 2) {
          dl = std::min(dl, (p - qnn) / 2);
          dk = std::min({dk, (p - q + 2) / 2, p - (qn - 1) - dl});
        }
        b[1].degree = fixedLambda[c].size() > 0 ? -1 : std::max(dl, 0);
        b[2].degree = std::max(dk, 0);
        if (rational) b[3].degree = std::max(p - q, 0);
      }
      if (kHi >= 2) {
        // With a varying rho the free functions are rho mu, rho nu2 and rho eta, of degrees up to p + deg(rho).
        const int pe = p + (rhoVaries[c] ? static_cast<int>(rhoC[c].size()) - 1 : 0);
        b[4].degree = std::max(pe - qn, 0);
        b[5].degree = std::max(pe - q + 1, 0);
        if (rational) b[6].degree = std::max(pe - q, 0);
      }
      for (auto& blk : b)
        if (blk.degree >= 0) {
          blk.offset = n;
          n += blk.size();
        }
    }
    System sys;
    sys.n = n;
    for (size_t c = 0; c < constraints.size(); ++c) {
      const EdgeData& e = ed[c];
      const SeamTarget& T = targets[c];
      const Interval rg = T.range();
      const Edge edge = constraints[c].edge;
      for (const auto& [sp, E] : e.spans) {
        const TargetPiece& tp = targetPieceFor(T, sp);
        const double h = sp.length();
        const BernsteinPoly Tp = restrictedTo(tp.point, tp.u, sp.lo, sp.hi);
        const BernsteinPoly Tn = restrictedTo(tp.cross1, tp.u, sp.lo, sp.hi);
        const BernsteinPoly Tt = (1.0 / h) * Tp.derivative();
        for (int k = kLo; k <= kHi; ++k) {
          // The equation's degree: p, or p + deg(rho) when the order-2 equation is multiplied through by a varying
          // rho; Ek holds the Bernstein coefficients (in that degree) of the patch's along basis times the factor.
          const bool byRho = k == 2 && rhoVaries[c];
          const int D = byRho ? e.p + static_cast<int>(rhoC[c].size()) - 1 : e.p;
          Matrix Ek = E;
          if (byRho) {
            const BernsteinPoly rhoSpan = polyFromCoeffs(
                restrictionMatrix(static_cast<int>(rhoC[c].size()) - 1, rg, sp.lo, sp.hi) * rhoC[c]);
            Ek = Matrix(D + 1, E.cols());
            for (Eigen::Index ai = 0; ai < E.cols(); ++ai)
              Ek.col(ai) = product(polyFromCoeffs(E.col(ai)), rhoSpan).coeffs().col(0);
          }
          // Known right-hand side polynomial (degree <= D) and the scalar-unknown terms.
          BernsteinPoly known = BernsteinPoly::zero(D, dimH);
          struct Term {
            const ScalarBlock* blk;
            BernsteinPoly factor;
            double sign;
          };
          std::vector<Term> terms;
          if (k == 0) {
            if (rational) terms.push_back({&sb[c][0], Tp, -1.0});
            else known = known + Tp;  // S = T
          } else if (k == 1) {
            if (fixedLambda[c].size() > 0) {  // S_n - kappa T_t - nu T = -lambda T_n with lambda known
              const Eigen::MatrixXd Rl =
                  restrictionMatrix(static_cast<int>(fixedLambda[c].size()) - 1, rg, sp.lo, sp.hi);
              known = known - product(polyFromCoeffs(Rl * fixedLambda[c]), Tn);
            } else {
              terms.push_back({&sb[c][1], Tn, +1.0});
            }
            terms.push_back({&sb[c][2], Tt, -1.0});
            if (rational) terms.push_back({&sb[c][3], Tp, -1.0});
          } else {
            const BernsteinPoly Tnn = restrictedTo(tp.cross2, tp.u, sp.lo, sp.hi);
            const BernsteinPoly Tnt = (1.0 / h) * Tn.derivative();
            const BernsteinPoly Ttt = (1.0 / (h * h)) * Tp.derivative(2);
            const Eigen::MatrixXd Rl = restrictionMatrix(static_cast<int>(lambdaC[c].size()) - 1, rg, sp.lo, sp.hi);
            const Eigen::MatrixXd Rk = restrictionMatrix(static_cast<int>(kappaC[c].size()) - 1, rg, sp.lo, sp.hi);
            const BernsteinPoly lam = polyFromCoeffs(Rl * lambdaC[c]), kap = polyFromCoeffs(Rk * kappaC[c]);
            // S_nn = lam^2 Tnn - 2 lam kap Tnt + kap^2 Ttt - mu Tn + nu2 Tt. Rational (homogeneous, S^h = r T^h(x, y)
            // with r = rho, kappa = r x_s, -lambda = r y_s on the edge): the quadratic terms carry 1 / rho, and
            // r_ss T^h, 2 r_s (x_s T_t + y_s T_n) and r (x_ss T_t + y_ss T_n) are absorbed by free functions eta,
            // nu2, mu (docs/algorithms/zheng-wang-liang.md). A varying rho multiplies the equation through instead
            // (rho S_nn = the quadratic terms + rho mu, rho nu2, rho eta terms, those products free polynomials).
            const double invRho = rational && !byRho ? 1.0 / rhoC[c][0] : 1.0;
            known = known + invRho * (product(product(lam, lam), Tnn) - 2.0 * product(product(lam, kap), Tnt) +
                                      product(product(kap, kap), Ttt));
            terms.push_back({&sb[c][4], Tn, +1.0});
            terms.push_back({&sb[c][5], Tt, -1.0});
            if (rational) terms.push_back({&sb[c][6], Tp, -1.0});
          }
          if (known.degree() > D)
            return Status(ErrorCode::kNoSolution,
                          fmt::format("edge {}: the G{} terms have degree {} > {}", edgeName(edge), k, known.degree(), D));
          known = known.elevatedTo(D);
          // Scalar-term columns: for each global coefficient g, (restricted unit) * factor, elevated to p.
          std::vector<std::pair<int, Matrix>> scalarCols;
          for (const Term& t : terms) {
            if (t.blk->degree < 0) continue;
            const Eigen::MatrixXd R = restrictionMatrix(t.blk->degree, rg, sp.lo, sp.hi);
            for (int g = 0; g < t.blk->size(); ++g) {
              BernsteinPoly prod = product(polyFromCoeffs(R.col(g)), t.factor);
              if (prod.degree() > D)
                return Status(ErrorCode::kNoSolution, fmt::format("edge {}: connecting-function degree too high", edgeName(edge)));
              scalarCols.emplace_back(t.blk->offset + g, t.sign * prod.elevatedTo(D).coeffs());
            }
          }
          for (int r = 0; r <= D; ++r)
            for (int cc = 0; cc < dimH; ++cc) {
              SparseRow row;
              double rhs = known.coeffs()(r, cc);
              for (size_t ai = 0; ai < static_cast<size_t>(Ek.cols()); ++ai) {
                const double ea = Ek(r, static_cast<Eigen::Index>(ai));
                if (ea == 0.0) continue;
                for (int j = 0; j <= k; ++j) {
                  const double wj = e.w[static_cast<size_t>(k)][static_cast<size_t>(j)];
                  if (wj == 0.0) continue;
                  const int g = gridIndex(s, edge, static_cast<int>(ai), j);
                  const int sl = slot[static_cast<size_t>(g)];
                  if (sl >= 0 && cc < perPt) row.emplace_back(sl * perPt + cc, ea * wj);
                  else rhs -= ea * wj * mv.H(g, cc);
                }
              }
              for (const auto& [col, coeffs] : scalarCols) row.emplace_back(col, coeffs(r, cc));
              sys.add(std::move(row), rhs);
            }
        }
      }
      if (kLo <= 1 && kHi >= 1) {
        // kappa = 0 at the ends where asked (Bernstein end coefficients).
        const ScalarBlock& kb = sb[c][2];
        if (constraints[c].kappaZeroAtStart && kb.degree >= 0) sys.add({{kb.offset, 1.0}}, 0.0);
        if (constraints[c].kappaZeroAtEnd && kb.degree >= 0) sys.add({{kb.offset + kb.degree, 1.0}}, 0.0);
      }
    }
    // Objective: displacement of the points, nothing on the scalars. Free weights: homogeneous displacement, weight
    // changes scaled by the model size. Weights fixed: the Cartesian displacement |P - P0| = |w P - w P0| / w.
    Eigen::VectorXd x0 = Eigen::VectorXd::Zero(n), wgt = Eigen::VectorXd::Zero(n);
    for (size_t i = 0; i < points.size(); ++i)
      for (int cc = 0; cc < perPt; ++cc) {
        x0[static_cast<Eigen::Index>(i) * perPt + cc] = mv.H(points[i], cc);
        wgt[static_cast<Eigen::Index>(i) * perPt + cc] =
            !rational ? 1.0 : (weightsFixed ? 1.0 / mv.H(points[i], dimH - 1) : (cc == dimH - 1 ? opt.scale : 1.0));
      }
    const Solution sol = solveConstrained(sys, x0, wgt);
    for (size_t i = 0; i < points.size(); ++i)
      for (int cc = 0; cc < perPt; ++cc) mv.H(points[i], cc) = sol.x[static_cast<Eigen::Index>(i) * perPt + cc];
    if (kLo <= 1 && kHi >= 1)
      for (size_t c = 0; c < constraints.size(); ++c) {
        lambdaC[c] = fixedLambda[c].size() > 0 ? fixedLambda[c] : Eigen::VectorXd(sol.x.segment(sb[c][1].offset, sb[c][1].size()));
        kappaC[c] = sol.x.segment(sb[c][2].offset, sb[c][2].size());
      }
    if (kLo == 0)
      for (size_t c = 0; c < constraints.size(); ++c)
        if (sb[c][0].degree >= 0) rhoC[c] = sol.x.segment(sb[c][0].offset, sb[c][0].size());
    double dataScale = opt.scale;
    for (double r : sys.rhs) dataScale = std::max(dataScale, std::abs(r));
    return sol.residual / dataScale;
  };

  std::vector<char> none(static_cast<size_t>(mv.H.rows()), 0);
  // G0 and G1 rows; for G1/G2 the fold test: lambda must be certified above kLambdaFloorRel x lambda0 on every seam,
  // else that seam's lambda is fixed to lambda0 and the rows are solved again from the input (each round fixes at
  // least one more seam, so this ends).
  out.lambda0.assign(constraints.size(), 1.0);
  out.lambdaFixed.assign(constraints.size(), 0);
  if (K >= 1)
    for (size_t c = 0; c < constraints.size(); ++c) out.lambda0[c] = geometricLambda(ed[c].frame, targets[c], rational);
  const Matrix H0 = mv.H;
  std::vector<CertifiedMin> lamMin(constraints.size());
  std::vector<std::string> rowNotes;
  // Rows 0..min(K,1) from the input, with lambda fixed where the solve would fold; the residual.
  auto solveRows = [&]() -> Result<double> {
  mv.H = H0;
  rowNotes.clear();
  for (size_t c = 0; c < constraints.size(); ++c) {
    fixedLambda[c] = Eigen::VectorXd();
    out.lambdaFixed[c] = 0;
  }
  double residual = 0.0;
  for (;;) {
    auto r1 = stage(0, std::min(K, 1), 0, std::min(K, 1), none);
    if (!r1) return r1.status();
    residual = *r1;
    if (K == 0) break;
    bool again = false;
    for (size_t c = 0; c < constraints.size(); ++c) {
      const BernsteinPoly lam = polyFromCoeffs(lambdaC[c]);
      const double floor = kLambdaFloorRel * out.lambda0[c];
      lamMin[c] = certifiedMinimum(lam, 1e-9 * std::max(out.lambda0[c], lam.maxAbsCoeff()));
      if (lamMin[c].lower > floor || out.lambdaFixed[c]) continue;
      rowNotes.push_back(fmt::format(
          "edge {}: the free solve's lambda reaches {:.4g} at u = {:.6g} (floor {:.3g} = {} x lambda0): {}; lambda "
          "fixed to lambda0 = {:.6g}, kappa{} free",
          edgeName(constraints[c].edge), lamMin[c].attained,
          targets[c].range().lo + lamMin[c].at * targets[c].range().length(), floor, kLambdaFloorRel,
          lamMin[c].attained <= 0.0 ? "the patch would fold back over its neighbour"
                                    : "the moved rows would be squeezed onto the edge",
          out.lambda0[c], rational ? " and nu" : ""));
      fixedLambda[c] = Eigen::VectorXd::Constant(1, out.lambda0[c]);
      out.lambdaFixed[c] = 1;
      again = true;
    }
    if (!again) break;
    mv.H = H0;
  }
  return residual;
  };
  // Rational: first with the moved rows' weights fixed (the Cartesian points and the connecting functions are the
  // unknowns, the displacement is Cartesian); only when that has no solution are the weights solved for too.
  if (rational) {
    weightsFixed = true;
    auto rf = solveRows();
    if (!rf) return rf.status();
    if (*rf <= kConstraintRelTol) {
      out.weightsFixed = true;
      out.residual = *rf;
      out.notes.push_back("rational: solved with the moved rows' weights fixed (Cartesian displacement)");
    } else {
      out.notes.push_back(fmt::format("rational: with the moved rows' weights fixed the seam equations have no "
                                      "solution (residual {:.3g}); solved again with the weights as unknowns",
                                      *rf));
      weightsFixed = false;
    }
  }
  if (!out.weightsFixed) {
    auto rr = solveRows();
    if (!rr) return rr.status();
    out.residual = *rr;
  }
  for (std::string& n : rowNotes) out.notes.push_back(std::move(n));
  if (K == 2) {
    // Rows 0 and 1 of every constrained edge are final; row 2 and the second-order functions are solved next.
    std::vector<char> fixedMask(static_cast<size_t>(mv.H.rows()), 0);
    for (size_t c = 0; c < constraints.size(); ++c) {
      const BSplineSurface f = toEdgeFrame(s, constraints[c].edge, false);
      for (int a = 0; a < f.numU(); ++a)
        for (int b = 0; b <= 1; ++b) fixedMask[static_cast<size_t>(gridIndex(s, constraints[c].edge, a, b))] = 1;
    }
    if (rational)
      for (size_t c = 0; c < constraints.size(); ++c) {
        // The quadratic terms carry 1 / rho. A constant rho (equal weight ratios along the seam, the usual case)
        // divides them; a varying one multiplies the whole order-2 equation instead (rhoVaries, in `stage`). rho is
        // the ratio of two positive weight functions: a rho that is not positive on its Bernstein coefficients means
        // the G0 stage failed, and the patch is left as it was.
        const Eigen::VectorXd& r = rhoC[c];
        const double r0 = r.size() > 0 ? r[0] : 0.0;
        const double spread = r.size() > 0 ? (r.array() - r0).abs().maxCoeff() : 0.0;
        if (!(r.size() > 0) || !(r.minCoeff() > 0.0))
          return Status(ErrorCode::kNoSolution,
                        fmt::format("edge {}: the weight ratio of the two patches along the seam is not positive "
                                    "(rho's Bernstein coefficients reach {:.3g})",
                                    edgeName(constraints[c].edge), r.size() > 0 ? r.minCoeff() : 0.0));
        if (spread > kConstraintRelTol * r0) {
          rhoVaries[c] = 1;
          out.notes.push_back(fmt::format("edge {}: the weight ratio rho of the two patches varies along the seam "
                                          "({:.6g} to {:.6g}); the curvature equations are multiplied through by it",
                                          edgeName(constraints[c].edge), r.minCoeff(), r.maxCoeff()));
        }
      }
    auto r2 = stage(2, 2, 2, 2, fixedMask);
    if (!r2) return r2.status();
    if (rational && weightsFixed && *r2 > kConstraintRelTol) {
      // Row 2 with its weights fixed has no solution: solve it again with its weights as unknowns (rows 0 and 1
      // stay as solved).
      out.notes.push_back(fmt::format("rational G2: with row 2's weights fixed the equations have no solution "
                                      "(residual {:.3g}); row 2 solved again with its weights as unknowns",
                                      *r2));
      weightsFixed = false;
      out.weightsFixed = false;
      r2 = stage(2, 2, 2, 2, fixedMask);
      if (!r2) return r2.status();
    }
    out.residual = std::max(out.residual, *r2);
  }
  out.feasible = out.residual <= kConstraintRelTol;

  // Connecting functions (lambda certified above its floor by the loop above, or fixed to lambda0).
  out.lambdaMin = std::numeric_limits<double>::infinity();
  for (size_t c = 0; c < constraints.size() && K >= 1; ++c) {
    out.lambda.push_back(polyFromCoeffs(lambdaC[c]));
    out.kappa.push_back(polyFromCoeffs(kappaC[c]));
    out.lambdaMin = std::min(out.lambdaMin, out.lambdaFixed[c] ? out.lambda0[c] : lamMin[c].lower);
  }

  if (rational) {
    for (Eigen::Index i = 0; i < mv.H.rows(); ++i)
      if (!(mv.H(i, dimH - 1) > 0.0)) {
        out.feasible = false;
        out.notes.push_back("a weight became non-positive: no valid rational solution with these rows");
        for (Eigen::Index j = 0; j < mv.H.rows(); ++j) mv.H(j, dimH - 1) = std::max(mv.H(j, dimH - 1), kRoundoff);
        break;
      }
  }
  const bool anyFixed = std::any_of(out.lambdaFixed.begin(), out.lambdaFixed.end(), [](char f) { return f != 0; });
  if (anyFixed && !out.feasible) {
    // Without the fold the constraints cannot be met: leave the patch as it was.
    out.notes.push_back(fmt::format("cannot reach G{} without folding the patch; left as it was ({} with lambda "
                                    "fixed)",
                                    K, out.residual > kConstraintRelTol
                                           ? fmt::format("residual {:.3g}", out.residual)
                                           : std::string("a weight would become non-positive")));
    out.surface = s0;
    out.unchanged = true;
    out.insertedKnotsU.clear();
    out.insertedKnotsV.clear();
    out.elevatedU = out.elevatedV = 0;
    return out;
  }
  out.surface = BSplineSurface::fromHomogeneous(s.degreeU(), s.degreeV(), s.knotsU(), s.knotsV(), s.numU(), s.numV(),
                                                mv.H, rational);
  if (!out.feasible && out.residual > kConstraintRelTol)
    out.notes.push_back(fmt::format("the constraints cannot be met with these rows (residual {:.3g})", out.residual));
  return out;
}

}  // namespace seam::detail
