// Tests of the rational GC^n module (Zheng-Wang-Liang): include/seam/rational/*.h.
//
// Independence: expected values come from exact constructions made here (rbar = rho * Q(phi) + ubar^{n+1} Z
// is GC^n and generically not GC^{n+1} by construction), the paper's published example values (Section 3.1,
// Section 4.2's bicubic formulas), direct one-variable automatic differentiation of composed maps, and
// determinants from Eigen. The kernel's Bernstein algebra (tested in bernstein_test) is used to build inputs.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <boost/math/differentiation/autodiff.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "rational/rational_internal.h"
#include "seam/core/bernstein.h"
#include "seam/io/json.h"
#include "seam/rational/autodiff_surface.h"
#include "seam/rational/connecting.h"
#include "seam/rational/construction.h"
#include "seam/rational/exact_gcn.h"
#include "seam/rational/expression.h"
#include "seam/rational/gcn.h"
#include "seam/spline/bezier.h"

namespace seam::rational {
namespace {

namespace fs = std::filesystem;
namespace ad = boost::math::differentiation;
using Rng = std::mt19937_64;

/// Values computed by two routes from exact data agree to round-off of a few hundred operations.
constexpr double kTwoRoutesRelTol = 1e-9;

double urand(Rng& rng, double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }

// ---------------------------------------------------------------------------------------------------------------
// Constructions.

/// Random homogeneous Bezier patch (w P, w) of degree m x l, a gently curved regular sheet over [0,1]^2 in x,
/// y; weights in [0.8, 1.2] (all 1 when integral: then 3-D points).
BernsteinPatch randomPatch(Rng& rng, int m, int l, bool integral) {
  Matrix c((m + 1) * (l + 1), integral ? 3 : 4);
  for (int i = 0; i <= m; ++i)
    for (int j = 0; j <= l; ++j) {
      // (drawn last argument first: test_helpers.h, "Random draws and argument order")
      const double z = urand(rng, -0.2, 0.2), y = urand(rng, -0.05, 0.05), x = urand(rng, -0.05, 0.05);
      const Vec3 p(double(i) / m + x, double(j) / l + y, z);
      const double w = integral ? 1.0 : urand(rng, 0.8, 1.2);
      if (integral)
        c.row(i * (l + 1) + j) = p.transpose();
      else
        c.row(i * (l + 1) + j) << w * p.transpose(), w;
    }
  return BernsteinPatch(m, l, std::move(c));
}

/// Sum of two patches of any degrees (elevated to the larger ones).
BernsteinPatch add(const BernsteinPatch& a, const BernsteinPatch& b) {
  const int du = std::max(a.degreeU(), b.degreeU()), dv = std::max(a.degreeV(), b.degreeV());
  const BernsteinPatch ea = a.elevatedTo(du, dv), eb = b.elevatedTo(du, dv);
  return BernsteinPatch(du, dv, Matrix(ea.coeffs() + eb.coeffs()));
}

/// Q(phiU, phiV) for scalar patches phiU, phiV (tensor-product Bernstein sum with kernel products).
BernsteinPatch compose(const BernsteinPatch& q, const BernsteinPatch& phiU, const BernsteinPatch& phiV) {
  auto bernstein = [](const BernsteinPatch& x, int n, int i) {
    BernsteinPatch oneMinus(x.degreeU(), x.degreeV(),
                            Matrix(Matrix::Ones(x.coeffs().rows(), 1) - x.coeffs()));
    BernsteinPatch r(
        0, 0,
        Matrix::Constant(1, 1, std::tgamma(n + 1.0) / (std::tgamma(i + 1.0) * std::tgamma(n - i + 1.0))));
    for (int k = 0; k < i; ++k) r = product(r, x);
    for (int k = 0; k < n - i; ++k) r = product(r, oneMinus);
    return r;
  };
  std::optional<BernsteinPatch> sum;
  for (int i = 0; i <= q.degreeU(); ++i) {
    const BernsteinPatch bu = bernstein(phiU, q.degreeU(), i);
    for (int j = 0; j <= q.degreeV(); ++j) {
      const BernsteinPatch b = product(bu, bernstein(phiV, q.degreeV(), j));
      const BernsteinPatch term = product(b, BernsteinPatch(0, 0, Matrix(q.coeff(i, j))));
      sum = sum ? add(*sum, term) : term;
    }
  }
  return *sum;
}

/// A pair (q, qbar) in the paper's frame (q's edge u = 1, qbar's edge ubar = 0, v = vbar) that is GC^n and
/// generically not GC^{n+1}: qbar = rho * q(phi) + ubar^{n+1} Z with phi(0, vbar) = (1, vbar) mapping ubar >
/// 0 beyond q's edge (the analytic continuation of r), rho > 0 a random polynomial, Z random.
struct Pair {
  BernsteinPatch q, qbar;
};
enum class PairKind { kGeneral, kEqualEdgeWeights, kIntegral };
Pair gcnPair(Rng& rng, int n, PairKind kind) {
  const bool integral = kind == PairKind::kIntegral;
  Pair p;
  p.q = randomPatch(rng, 2, 2, integral);
  // phiU = 1 + ubar (a0 (1 - vbar) + a1 vbar), phiV = vbar + ubar (b0 (1 - vbar) + b1 vbar): bilinear.
  const double a0 = urand(rng, 0.2, 0.4), a1 = urand(rng, 0.2, 0.4), b0 = urand(rng, -0.1, 0.1),
               b1 = urand(rng, -0.1, 0.1);
  Matrix pu(4, 1), pv(4, 1);
  pu << 1.0, 1.0, 1.0 + a0, 1.0 + a1;
  pv << 0.0, 1.0, b0, 1.0 + b1;
  const BernsteinPatch composed = compose(p.q, BernsteinPatch(1, 1, pu), BernsteinPatch(1, 1, pv));
  BernsteinPatch qbar = composed;
  if (!integral) {
    Matrix rho(4, 1);
    rho << urand(rng, 0.6, 1.6), urand(rng, 0.6, 1.6), urand(rng, 0.6, 1.6), urand(rng, 0.6, 1.6);
    if (kind == PairKind::kEqualEdgeWeights) rho(0) = rho(1) = 1.0;  // rho(0, vbar) = 1: Qbar = Q on the edge
    qbar = product(BernsteinPatch(1, 1, rho), composed);
  }
  // ubar^{n+1} Z, Z of degree 0 x 2 with a small weight component.
  Matrix un = Matrix::Zero(n + 2, 1);
  un(n + 1) = 1.0;
  Matrix z(3, qbar.dim());
  for (int j = 0; j < 3; ++j)
    for (int k = 0; k < qbar.dim(); ++k) z(j, k) = k == 3 ? urand(rng, -0.05, 0.05) : urand(rng, -0.5, 0.5);
  p.qbar = add(qbar, product(BernsteinPatch(n + 1, 0, un), BernsteinPatch(0, 2, z)));
  return p;
}

/// A model patch from a homogeneous (or integral) Bezier patch on [0,1]^2.
Patch toPatch(const std::string& name, const BernsteinPatch& h) {
  const BezierPatch bp =
      h.dim() == 4 ? BezierPatch::fromHomogeneous(h) : BezierPatch(h.degreeU(), h.degreeV(), h.coeffs());
  return Patch{name, PatchKind::kBezier, bp.toBSpline()};
}

/// The same patch with every weight multiplied by `f` (the rational surface is unchanged).
Patch scaledWeights(const Patch& p, double f) {
  const BSplineSurface& s = p.surface;
  VecX w = s.isRational() ? VecX(s.weights()) : VecX::Ones(s.numU() * s.numV());
  w *= f;
  return Patch{
      p.name, p.kind,
      BSplineSurface(s.degreeU(), s.degreeV(), s.knotsU(), s.knotsV(), s.numU(), s.numV(), s.points(), w)};
}

ShapeParameters randomShape(Rng& rng, int n) {
  ShapeParameters sp;
  for (int i = 0; i < n; ++i) {
    sp.gamma.push_back(urand(rng, -0.3, 0.3));
    sp.alpha.push_back(i == 0 ? urand(rng, 0.6, 1.4) : urand(rng, -0.3, 0.3));
    sp.beta0.push_back(urand(rng, -0.2, 0.2));
    sp.beta1.push_back(urand(rng, -0.2, 0.2));
  }
  return sp;
}

// ---------------------------------------------------------------------------------------------------------------
// Lemma 1 and the brackets.

TEST(GcnLemma1, TotalDifferentialMatchesDirectAutodiffOfTheComposition) {
  // Q(u, v) analytic; psi(t) = (u0 + sum p_i t^i / i!, v0 + sum q_i t^i / i!). The m-th t-derivative of
  // Q(psi(t)) by one-variable autodiff (independent) against Lemma 1's triple sum and against series
  // composition.
  auto Qf = [](auto u, auto v) {
    using std::exp;
    using std::sin;
    using T = decltype(u * v);
    return std::array<T, 4>{sin(u) * v + u * u, exp(0.3 * u - v), u * v * v, 1.0 + 0.2 * u * u + 0.1 * v};
  };
  const int n = 5;
  const double u0 = 0.3, v0 = 0.6;
  const std::vector<double> p{0.7, -0.4, 1.3, 0.2, -0.9}, q{-0.5, 0.8, 0.1, -1.1, 0.6};
  const auto t = ad::make_fvar<double, n>(0.0);
  using T1 = std::decay_t<decltype(t)>;
  T1 du = 0.0 * t, dv = 0.0 * t, tp = t;
  double fact = 1.0;
  for (int i = 1; i <= n; ++i) {
    fact *= i;
    du += (p[i - 1] / fact) * tp;
    dv += (q[i - 1] / fact) * tp;
    tp *= t;
  }
  const auto direct = Qf(u0 + du, v0 + dv);
  const HomogeneousSurface s = autodiffSurface<n>("Q", {0, 1}, {0, 1}, Qf);
  const auto d = s.derivatives(u0, v0, n);
  ASSERT_TRUE(d.isOk());
  detail::Series ps(n + 1, 0.0), qs(n + 1, 0.0);
  fact = 1.0;
  for (int i = 1; i <= n; ++i) {
    fact *= i;
    ps[i] = p[i - 1] / fact;
    qs[i] = q[i - 1] / fact;
  }
  const std::vector<Vec4> series = detail::composeSeries(*d, ps, qs, n);
  for (int m = 0; m <= n; ++m) {
    const Vec4 lemma = totalDifferential(*d, p, q, m);
    for (int k = 0; k < 4; ++k) {
      const double ref = static_cast<double>(direct[k].derivative(m));
      const double tol = kTwoRoutesRelTol * (1.0 + std::abs(ref));
      EXPECT_NEAR(lemma[k], ref, tol) << "m=" << m << " k=" << k;
      EXPECT_NEAR(series[m][k] * detail::factorial(m), ref, tol) << "m=" << m << " k=" << k;
    }
  }
}

TEST(GcnLemma2, BracketsAreTheCofactorsOfTheFirstColumn) {
  Rng rng(11);
  for (int trial = 0; trial < 5; ++trial) {
    Eigen::Matrix4d M = Eigen::Matrix4d::Random();
    const Vec4 x = M.col(0), r = M.col(1), s = M.col(2), t = M.col(3);
    double sum = 0.0;
    for (int i = 1; i <= 4; ++i) sum += x[i - 1] * detail::bracket4(i, r, s, t);
    EXPECT_NEAR(sum, M.determinant(), 1e-12);
    // Polynomial version agrees with the pointwise one.
    Matrix cr(3, 4), cs(3, 4), ct(3, 4);
    for (int k = 0; k < 3; ++k)
      for (int c = 0; c < 4; ++c) {
        cr(k, c) = urand(rng, -1, 1);
        cs(k, c) = urand(rng, -1, 1);
        ct(k, c) = urand(rng, -1, 1);
      }
    const BernsteinPoly R(cr), S(cs), Tp(ct);
    for (int i = 1; i <= 4; ++i) {
      const double tau = 0.37;
      EXPECT_NEAR(detail::bracket4(i, R, S, Tp).scalar(tau),
                  detail::bracket4(i, Vec4(R(tau)), Vec4(S(tau)), Vec4(Tp(tau))), 1e-12);
    }
  }
}

TEST(GcnHelpers, RootsAndDeflation) {
  // (t - 0.3)^2 (t - 0.8) (1 + t)
  BernsteinPoly p = product(product(BernsteinPoly::linear(-0.3, 0.7), BernsteinPoly::linear(-0.3, 0.7)),
                            product(BernsteinPoly::linear(-0.8, 0.2), BernsteinPoly::linear(1.0, 2.0)));
  const auto roots = detail::rootsInUnitInterval(p, 1e-12);
  ASSERT_EQ(roots.size(), 2u);
  EXPECT_NEAR(roots[0], 0.3, 1e-5);
  EXPECT_NEAR(roots[1], 0.8, 1e-7);
  auto [q, rem] = detail::divideExactly(p, product(BernsteinPoly::linear(-0.3, 0.7), BernsteinPoly::linear(-0.3, 0.7)));
  EXPECT_LT(rem, 1e-14);
  EXPECT_EQ(q.degree(), 2);
  EXPECT_NEAR(q.scalar(0.5), (0.5 - 0.8) * 1.5, 1e-14);
  auto [q2, rem2] = detail::divideExactly(p, BernsteinPoly::linear(-0.5, 0.5));  // not a factor
  EXPECT_GT(rem2, 1e-4);
  EXPECT_EQ(detail::effectiveDegree(p.elevated(5), 1e-12), 4);
  EXPECT_EQ(detail::certifyPositive(BernsteinPoly::linear(1.0, 2.0), 0.0), detail::SignCheck::kPositive);
  EXPECT_EQ(detail::certifyPositive(p, 0.0), detail::SignCheck::kNotPositive);
}

// ---------------------------------------------------------------------------------------------------------------
// The paper's example (Section 3.1).

// r = {u, v, 0} / (1 + v); rbar with a = ubar - vbar/2, b = ubar + vbar/2:
//   rbar = {a + 1 + a^3, b + a^3 (b - sin a), 5 b a^5} / (1 + b + (1 + 2 ubar) a^3).
auto paperR = [](auto u, auto v) {
  using T = decltype(u * v);
  return std::array<T, 4>{T(u), T(v), T(0.0 * u), 1.0 + v};
};
auto paperRbar = [](auto ub, auto vb) {
  using std::sin;
  using T = decltype(ub * vb);
  const T a = ub - 0.5 * vb, b = ub + 0.5 * vb;
  return std::array<T, 4>{a + 1.0 + a * a * a, b + a * a * a * (b - sin(a)), 5.0 * b * a * a * a * a * a,
                          1.0 + b + (1.0 + 2.0 * ub) * a * a * a};
};

std::vector<double> interiorSamples(int count) {
  std::vector<double> s;
  for (int i = 0; i < count; ++i) s.push_back((i + 0.5) / count);
  return s;
}

void expectPaperConnectingFunctions(const ConnectingReport& rep) {
  for (const ConnectingSample& x : rep.samples) {
    ASSERT_GE(x.c.size(), 4u);
    EXPECT_NEAR(x.c[0], 1.0, 1e-12);
    EXPECT_NEAR(x.c[1], 0.0, 1e-12);
    EXPECT_NEAR(x.c[2], 0.0, 1e-12);
    EXPECT_NEAR(x.c[3], 6.0, 1e-10);
    EXPECT_NEAR(x.p[0], 1.0, 1e-12);
    for (int i = 1; i < 3; ++i) EXPECT_NEAR(x.p[i], 0.0, 1e-10) << "p_" << i + 1;
    for (int i = 0; i < 3; ++i) EXPECT_NEAR(x.q[i], 0.0, 1e-10) << "q_" << i + 1;
  }
}

TEST(GcnPaperExample, AutodiffCallablesGiveThePublishedConnectingFunctions) {
  const HomogeneousSurface r = autodiffSurface<6>("r", {0, 1}, {0, 1}, paperR);
  const HomogeneousSurface rbar = autodiffSurface<6>("rbar", {0, 1}, {0, 1}, paperRbar);
  const ParameterLine e1{Vec2(1.0, 0.0), Vec2(0.0, 1.0)}, e2{Vec2(0.0, 0.0), Vec2(0.5, 1.0)};
  ConnectingOptions o;
  o.order = 3;
  o.pbar = {0.5};
  o.qbar = {-1.0};
  const auto samples = interiorSamples(16);
  auto rep = solveConnectingFunctions(r, e1, rbar, e2, samples, o);
  ASSERT_TRUE(rep.isOk()) << rep.status().message();
  EXPECT_EQ(rep->gcOrder, 3);
  EXPECT_TRUE(rep->cnClaimVerified);  // r(psi2) and rbar(psi1) are C^3, as the paper states
  expectPaperConnectingFunctions(*rep);
  // Beyond the paper's statement: the pair is GC^4 (r is the plane z = 0 and rbar leaves it with t^5) but not
  // GC^5.
  o.order = 5;
  auto rep5 = solveConnectingFunctions(r, e1, rbar, e2, samples, o);
  ASSERT_TRUE(rep5.isOk());
  EXPECT_EQ(rep5->gcOrder, 4);
  EXPECT_GT(rep5->residuals[5], 1e-3);
}

TEST(GcnPaperExample, ExpressionPatchesAgreeWithAutodiff) {
  ExpressionPatch pr{"r", {"u", "v", "0", "1 + v"}, {0, 1}, {0, 1}};
  ExpressionPatch pb{"rbar",
                     {"(u - v/2) + 1 + (u - v/2)^3", "(u + v/2) + (u - v/2)^3 * ((u + v/2) - sin(u - v/2))",
                      "5 * (u + v/2) * (u - v/2)^5", "1 + (u + v/2) + (1 + 2*u) * (u - v/2)^3"},
                     {0, 1},
                     {0, 1}};
  auto r = compileExpressionPatch(pr);
  auto rbar = compileExpressionPatch(pb);
  ASSERT_TRUE(r.isOk()) << r.status().message();
  ASSERT_TRUE(rbar.isOk()) << rbar.status().message();
  // Symbolic derivatives against autodiff at a point.
  const HomogeneousSurface ref = autodiffSurface<5>("rbar", {0, 1}, {0, 1}, paperRbar);
  const auto d1 = rbar->derivatives(0.31, 0.77, 5), d2 = ref.derivatives(0.31, 0.77, 5);
  ASSERT_TRUE(d1.isOk() && d2.isOk());
  for (int a = 0; a <= 5; ++a)
    for (int b = 0; a + b <= 5; ++b)
      EXPECT_LT(((*d1)[a][b] - (*d2)[a][b]).norm(), 1e-11 * (1.0 + (*d2)[a][b].norm())) << a << "," << b;
  const ParameterLine e1{Vec2(1.0, 0.0), Vec2(0.0, 1.0)}, e2{Vec2(0.0, 0.0), Vec2(0.5, 1.0)};
  ConnectingOptions o;
  o.order = 3;
  o.pbar = {0.5};
  o.qbar = {-1.0};
  auto rep = solveConnectingFunctions(*r, e1, *rbar, e2, interiorSamples(8), o);
  ASSERT_TRUE(rep.isOk()) << rep.status().message();
  EXPECT_EQ(rep->gcOrder, 3);
  expectPaperConnectingFunctions(*rep);
}

TEST(GcnPaperExample, ExampleModelFileThroughThePatchFrames) {
  auto model = readModelWithExpressions(fs::path(SEAM_EXAMPLES_DIR) / "models" / "zwl_example.json");
  ASSERT_TRUE(model.isOk()) << model.status().message();
  ASSERT_EQ(model->expressions.size(), 2u);
  auto r = compileExpressionPatch(*model->findExpression("r"));
  auto rbar = compileExpressionPatch(*model->findExpression("rbar"));
  ASSERT_TRUE(r.isOk() && rbar.isOk());
  GcnOptions o;
  o.order = 3;
  o.surfaceSamples = 16;
  auto rep = analyzeGcn(*r, Edge::U1, *rbar, Edge::U0, o);
  ASSERT_TRUE(rep.isOk()) << rep.status().message();
  EXPECT_EQ(rep->gcOrder, 3);
  EXPECT_FALSE(rep->certified);
  expectPaperConnectingFunctions(rep->sampled);
}

TEST(GcnExpression, ParseErrorsNameThePatchAndTheProblem) {
  ExpressionPatch bad{"B", {"tan(u)", "v", "0", "1"}, {0, 1}, {0, 1}};
  auto r = compileExpressionPatch(bad);
  ASSERT_FALSE(r.isOk());
  EXPECT_NE(r.status().message().find("\"B\""), std::string::npos);
  EXPECT_NE(r.status().message().find("tan"), std::string::npos);
  bad.homogeneous = {"u + x", "v", "0", "1"};
  r = compileExpressionPatch(bad);
  ASSERT_FALSE(r.isOk());
  EXPECT_NE(r.status().message().find("x = \"u + x\""), std::string::npos);
  bad.homogeneous = {"u", "v", "log(u - 2)", "1"};
  r = compileExpressionPatch(bad);
  ASSERT_FALSE(r.isOk());
  EXPECT_NE(r.status().message().find("not finite"), std::string::npos);
  // JSON: w omitted means 1; unknown keys are rejected.
  auto m = parseModelWithExpressions(
      R"({"patches": [{"name": "E", "type": "expression", "homogeneous": ["u", "v", "u*v"]}]})", "t.json");
  ASSERT_TRUE(m.isOk()) << m.status().message();
  EXPECT_EQ(m->expressions[0].homogeneous[3], "1");
  m = parseModelWithExpressions(
      R"({"patches": [{"name": "E", "type": "expression", "homogeneous": ["u", "v", "0"], "color": 1}]})",
      "t.json");
  ASSERT_FALSE(m.isOk());
  EXPECT_NE(m.status().message().find("color"), std::string::npos);
}

// Issue 15: the expression-model parser makes the model reader's checks before its own nlohmann parse. Arrays
// nested a million deep inside "patches" (a valid JSON text) used to overflow the stack in nlohmann's recursive
// copy / dump; a NUL byte is refused wherever it stands.
TEST(GcnExpressionJson, DeepNestingAndNulBytesAreRefusedBeforeParsing) {
  const size_t depth = 1000000;
  const std::string deep = R"({"patches": [)" + std::string(depth, '[') + std::string(depth, ']') + "]}";
  auto m = parseModelWithExpressions(deep, "deep.json");
  ASSERT_FALSE(m.isOk());
  EXPECT_EQ(m.status().code(), ErrorCode::kInvalidInput);
  EXPECT_NE(m.status().message().find("deep.json"), std::string::npos) << m.status().message();
  EXPECT_NE(m.status().message().find("nested more than 256 deep"), std::string::npos) << m.status().message();
  const std::string nul = std::string(R"({"patches": [{"name": "E", "type": "expression", "homogeneous": ["u", "v", )") +
                          std::string(1, '\0') + R"("0"]}]})";
  m = parseModelWithExpressions(nul, "nul.json");
  ASSERT_FALSE(m.isOk());
  EXPECT_NE(m.status().message().find("nul.json"), std::string::npos) << m.status().message();
  EXPECT_NE(m.status().message().find("a NUL byte"), std::string::npos) << m.status().message();
}

// Found by fuzz_gcn (docs/reliability.md, "Fuzzing"; fuzz/regressions/gcn/division_by_zero.json): a literal division
// by zero in an expression is GiNaC's error, returned with the patch and the coordinate (GiNaC leaks a few bytes
// when it throws there: suppressed as third-party, like its load-time allocations).
TEST(GcnExpressionJson, DivisionByZeroIsAnErrorNamingThePatch) {
  const auto m = parseModelWithExpressions(
      R"({"patches": [{"name": "r", "type": "expression", "homogeneous": ["u", "v", "0", "1 + (u + v)/0"]}]})",
      "div.json");
  ASSERT_FALSE(m.isOk());
  EXPECT_EQ(m.status().code(), ErrorCode::kInvalidInput);
  EXPECT_NE(m.status().message().find("div.json: expression patch \"r\": w = \"1 + (u + v)/0\""), std::string::npos)
      << m.status().message();
  EXPECT_NE(m.status().message().find("division by zero"), std::string::npos) << m.status().message();
}

// fuzz_gcn (fuzz/regressions/gcn/number_overflow.json): a number literal that overflows a double is nlohmann's
// out_of_range, not a parse_error; it escaped the expression reader and ended the process. It is the model reader's
// usual error now, naming the file and the number.
TEST(GcnExpressionJson, AnOverflowingNumberIsAnErrorNotACrash) {
  const auto m = parseModelWithExpressions(
      R"({"patches": [{"name": "r", "type": "expression", "homogeneous": ["u", "v", "0", "1"], "w": 1e1111111}]})",
      "big.json");
  ASSERT_FALSE(m.isOk());
  EXPECT_EQ(m.status().code(), ErrorCode::kInvalidInput);
  EXPECT_NE(m.status().message().find("big.json"), std::string::npos) << m.status().message();
  EXPECT_NE(m.status().message().find("1e1111111"), std::string::npos) << m.status().message();
}

// ---------------------------------------------------------------------------------------------------------------
// Theorem 5, exactly.

class GcnReparametrised : public ::testing::TestWithParam<std::tuple<int, PairKind>> {};

TEST_P(GcnReparametrised, ExactlyGcnForTheConstructedOrderAndNotHigher) {
  const auto [n, kind] = GetParam();
  Rng rng(1000 + 10 * n + static_cast<int>(kind));
  const Pair p = gcnPair(rng, n, kind);
  ExactGcnOptions o;
  o.order = n + 1;
  auto r = exactGcnBezier(p.q, p.qbar, o);
  ASSERT_TRUE(r.isOk()) << r.status().message();
  EXPECT_EQ(r->gcOrder, n);
  EXPECT_TRUE(r->certified);
  EXPECT_EQ(r->gcnCase, kind == PairKind::kIntegral           ? GcnCase::kIntegral
                        : kind == PairKind::kEqualEdgeWeights ? GcnCase::kPositionC0
                                                              : GcnCase::kGeneral);
  ASSERT_EQ(static_cast<int>(r->residuals.size()), n + 2);
  for (int m = 0; m <= n; ++m) EXPECT_LE(r->residuals[m], kIdentityRelTol);
  EXPECT_GT(r->residuals[n + 1], 1e-4);
  for (const DegreeEntry& d : r->degrees) EXPECT_LE(d.found, d.bound) << d.name;
  // Not a parametric C^1 join (phi is not the identity).
  EXPECT_EQ(r->cOrder, 0);
}

INSTANTIATE_TEST_SUITE_P(All, GcnReparametrised,
                         ::testing::Combine(::testing::Values(1, 2, 3),
                                            ::testing::Values(PairKind::kGeneral, PairKind::kEqualEdgeWeights,
                                                              PairKind::kIntegral)));

TEST(GcnExact, ConnectingFunctionsMatchTheSampledRecursion) {
  // (4.5): c_s = c(under)/(D^{2s-1} H^{s-1}), p_s = G p(under)/(D^{2s-1} H^s), q_s likewise, against the jets
  // of the sampled route on the same pair (Theorem 4 frame: pbar_1 = 1).
  Rng rng(77);
  const int n = 3;
  const Pair p = gcnPair(rng, n, PairKind::kGeneral);
  ExactGcnOptions eo;
  eo.order = n;
  auto ex = exactGcnBezier(p.q, p.qbar, eo);
  ASSERT_TRUE(ex.isOk());
  ASSERT_EQ(ex->gcOrder, n);
  const Patch A = toPatch("A", p.q), B = toPatch("B", p.qbar);
  const HomogeneousSurface hA = homogeneousSurface(A.surface, "A").edgeFrame(Edge::U1, true);
  const HomogeneousSurface hB = homogeneousSurface(B.surface, "B").edgeFrame(Edge::U0, false);
  ConnectingOptions co;
  co.order = n;
  const std::vector<double> taus{0.1, 0.45, 0.9};
  auto rep = solveConnectingFunctions(hA, {Vec2(0, 0), Vec2(0, 1)}, hB, {Vec2(0, 0), Vec2(0, 1)}, taus, co);
  ASSERT_TRUE(rep.isOk()) << rep.status().message();
  EXPECT_EQ(rep->gcOrder, n);
  const ExactConnecting& f = ex->functions;
  for (size_t k = 0; k < taus.size(); ++k) {
    const double t = taus[k];
    const double G = f.G.scalar(t), H = f.H.scalar(t), D = f.D.scalar(t);
    const ConnectingSample& x = rep->samples[k];
    EXPECT_NEAR(x.c[0], H / G, 1e-10);
    for (int s = 1; s <= n; ++s) {
      const double den = std::pow(D, 2 * s - 1) * std::pow(H, s - 1);
      const double c = f.c[s - 1].scalar(t) / den, pp = G * f.p[s - 1].scalar(t) / (den * H),
                   qq = G * f.q[s - 1].scalar(t) / (den * H);
      EXPECT_NEAR(x.c[s], c, 1e-8 * (1 + std::abs(c))) << "c_" << s;
      EXPECT_NEAR(x.p[s - 1], pp, 1e-8 * (1 + std::abs(pp))) << "p_" << s;
      EXPECT_NEAR(x.q[s - 1], qq, 1e-8 * (1 + std::abs(qq))) << "q_" << s;
    }
  }
}

TEST(GcnExact, EveryMinorGivesTheSameVerdictAndRootsOfDAreEliminated) {
  int withRoots = 0;
  for (int seed = 0; seed < 12; ++seed) {
    Rng rng(2000 + seed);
    const int n = 2;
    const PairKind kind = seed % 2 == 1 ? PairKind::kIntegral : PairKind::kGeneral;
    const Pair p = gcnPair(rng, n, kind);
    const int minors = kind == PairKind::kIntegral ? 3 : 4;
    for (int i = 1; i <= minors; ++i) {
      ExactGcnOptions o;
      o.order = n + 1;
      o.forceMinor = i;
      auto r = exactGcnBezier(p.q, p.qbar, o);
      if (!r.isOk() && r.status().code() == ErrorCode::kDegenerate) continue;  // a minor that vanishes identically
      ASSERT_TRUE(r.isOk()) << r.status().message();
      EXPECT_EQ(r->gcOrder, n) << "seed " << seed << " minor " << i;
      const ExactConnecting& f = r->functions;
      if (f.rootsOfD.empty()) continue;
      ++withRoots;
      for (const std::string& note : r->notes) EXPECT_EQ(note.find("elimination"), std::string::npos) << note;
      EXPECT_TRUE(detail::rootsInUnitInterval(f.Dbar, 1e-9 * f.D.maxAbsCoeff()).empty());
      EXPECT_EQ(f.Dbar.degree(), f.D.degree() - static_cast<int>(f.rootsOfD.size()));
      // c_s / D^{2s-1} is unchanged by the elimination (away from the roots).
      const double tau = 0.5 * (f.rootsOfD[0] + (f.rootsOfD[0] < 0.5 ? 1.0 : 0.0));
      for (int s = 1; s <= n; ++s) {
        const double a = f.p[s - 1].scalar(tau) / std::pow(f.D.scalar(tau), 2 * s - 1);
        const double b = f.pbar[s - 1].scalar(tau) / std::pow(f.Dbar.scalar(tau), 2 * s - 1);
        EXPECT_NEAR(a, b, 1e-7 * (1.0 + std::abs(a))) << "s=" << s;
      }
    }
  }
  EXPECT_GT(withRoots, 0) << "no minor with a root on the edge: the elimination was not exercised";
}

TEST(GcnPatches, ReparametrisedPairsAtPatchLevelAndWeightScalingInvariance) {
  for (int n = 1; n <= 3; ++n) {
    Rng rng(500 + n);
    const Pair p = gcnPair(rng, n, PairKind::kGeneral);
    ASSERT_GT(p.qbar.coeffs().col(3).minCoeff(), 0.0) << "test construction: weights must stay positive";
    const Patch A = toPatch("A", p.q), B = toPatch("B", p.qbar);
    GcnOptions o;
    o.order = n + 1;
    o.samplesPerSpan = 8;
    for (double fa : {1.0, 0.25}) {
      for (double fb : {1.0, 7.5}) {
        auto rep = analyzeGcn(scaledWeights(A, fa), Edge::U1, scaledWeights(B, fb), Edge::U0, o);
        ASSERT_TRUE(rep.isOk()) << rep.status().message();
        EXPECT_EQ(rep->gcOrder, n) << "n=" << n << " fa=" << fa << " fb=" << fb;
        EXPECT_TRUE(rep->certified);
        EXPECT_EQ(rep->sampled.gcOrder, n);
        EXPECT_EQ(rep->cOrder, 0);
        EXPECT_TRUE(rep->sampled.cnClaimVerified);
      }
    }
    // Seen from the other side (B's edge u0 against A's edge u1) the verdict is the same.
    auto back = analyzeGcn(B, Edge::U0, A, Edge::U1, o);
    ASSERT_TRUE(back.isOk()) << back.status().message();
    EXPECT_EQ(back->gcOrder, n);
  }
}

TEST(GcnPatches, SplitEdgeAndReversedParametrisation) {
  // B split along the edge into two spans and reversed along v: the exact route works piece by piece.
  Rng rng(901);
  const Pair p = gcnPair(rng, 2, PairKind::kGeneral);
  const Patch A = toPatch("A", p.q);
  Patch B = toPatch("B", p.qbar);
  B.surface = B.surface.withKnotInsertedV(0.4, B.surface.degreeV()).reversedV();
  GcnOptions o;
  o.order = 3;
  o.samplesPerSpan = 6;
  auto rep = analyzeGcn(A, Edge::U1, B, Edge::U0, o);
  ASSERT_TRUE(rep.isOk()) << rep.status().message();
  EXPECT_EQ(rep->gcOrder, 2);
  EXPECT_TRUE(rep->certified);
  EXPECT_EQ(rep->exact.size(), 2u);
  EXPECT_LT(rep->slope, 0.0);
}

TEST(GcnPatches, NonGc1PairsAreRejected) {
  Rng rng(42);
  // A crease: B continues A's edge in a direction that leaves the tangent plane.
  const BernsteinPatch q = randomPatch(rng, 2, 2, false);
  Matrix c(3 * 3, 4);
  for (int j = 0; j <= 2; ++j) {
    const auto e = q.coeff(2, j);
    const Vec3 edge = e.head(3).transpose() / e[3];
    for (int i = 0; i <= 2; ++i) {
      const Vec3 pt = edge + Vec3(0.0, 0.0, 0.4 * i);
      c.row(i * 3 + j) << e[3] * pt.transpose(), e[3];
    }
  }
  const Patch A = toPatch("A", q), B = toPatch("B", BernsteinPatch(2, 2, c));
  GcnOptions o;
  o.order = 2;
  auto rep = analyzeGcn(A, Edge::U1, B, Edge::U0, o);
  ASSERT_TRUE(rep.isOk()) << rep.status().message();
  EXPECT_EQ(rep->gcOrder, 0);
  EXPECT_TRUE(rep->certified);
  EXPECT_EQ(rep->sampled.gcOrder, 0);
  // A fold: B = A's own last span reflected back over A (p_1 < 0).
  const BernsteinPatch folded = q.restricted(1.0, 0.5, 0.0, 1.0);  // starts on the edge, runs back into A
  auto fold = analyzeGcn(A, Edge::U1, toPatch("F", folded), Edge::U0, o);
  ASSERT_TRUE(fold.isOk()) << fold.status().message();
  EXPECT_EQ(fold->gcOrder, 0);
  bool noted = false;
  for (const auto& note : fold->notes) noted = noted || note.find("fold") != std::string::npos;
  EXPECT_TRUE(noted);
  // Exact identity failure at order 0: a gap.
  Matrix g = c;
  for (int r = 0; r < g.rows(); ++r) g(r, 2) += 0.05 * g(r, 3);
  auto gap = analyzeGcn(A, Edge::U1, toPatch("G", BernsteinPatch(2, 2, g)), Edge::U0, o);
  ASSERT_TRUE(gap.isOk()) << gap.status().message();
  EXPECT_EQ(gap->gcOrder, -1);
}

TEST(GcnPatches, ParametricContinuationIsRationalCn) {
  // B = A's polynomial continuation beyond its edge (u in [1, 1.5]) with its homogeneous form scaled by a
  // constant: rational C^infinity (Corollary), so C^n = GC^n = n.
  Rng rng(5);
  const BernsteinPatch q = randomPatch(rng, 3, 2, false);
  BernsteinPatch ext = q.restricted(1.0, 1.5, 0.0, 1.0);
  ext = BernsteinPatch(ext.degreeU(), ext.degreeV(), Matrix(2.0 * ext.coeffs()));
  const Patch A = toPatch("A", q);
  Patch B = toPatch("B", ext);
  B.surface =
      B.surface.reparametrized({0.0, 0.5}, {0.0, 1.0});  // own parameters match A's (slope 1, same speed)
  GcnOptions o;
  o.order = 3;
  auto rep = analyzeGcn(A, Edge::U1, B, Edge::U0, o);
  ASSERT_TRUE(rep.isOk()) << rep.status().message();
  EXPECT_EQ(rep->gcOrder, 3);
  EXPECT_EQ(rep->cOrder, 3);
  EXPECT_EQ(rep->sampled.cOrder, 3);
}

// ---------------------------------------------------------------------------------------------------------------
// Theorem 6 / (4.8).

TEST(GcnConstruction, BicubicGc1FormulasOfSection42) {
  // The paper's bicubic formulas equal (4.8) with gamma_1 = 3 (gamma_1' - 1) and alpha_1 in every row;
  // printed with 3 alpha_1 in rows 1 and 2, they are not GC^1 for generic data.
  Rng rng(3);
  const BernsteinPatch q = randomPatch(rng, 3, 3, false);
  const double g = 1.1, a = 0.8, b0 = 0.3, b1 = -0.2;
  auto Q = [&](int i, int j) { return Eigen::RowVectorXd(q.coeff(i, j)); };
  std::vector<Eigen::RowVectorXd> paper(4), misprint(4);
  for (int i = 0; i <= 3; ++i) paper[i] = g * Q(3, i);
  paper[0] += a * (Q(3, 0) - Q(2, 0)) + b0 * (Q(3, 1) - Q(3, 0));
  paper[1] +=
      a * (Q(3, 1) - Q(2, 1)) + 2.0 / 3.0 * b0 * (Q(3, 2) - Q(3, 1)) + 1.0 / 3.0 * b1 * (Q(3, 1) - Q(3, 0));
  paper[2] +=
      a * (Q(3, 2) - Q(2, 2)) + 1.0 / 3.0 * b0 * (Q(3, 3) - Q(3, 2)) + 2.0 / 3.0 * b1 * (Q(3, 2) - Q(3, 1));
  paper[3] += a * (Q(3, 3) - Q(2, 3)) + b1 * (Q(3, 3) - Q(3, 2));
  misprint = paper;
  misprint[1] += 2.0 * a * (Q(3, 1) - Q(2, 1));
  misprint[2] += 2.0 * a * (Q(3, 2) - Q(2, 2));
  ShapeParameters sp{{3.0 * (g - 1.0)}, {a}, {b0}, {b1}};
  auto cols = gcnColumns(q, sp, 3);
  ASSERT_TRUE(cols.isOk()) << cols.status().message();
  for (int i = 0; i <= 3; ++i) {
    EXPECT_LT((cols->row(i) - Q(3, i)).norm(), 1e-14);
    EXPECT_LT((cols->row(4 + i) - paper[i]).norm(), 1e-13) << "i=" << i;
  }
  // Complete both to bicubic patches with the same last two columns and decide GC^1 exactly.
  auto full = extendBezier(q, sp);
  ASSERT_TRUE(full.isOk()) << full.status().message();
  BernsteinPatch bad = *full;
  for (int i = 0; i <= 3; ++i) bad.coeff(1, i) = misprint[i];
  ExactGcnOptions o;
  o.order = 1;
  auto good = exactGcnBezier(q, *full, o), wrong = exactGcnBezier(q, bad, o);
  ASSERT_TRUE(good.isOk() && wrong.isOk());
  EXPECT_EQ(good->gcOrder, 1);
  EXPECT_EQ(wrong->gcOrder, 0);
}

class GcnConstructionOrder : public ::testing::TestWithParam<int> {};

TEST_P(GcnConstructionOrder, ConstructedPatchIsGcnByBothRoutesWithTheChosenConnectingFunctions) {
  const int n = GetParam();
  Rng rng(300 + n);
  const BernsteinPatch q = randomPatch(rng, 3, 3, false);
  const ShapeParameters sp = randomShape(rng, n);
  ExtensionOptions eo;
  eo.degree = n + 2;
  auto rbar = extendBezier(q, sp, eo);
  ASSERT_TRUE(rbar.isOk()) << rbar.status().message();
  // Section 3: exact.
  ExactGcnOptions o;
  o.order = n + 1;
  auto ex = exactGcnBezier(q, *rbar, o);
  ASSERT_TRUE(ex.isOk()) << ex.status().message();
  EXPECT_EQ(ex->gcnCase, GcnCase::kPositionC0);
  EXPECT_EQ(ex->gcOrder, n);
  EXPECT_TRUE(ex->certified);
  // Section 2: sampled, connecting functions = the shape parameters (c_s = gamma_s, p_s = alpha_s,
  // q_s = beta0_s (1 - v) + beta1_s v).
  const Patch A = toPatch("A", q), B = toPatch("B", *rbar);
  const HomogeneousSurface hA = homogeneousSurface(A.surface, "A").edgeFrame(Edge::U1, true);
  const HomogeneousSurface hB = homogeneousSurface(B.surface, "B").edgeFrame(Edge::U0, false);
  ConnectingOptions co;
  co.order = n;
  auto rep = solveConnectingFunctions(hA, {Vec2(0, 0), Vec2(0, 1)}, hB, {Vec2(0, 0), Vec2(0, 1)},
                                      interiorSamples(5), co);
  ASSERT_TRUE(rep.isOk()) << rep.status().message();
  EXPECT_EQ(rep->gcOrder, n);
  for (const ConnectingSample& x : rep->samples) {
    EXPECT_NEAR(x.c[0], 1.0, 1e-12);
    for (int s = 1; s <= n; ++s) {
      EXPECT_NEAR(x.c[s], sp.gamma[s - 1], 1e-9) << "c_" << s;
      EXPECT_NEAR(x.p[s - 1], sp.alpha[s - 1], 1e-9) << "p_" << s;
      EXPECT_NEAR(x.q[s - 1], sp.beta0[s - 1] * (1 - x.s) + sp.beta1[s - 1] * x.s, 1e-9) << "q_" << s;
    }
  }
  // Model level: the constructed patch attached to A's edge u1.
  auto surf = extendSurface(A.surface, Edge::U1, sp, eo);
  ASSERT_TRUE(surf.isOk()) << surf.status().message();
  GcnOptions go;
  go.order = n + 1;
  go.samplesPerSpan = 6;
  auto g = analyzeGcn(A, Edge::U1, Patch{"N", PatchKind::kBezier, *surf}, Edge::U0, go);
  ASSERT_TRUE(g.isOk()) << g.status().message();
  EXPECT_EQ(g->gcOrder, n);
}

INSTANTIATE_TEST_SUITE_P(N123, GcnConstructionOrder, ::testing::Values(1, 2, 3));

TEST(GcnConstruction, InvalidParametersAreRejected) {
  Rng rng(8);
  const BernsteinPatch q = randomPatch(rng, 2, 2, false);
  EXPECT_EQ(gcnColumns(q, {{0.0}, {0.0}, {0.0}, {0.0}}, 3).status().code(),
            ErrorCode::kInvalidInput);  // alpha_1 = 0
  EXPECT_EQ(gcnColumns(q, {{0.0, 0.0}, {1.0}, {0.0}, {0.0}}, 3).status().code(), ErrorCode::kInvalidInput);
  EXPECT_EQ(gcnColumns(q, {{0, 0, 0}, {1, 0, 0}, {0, 0, 0}, {0, 0, 0}}, 2).status().code(),
            ErrorCode::kInvalidInput);
  // A huge negative gamma_1 makes a weight negative.
  EXPECT_EQ(extendBezier(q, {{-100.0}, {1.0}, {0.0}, {0.0}}).status().code(), ErrorCode::kNoSolution);
}

// ---------------------------------------------------------------------------------------------------------------
// The command line.

#ifdef SEAM_CLI_PATH
struct CliResult {
  int exitCode = -1;
  std::string out;
};

CliResult runCli(const std::string& args) {
  const std::string cmd = std::string("\"") + SEAM_CLI_PATH + "\" " + args + " 2>/dev/null";
  CliResult r;
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (pipe == nullptr) return r;
  char buf[4096];
  size_t k = 0;
  while ((k = std::fread(buf, 1, sizeof buf, pipe)) > 0) r.out.append(buf, k);
  const int status = ::pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

TEST(GcnCli, PaperExampleAsExpressionModel) {
  const std::string file = (fs::path(SEAM_EXAMPLES_DIR) / "models" / "zwl_example.json").string();
  const CliResult r = runCli("gcn \"" + file + "\" --seam r:u1 rbar:u0 --order 3 --json");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["gc_order"], 3);
  EXPECT_EQ(j["certified"], false);
  ASSERT_EQ(j["residuals"].size(), 4u);
  const auto& cf = j["connecting_functions"];
  ASSERT_EQ(cf["c"].size(), 4u);
  ASSERT_EQ(cf["p"].size(), 3u);
  for (size_t k = 0; k < cf["s"].size(); ++k) {
    EXPECT_NEAR(cf["c"][0][k].get<double>(), 1.0, 1e-10);
    EXPECT_NEAR(cf["c"][3][k].get<double>(), 6.0, 1e-9);
    EXPECT_NEAR(cf["p"][0][k].get<double>(), 1.0, 1e-10);
    EXPECT_NEAR(cf["q"][0][k].get<double>(), 0.0, 1e-10);
  }
  // Order 5 requested: GC^4 only -> exit 1.
  const CliResult r5 = runCli("gcn \"" + file + "\" --seam r:u1 rbar:u0 --order 5");
  EXPECT_EQ(r5.exitCode, 1) << r5.out;
  // Bad input -> 2.
  EXPECT_EQ(runCli("gcn \"" + file + "\" --seam r:u1 nope:u0").exitCode, 2);
  EXPECT_EQ(runCli("gcn \"" + file + "\" --seam r:q1 rbar:u0").exitCode, 2);
}

TEST(GcnCli, ExtendThenCheck) {
  const fs::path dir = fs::temp_directory_path() / ("seam_gcn_test_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string in = (fs::path(SEAM_TEST_DATA_DIR) / "gcn" / "rational_patch.json").string();
  const std::string out = (dir / "out.json").string();
  CliResult r = runCli("extend \"" + in +
                       "\" --patch A --edge u1 --order 2 --gamma 0.1 0.0 --alpha 1.2 0.1 "
                       "--beta0 0.1 0.0 --beta1 -0.1 0.05 --degree 4 --name N -o \"" +
                       out + "\"");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  r = runCli("gcn \"" + out + "\" --seam A:u1 N:u0 --order 2 --json");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["gc_order"], 2);
  EXPECT_EQ(j["certified"], true);
  r = runCli("gcn \"" + out + "\" --seam A:u1 N:u0 --order 3");
  EXPECT_EQ(r.exitCode, 1) << r.out;
  // Existing name, missing parameters -> 2.
  EXPECT_EQ(runCli("extend \"" + in +
                   "\" --patch A --edge u1 --order 1 --gamma 0 --alpha 1 --beta0 0 --beta1 0 "
                   "--name A -o \"" +
                   out + "\"")
                .exitCode,
            2);
  EXPECT_EQ(runCli("extend \"" + in +
                   "\" --patch A --edge u1 --order 2 --gamma 0 --alpha 1 --beta0 0 --beta1 0 "
                   "--name M -o \"" +
                   out + "\"")
                .exitCode,
            2);
  fs::remove_all(dir);
}
#endif

// Issue 15: expressions GiNaC cannot take in bounded time or stack are refused before it parses them.
std::string nested(const std::string& open, const std::string& inner, const std::string& close, int depth) {
  std::string s;
  for (int i = 0; i < depth; ++i) s += open;
  s += inner;
  for (int i = 0; i < depth; ++i) s += close;
  return s;
}

TEST(ExpressionLimits, DeepParenthesesAreRefusedWithAMessage) {
  // 10 000 levels crashed GiNaC's parser (stack overflow) before; they are now too long as well, so 4 000 (within
  // kMaxExpressionChars) show the nesting limit.
  ExpressionPatch p{"deep", {nested("(", "u", ")", 4000), "v", "0", "1"}, {0, 1}, {0, 1}};
  const auto r = compileExpressionPatch(p);
  ASSERT_FALSE(r.isOk());
  EXPECT_EQ(r.status().code(), ErrorCode::kInvalidInput);
  EXPECT_NE(r.status().message().find("expression patch \"deep\": x"), std::string::npos) << r.status().message();
  EXPECT_NE(r.status().message().find("nested more than"), std::string::npos) << r.status().message();
}

TEST(ExpressionLimits, LongSignRunsAndLongTextAreRefused) {
  ExpressionPatch signs{"signs", {std::string(5000, '-') + "u", "v", "0", "1"}, {0, 1}, {0, 1}};
  EXPECT_FALSE(compileExpressionPatch(signs).isOk());
  std::string sum = "u";
  while (sum.size() <= kMaxExpressionChars) sum += "+u";
  ExpressionPatch longText{"long", {"u", sum, "0", "1"}, {0, 1}, {0, 1}};
  const auto r = compileExpressionPatch(longText);
  ASSERT_FALSE(r.isOk());
  EXPECT_NE(r.status().message().find("characters"), std::string::npos) << r.status().message();
}

TEST(ExpressionLimits, DeeplyNestedFunctionsAreRefusedShallowOnesKept) {
  ExpressionPatch deep{"sin100", {nested("sin(", "u", ")", 100), "v", "0", "1"}, {0, 1}, {0, 1}};
  const auto r = compileExpressionPatch(deep);  // ran for more than a minute before
  ASSERT_FALSE(r.isOk());
  EXPECT_NE(r.status().message().find("function calls nested"), std::string::npos) << r.status().message();
  // At the limit: accepted, and the value agrees with the same nesting evaluated directly.
  ExpressionPatch ok{"sinMax", {nested("sin(", "u", ")", kMaxFunctionNesting), "v", "0", "1"}, {0, 1}, {0, 1}};
  const auto s = compileExpressionPatch(ok);
  ASSERT_TRUE(s.isOk()) << s.status().message();
  double x = 0.3;
  for (int i = 0; i < kMaxFunctionNesting; ++i) x = std::sin(x);
  const auto d = s->derivatives(0.3, 0.5, 0);
  ASSERT_TRUE(d.isOk());
  EXPECT_NEAR((*d)[0][0][0], x, 1e-15);
  // Parentheses that are not calls do not count as function nesting.
  ExpressionPatch parens{"parens", {nested("(", "u", ")", 50), "v", "0", "1"}, {0, 1}, {0, 1}};
  EXPECT_TRUE(compileExpressionPatch(parens).isOk());
}

// CI's fuzz_gcn stopped on a timeout inside GMP: GiNaC computes numbers exactly while it parses, at any size
// (2^9999999 took 1.5 s, 3^(3^15) 3 s, (1 + 2^-99999)^999 more than 20 s, and reading the float literal
// 1e11111111111 did not finish). Such expressions are refused before GiNaC evaluates anything; the expected bit
// counts are the exact sizes (2^9999999 has 10^7 bits), far above kMaxExpressionNumberBits.
TEST(ExpressionLimits, HugeExactNumbersAreRefusedBeforeGiNaCComputesThem) {
  // The second row: exponents whose exact value differs from the double one (10^25 + 10^9 - 10^25 is 0 in
  // doubles), comes out of GiNaC's own evaluation (exp(0) = 1, ((10^40)^2)^(1/2) = 10^40), or raises a root
  // (2^-9/999 is 2^(-1/111) = 1/2 * 2^(110/111) to GiNaC; a local fuzz_gcn run stopped on it after 2 million inputs),
  // or raises the content GiNaC takes out of a sum ((5/6 u + 1/6 v)^k is (1/6)^k (5 u + v)^k: another local run).
  for (const char* text : {"2^9999999*u", "3^(3^15)", "(1+2^-99999)^999", "(2^60000*u)^2", "u + 2^(2^20)",
                           "sin(7^99999*u)", "2^(1000*1000*1000)", "2^((10^25+10^9)-10^25)", "7^(exp(0)*10^40)",
                           "7^(((10^40)^2)^(1/2))", "(2^-9/999)^9111111105-11*u", "(2^(1/3))^99999999",
                           "((u + v)/2 - (v - u)/3)^33333333333333333333333"}) {
    ExpressionPatch p{"big", {text, "v", "0", "1"}, {0, 1}, {0, 1}};
    const auto r = compileExpressionPatch(p);
    ASSERT_FALSE(r.isOk()) << text;
    EXPECT_EQ(r.status().code(), ErrorCode::kInvalidInput);
    EXPECT_NE(r.status().message().find(fmt::format("expression patch \"big\": x = \"{}\"", text)),
              std::string::npos) << r.status().message();
    EXPECT_NE(r.status().message().find(fmt::format("more than the {} accepted", kMaxExpressionNumberBits)),
              std::string::npos) << r.status().message();
  }
  // CI's fuzz_gcn stopped on a leak: (-2/111)^9.1e111 underflows CLN's floats, which throws inside GiNaC's
  // power::eval after it allocated the power. A power holding a float is bounded from its logarithm first: the
  // expected sizes are |e| log2|b| by hand (9.1e111 * 5.8 bits; 10^9 bits; 10^6 bits; 10^9 / 2 bits).
  for (const char* text : {"(2*-9/999)^9111111E105-11*u", "2.0^(10^9)*u", "(0.5)^1e6 + u", "u*(1 + (-1.0)^0.5)^(10^9)",
                           "(2*pi)^1e300", "2^(2.0^70)"}) {
    ExpressionPatch p{"float", {text, "v", "0", "1"}, {0, 1}, {0, 1}};
    const auto r = compileExpressionPatch(p);
    ASSERT_FALSE(r.isOk()) << text;
    EXPECT_EQ(r.status().code(), ErrorCode::kInvalidInput);
    EXPECT_NE(r.status().message().find("a power of floats"), std::string::npos) << r.status().message();
  }
  for (const char* text : {"1e11111111111", "1e-11111111111", "u*1e400", "u + 2.5E+309"}) {
    ExpressionPatch p{"range", {text, "v", "0", "1"}, {0, 1}, {0, 1}};
    const auto r = compileExpressionPatch(p);
    ASSERT_FALSE(r.isOk()) << text;
    EXPECT_TRUE(r.status().message().find("out of range") != std::string::npos ||
                r.status().message().find("beyond the range of a double") != std::string::npos)
        << r.status().message();
  }
  for (const char* text : {"1e", "1.2.3", "3.5e-", "u*1ex"}) {
    ExpressionPatch p{"malformed", {text, "v", "0", "1"}, {0, 1}, {0, 1}};
    const auto r = compileExpressionPatch(p);
    ASSERT_FALSE(r.isOk()) << text;
    EXPECT_NE(r.status().message().find("is not a number"), std::string::npos) << r.status().message();
  }
}

TEST(ExpressionLimits, LargeButBoundedNumbersAreComputedExactly) {
  // Values at (u, v) = (0.5, 0.5), each from arithmetic done by hand.
  const std::vector<std::pair<std::string, double>> cases{
      {"2^1000/2^999*u", 1.0},            // 2 exactly
      {"3.5e2*u", 175.0},                 // a float literal with an exponent
      {"(3/7)^3000 + u", 0.5},            // an exact rational of 7 300 bits, below any double: 0
      {"u^(2^70)", 0.0},                  // an integer exponent beyond a long: std::pow
      {"2^sin(1)*u", 0.5 * std::pow(2.0, std::sin(1.0))},  // GiNaC keeps 2^sin(1) symbolic
      {"u # 2^999999999", 0.5},           // a comment, as GiNaC's lexer reads it
      {"(u + 1)^5000 - (u + 1)^5000 + u", 0.5},
      {"10^300*u/10^300", 0.5},
      {"(4^(1/2))^3*u", 4.0},             // GiNaC's exact root: 2^3
      {"(2^(1/3))^3000*u/2^999", 1.0},    // 2^1000 / 2^999 = 2
      {"sin(0) + exp(0)*u", 0.5},
      {"2.0^10*u", 512.0},                // powers holding floats, below the bound: as doubles compute them
      {"1.5^2.5*u", 0.5 * std::pow(1.5, 2.5)},
      {"(2*pi)^100.5*u/10^80", 0.5 * std::pow(2.0 * std::numbers::pi, 100.5) / 1e80},
      {"0.5^60000.0 + u", 0.5}};
  for (const auto& [text, expected] : cases) {
    ExpressionPatch p{"ok", {text, "v", "0", "1"}, {0, 1}, {0, 1}};
    const auto s = compileExpressionPatch(p);
    ASSERT_TRUE(s.isOk()) << text << ": " << s.status().message();
    const auto d = s->derivatives(0.5, 0.5, 1);
    ASSERT_TRUE(d.isOk()) << text << ": " << d.status().message();
    EXPECT_DOUBLE_EQ((*d)[0][0][0], expected) << text;
  }
  // A parse error after a number: GiNaC's message, with the literal as written (the check parses the text with the
  // numbers replaced by symbols, and must not show their names).
  ExpressionPatch p{"bad", {"u*2 3.5e2", "v", "0", "1"}, {0, 1}, {0, 1}};
  const auto r = compileExpressionPatch(p);
  ASSERT_FALSE(r.isOk());
  EXPECT_NE(r.status().message().find("got: \"3.5e2\""), std::string::npos) << r.status().message();
  EXPECT_EQ(r.status().message().find("seam_number"), std::string::npos) << r.status().message();
  EXPECT_EQ(r.status().message().find('\n'), std::string::npos) << r.status().message();
}

// GiNaC's parser matches a call without arguments to any function of that name and evaluates it with none:
// "sin()" crashed the process (a null dereference, found by a local fuzz_gcn run). Its default table also holds
// every GiNaC function, evaluated while it reads: binomial(9999999, 4999999) took 5.8 s before the check of the
// allowed functions ran. Both are refused before GiNaC reads the text now.
TEST(ExpressionLimits, EmptyCallsAndOtherFunctionsAreRefusedBeforeGiNaCReadsThem) {
  const std::vector<std::pair<std::string, std::string>> refused{
      {"sin()", "sin() has no argument"},
      {"1 + sqrt ( )", "sqrt() has no argument"},
      {"cos( # a comment\n)", "cos() has no argument"},
      {"factorial(999999) + u", "function \"factorial\" is not supported"},
      {"binomial(9999999, 4999999) + u", "function \"binomial\" is not supported"},
      {"tan (u)", "function \"tan\" is not supported"}};
  for (const auto& [text, message] : refused) {
    ExpressionPatch p{"call", {text, "v", "0", "1"}, {0, 1}, {0, 1}};
    const auto r = compileExpressionPatch(p);
    ASSERT_FALSE(r.isOk()) << text;
    EXPECT_EQ(r.status().code(), ErrorCode::kInvalidInput);
    EXPECT_NE(r.status().message().find(message), std::string::npos) << r.status().message();
  }
  ExpressionPatch ok{"ok", {"sqrt(u) + pow(u, 2)", "v", "0", "1"}, {0, 1}, {0, 1}};
  const auto s = compileExpressionPatch(ok);
  ASSERT_TRUE(s.isOk()) << s.status().message();
  const auto d = s->derivatives(0.5, 0.5, 0);
  ASSERT_TRUE(d.isOk());
  EXPECT_DOUBLE_EQ((*d)[0][0][0], std::sqrt(0.5) + 0.25);
}

// The product rule multiplies the terms: the third derivative of a product of 100 factors took 23 s and 840 MB
// under `seam gcn` (its default order is 3). An order whose derivatives would pass kMaxDerivativeNodes is refused
// before GiNaC forms it; the orders below it are exact.
TEST(ExpressionLimits, DerivativesTooLargeToFormAreRefusedSmallerOrdersExact) {
  const auto product = [](int m) {
    std::string s;
    for (int i = 1; i <= m; ++i) s += fmt::format("{}(u+{})", i > 1 ? "*" : "", i);
    return s;
  };
  ExpressionPatch wide{"wide", {product(100), "v", "0", "1"}, {0, 1}, {0, 1}};
  const auto s = compileExpressionPatch(wide);
  ASSERT_TRUE(s.isOk()) << s.status().message();
  // f = prod (u + i): f' = f S1, f'' = f (S1^2 - S2) with S1 = sum 1/(u + i), S2 = sum 1/(u + i)^2.
  const auto exact = [](int m, double u) {
    double f = 1.0, s1 = 0.0, s2 = 0.0;
    for (int i = 1; i <= m; ++i) {
      f *= u + i;
      s1 += 1.0 / (u + i);
      s2 += 1.0 / ((u + i) * (u + i));
    }
    return std::array<double, 3>{f, f * s1, f * (s1 * s1 - s2)};
  };
  const auto d1 = s->derivatives(0.5, 0.5, 1);
  ASSERT_TRUE(d1.isOk()) << d1.status().message();
  EXPECT_NEAR((*d1)[1][0][0] / exact(100, 0.5)[1], 1.0, 1e-12);
  const auto d3 = s->derivatives(0.5, 0.5, 3);
  ASSERT_FALSE(d3.isOk());
  EXPECT_EQ(d3.status().code(), ErrorCode::kInvalidInput);
  EXPECT_NE(d3.status().message().find("expression patch \"wide\": the derivatives of order"), std::string::npos)
      << d3.status().message();
  EXPECT_NE(d3.status().message().find(fmt::format("more than the {} accepted", kMaxDerivativeNodes)),
            std::string::npos) << d3.status().message();
  ExpressionPatch narrow{"narrow", {product(30), "v", "0", "1"}, {0, 1}, {0, 1}};
  const auto t = compileExpressionPatch(narrow);
  ASSERT_TRUE(t.isOk()) << t.status().message();
  const auto d2 = t->derivatives(0.5, 0.5, 2);
  ASSERT_TRUE(d2.isOk()) << d2.status().message();
  EXPECT_NEAR((*d2)[2][0][0] / exact(30, 0.5)[2], 1.0, 1e-12);
}

}  // namespace
}  // namespace seam::rational
