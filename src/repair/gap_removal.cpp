// Lai-Lian-Cassidy §3: Theorem 1 (proportional knots) and Algorithm 3.3 (the Bezier strip). Paper indices are kept
// in the comments and in the code (de Boor points d_{i,j}, i = 0..2m+1; junctions i = 1..m^-1 at u_{2i+2}); the
// derivations and the corrections of the extracted text are in docs/algorithms/lai-lian-cassidy.md.
#include "seam/repair/gap_removal.h"

#include <fmt/format.h>

#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "seam/core/tolerances.h"
#include "seam/repair/bicubic.h"

namespace seam {

std::string_view toString(SpanCountCase c) {
  switch (c) {
    case SpanCountCase::kEqual: return "m = m~";
    case SpanCountCase::kMore: return "m > m~";
    case SpanCountCase::kFewer: return "m < m~";
  }
  return "?";
}

Result<KnotProportionality> proportionalKnots(const KnotVector& u, const KnotVector& uTilde, double tol) {
  if (Status s = checkC1CubicKnots(u); !s) return s.withContext("u");
  if (Status s = checkC1CubicKnots(uTilde); !s) return s.withContext("u~");
  KnotProportionality r;
  r.alpha = c1CubicAlphas(u);
  r.alphaTilde = c1CubicAlphas(uTilde);
  r.m = static_cast<int>(r.alpha.size()) - 1;
  r.mTilde = static_cast<int>(r.alphaTilde.size()) - 1;
  r.mHat = std::min(r.m, r.mTilde);
  r.spanCase = r.m == r.mTilde ? SpanCountCase::kEqual : (r.m > r.mTilde ? SpanCountCase::kMore : SpanCountCase::kFewer);
  for (int i = 1; i <= r.mHat - 1; ++i) {
    const double dev = std::abs(r.alpha[static_cast<size_t>(i)] - r.alphaTilde[static_cast<size_t>(i)]);
    r.maxAlphaDeviation = std::max(r.maxAlphaDeviation, dev);
    if (dev > tol) r.wrinkled.push_back(i);
  }
  r.proportional = r.wrinkled.empty();
  return r;
}

namespace {

// Shared data of Theorem 1 and Algorithm 3.3: the checks, alpha's and the new boundary rows d*_{i,0}, d*_{i,1},
// i = 0..2m^+1 (the C0 step and the G1 step across the seam, (3.7)-(3.12)).
struct PaperSetup {
  KnotProportionality prop;
  double r = 0.0;
  int nv = 0;
  Matrix row0, row1;  // (2m^+2) x dim
};

Result<PaperSetup> setup(const BSplineSurface& s, const BSplineSurface& t) {
  if (Status st = checkC1Bicubic(s); !st) return st.withContext("S");
  if (Status st = checkC1Bicubic(t); !st) return st.withContext("S~");
  if (s.dim() != t.dim()) return invalidInput("S and S~ have control points of different dimensions");
  auto prop = proportionalKnots(s.knotsU(), t.knotsU());
  if (!prop) return prop.status();
  PaperSetup ps;
  ps.prop = *prop;
  const std::vector<double> bv = s.knotsV().breakpoints(), btv = t.knotsV().breakpoints();
  ps.r = (bv[1] - bv[0]) / (btv[1] - btv[0]);  // (v_4 - v_2) / (v~_4 - v~_2)
  ps.nv = s.numV();
  const int mh = ps.prop.mHat;
  const double r = ps.r;
  auto dt = [&](int i, int j) -> VecX { return t.point(i, j).transpose(); };
  ps.row0.resize(2 * mh + 2, s.dim());
  ps.row1.resize(2 * mh + 2, s.dim());
  // (3.7)/(3.9)/(3.11) and (3.8)/(3.10)/(3.12), i = 0..2m^: copy row 0 of S~ and reflect its row 1.
  for (int i = 0; i <= 2 * mh; ++i) {
    ps.row0.row(i) = dt(i, 0).transpose();
    ps.row1.row(i) = ((1.0 + r) * dt(i, 0) - r * dt(i, 1)).transpose();
  }
  const int e = 2 * mh + 1;
  VecX p0, p1;
  switch (ps.prop.spanCase) {
    case SpanCountCase::kEqual:  // (3.7), (3.8) at i = 2m^+1
      p0 = dt(e, 0);
      p1 = dt(e, 1);
      break;
    case SpanCountCase::kMore: {  // (3.9), (3.10): S's junction at u_{2m^+2} must be S~'s end point
      const double a = ps.prop.alpha[static_cast<size_t>(mh)], b = 1.0 - a;
      p0 = (dt(e, 0) - a * dt(e - 1, 0)) / b;
      p1 = (dt(e, 1) - a * dt(e - 1, 1)) / b;
      break;
    }
    case SpanCountCase::kFewer: {  // (3.11), (3.12): S's end point is S~'s junction at u~_{2m^+2}
      const double a = ps.prop.alphaTilde[static_cast<size_t>(mh)], b = 1.0 - a;
      p0 = a * dt(e - 1, 0) + b * dt(e, 0);
      p1 = a * dt(e - 1, 1) + b * dt(e, 1);
      break;
    }
  }
  ps.row0.row(e) = p0.transpose();
  ps.row1.row(e) = ((1.0 + r) * p0 - r * p1).transpose();
  return ps;
}

}  // namespace

Result<Theorem1Result> theorem1Join(const BSplineSurface& s, const BSplineSurface& sTilde) {
  auto ps = setup(s, sTilde);
  if (!ps) return ps.status();
  if (!ps->prop.proportional)
    return Status(ErrorCode::kNoSolution,
                  fmt::format("the knots are not proportional (Def. 3.1): alpha_{} = {} but alpha~_{} = {}; use the "
                              "Bezier strip (Algorithm 3.3)",
                              ps->prop.wrinkled.front(), ps->prop.alpha[static_cast<size_t>(ps->prop.wrinkled.front())],
                              ps->prop.wrinkled.front(),
                              ps->prop.alphaTilde[static_cast<size_t>(ps->prop.wrinkled.front())]));
  Matrix pts = s.points();
  const int nv = s.numV();
  for (int i = 0; i < ps->row0.rows(); ++i) {
    pts.row(i * nv + 0) = ps->row0.row(i);
    pts.row(i * nv + 1) = ps->row1.row(i);
  }
  Theorem1Result out;
  out.surface = BSplineSurface(3, 3, s.knotsU(), s.knotsV(), s.numU(), s.numV(), std::move(pts));
  out.spanCase = ps->prop.spanCase;
  out.mHat = ps->prop.mHat;
  out.r = ps->r;
  return out;
}

Result<BezierStripResult> bezierStripJoin(const BSplineSurface& s, const BSplineSurface& sTilde,
                                          const BezierStripOptions& options) {
  if (options.ell && !(std::isfinite(*options.ell) && *options.ell > 0.0))
    return invalidInput(fmt::format("the ironing parameter l = {} must be a positive number", *options.ell));
  auto psr = setup(s, sTilde);
  if (!psr) return psr.status();
  const PaperSetup& ps = *psr;
  const int mh = ps.prop.mHat, nv = s.numV(), m = ps.prop.m;
  const int n = (nv - 2) / 2;  // v-spans of S
  const std::vector<double> xi = c1CubicAlphas(s.knotsV());
  const double xi1 = n >= 2 ? xi[1] : 1.0, eta1 = 1.0 - xi1;
  auto d = [&](int i, int j) -> VecX { return s.point(i, j).transpose(); };
  auto dt = [&](int i, int j) -> VecX { return sTilde.point(i, j).transpose(); };
  auto A = [&](int i) { return ps.prop.alpha[static_cast<size_t>(i)]; };
  auto At = [&](int i) { return ps.prop.alphaTilde[static_cast<size_t>(i)]; };

  BezierStripResult out;
  out.spanCase = ps.prop.spanCase;
  out.mHat = mh;
  out.r = ps.r;

  // New de Boor points of S (before the knot raising): rows 0, 1 from the C0/G1 step; rows 2, 3 ironed below.
  Matrix dstar = s.points();
  for (int i = 0; i < ps.row0.rows(); ++i) {
    dstar.row(i * nv + 0) = ps.row0.row(i);
    dstar.row(i * nv + 1) = ps.row1.row(i);
  }
  auto ds = [&](int i, int j) -> VecX { return dstar.row(i * nv + j).transpose(); };

  // Step 2 and 3: wrinkles and ironing at the interior junctions i = 1..m^-1 (the extracted text says 1..m~; the
  // junction i = m~ is S~'s end, where nothing needs ironing, see the docs).
  std::vector<bool> raise(static_cast<size_t>(m) + 1, false);
  for (int i = 1; i <= mh - 1; ++i) {
    StripJunction J;
    J.index = i;
    J.u = s.knotsU().values()[static_cast<size_t>(2 * i + 2)];
    J.wrinkled = std::find(ps.prop.wrinkled.begin(), ps.prop.wrinkled.end(), i) != ps.prop.wrinkled.end();
    if (J.wrinkled) {
      const VecX D0 = dt(2 * i + 1, 0) - dt(2 * i, 0);          // d~_{2i+1,0} - d~_{2i,0}
      const VecX D1 = ds(2 * i + 1, 1) - ds(2 * i, 1);          // d*_{2i+1,1} - d*_{2i,1}
      if (!(D0.norm() > kRoundoff * std::max(dt(2 * i, 0).norm(), 1.0)))
        return Status(ErrorCode::kDegenerate,
                      fmt::format("S~ has a cusp at junction {} (d~_{},0 = d~_{},0)", i, 2 * i + 1, 2 * i));
      // Bezier row 3 of the strip is d_{.,3} when n = 1, xi_1 d_{.,2} + eta_1 d_{.,3} when n >= 2. G1 needs
      // (row-2 leg) = a D0 and (row-3 Bezier leg) = 9 a D1, a = l alpha~_i / (3 alpha_i); the de Boor leg of row 3 is
      // then g a with g below.
      const bool bezierRow3 = n == 1 || options.literalRow3;
      const VecX g = bezierRow3 ? VecX(9.0 * D1) : VecX((9.0 * D1 - xi1 * D0) / eta1);
      const VecX F2 = d(2 * i + 1, 2) - d(2 * i, 2), G3 = d(2 * i + 1, 3) - d(2 * i, 3);
      double a;
      if (options.ell) {
        a = *options.ell * At(i) / (3.0 * A(i));
      } else {
        a = (F2.dot(D0) + G3.dot(g)) / (D0.squaredNorm() + g.squaredNorm());
        if (!(a > 0.0)) {
          // The displacement grows with a on a > 0, and a -> 0 collapses the u-legs of rows 2 and 3 (a vanishing
          // normal at the strip's corner). Keep the length of one of the two Bezier legs that the ironing turns:
          // row 2's (F2 = a D0) or row 3's (F3 = 9 a D1), whichever needs the smaller a (it moves less).
          const VecX F3 = bezierRow3 ? G3 : VecX(xi1 * F2 + eta1 * G3);
          const double a2 = F2.norm() / D0.norm();
          const double a3 = D1.norm() > 0.0 ? F3.norm() / (9.0 * D1.norm()) : a2;
          a = a3 > 0.0 ? std::min(a2, a3) : a2;
          if (!(a > 0.0)) a = 1.0;  // F2 = F3 = 0: any a is as good; l = 3 alpha / alpha~
          out.notes.push_back(fmt::format(
              "junction {}: the displacement-optimal l is not positive (S's rows 2, 3 point against S~'s edge); "
              "used the l that keeps the length of the Bezier u-leg of row {}",
              i, a == a2 ? 2 : 3));
        }
      }
      J.ell = 3.0 * A(i) * a / At(i);
      const VecX n2 = d(2 * i + 1, 2) - a * D0;
      const VecX n3 = d(2 * i + 1, 3) - a * g;
      J.displacement = std::sqrt((n2 - d(2 * i, 2)).squaredNorm() + (n3 - d(2 * i, 3)).squaredNorm());
      dstar.row(2 * i * nv + 2) = n2.transpose();
      dstar.row(2 * i * nv + 3) = n3.transpose();
      raise[static_cast<size_t>(i)] = true;
    }
    out.junctions.push_back(J);
  }

  // The strip in Bezier form across the wrinkled junctions: raise u_{2i+2} from multiplicity 2 to 3. The new control
  // point between d_{2i} and d_{2i+1} is the Bezier junction c_{i,.,3,.} = c_{i+1,.,0,.}: for rows 0 and 1 S~'s
  // junction (step 5°), for the other rows S's own alpha_i d_{2i} + beta_i d_{2i+1} (what exact knot insertion gives).
  std::vector<double> knots = s.knotsU().values();
  std::vector<double> newKnots;
  std::vector<int> newIndex(static_cast<size_t>(s.numU()));
  std::vector<int> junctionIndex(static_cast<size_t>(m) + 1, -1);
  {
    int idx = 0;
    for (int q = 0; q < s.numU(); ++q) {
      newIndex[static_cast<size_t>(q)] = idx++;
      if (q % 2 == 0 && q / 2 >= 1 && q / 2 <= m - 1 && raise[static_cast<size_t>(q / 2)])
        junctionIndex[static_cast<size_t>(q / 2)] = idx++;
    }
  }
  for (int i = 1; i <= m - 1; ++i)
    if (raise[static_cast<size_t>(i)]) {
      const double u = knots[static_cast<size_t>(2 * i + 2)];
      newKnots.push_back(u);
      out.raisedKnots.push_back(u);
    }
  for (double u : newKnots) knots.insert(std::upper_bound(knots.begin(), knots.end(), u), u);
  const int nuNew = s.numU() + static_cast<int>(newKnots.size());
  Matrix pts(static_cast<Eigen::Index>(nuNew) * nv, s.dim());
  for (int q = 0; q < s.numU(); ++q)
    for (int j = 0; j < nv; ++j) pts.row(newIndex[static_cast<size_t>(q)] * nv + j) = dstar.row(q * nv + j);
  for (int i = 1; i <= m - 1; ++i) {
    const int ji = junctionIndex[static_cast<size_t>(i)];
    if (ji < 0) continue;
    const double a = A(i), at = At(i), r = ps.r;
    const VecX J0 = at * dt(2 * i, 0) + (1.0 - at) * dt(2 * i + 1, 0);
    const VecX J1 = at * dt(2 * i, 1) + (1.0 - at) * dt(2 * i + 1, 1);
    pts.row(ji * nv + 0) = J0.transpose();
    pts.row(ji * nv + 1) = ((1.0 + r) * J0 - r * J1).transpose();
    for (int j = 2; j < nv; ++j) pts.row(ji * nv + j) = (a * ds(2 * i, j) + (1.0 - a) * ds(2 * i + 1, j)).transpose();
  }
  out.surface = BSplineSurface(3, 3, KnotVector(std::move(knots)), s.knotsV(), nuNew, nv, std::move(pts));
  return out;
}

Result<ThreePatchCornerDiagnostic> threePatchCornerDiagnostic(double h1, double h2, double k1, double k3, double k2,
                                                             double h3) {
  for (double x : {h1, h2, k1, k3, k2, h3})
    if (!(std::isfinite(x) && x > 0.0)) return invalidInput("parametric interval lengths must be positive");
  ThreePatchCornerDiagnostic dg;
  dg.alpha = h1 / h2;
  dg.beta = k1 / k3;
  dg.gamma = k2 / h3;
  // Unknowns a, b, c, d, e, f, g (columns 0..6); the six equations of §4.2 as printed, each written as row . x = 0.
  enum { a, b, c, d, e, f, g };
  Eigen::Matrix<double, 6, 7> M = Eigen::Matrix<double, 6, 7>::Zero();
  auto eq = [&](int row, int lhsPlus, int lhsMinus, double k, int rhsPlus, int rhsMinus) {
    // (x_lhsPlus - x_lhsMinus) - k (x_rhsPlus - x_rhsMinus) = 0
    M(row, lhsPlus) += 1.0;
    M(row, lhsMinus) -= 1.0;
    M(row, rhsPlus) -= k;
    M(row, rhsMinus) += k;
  };
  eq(0, b, a, dg.alpha, f, b);  // b - a = alpha (f - b)
  eq(1, g, c, dg.alpha, e, g);  // g - c = alpha (e - g)
  eq(2, c, a, dg.beta, d, c);   // c - a = beta (d - c)
  eq(3, g, b, dg.beta, e, g);   // g - b = beta (e - g)
  eq(4, g, b, dg.gamma, c, g);  // g - b = gamma (c - g)
  eq(5, e, f, dg.gamma, d, e);  // e - f = gamma (d - e)
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(Eigen::MatrixXd(M), Eigen::ComputeFullV);
  const Eigen::VectorXd sv = svd.singularValues();
  int rank = 0;
  for (Eigen::Index k = 0; k < sv.size(); ++k)
    if (sv[k] > kIdentityRelTol * sv[0]) ++rank;
  dg.nullity = 7 - rank;
  // The constant vector always solves the system (every equation is a difference of differences).
  dg.coefficientsCoincide = dg.nullity == 1;
  dg.explanation =
      dg.coefficientsCoincide
          ? fmt::format("with alpha = {:.6g}, beta = {:.6g}, gamma = {:.6g} the six C1 conditions have rank 6: the only "
                        "solution is a = b = ... = g, so a C1 join collapses the corner (all seven Bezier "
                        "coefficients coincide); join G1 instead",
                        dg.alpha, dg.beta, dg.gamma)
          : fmt::format("with alpha = {:.6g}, beta = {:.6g}, gamma = {:.6g} the six C1 conditions have rank {}: "
                        "non-degenerate C1 corners exist for these interval lengths",
                        dg.alpha, dg.beta, dg.gamma, rank);
  return dg;
}

}  // namespace seam
