// The general engine of the Johansson Section 4 constructions: one new Bezier patch N, G1 to known neighbours
// with polynomial connecting functions, as one linear system solved with the constraints exact and the
// freedom spent on a fairness energy. Derivation: docs/algorithms/johansson-constructions.md.
#include "seam/construct/g1_patch.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "construct/construct_internal.h"
#include "seam/core/tolerances.h"

namespace seam {

namespace ci = construct_internal;

namespace {

/// Singular values of the (row-scaled, dimensionless) constraint matrix below this fraction of the largest
/// one are treated as zero: the rows are then dependent (e.g. the corner point that two seams both fix, or a
/// compatibility relation that the data satisfy). The entries are O(1) after scaling, so true dependencies
/// sit at ~1e-15 and any genuine independence of CAD-sized data is far above 1e-10 (kIdentityRelTol, the same
/// margin as for identities).
constexpr double kConstraintRankRelTol = kIdentityRelTol;

/// The constraints are "exact" when every scaled residual (an angle in radians for G1 rows, a distance over
/// the neighbours' size for G0 rows) is below this: the polynomial identities then hold to round-off, which
/// is what analyzeSeam certifies as g1Identity.
constexpr double kExactResidual = kIdentityRelTol;

/// Eigenvalues of the reduced energy below this fraction of the largest are treated as zero (pseudo-inverse),
/// so a direction the energy does not see keeps the minimum-norm value instead of blowing up.
constexpr double kEnergyRankRelTol = 1e-12;

/// Samples used only to report how negative a lambda without a certified positive Bernstein bound gets.
constexpr int kLambdaSamples = 65;

// Gram matrix of the Bernstein basis of degree d on [0,1]: integral of B_a^d B_b^d.
Eigen::MatrixXd bernsteinGram(int d) {
  Eigen::MatrixXd g(d + 1, d + 1);
  for (int a = 0; a <= d; ++a)
    for (int b = 0; b <= d; ++b)
      g(a, b) = binomial(d, a) * binomial(d, b) / ((2 * d + 1) * binomial(2 * d, a + b));
  return g;
}

// The quadratic form of integral (p^(k))^2 on the coefficients of a degree-n polynomial (zero when k > n).
Eigen::MatrixXd derivativeEnergy(int n, int k) {
  if (k > n) return Eigen::MatrixXd::Zero(n + 1, n + 1);
  Eigen::MatrixXd dk(n - k + 1, n + 1);
  for (int a = 0; a <= n; ++a) dk.col(a) = ci::unitPoly(n, a).derivative(k).coeffs().col(0);
  return dk.transpose() * bernsteinGram(n - k) * dk;
}

// Elevation matrix from degree d to degree D (columns: the elevated unit polynomials).
Eigen::MatrixXd elevationMatrix(int d, int D) {
  Eigen::MatrixXd e(D + 1, d + 1);
  for (int a = 0; a <= d; ++a) e.col(a) = ci::unitPoly(d, a).elevatedTo(D).coeffs().col(0);
  return e;
}

// Thin-plate quadratic form on the control points (one coordinate) of a (nu, nv) patch, rows i*(nv+1)+j.
Eigen::MatrixXd thinPlateForm(int nu, int nv) {
  const Eigen::MatrixXd u0 = derivativeEnergy(nu, 0), u1 = derivativeEnergy(nu, 1),
                        u2 = derivativeEnergy(nu, 2);
  const Eigen::MatrixXd v0 = derivativeEnergy(nv, 0), v1 = derivativeEnergy(nv, 1),
                        v2 = derivativeEnergy(nv, 2);
  const int n = (nu + 1) * (nv + 1);
  Eigen::MatrixXd h(n, n);
  for (int i = 0; i <= nu; ++i)
    for (int j = 0; j <= nv; ++j)
      for (int k = 0; k <= nu; ++k)
        for (int l = 0; l <= nv; ++l)
          h(i * (nv + 1) + j, k * (nv + 1) + l) =
              u2(i, k) * v0(j, l) + 2.0 * u1(i, k) * v1(j, l) + u0(i, k) * v2(j, l);
  return h;
}

/// Least-squares solution of A x = b of minimum norm, with the rank and an orthonormal basis of the null space of A
/// (singular values below kConstraintRankRelTol x the largest count as zero).
struct LeastSquares {
  Eigen::VectorXd x;
  Eigen::MatrixXd nullspace;
  int rank = 0;
};
LeastSquares leastSquares(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
  LeastSquares out;
  const Eigen::Index n = A.cols();
  out.x = Eigen::VectorXd::Zero(n);
  if (A.rows() == 0 || n == 0) {
    out.nullspace = Eigen::MatrixXd::Identity(n, n);
    return out;
  }
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::VectorXd& sv = svd.singularValues();
  const double smax = sv(0);
  while (out.rank < sv.size() && sv(out.rank) > kConstraintRankRelTol * smax) ++out.rank;
  for (int i = 0; i < out.rank; ++i) out.x += svd.matrixV().col(i) * (svd.matrixU().col(i).dot(b) / sv(i));
  out.nullspace = svd.matrixV().rightCols(n - out.rank);
  return out;
}

/// Everything one seam contributes at one bi-degree.
struct SeamSetup {
  ci::EdgeJet jet;  // normalised coordinates
  int p = 0;        // A's degree along the edge
  int dAlong = 0;   // N's degree along / across the edge
  int dCross = 0;
  int dl = 0;         // lambda degree
  int dk = -1;        // kappa degree (-1: kappa == 0)
  int D = 0;          // degree of the G1 identity
  int lamOffset = 0;  // first unknown of lambda / kappa
  int kapOffset = 0;
  double outScale = 1.0;    // max |A_out| coefficient (normalised): G1 rows are divided by it
  double alongScale = 1.0;  // max |A_t| coefficient
};

struct Attempt {
  G1Attempt info;
  Eigen::VectorXd x;
  std::vector<SeamSetup> setup;
  int nq = 0;  // number of control points
  std::vector<std::string> notes;
};

Status validate(std::span<const G1SeamSpec> seams, const G1PatchOptions& options) {
  if (seams.empty()) return invalidInput("buildG1Patch: no seam given");
  if (options.degreeU < 1 || options.degreeV < 1) {
    return invalidInput(fmt::format("buildG1Patch: bi-degree ({}, {}) must be at least (1, 1)",
                                    options.degreeU, options.degreeV));
  }
  std::array<bool, 4> used{};
  for (size_t s = 0; s < seams.size(); ++s) {
    const G1SeamSpec& spec = seams[s];
    if (spec.neighbour.isRational())
      return invalidInput(fmt::format("seam {}: the neighbour is rational", s));
    if (spec.neighbour.dim() != 3) {
      return invalidInput(
          fmt::format("seam {}: the neighbour is {}-dimensional (3 expected)", s, spec.neighbour.dim()));
    }
    if (spec.neighbour.degreeU() < 1 || spec.neighbour.degreeV() < 1) {
      return invalidInput(fmt::format("seam {}: the neighbour has a degree below 1", s));
    }
    const int e = static_cast<int>(spec.newEdge);
    if (used[static_cast<size_t>(e)]) {
      return invalidInput(
          fmt::format("seam {}: two seams on edge {} of the new patch", s, edgeName(spec.newEdge)));
    }
    used[static_cast<size_t>(e)] = true;
    if ((spec.lambdaDegree && *spec.lambdaDegree < 0) || (spec.kappaDegree && *spec.kappaDegree < 0)) {
      return invalidInput(fmt::format("seam {}: negative lambda/kappa degree", s));
    }
  }
  return Status::ok();
}

// Assembles and solves the system at bi-degree (nu, nv). `jets` are in normalised coordinates.
Result<Attempt> solveAt(std::span<const G1SeamSpec> seams, const std::vector<ci::EdgeJet>& jets, int nu,
                        int nv, const G1PatchOptions& options) {
  Attempt at;
  at.info.degreeU = nu;
  at.info.degreeV = nv;
  at.nq = (nu + 1) * (nv + 1);
  int unknowns = 3 * at.nq;
  for (size_t s = 0; s < seams.size(); ++s) {
    const G1SeamSpec& spec = seams[s];
    SeamSetup su;
    su.jet = jets[s];
    su.p = su.jet.curve.degree();
    su.dAlong = ci::alongDegree(spec.newEdge, nu, nv);
    su.dCross = ci::crossDegree(spec.newEdge, nu, nv);
    if (su.dAlong < su.p) {
      return Status(
          ErrorCode::kNoSolution,
          fmt::format("degree ({}, {}): the new patch's degree {} along edge {} is below the neighbour's {}",
                      nu, nv, su.dAlong, edgeName(spec.newEdge), su.p));
    }
    su.dl = spec.lambdaDegree.value_or(su.dAlong - su.p);
    const bool kappaZero = options.kappaZero || spec.kappaZero;
    su.dk = kappaZero ? -1 : spec.kappaDegree.value_or(su.dAlong - su.p + 1);
    su.D = std::max({su.dAlong, su.dl + su.p, su.dk >= 0 ? su.dk + su.p - 1 : 0});
    su.lamOffset = unknowns;
    unknowns += su.dl + 1;
    su.kapOffset = unknowns;
    if (su.dk >= 0) unknowns += su.dk + 1;
    su.outScale = std::max(su.jet.out.maxCoeffNorm(), std::numeric_limits<double>::min());
    su.alongScale = std::max(su.jet.along.maxCoeffNorm(), std::numeric_limits<double>::min());
    for (const auto& [index, value] : spec.fixedLambda) {
      (void)value;
      if (index < 0 || index > su.dl) {
        return invalidInput(
            fmt::format("seam {}: fixed lambda coefficient {} out of range (degree {})", s, index, su.dl));
      }
    }
    for (const auto& [index, value] : spec.fixedKappa) {
      (void)value;
      if (index < 0 || index > su.dk) {
        return invalidInput(
            fmt::format("seam {}: fixed kappa coefficient {} out of range (degree {})", s, index, su.dk));
      }
    }
    at.setup.push_back(std::move(su));
  }

  // Corners of N between two seams (for the twist rule).
  std::array<const G1SeamSpec*, 4> onEdge{};
  for (const G1SeamSpec& spec : seams) onEdge[static_cast<size_t>(spec.newEdge)] = &spec;
  std::vector<int> twistCorners;
  if (options.interior == InteriorRule::kTwistRule) {
    if (nu >= 5 && nv >= 5) {
      for (int c = 0; c < 4; ++c) {
        const Edge eu = (c & 1) ? Edge::U1 : Edge::U0;
        const Edge ev = (c & 2) ? Edge::V1 : Edge::V0;
        if (onEdge[static_cast<size_t>(eu)] && onEdge[static_cast<size_t>(ev)]) twistCorners.push_back(c);
      }
    } else {
      at.notes.push_back(
          fmt::format("twist rule (4.54) needs bi-degree >= (5, 5); ({}, {}) uses fairness only", nu, nv));
    }
  }

  int rows = 3 * static_cast<int>(twistCorners.size());
  for (size_t s = 0; s < seams.size(); ++s) {
    const SeamSetup& su = at.setup[s];
    rows += 3 * (su.dAlong + 1) + 3 * (su.D + 1);
    rows += static_cast<int>(seams[s].fixedLambda.size() + seams[s].fixedKappa.size());
  }
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(rows, unknowns);
  Eigen::VectorXd d = Eigen::VectorXd::Zero(rows);
  std::vector<bool> isG0(static_cast<size_t>(rows), false);
  auto q = [&](int point, int coord) { return 3 * point + coord; };

  int r = 0;
  for (size_t s = 0; s < seams.size(); ++s) {
    const G1SeamSpec& spec = seams[s];
    const SeamSetup& su = at.setup[s];
    auto newPoint = [&](int k, int lt) {  // N's point k rows from the edge at A's t-index lt
      const int l = spec.reversed ? su.dAlong - lt : lt;
      return ci::netIndex(spec.newEdge, k, l, nu, nv);
    };
    // G0 (4.27): N's boundary row is A's edge curve elevated to N's degree along the edge.
    const Matrix edge = su.jet.curve.elevatedTo(su.dAlong).coeffs();
    for (int lt = 0; lt <= su.dAlong; ++lt) {
      for (int c = 0; c < 3; ++c, ++r) {
        C(r, q(newPoint(0, lt), c)) = 1.0;
        d(r) = edge(lt, c);
        isG0[static_cast<size_t>(r)] = true;
      }
    }
    // G1 (4.24)/(4.26): the Bernstein coefficients of N_cross - lambda A_out - kappa A_t vanish at degree D.
    const Eigen::MatrixXd elev = elevationMatrix(su.dAlong, su.D);
    std::vector<Matrix> lamCols, kapCols;
    for (int a = 0; a <= su.dl; ++a)
      lamCols.push_back(product(ci::unitPoly(su.dl, a), su.jet.out).elevatedTo(su.D).coeffs());
    for (int b = 0; b <= su.dk; ++b) {
      kapCols.push_back(product(ci::unitPoly(su.dk, b), su.jet.along).elevatedTo(su.D).coeffs());
    }
    const double w = 1.0 / su.outScale;
    for (int k = 0; k <= su.D; ++k) {
      for (int c = 0; c < 3; ++c, ++r) {
        for (int lt = 0; lt <= su.dAlong; ++lt) {
          const double e = elev(k, lt) * su.dCross * w;
          if (e == 0.0) continue;
          C(r, q(newPoint(1, lt), c)) += e;
          C(r, q(newPoint(0, lt), c)) -= e;
        }
        for (int a = 0; a <= su.dl; ++a) C(r, su.lamOffset + a) = -lamCols[static_cast<size_t>(a)](k, c) * w;
        for (int b = 0; b <= su.dk; ++b) C(r, su.kapOffset + b) = -kapCols[static_cast<size_t>(b)](k, c) * w;
      }
    }
    for (const auto& [index, value] : spec.fixedLambda) {
      C(r, su.lamOffset + index) = 1.0;
      d(r++) = value;
    }
    for (const auto& [index, value] : spec.fixedKappa) {
      C(r, su.kapOffset + index) = su.alongScale / su.outScale;  // kappa A_t against lambda A_out: same units
      d(r++) = value * su.alongScale / su.outScale;
    }
  }
  // Twist rule (4.54) at corner (i0, j0): q[i0+2di][j0+2dj] - q[i0+2di][j0+dj] - q[i0+di][j0+2dj] +
  // q[i0+di][j0+dj] = 0.
  for (int corner : twistCorners) {
    const int i0 = (corner & 1) ? nu : 0, di = (corner & 1) ? -1 : 1;
    const int j0 = (corner & 2) ? nv : 0, dj = (corner & 2) ? -1 : 1;
    auto idx = [&](int a, int b) { return (i0 + a * di) * (nv + 1) + (j0 + b * dj); };
    for (int c = 0; c < 3; ++c, ++r) {
      C(r, q(idx(2, 2), c)) += 1.0;
      C(r, q(idx(2, 1), c)) -= 1.0;
      C(r, q(idx(1, 2), c)) -= 1.0;
      C(r, q(idx(1, 1), c)) += 1.0;
    }
  }
  assert(r == rows);

  // Energy: thin plate on the points, (lambda')^2 + kappa^2 regularisation on the connecting functions.
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(unknowns, unknowns);
  const Eigen::MatrixXd tp = thinPlateForm(nu, nv);
  for (int a = 0; a < at.nq; ++a)
    for (int b = 0; b < at.nq; ++b)
      for (int c = 0; c < 3; ++c) H(q(a, c), q(b, c)) = tp(a, b);
  for (const SeamSetup& su : at.setup) {
    H.block(su.lamOffset, su.lamOffset, su.dl + 1, su.dl + 1) +=
        options.parameterWeight * su.outScale * su.outScale * derivativeEnergy(su.dl, 1);
    if (su.dk >= 0) {
      H.block(su.kapOffset, su.kapOffset, su.dk + 1, su.dk + 1) +=
          options.parameterWeight * su.alongScale * su.alongScale * derivativeEnergy(su.dk, 0);
    }
  }

  // Constraints in the least-squares sense, lexicographically: first the G0 rows (the boundaries on the
  // neighbours' edges), then the G1 and other rows on the solution space of the G0 rows. Consistent constraints
  // are solved exactly; for input that is G1 only within a tolerance the compromise goes into the tangent planes
  // and no gap opens. Then the energy on the remaining solution space.
  std::vector<int> rows0, rows1;
  for (int i = 0; i < rows; ++i) (isG0[static_cast<size_t>(i)] ? rows0 : rows1).push_back(i);
  const Eigen::MatrixXd C0 = C(rows0, Eigen::all), C1 = C(rows1, Eigen::all);
  const Eigen::VectorXd d0 = d(rows0), d1 = d(rows1);
  const LeastSquares s0 = leastSquares(C0, d0);
  const LeastSquares s1 = leastSquares(C1 * s0.nullspace, d1 - C1 * s0.x);
  const Eigen::VectorXd x0 = s0.x + s0.nullspace * s1.x;
  const Eigen::MatrixXd Z = s0.nullspace * s1.nullspace;
  const int rank = s0.rank + s1.rank;
  Eigen::VectorXd x = x0;
  if (Z.cols() > 0) {
    const Eigen::MatrixXd hz = Z.transpose() * H * Z;
    const Eigen::VectorXd gz = Z.transpose() * (H * x0);
    Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(hz);
    const Eigen::VectorXd& mu = eig.eigenvalues();
    const double mumax = mu.size() > 0 ? mu.cwiseAbs().maxCoeff() : 0.0;
    Eigen::VectorXd y = Eigen::VectorXd::Zero(Z.cols());
    for (Eigen::Index i = 0; i < mu.size(); ++i) {
      if (mu(i) > kEnergyRankRelTol * mumax)
        y -= eig.eigenvectors().col(i) * (eig.eigenvectors().col(i).dot(gz) / mu(i));
    }
    x = x0 + Z * y;
  }
  at.info.unknowns = unknowns;
  at.info.constraints = rows;
  at.info.rank = rank;
  at.info.residual = rows > 0 ? (C * x - d).cwiseAbs().maxCoeff() : 0.0;
  at.info.exact = at.info.residual <= kExactResidual;
  at.x = std::move(x);
  return at;
}

// The general-form compatibility (4.30)/(4.36) at the corners of N between two seams, in world coordinates.
std::vector<CornerCompatibility> cornerCompatibility(std::span<const G1SeamSpec> seams,
                                                     const std::vector<ConnectingFunctions>& functions) {
  std::vector<CornerCompatibility> out;
  std::array<int, 4> seamOn{-1, -1, -1, -1};
  for (size_t s = 0; s < seams.size(); ++s)
    seamOn[static_cast<size_t>(seams[s].newEdge)] = static_cast<int>(s);
  for (int corner = 0; corner < 4; ++corner) {
    const double uc = (corner & 1) ? 1.0 : 0.0, vc = (corner & 2) ? 1.0 : 0.0;
    const Edge eu = (corner & 1) ? Edge::U1 : Edge::U0;  // runs along v, fixes N_u
    const Edge ev = (corner & 2) ? Edge::V1 : Edge::V0;  // runs along u, fixes N_v
    const int su = seamOn[static_cast<size_t>(eu)], sv = seamOn[static_cast<size_t>(ev)];
    if (su < 0 || sv < 0) continue;
    struct Side {
      Vec3 cross, along, twist;
    };
    auto side = [&](int s, double alongParam) {
      const G1SeamSpec& spec = seams[static_cast<size_t>(s)];
      const ci::EdgeJet jet = ci::edgeJet(spec.neighbour.numerator(), spec.neighbourEdge);
      const ConnectingFunctions& f = functions[static_cast<size_t>(s)];
      const BernsteinPoly F = product(f.lambda, jet.out) + product(f.kappa, jet.along);
      const double t = spec.reversed ? 1.0 - alongParam : alongParam;
      const double rho = spec.reversed ? -1.0 : 1.0;
      const double sigma = ci::intoSign(spec.newEdge);
      Side sd;
      sd.cross = sigma * Vec3(F(t).head<3>());        // the N derivative across this edge
      sd.along = rho * Vec3(jet.along(t).head<3>());  // the N derivative along this edge
      sd.twist = sigma * rho * Vec3(F.derivative()(t).head<3>());
      return sd;
    };
    const Side a = side(su, vc);  // N_u = a.cross, N_v = a.along
    const Side b = side(sv, uc);  // N_v = b.cross, N_u = b.along
    const double scale = std::max(a.along.norm() + b.along.norm(), std::numeric_limits<double>::min());
    CornerCompatibility cc;
    cc.corner = corner;
    cc.seamU = su;
    cc.seamV = sv;
    cc.tangentResidual = std::max((a.cross - b.along).norm(), (a.along - b.cross).norm()) / scale;
    const Vec3 diff = a.twist - b.twist;
    cc.twistResidual = diff.norm() / scale;
    const Vec3 n = b.along.cross(a.along);
    cc.twistNormalResidual = n.norm() > 0.0 ? std::abs(diff.dot(n.normalized())) / scale : 0.0;
    out.push_back(cc);
  }
  return out;
}

}  // namespace

Result<G1EdgeRows> g1NeighbourRows(const BezierPatch& r, Edge edge, const BernsteinPoly& lambda,
                                   const BernsteinPoly& kappa, int crossDegree,
                                   std::optional<int> alongDegree) {
  if (r.isRational())
    return invalidInput("g1NeighbourRows: the patch is rational (polynomial Bezier expected)");
  if (lambda.empty() || lambda.dim() != 1)
    return invalidInput("g1NeighbourRows: lambda must be a scalar polynomial");
  if (!kappa.empty() && kappa.dim() != 1)
    return invalidInput("g1NeighbourRows: kappa must be a scalar polynomial");
  if (crossDegree < 1) return invalidInput(fmt::format("g1NeighbourRows: cross degree {} < 1", crossDegree));
  const ci::EdgeJet jet = ci::edgeJet(r.numerator(), edge);
  const int p = jet.curve.degree();
  int minDegree = std::max(p, lambda.degree() + p);
  if (!kappa.empty()) minDegree = std::max(minDegree, kappa.degree() + p - 1);
  const int D = alongDegree.value_or(minDegree);
  if (D < minDegree) {
    return invalidInput(
        fmt::format("g1NeighbourRows: along degree {} below the minimum {} (edge degree {}, lambda "
                    "degree {}, kappa degree {})",
                    D, minDegree, p, lambda.degree(), kappa.empty() ? -1 : kappa.degree()));
  }
  BernsteinPoly cross = product(lambda, jet.out);
  if (!kappa.empty()) cross = cross + product(kappa, jet.along);
  G1EdgeRows rows;
  rows.degreeAlong = D;
  rows.boundary = jet.curve.elevatedTo(D).coeffs();
  rows.inner = rows.boundary + cross.elevatedTo(D).coeffs() / static_cast<double>(crossDegree);
  return rows;
}

double thinPlateEnergy(const BezierPatch& patch) {
  const Eigen::MatrixXd h = thinPlateForm(patch.degreeU(), patch.degreeV());
  const BernsteinPatch numerator = patch.numerator();
  const Matrix& p = numerator.coeffs();
  double e = 0.0;
  for (Eigen::Index c = 0; c < p.cols(); ++c) e += p.col(c).dot(h * p.col(c));
  return e;
}

Result<G1PatchResult> buildG1Patch(std::span<const G1SeamSpec> seams, const G1PatchOptions& options) {
  if (Status s = validate(seams, options); !s) return s;

  // Normalise: centre and size of the neighbours' control points (lambda and kappa are invariant).
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const G1SeamSpec& spec : seams) {
    for (Eigen::Index i = 0; i < spec.neighbour.points().rows(); ++i) {
      const Vec3 p = spec.neighbour.points().row(i).transpose();
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  const Vec3 centre = 0.5 * (lo + hi);
  const double size = (hi - lo).norm() > 0.0 ? (hi - lo).norm() : 1.0;
  std::vector<ci::EdgeJet> jets, worldJets;
  for (const G1SeamSpec& spec : seams) {
    const BernsteinPatch world = spec.neighbour.numerator();
    Matrix c = world.coeffs();
    for (Eigen::Index i = 0; i < c.rows(); ++i) c.row(i) = (c.row(i) - centre.transpose()) / size;
    jets.push_back(
        ci::edgeJet(BernsteinPatch(world.degreeU(), world.degreeV(), std::move(c)), spec.neighbourEdge));
    worldJets.push_back(ci::edgeJet(world, spec.neighbourEdge));
  }

  int maxP = 0;
  for (const ci::EdgeJet& j : jets) maxP = std::max(maxP, j.curve.degree());
  const int maxDegree = std::max({options.maxDegree, options.degreeU, options.degreeV});
  if (maxDegree < maxP) {
    return Status(
        ErrorCode::kUnsupported,
        fmt::format("buildG1Patch: the neighbours have degree {} along their edges, above the maximum "
                    "bi-degree {} of the new patch",
                    maxP, maxDegree));
  }

  G1PatchResult result;
  std::optional<Attempt> best;
  for (int nu = options.degreeU, nv = options.degreeV; nu <= maxDegree && nv <= maxDegree; ++nu, ++nv) {
    Result<Attempt> at = solveAt(seams, jets, nu, nv, options);
    if (!at) {
      if (at.status().code() != ErrorCode::kNoSolution) return at.status();
      result.notes.push_back(at.status().message());
      continue;
    }
    result.attempts.push_back(at->info);
    const bool better = !best || at->info.residual < 0.5 * best->info.residual;
    if (!at->info.exact) {
      result.notes.push_back(
          fmt::format("bi-degree ({}, {}): the G1 constraints are inconsistent (scaled residual "
                      "{:.3g})",
                      nu, nv, at->info.residual));
    }
    if (better) best = std::move(*at);
    if (best->info.exact) break;
  }
  if (!best) {
    return Status(ErrorCode::kNoSolution,
                  "buildG1Patch: no bi-degree up to the maximum can hold the neighbours' edges");
  }
  Attempt& at = *best;
  const int nu = at.info.degreeU, nv = at.info.degreeV;
  if (nu != options.degreeU || nv != options.degreeV) {
    result.notes.push_back(
        fmt::format("bi-degree raised from ({}, {}) to ({}, {})", options.degreeU, options.degreeV, nu, nv));
  }
  if (!at.info.exact) {
    result.notes.push_back(
        fmt::format("no bi-degree up to ({0}, {0}) satisfies the constraints exactly; the best "
                    "(least-squares) attempt is returned",
                    maxDegree));
  }
  result.notes.insert(result.notes.end(), at.notes.begin(), at.notes.end());

  // Control points back in world coordinates; exact boundary rows straight from the neighbours' edges.
  Matrix points(at.nq, 3);
  for (int i = 0; i < at.nq; ++i)
    for (int c = 0; c < 3; ++c) points(i, c) = centre(c) + size * at.x(3 * i + c);
  if (at.info.exact) {
    for (size_t s = 0; s < seams.size(); ++s) {
      const SeamSetup& su = at.setup[s];
      const Matrix edge = worldJets[s].curve.elevatedTo(su.dAlong).coeffs();
      for (int lt = 0; lt <= su.dAlong; ++lt) {
        const int l = seams[s].reversed ? su.dAlong - lt : lt;
        points.row(ci::netIndex(seams[s].newEdge, 0, l, nu, nv)) = edge.row(lt);
      }
    }
  }
  result.patch = BezierPatch(nu, nv, std::move(points));
  for (size_t s = 0; s < seams.size(); ++s) {
    const SeamSetup& su = at.setup[s];
    ConnectingFunctions f;
    f.lambda = BernsteinPoly(Matrix(at.x.segment(su.lamOffset, su.dl + 1)));
    f.kappa =
        su.dk >= 0 ? BernsteinPoly(Matrix(at.x.segment(su.kapOffset, su.dk + 1))) : BernsteinPoly::zero(0, 1);
    const double lmin = f.lambda.minCoeff()(0);
    if (lmin <= 0.0) {
      double sampled = std::numeric_limits<double>::infinity();
      for (int k = 0; k < kLambdaSamples; ++k)
        sampled = std::min(sampled, f.lambda.scalar(k / (kLambdaSamples - 1.0)));
      result.notes.push_back(
          fmt::format("seam {}: lambda is not certified positive (smallest Bernstein coefficient "
                      "{:.3g}, sampled minimum {:.3g}){}",
                      s, lmin, sampled, sampled <= 0.0 ? ": the new patch folds over the neighbour" : ""));
    }
    result.functions.push_back(std::move(f));
  }
  result.corners = cornerCompatibility(seams, result.functions);
  result.freeParameters = at.info.unknowns - at.info.rank;
  result.energy = thinPlateEnergy(result.patch);
  result.exact = at.info.exact;
  return result;
}

}  // namespace seam
