// Tests of the vertex analysis (seam/continuity/corner.h): valence, consistently oriented normals, degenerate
// corners, and Johansson's compatibility relations at 4-valent vertices (Theorems 1 and 2).
//
// Expected values come from independent routes:
//  * configurations cut from ONE smooth surface, where Theorems 1 and 2 say every relation holds: the
//  residuals must
//    vanish even with sheared, scaled and nonlinearly reparametrised patches (lambda != 1, kappa != 0,
//    lambda' != 0);
//  * lambda and kappa of affine (parallelogram) patches solved in the 2-D parameter plane from the
//  construction;
//  * a square pyramid, whose lambda, kappa and G1 residual have closed forms (derived in the test);
//  * invariance: reorienting the stored patches (swap/reverse) must not change any reported number;
//  * a normal twist perturbation, whose first-order G1 defect along the seam is measured by finite
//  differences on the
//    kernel's derivatives.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <functional>
#include <numbers>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "seam/continuity/corner.h"
#include "seam/core/bernstein.h"
#include "seam/spline/bspline_surface.h"

namespace seam {
namespace {

/// Residuals of exact configurations: relations are evaluated from O(10) products of derivatives of
/// polynomial patches of degree <= 6 fitted by interpolation (fit error ~1e-13 relative); 1e-8 is far above
/// that round-off and far below the O(0.1..1) residual any wrong formula, sign or reparametrisation produces.
constexpr double kExactTol = 1e-8;

/// Bernstein basis value by the explicit formula (test-local).
double bernstein(int n, int i, double t) {
  double c = 1.0;
  for (int k = 1; k <= i; ++k) c = c * (n - i + k) / k;
  return c * std::pow(t, i) * std::pow(1.0 - t, n - i);
}

/// The Bezier patch of bi-degree (du, dv) on [0,1]^2 that interpolates f at Chebyshev-Lobatto nodes: exact
/// (up to round-off) when f is a polynomial of that bi-degree.
BSplineSurface fitBezier(const std::function<Vec3(double, double)>& f, int du, int dv) {
  auto nodes = [](int n) {
    std::vector<double> x(static_cast<size_t>(n + 1));
    for (int i = 0; i <= n; ++i) x[static_cast<size_t>(i)] = 0.5 - 0.5 * std::cos(std::numbers::pi * i / n);
    return x;
  };
  const std::vector<double> nu = nodes(du), nv = nodes(dv);
  Eigen::MatrixXd Bu(du + 1, du + 1), Bv(dv + 1, dv + 1);
  for (int i = 0; i <= du; ++i)
    for (int j = 0; j <= du; ++j) Bu(i, j) = bernstein(du, j, nu[static_cast<size_t>(i)]);
  for (int i = 0; i <= dv; ++i)
    for (int j = 0; j <= dv; ++j) Bv(i, j) = bernstein(dv, j, nv[static_cast<size_t>(i)]);
  Matrix points(static_cast<Eigen::Index>((du + 1) * (dv + 1)), 3);
  const Eigen::MatrixXd BuInv = Bu.inverse(), BvInvT = Bv.inverse().transpose();
  for (int c = 0; c < 3; ++c) {
    Eigen::MatrixXd F(du + 1, dv + 1);
    for (int i = 0; i <= du; ++i)
      for (int j = 0; j <= dv; ++j) F(i, j) = f(nu[static_cast<size_t>(i)], nv[static_cast<size_t>(j)])[c];
    const Eigen::MatrixXd X = BuInv * F * BvInvT;
    for (int i = 0; i <= du; ++i)
      for (int j = 0; j <= dv; ++j) points(i * (dv + 1) + j, c) = X(i, j);
  }
  return BSplineSurface(du, dv, KnotVector::bezier(du), KnotVector::bezier(dv), du + 1, dv + 1, points);
}

/// A regular cubic polynomial surface R^2 -> R^3 (the one smooth surface every configuration is cut from).
Vec3 smoothSurface(double x, double y) {
  return {x + 0.2 * y * y, y - 0.1 * x * x + 0.15 * x * y,
          0.4 * x * x - 0.3 * x * y + 0.25 * y * y + 0.1 * x * x * x - 0.05 * y * y * y + 0.08 * x * y * y};
}

/// Four sectors around V in the parameter plane of smoothSurface, between the directions d[0..3]
/// (counter-clockwise). Sector k: A_k(s, t) = V + l[k] f_k(s) d[k] + l[k+1] g_k(t) d[k+1] + c_k s t w_k with
/// f, g monotone quadratics (f(0) = 0, f(1) = 1) and a twist term that vanishes on both seams: the seams are
/// the segments V + [0, l] d, shared by neighbours with different (nonlinear) parametrisations.
struct SectorConfig {
  Vec2 V{0.3, -0.2};
  std::array<Vec2, 4> d{Vec2(1.0, 0.25), Vec2(-0.3, 1.0), Vec2(-1.0, -0.2), Vec2(0.15, -1.0)};
  std::array<double, 4> l{0.5, 0.4, 0.6, 0.45};
  std::array<double, 4> fQuad{0.0, 0.0, 0.0, 0.0};  // f_k(s) = s + a (s^2 - s)
  std::array<double, 4> gQuad{0.0, 0.0, 0.0, 0.0};
  std::array<double, 4> twist{0.0, 0.0, 0.0, 0.0};
  std::array<Vec2, 4> twistDir{Vec2(1, 0), Vec2(0, 1), Vec2(1, 1), Vec2(1, -1)};
  [[nodiscard]] bool affine() const {
    for (int k = 0; k < 4; ++k)
      if (fQuad[k] != 0.0 || gQuad[k] != 0.0 || twist[k] != 0.0) return false;
    return true;
  }
};

std::vector<Patch> sectorPatches(const SectorConfig& c) {
  std::vector<Patch> out;
  const int deg = c.affine() ? 3 : 6;
  for (int k = 0; k < 4; ++k) {
    const int k1 = (k + 1) % 4;
    auto A = [&c, k, k1](double s, double t) {
      const double f = s + c.fQuad[static_cast<size_t>(k)] * (s * s - s);
      const double g = t + c.gQuad[static_cast<size_t>(k)] * (t * t - t);
      const Vec2 p = c.V + c.l[static_cast<size_t>(k)] * f * c.d[static_cast<size_t>(k)] +
                     c.l[static_cast<size_t>(k1)] * g * c.d[static_cast<size_t>(k1)] +
                     c.twist[static_cast<size_t>(k)] * s * t * c.twistDir[static_cast<size_t>(k)];
      return smoothSurface(p.x(), p.y());
    };
    out.push_back({"S" + std::to_string(k), PatchKind::kBezier, fitBezier(A, deg, deg)});
  }
  return out;
}

/// The corner of `s` closest to `p` (found by evaluation, independent of any orientation bookkeeping).
PatchCorner cornerAt(const std::vector<Patch>& patches, int index, const Vec3& p) {
  const BSplineSurface& s = patches[static_cast<size_t>(index)].surface;
  PatchCorner best{index, false, false};
  double bestD = INFINITY;
  for (bool um : {false, true})
    for (bool vm : {false, true}) {
      const double u = um ? s.domainU().hi : s.domainU().lo, v = vm ? s.domainV().hi : s.domainV().lo;
      const double d = (s.evaluate(u, v).head<3>() - p).norm();
      if (d < bestD) bestD = d, best = {index, um, vm};
    }
  return best;
}

std::vector<PatchCorner> cornersAt(const std::vector<Patch>& patches, const Vec3& p) {
  std::vector<PatchCorner> c;
  for (int i = 0; i < static_cast<int>(patches.size()); ++i) c.push_back(cornerAt(patches, i, p));
  return c;
}

CornerReport analyze(const std::vector<Patch>& patches, const Vec3& V, CornerOptions options = {}) {
  if (!options.lengthScale) options.lengthScale = 1.0;
  const std::vector<PatchCorner> corners = cornersAt(patches, V);
  Result<CornerReport> r = analyzeCorner(patches, corners, options);
  EXPECT_TRUE(r.isOk()) << r.status().message();
  return r.isOk() ? r.value() : CornerReport{};
}

void expectAllRelationsVanish(const CornerReport& r) {
  ASSERT_TRUE(r.fourPatch.has_value());
  const FourPatchVertex& fp = *r.fourPatch;
  for (int k = 0; k < 4; ++k)
    EXPECT_NEAR(fp.g1Relations[static_cast<size_t>(k)], 0.0, kExactTol) << "G1 relation " << k;
  ASSERT_TRUE(fp.g2Relations.has_value()) << "all four seams of one smooth surface are G2";
  for (int k = 0; k < 6; ++k)
    EXPECT_NEAR((*fp.g2Relations)[static_cast<size_t>(k)], 0.0, kExactTol) << "G2 relation " << k + 1;
  for (const VertexSeam& s : fp.seams) {
    EXPECT_NEAR(s.g1Residual, 0.0, kExactTol);
    EXPECT_NEAR(s.g1SlopeResidual, 0.0, kExactTol);
    EXPECT_NEAR(s.g2Jump, 0.0, kExactTol);
    EXPECT_TRUE(s.g1 && s.g2);
  }
  ASSERT_TRUE(r.normalSpreadDeg.has_value());
  EXPECT_NEAR(*r.normalSpreadDeg, 0.0, 1e-6);
  // One smooth surface: one second fundamental form at V.
  ASSERT_TRUE(r.curvatureSpreadRel.has_value());
  EXPECT_NEAR(*r.curvatureSpreadRel, 0.0, 1e-7);
}

const Vec3 kV = smoothSurface(0.3, -0.2);

// ---------------------------------------------------------------------------------------------------------------

TEST(Corner, SplitBSplineSurfaceIsC2AtTheVertex) {
  // A bicubic B-spline with one interior knot per direction, split into its four Bezier patches: C2
  // everywhere, so lambda = 1, kappa = 0, mu = nu = 0 and all derivatives of lambda, kappa vanish.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> z(-0.3, 0.3);
  Matrix pts(25, 3);
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) pts.row(i * 5 + j) = Eigen::RowVector3d(i * 0.5, j * 0.5 + 0.1 * i, z(rng));
  const BSplineSurface s =
      BSplineSurface::create(3, 3, {0, 0, 0, 0, 0.4, 1, 1, 1, 1}, {0, 0, 0, 0, 0.7, 1, 1, 1, 1}, 5, 5, pts)
          .value();
  std::vector<Patch> patches;
  for (const BezierPatchPiece& piece : s.bezierPatches())
    patches.push_back({"P", PatchKind::kBezier, piece.patch.toBSpline(piece.u, piece.v)});
  ASSERT_EQ(patches.size(), 4u);
  const Vec3 V = s.evaluate(0.4, 0.7).head<3>();
  const CornerReport r = analyze(patches, V);
  EXPECT_EQ(r.valence, 4);
  EXPECT_TRUE(r.closed);
  EXPECT_FALSE(r.degenerate);
  expectAllRelationsVanish(r);
  for (const VertexSeam& seam : r.fourPatch->seams) {
    EXPECT_NEAR(seam.lambda, 1.0, 1e-12);
    EXPECT_NEAR(seam.kappa, 0.0, 1e-12);
    EXPECT_NEAR(seam.dLambda, 0.0, 1e-9);
    EXPECT_NEAR(seam.dKappa, 0.0, 1e-9);
    EXPECT_NEAR(*seam.mu, 0.0, 1e-9);
    EXPECT_NEAR(*seam.nu, 0.0, 1e-9);
  }

  // Affine rescaling of the parameter domains keeps the geometry: lambda becomes a ratio of domain lengths
  // (known exactly), kappa stays 0, and the relations still hold.
  std::vector<Patch> scaled = patches;
  const std::array<std::pair<double, double>, 4> factor = {{{1.0, 1.0}, {3.0, 0.5}, {0.25, 2.0}, {1.5, 0.2}}};
  for (size_t k = 0; k < 4; ++k) {
    const BSplineSurface& p = patches[k].surface;
    scaled[k].surface = p.reparametrized({0.0, factor[k].first * p.domainU().length()},
                                         {1.0, 1.0 + factor[k].second * p.domainV().length()});
  }
  const CornerReport rs = analyze(scaled, V);
  expectAllRelationsVanish(rs);
  // Paper patch k is stored patch fp.corner[k]; lambda of seam (i,j) across a u-seam is (u-speed of
  // j)/(u-speed of i) = factor_i / factor_j (speeds scale with 1/factor); across a v-seam likewise with the v
  // factors. The common parametrisation gives patch 3 the u-speed of patch 2 and the v-speed of patch 4
  // (johansson.md).
  const FourPatchVertex& fp = *rs.fourPatch;
  const auto f = [&](int paper) {
    return factor[static_cast<size_t>(
        rs.corners[static_cast<size_t>(fp.corner[static_cast<size_t>(paper - 1)])].patch)];
  };
  // Which stored direction is the paper's u for each patch: no swaps occur here (all patches share one
  // (u,v)).
  for (int k = 0; k < 4; ++k) EXPECT_FALSE(fp.layout[static_cast<size_t>(k)].swapUV);
  EXPECT_NEAR(fp.seams[0].lambda, f(1).first / f(2).first, 1e-12);    // (1,2)
  EXPECT_NEAR(fp.seams[3].lambda, f(1).second / f(4).second, 1e-12);  // (1,4)
  EXPECT_NEAR(fp.seams[1].lambda, f(1).second / f(4).second,
              1e-12);  // (2,3): v-speeds of 2 (= 1's) and 3 (= 4's)
  EXPECT_NEAR(fp.seams[2].lambda, f(1).first / f(2).first,
              1e-12);  // (4,3): u-speeds of 4 (= 1's) and 3 (= 2's)
  for (const VertexSeam& seam : fp.seams) EXPECT_NEAR(seam.kappa, 0.0, 1e-12);
  EXPECT_NE(fp.seams[0].lambda, 1.0);
}

// The corner jets of polynomial patches clamped at the corner are read from their 3 x 3 corner control points
// (issue 16 goal 2); every other patch is evaluated (basis functions, NURBS Book A2.3 / A4.4). The same four
// B-spline patches once polynomial and once as rational patches with unit weights (the evaluator's route) must give
// the same report: random control points on a 2 x 2 layout whose patches share their boundary rows (a G0 vertex
// where no relation vanishes), non-uniform clamped knots with interior knots, the vertex at the low end of some
// patches' parameters and at the high end of others', degrees 2 to 4, domains away from [0, 1].
TEST(Corner, CornerJetsFromTheControlNetAgreeWithTheEvaluator) {
  std::mt19937_64 rng(77);
  std::uniform_real_distribution<double> jitter(-0.2, 0.2), cut(0.2, 0.8);
  for (const int p : {2, 3, 4}) {
    const int m = p + 2;  // control points per patch and direction: m + 1 (two interior knots)
    std::vector<std::vector<Vec3>> grid(static_cast<size_t>(2 * m + 1), std::vector<Vec3>(static_cast<size_t>(2 * m + 1)));
    for (int i = 0; i <= 2 * m; ++i)
      for (int j = 0; j <= 2 * m; ++j) {
        const double z = jitter(rng), y = jitter(rng), x = jitter(rng);  // drawn last argument first (test_helpers.h)
        grid[static_cast<size_t>(i)][static_cast<size_t>(j)] =
            Vec3(i + x, j + y, 0.3 * std::sin(0.7 * i + 0.4 * j) + z);
      }
    auto knots = [&](double lo, double hi) {  // clamped, two interior knots, non-uniform
      double a = cut(rng), b = cut(rng);
      if (a > b) std::swap(a, b);
      if (b - a < 0.1) b = std::min(0.95, a + 0.1);
      std::vector<double> k(static_cast<size_t>(p + 1), lo);
      k.push_back(lo + a * (hi - lo));
      k.push_back(lo + b * (hi - lo));
      for (int i = 0; i <= p; ++i) k.push_back(hi);
      return k;
    };
    const std::array<std::vector<double>, 2> ku = {knots(-1.0, 2.5), knots(0.3, 0.9)};
    const std::array<std::vector<double>, 2> kv = {knots(5.0, 7.0), knots(-3.0, -2.0)};
    std::vector<Patch> poly, rational;
    for (int a = 0; a < 2; ++a)
      for (int b = 0; b < 2; ++b) {
        Matrix pts((m + 1) * (m + 1), 3);
        for (int i = 0; i <= m; ++i)
          for (int j = 0; j <= m; ++j)
            pts.row(i * (m + 1) + j) = grid[static_cast<size_t>(a * m + i)][static_cast<size_t>(b * m + j)].transpose();
        const auto make = [&](VecX w) {
          return BSplineSurface::create(p, p, ku[static_cast<size_t>(a)], kv[static_cast<size_t>(b)], m + 1, m + 1,
                                        pts, std::move(w))
              .value();
        };
        poly.push_back({"P", PatchKind::kBSpline, make({})});
        rational.push_back({"R", PatchKind::kBSpline, make(VecX::Ones((m + 1) * (m + 1)))});
      }
    const Vec3 V = grid[static_cast<size_t>(m)][static_cast<size_t>(m)];
    const CornerReport rp = analyze(poly, V), rr = analyze(rational, V);
    ASSERT_EQ(rp.valence, 4) << "degree " << p;
    ASSERT_TRUE(rp.fourPatch.has_value() && rr.fourPatch.has_value());
    EXPECT_GT(*rp.normalSpreadDeg, 1.0) << "a G0 vertex, not a smooth one";
    constexpr double kTol = 1e-9;
    auto near = [&](double x, double y, const char* what) {
      EXPECT_NEAR(x, y, kTol * std::max(1.0, std::abs(y))) << what << ", degree " << p;
    };
    near(*rp.normalSpreadDeg, *rr.normalSpreadDeg, "normal spread");
    ASSERT_EQ(rp.curvatureSpread.has_value(), rr.curvatureSpread.has_value());
    if (rp.curvatureSpread) near(*rp.curvatureSpread, *rr.curvatureSpread, "curvature spread");
    near(rp.cornerGap, rr.cornerGap, "corner gap");
    for (size_t k = 0; k < 4; ++k)
      near(rp.fourPatch->g1Relations[k], rr.fourPatch->g1Relations[k], "Theorem 1 relation");
    for (size_t k = 0; k < 4; ++k) {
      const VertexSeam& x = rp.fourPatch->seams[k];
      const VertexSeam& y = rr.fourPatch->seams[k];
      near(x.lambda, y.lambda, "lambda");
      near(x.kappa, y.kappa, "kappa");
      near(x.dLambda, y.dLambda, "lambda'");
      near(x.dKappa, y.dKappa, "kappa'");
      near(x.g1Residual, y.g1Residual, "G1 residual");
      near(x.g2Jump, y.g2Jump, "G2 jump");
    }
  }
}

TEST(Corner, ShearedParallelogramsHaveKnownLambdaKappa) {
  // Affine sectors: every seam is G-infinity, lambda and kappa are constants that solve 2-D linear systems in
  // the parameter plane (derived in johansson.md, "a worked example"):
  //   (1,2): l2 d2 = -lambda l0 d0 - kappa l1 d1      (1,4): l3 d3 = -lambda l1 d1 - kappa l0 d0
  //   (2,3): l3 d3 = -lambda l1 d1 + kappa l2 d2      (4,3): l2 d2 = -lambda l0 d0 + kappa l3 d3
  SectorConfig c;
  const std::vector<Patch> patches = sectorPatches(c);
  const CornerReport r = analyze(patches, kV);
  expectAllRelationsVanish(r);
  const FourPatchVertex& fp = *r.fourPatch;
  EXPECT_EQ(fp.corner[0], 0);
  auto solve = [](const Vec2& target, const Vec2& x, const Vec2& y) {
    Eigen::Matrix2d M;
    M.col(0) = x;
    M.col(1) = y;
    return Eigen::Vector2d(M.inverse() * target);
  };
  const auto& d = c.d;
  const auto& l = c.l;
  const Eigen::Vector2d e12 = solve(l[2] * d[2], -l[0] * d[0], -l[1] * d[1]);
  const Eigen::Vector2d e14 = solve(l[3] * d[3], -l[1] * d[1], -l[0] * d[0]);
  const Eigen::Vector2d e23 = solve(l[3] * d[3], -l[1] * d[1], l[2] * d[2]);
  const Eigen::Vector2d e43 = solve(l[2] * d[2], -l[0] * d[0], l[3] * d[3]);
  const std::array<Eigen::Vector2d, 4> expected = {e12, e23, e43, e14};
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_NEAR(fp.seams[k].lambda, expected[k][0], 1e-10) << "seam " << k;
    EXPECT_NEAR(fp.seams[k].kappa, expected[k][1], 1e-10) << "seam " << k;
    EXPECT_NEAR(fp.seams[k].dLambda, 0.0, 1e-8);
    EXPECT_NEAR(fp.seams[k].dKappa, 0.0, 1e-8);
  }
  // The test is not degenerate: kappa far from 0 and lambda far from 1 on some seams.
  double maxKappa = 0.0, maxLambdaOff = 0.0;
  for (const Eigen::Vector2d& e : expected) {
    maxKappa = std::max(maxKappa, std::abs(e[1]));
    maxLambdaOff = std::max(maxLambdaOff, std::abs(e[0] - 1.0));
  }
  EXPECT_GT(maxKappa, 0.1);
  EXPECT_GT(maxLambdaOff, 0.15);
}

TEST(Corner, NonlinearReparametrisationsStillSatisfyTheorems1And2) {
  // Random quadratic reparametrisations along and across the seams plus twist terms: lambda', kappa', mu, nu
  // are all non-zero, yet the configuration is one smooth surface, so every relation of Theorems 1 and 2 must
  // hold.
  std::mt19937_64 rng(2024);
  std::uniform_real_distribution<double> a(-0.6, 0.6), tw(-0.3, 0.3);
  for (int trial = 0; trial < 4; ++trial) {
    SectorConfig c;
    for (int k = 0; k < 4; ++k) {
      c.fQuad[static_cast<size_t>(k)] = a(rng);
      c.gQuad[static_cast<size_t>(k)] = a(rng);
      c.twist[static_cast<size_t>(k)] = tw(rng);
    }
    const std::vector<Patch> patches = sectorPatches(c);
    const CornerReport r = analyze(patches, kV);
    expectAllRelationsVanish(r);
    double maxDerivative = 0.0, maxMuNu = 0.0;
    for (const VertexSeam& s : r.fourPatch->seams) {
      maxDerivative = std::max({maxDerivative, std::abs(s.dLambda), std::abs(s.dKappa)});
      maxMuNu = std::max({maxMuNu, std::abs(*s.mu), std::abs(*s.nu)});
    }
    EXPECT_GT(maxDerivative, 0.05) << "trial " << trial << ": the construction must exercise lambda', kappa'";
    EXPECT_GT(maxMuNu, 0.05) << "trial " << trial;
  }
}

TEST(Corner, ReorientingTheStoredPatchesChangesNothing) {
  // The mapping onto Figure 2 must absorb any storage orientation: swap and reverse patches 2..4 (and reverse
  // patch 1, which keeps which of its edges is the u-edge) with the kernel and compare every number.
  SectorConfig c;
  c.fQuad = {0.3, -0.2, 0.1, 0.4};
  c.gQuad = {-0.1, 0.25, -0.3, 0.2};
  c.twist = {0.1, -0.2, 0.15, 0.05};
  const std::vector<Patch> base = sectorPatches(c);
  const CornerReport r0 = analyze(base, kV);
  ASSERT_TRUE(r0.fourPatch.has_value());
  std::mt19937_64 rng(7);
  for (int trial = 0; trial < 8; ++trial) {
    std::vector<Patch> p = base;
    for (size_t k = 0; k < 4; ++k) {
      const PatchLayout l{k != 0 && (rng() & 1) != 0, (rng() & 1) != 0, (rng() & 1) != 0};
      p[k].surface = applyLayout(p[k].surface, l);
    }
    const CornerReport r = analyze(p, kV);
    ASSERT_TRUE(r.fourPatch.has_value());
    EXPECT_EQ(r.fourPatch->corner, r0.fourPatch->corner);
    for (size_t k = 0; k < 4; ++k) {
      const VertexSeam& a = r.fourPatch->seams[k];
      const VertexSeam& b = r0.fourPatch->seams[k];
      EXPECT_NEAR(a.lambda, b.lambda, 1e-10);
      EXPECT_NEAR(a.kappa, b.kappa, 1e-10);
      EXPECT_NEAR(a.dLambda, b.dLambda, 1e-8);
      EXPECT_NEAR(a.dKappa, b.dKappa, 1e-8);
      EXPECT_NEAR(*a.mu, *b.mu, 1e-8);
      EXPECT_NEAR(*a.nu, *b.nu, 1e-8);
    }
    // Applying the reported layouts to the stored patches puts V at the corner Figure 2 says.
    const std::array<std::pair<bool, bool>, 4> wanted = {
        {{true, true}, {false, true}, {false, false}, {true, false}}};
    for (size_t k = 0; k < 4; ++k) {
      const int stored = r.corners[static_cast<size_t>(r.fourPatch->corner[k])].patch;
      const BSplineSurface o = applyLayout(p[static_cast<size_t>(stored)].surface, r.fourPatch->layout[k]);
      const double u = wanted[k].first ? o.domainU().hi : o.domainU().lo;
      const double v = wanted[k].second ? o.domainV().hi : o.domainV().lo;
      EXPECT_LT((o.evaluate(u, v).head<3>() - kV).norm(), 1e-12) << "paper patch " << k + 1;
    }
  }
}

TEST(Corner, SquarePyramidHasClosedFormResiduals) {
  // Four planar quads around an apex with edge directions s_k = (cos theta_k, sin theta_k, -h), theta_k = k
  // pi / 2; face k is S(u, v) = u s_k + v s_(k+1). In the common parametrisation (johansson.md) the tangent
  // vectors at V are r1_u = r4_u = -s0, r1_v = r2_v = -s1, r2_u = r3_u = s2, r4_v = r3_v = s3, so the
  // least-squares systems are
  //   (1,2): s2 = l (-s0) + k (-s1)   (1,4): s3 = l (-s1) + k (-s0)   (2,3): s3 = l (-s1) + k s2   (4,3): s2
  //   = l (-s0) + k s3
  // with Gram matrix [[1+h^2, +-h^2], [+-h^2, 1+h^2]]; solved by hand:
  //   lambda = 1 / (1 + 2h^2) on every seam, kappa = -2h^2 / (1 + 2h^2) on (1,2), (1,4) and +2h^2 / (1 +
  //   2h^2) on (2,3), (4,3).
  // Then (2.6): kappa12 - lambda14 kappa43 = kappa (1 + lambda) = kappa14 - lambda12 kappa23, and
  // (2.7): lambda12 - lambda43 - kappa14 kappa43 = kappa^2 = lambda14 - lambda23 - kappa12 kappa23. All
  // tangent vectors have length sqrt(1 + h^2), so the scaled residuals are these numbers themselves. Adjacent
  // faces have normals at the dihedral angle, opposite ones at the largest angle, computed here from the face
  // normals.
  const double h = 0.5;
  std::array<Vec3, 4> s;
  for (int k = 0; k < 4; ++k) {
    const double th = std::numbers::pi / 2 * k;
    s[static_cast<size_t>(k)] = Vec3(std::cos(th), std::sin(th), -h);
  }
  std::vector<Patch> patches;
  for (int k = 0; k < 4; ++k) {
    const Vec3 a = s[static_cast<size_t>(k)], b = s[static_cast<size_t>((k + 1) % 4)];
    Matrix pts(4, 3);
    pts.row(0) = Vec3::Zero().transpose();
    pts.row(1) = b.transpose();
    pts.row(2) = a.transpose();
    pts.row(3) = (a + b).transpose();
    patches.push_back({"F" + std::to_string(k), PatchKind::kBSpline,
                       BSplineSurface(1, 1, KnotVector::bezier(1), KnotVector::bezier(1), 2, 2, pts)});
  }
  const CornerReport r = analyze(patches, Vec3::Zero());
  ASSERT_TRUE(r.fourPatch.has_value());
  const double lambda = 1.0 / (1.0 + 2 * h * h), kappa = -2 * h * h / (1.0 + 2 * h * h);
  const std::array<double, 4> kappas = {kappa, -kappa, -kappa, kappa};  // (1,2), (2,3), (4,3), (1,4)
  for (size_t k = 0; k < 4; ++k) {
    const VertexSeam& seam = r.fourPatch->seams[k];
    EXPECT_NEAR(seam.lambda, lambda, 1e-12);
    EXPECT_NEAR(seam.kappa, kappas[k], 1e-12);
    EXPECT_FALSE(seam.g1);
    EXPECT_FALSE(seam.mu.has_value());
  }
  EXPECT_NEAR(r.fourPatch->g1Relations[0], kappa * (1 + lambda), 1e-12);
  EXPECT_NEAR(r.fourPatch->g1Relations[1], kappa * (1 + lambda), 1e-12);
  EXPECT_NEAR(r.fourPatch->g1Relations[2], kappa * kappa, 1e-12);
  EXPECT_NEAR(r.fourPatch->g1Relations[3], kappa * kappa, 1e-12);
  EXPECT_FALSE(r.fourPatch->g2Relations.has_value());
  double spread = 0.0;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const Vec3 ni = s[static_cast<size_t>(i)].cross(s[static_cast<size_t>((i + 1) % 4)]).normalized();
      const Vec3 nj = s[static_cast<size_t>(j)].cross(s[static_cast<size_t>((j + 1) % 4)]).normalized();
      spread = std::max(spread, std::acos(std::clamp(ni.dot(nj), -1.0, 1.0)));
    }
  EXPECT_NEAR(*r.normalSpreadDeg, spread * 180.0 / std::numbers::pi, 1e-9);
  EXPECT_GT(*r.normalSpreadDeg, 40.0);
}

TEST(Corner, NormalTwistPerturbationIsG1AtTheVertexButNotAlongTheSeams) {
  // Theorem 1's relations are consequences of eq. 2.1 holding at V on every seam (johansson.md): a
  // configuration whose seams are G1 at V always satisfies them. Moving the twist control point of patch 3
  // along the normal keeps every first derivative at V (so: same tangent plane, normal spread 0, relations 0)
  // but tilts the cross derivatives of the seams (2,3) and (4,3) linearly away from V: their first-order
  // defect g1SlopeResidual must equal the finite-difference slope of sin(angle between B_cross and A's
  // tangent plane), measured here with the kernel's derivatives, and the G2 relations must not be evaluated.
  Matrix pts(25, 3);
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j)
      pts.row(i * 5 + j) = Eigen::RowVector3d(i * 0.5, j * 0.5, 0.1 * std::sin(1.3 * i + 0.7 * j));
  const BSplineSurface s =
      BSplineSurface::create(3, 3, {0, 0, 0, 0, 0.5, 1, 1, 1, 1}, {0, 0, 0, 0, 0.5, 1, 1, 1, 1}, 5, 5, pts)
          .value();
  std::vector<Patch> patches;
  for (const BezierPatchPiece& piece : s.bezierPatches())
    patches.push_back({"P" + std::to_string(piece.spanU) + std::to_string(piece.spanV), PatchKind::kBezier,
                       piece.patch.toBSpline(piece.u, piece.v)});
  // Pieces: (0,0), (0,1), (1,0), (1,1) in some order; order them so that corner 0 is piece (0,0) (paper patch
  // 1, V at its (max,max)); then paper patch 3 is piece (1,1) with V at its (min,min).
  std::sort(patches.begin(), patches.end(), [](const Patch& a, const Patch& b) { return a.name < b.name; });
  ASSERT_EQ(patches[3].name, "P11");
  const Vec3 V = s.evaluate(0.5, 0.5).head<3>();
  const Vec3 n = s.normal(0.5, 0.5);
  const double delta = 0.01;
  Matrix q = patches[3].surface.points();
  q.row(1 * 4 + 1) += delta * n.transpose();
  patches[3].surface =
      BSplineSurface(3, 3, patches[3].surface.knotsU(), patches[3].surface.knotsV(), 4, 4, q);

  CornerOptions options;
  options.lengthScale = 1.0;
  const CornerReport r = analyze(patches, V, options);
  ASSERT_TRUE(r.fourPatch.has_value());
  const FourPatchVertex& fp = *r.fourPatch;
  EXPECT_EQ(r.corners[static_cast<size_t>(fp.corner[2])].patch, 3);
  EXPECT_NEAR(*r.normalSpreadDeg, 0.0, 1e-9);
  EXPECT_LT(fp.g1Residual, 1e-12);
  EXPECT_FALSE(fp.g2Relations.has_value());
  for (const VertexSeam& seam : fp.seams) EXPECT_LT(seam.g1Residual, 1e-12);

  // Seam (2,3) runs along u from V = (0.5, 0.5) into u > 0.5 with patch 2 = piece (1,0) below (A side) and
  // patch 3 above; B_cross = d/dv of patch 3 (all pieces share the parametrisation of s, so no
  // reparametrisation is needed).
  const BSplineSurface& p2 = patches[2].surface;
  const BSplineSurface& p3 = patches[3].surface;
  auto sinAngle = [&](double u) {
    const auto dA = p2.derivatives(u, 0.5, 1);
    const auto dB = p3.derivatives(u, 0.5, 1);
    const Vec3 nA = Vec3(dA[1][0].head<3>()).cross(Vec3(dA[0][1].head<3>())).normalized();
    const Vec3 B = dB[0][1].head<3>();
    return std::abs(nA.dot(B)) / B.norm();
  };
  const double h = 1e-5;
  const double speed = Vec3(p2.derivatives(0.5, 0.5, 1)[1][0].head<3>()).norm();
  const double slope = (sinAngle(0.5 + h) - sinAngle(0.5)) / (h * speed);  // per unit length, times L = 1
  EXPECT_GT(slope, 1e-3);
  EXPECT_NEAR(fp.seams[1].g1SlopeResidual, slope, 1e-3 * slope);
  EXPECT_FALSE(fp.seams[1].g1);
  EXPECT_FALSE(fp.seams[2].g1);
  EXPECT_TRUE(fp.seams[0].g1);
  EXPECT_TRUE(fp.seams[3].g1);
}

TEST(Corner, CurvatureJumpAcrossOneSeamLineIsG1NotG2) {
  // Sectors 0,1 (x > 0 side of the line through d1/d3... here: patches on one side of the seam line
  // d[0]-d[2]) get an extra term c * dist^2 * e_z that vanishes to first order on that line: the seams along
  // the line are G1 with a known curvature jump; the other two seams stay G2. The G1 relations hold (G1 at
  // V), the G2 ones are not defined.
  SectorConfig c;
  c.d = {Vec2(1, 0), Vec2(0, 1), Vec2(-1, 0), Vec2(0, -1)};
  c.l = {0.5, 0.5, 0.5, 0.5};
  std::vector<Patch> patches;
  const double bump = 0.8;
  for (int k = 0; k < 4; ++k) {
    const int k1 = (k + 1) % 4;
    auto A = [&, k, k1](double s, double t) {
      const Vec2 p = c.V + c.l[static_cast<size_t>(k)] * s * c.d[static_cast<size_t>(k)] +
                     c.l[static_cast<size_t>(k1)] * t * c.d[static_cast<size_t>(k1)];
      Vec3 r = smoothSurface(p.x(), p.y());
      const double y = p.y() - c.V.y();
      if (k <= 1) r.z() += bump * y * y;  // sectors 0 and 1 lie in y >= V.y
      return r;
    };
    patches.push_back({"S" + std::to_string(k), PatchKind::kBezier, fitBezier(A, 3, 3)});
  }
  const CornerReport r = analyze(patches, kV);
  ASSERT_TRUE(r.fourPatch.has_value());
  const FourPatchVertex& fp = *r.fourPatch;
  EXPECT_LT(fp.g1Residual, kExactTol);
  EXPECT_FALSE(fp.g2Relations.has_value());
  // Seams (1,2) (along d1: x = const, inside y > V.y) and (4,3) (along d3) stay G2; (2,3) along d2 and (1,4)
  // along d0 are the line y = V.y, where the z-curvature in y jumps by 2 * bump. The jump is the
  // normal-curvature jump in the cross direction; at V the cross direction is (anti)parallel to y and |n .
  // e_z| = 1 / |(-z_x, -z_y, 1)|.
  int g2Seams = 0;
  for (const VertexSeam& seam : fp.seams) {
    EXPECT_TRUE(seam.g1);
    if (seam.g2) ++g2Seams;
  }
  EXPECT_EQ(g2Seams, 2);
  EXPECT_TRUE(fp.seams[0].g2);
  EXPECT_TRUE(fp.seams[2].g2);
  // Independent value: B = r_y direction (up to sign and speed); the extra normal curvature in direction y of
  // the graph-like bump 2*bump*(n . e_z) / |r_y|^2 * |d y / d param|^2 / |B|^2 ... = 2 bump (n . e_z) /
  // |r_y|^2.
  const double eps = 1e-6;
  const Vec3 rx = (smoothSurface(0.3 + eps, -0.2) - smoothSurface(0.3 - eps, -0.2)) / (2 * eps);
  const Vec3 ry = (smoothSurface(0.3, -0.2 + eps) - smoothSurface(0.3, -0.2 - eps)) / (2 * eps);
  const Vec3 nrm = rx.cross(ry).normalized();
  const double jump = 2 * bump * std::abs(nrm.z()) / ry.squaredNorm();
  EXPECT_NEAR(std::abs(fp.seams[1].g2Jump), jump, 1e-6 * jump);
  EXPECT_NEAR(std::abs(fp.seams[3].g2Jump), jump, 1e-6 * jump);
  // The curvature spread: the bump adds 2 bump n_z (dy)^2 to the second fundamental form of sectors 0 and 1, a
  // rank-one form whose largest value over unit tangent vectors is 2 bump |n_z| |grad y|^2, where y restricted to
  // the tangent plane has gradient (n x r_x) / |r_x x r_y| (norm |r_x| / |r_x x r_y|).
  const double spread = 2 * bump * std::abs(nrm.z()) * rx.squaredNorm() / rx.cross(ry).squaredNorm();
  ASSERT_TRUE(r.curvatureSpread.has_value());
  EXPECT_NEAR(*r.curvatureSpread, spread, 1e-6 * spread);
}

TEST(Corner, ValenceThreeCubeCornerAndOpenFan) {
  // Three unit squares at a cube corner: valence 3, closed, normals 90 degrees apart (consistently oriented
  // outward or inward, never mixed: a mixed orientation would show 180 degrees).
  auto quad = [](const Vec3& o, const Vec3& a, const Vec3& b) {
    Matrix pts(4, 3);
    pts.row(0) = o.transpose();
    pts.row(1) = (o + b).transpose();
    pts.row(2) = (o + a).transpose();
    pts.row(3) = (o + a + b).transpose();
    return BSplineSurface(1, 1, KnotVector::bezier(1), KnotVector::bezier(1), 2, 2, pts);
  };
  const Vec3 o = Vec3::Zero(), x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ();
  // Deliberately inconsistent storage orientations (the second face is flipped).
  std::vector<Patch> cube = {{"X", PatchKind::kBSpline, quad(o, y, z)},
                             {"Y", PatchKind::kBSpline, quad(o, x, z)},
                             {"Z", PatchKind::kBSpline, quad(o, x, y)}};
  CornerReport r = analyze(cube, o);
  EXPECT_EQ(r.valence, 3);
  EXPECT_TRUE(r.closed);
  EXPECT_FALSE(r.fourPatch.has_value());
  EXPECT_NEAR(*r.normalSpreadDeg, 90.0, 1e-9);
  EXPECT_FALSE(r.curvatureSpread.has_value());  // a crease at the vertex: no common tangent plane to compare in

  // Two coplanar squares sharing one edge: an open fan of valence 2 with normal spread 0, even though the
  // second is stored upside down.
  std::vector<Patch> two = {{"A", PatchKind::kBSpline, quad(o, x, y)},
                            {"B", PatchKind::kBSpline, quad(o, -x, y)}};
  r = analyze(two, o);
  EXPECT_EQ(r.valence, 2);
  EXPECT_FALSE(r.closed);
  EXPECT_NEAR(*r.normalSpreadDeg, 0.0, 1e-9);
  EXPECT_NEAR(r.curvatureSpread.value_or(-1.0), 0.0, 1e-12);  // flat and coplanar, one stored upside down
  // The same with a real 30-degree crease.
  const Vec3 tilted(-std::cos(std::numbers::pi / 6), 0.0, std::sin(std::numbers::pi / 6));
  two[1].surface = quad(o, tilted, y);
  r = analyze(two, o);
  EXPECT_NEAR(*r.normalSpreadDeg, 30.0, 1e-9);
}

TEST(Corner, CollapsedEdgesGiveDegenerateCornersNotNaN) {
  // Four bilinear "triangles" (one edge collapsed to the apex) around a pole, like the teapot's lid: each
  // patch contributes two corners joined by its collapsed edge (one sector), the corners have no normal, and
  // nothing is NaN.
  std::vector<Patch> patches;
  const Vec3 apex(0, 0, 1);
  for (int k = 0; k < 4; ++k) {
    const double a0 = std::numbers::pi / 2 * k, a1 = std::numbers::pi / 2 * (k + 1);
    Matrix pts(4, 3);
    pts.row(0) = apex.transpose();
    pts.row(1) = apex.transpose();
    pts.row(2) = Eigen::RowVector3d(std::cos(a0), std::sin(a0), 0.5);
    pts.row(3) = Eigen::RowVector3d(std::cos(a1), std::sin(a1), 0.5);
    patches.push_back({"T" + std::to_string(k), PatchKind::kBSpline,
                       BSplineSurface(1, 1, KnotVector::bezier(1), KnotVector::bezier(1), 2, 2, pts)});
  }
  std::vector<PatchCorner> corners;
  for (int k = 0; k < 4; ++k) {
    corners.push_back({k, false, false});
    corners.push_back({k, false, true});
  }
  CornerOptions options;
  options.lengthScale = 1.0;
  const Result<CornerReport> r = analyzeCorner(patches, corners, options);
  ASSERT_TRUE(r.isOk());
  EXPECT_TRUE(r->degenerate);
  EXPECT_EQ(r->degenerateCorners.size(), 8u);
  EXPECT_EQ(r->valence, 4);
  EXPECT_TRUE(r->closed);
  EXPECT_FALSE(r->normalSpreadDeg.has_value());
  EXPECT_FALSE(r->fourPatch.has_value());
  EXPECT_TRUE(std::isfinite(r->point.norm()));
}

TEST(Corner, ExplicitLinksAgreeWithGeometricLinksAndBadInputIsRejected) {
  SectorConfig c;
  const std::vector<Patch> patches = sectorPatches(c);
  const std::vector<PatchCorner> corners = cornersAt(patches, kV);
  const std::vector<CornerLink> links = findCornerLinks(patches, corners, 1e-9);
  EXPECT_EQ(links.size(), 4u);
  CornerOptions options;
  options.lengthScale = 1.0;
  const Result<CornerReport> a = analyzeCorner(patches, corners, links, options);
  const Result<CornerReport> b = analyzeCorner(patches, corners, options);
  ASSERT_TRUE(a.isOk() && b.isOk());
  ASSERT_TRUE(a->fourPatch && b->fourPatch);
  for (size_t k = 0; k < 4; ++k) EXPECT_EQ(a->fourPatch->seams[k].lambda, b->fourPatch->seams[k].lambda);

  EXPECT_EQ(analyzeCorner(patches, std::vector<PatchCorner>{}, options).status().code(),
            ErrorCode::kInvalidInput);
  EXPECT_EQ(analyzeCorner(patches, std::vector<PatchCorner>{{7, false, false}}, options).status().code(),
            ErrorCode::kInvalidInput);
  // A link naming an edge that does not pass through its corner.
  std::vector<CornerLink> bad = links;
  bad[0].aEdge = corners[static_cast<size_t>(bad[0].a)].uEdge() == Edge::U0 ? Edge::U1 : Edge::U0;
  EXPECT_EQ(analyzeCorner(patches, corners, bad, options).status().code(), ErrorCode::kInvalidInput);
}


// analyzeCorner keeps its working storage per thread and reuses it from vertex to vertex (checkModel analyses
// thousands). Reference: each vertex analysed first on a thread of its own (fresh storage). Then the vertices,
// different in size (8, 4, 3 and 2 corners), in fan structure (closed, open, two fans at one point) and in their
// collapsed edges, analysed one after another on this thread, each twice in a mixed order: every report must equal
// its reference exactly (no state carried over from a previous vertex).
TEST(Corner, ReusedWorkingStorageCarriesNothingFromOneVertexToTheNext) {
  struct Vertex {
    std::vector<Patch> patches;
    std::vector<PatchCorner> corners;
  };
  std::vector<Vertex> vertices;
  // A 4-valent vertex of one smooth surface (Theorems 1 and 2), sheared and reparametrised.
  SectorConfig sc;
  sc.fQuad = {0.2, -0.1, 0.15, 0.0};
  sc.gQuad = {0.0, 0.1, -0.2, 0.1};
  {
    std::vector<Patch> p = sectorPatches(sc);
    vertices.push_back({p, cornersAt(p, kV)});
  }
  // A pole: four bilinear triangles, each with its edge collapsed at the apex (eight corners, four sectors).
  {
    Vertex v;
    const Vec3 apex(0, 0, 1);
    for (int k = 0; k < 4; ++k) {
      const double a0 = std::numbers::pi / 2 * k, a1 = std::numbers::pi / 2 * (k + 1);
      Matrix pts(4, 3);
      pts.row(0) = apex.transpose();
      pts.row(1) = apex.transpose();
      pts.row(2) = Eigen::RowVector3d(std::cos(a0), std::sin(a0), 0.5);
      pts.row(3) = Eigen::RowVector3d(std::cos(a1), std::sin(a1), 0.5);
      v.patches.push_back({"T" + std::to_string(k), PatchKind::kBSpline,
                           BSplineSurface(1, 1, KnotVector::bezier(1), KnotVector::bezier(1), 2, 2, pts)});
      v.corners.push_back({k, false, false});
      v.corners.push_back({k, false, true});
    }
    vertices.push_back(std::move(v));
  }
  auto quad = [](const Vec3& o, const Vec3& a, const Vec3& b) {
    Matrix pts(4, 3);
    pts.row(0) = o.transpose();
    pts.row(1) = (o + b).transpose();
    pts.row(2) = (o + a).transpose();
    pts.row(3) = (o + a + b).transpose();
    return BSplineSurface(1, 1, KnotVector::bezier(1), KnotVector::bezier(1), 2, 2, pts);
  };
  const Vec3 o = Vec3::Zero(), x = Vec3::UnitX(), y = Vec3::UnitY(), z = Vec3::UnitZ();
  {  // a cube corner: closed, valence 3, one face stored flipped
    std::vector<Patch> p = {{"X", PatchKind::kBSpline, quad(o, y, z)},
                            {"Y", PatchKind::kBSpline, quad(o, x, z)},
                            {"Z", PatchKind::kBSpline, quad(o, x, y)}};
    vertices.push_back({p, cornersAt(p, o)});
  }
  {  // two squares touching at one corner only: two open fans at the point
    std::vector<Patch> p = {{"A", PatchKind::kBSpline, quad(o, x, y)},
                            {"B", PatchKind::kBSpline, quad(o, -x, -z)}};
    vertices.push_back({p, cornersAt(p, o)});
  }
  auto run = [](const Vertex& v) {
    CornerOptions options;
    options.lengthScale = 1.0;
    Result<CornerReport> r = analyzeCorner(v.patches, v.corners, options);
    EXPECT_TRUE(r.isOk());
    return r.isOk() ? r.value() : CornerReport{};
  };
  std::vector<CornerReport> reference(vertices.size());
  for (size_t k = 0; k < vertices.size(); ++k) std::thread([&, k] { reference[k] = run(vertices[k]); }).join();
  EXPECT_EQ(reference[1].valence, 4);
  EXPECT_TRUE(reference[1].degenerate);
  EXPECT_EQ(reference[2].valence, 3);
  EXPECT_NE(std::count(reference[3].notes.begin(), reference[3].notes.end(), "2 separate fans meet at the vertex"), 0);
  ASSERT_TRUE(reference[0].fourPatch.has_value());
  auto same = [](const std::optional<double>& a, const std::optional<double>& b) {
    return a.has_value() == b.has_value() && (!a || *a == *b);
  };
  for (const size_t k : {1, 0, 3, 2, 0, 1, 2, 3}) {
    SCOPED_TRACE("vertex " + std::to_string(k));
    const CornerReport r = run(vertices[k]);
    const CornerReport& e = reference[k];
    EXPECT_EQ(r.point, e.point);
    EXPECT_EQ(r.cornerGap, e.cornerGap);
    ASSERT_EQ(r.corners.size(), e.corners.size());
    for (size_t c = 0; c < r.corners.size(); ++c) {
      EXPECT_EQ(r.corners[c].patch, e.corners[c].patch);
      EXPECT_EQ(r.corners[c].uMax, e.corners[c].uMax);
      EXPECT_EQ(r.corners[c].vMax, e.corners[c].vMax);
    }
    EXPECT_EQ(r.sectors, e.sectors);
    EXPECT_EQ(r.orientation, e.orientation);
    EXPECT_EQ(r.valence, e.valence);
    EXPECT_EQ(r.closed, e.closed);
    EXPECT_EQ(r.degenerate, e.degenerate);
    EXPECT_EQ(r.degenerateCorners, e.degenerateCorners);
    EXPECT_TRUE(same(r.normalSpreadDeg, e.normalSpreadDeg));
    EXPECT_TRUE(same(r.curvatureSpread, e.curvatureSpread));
    EXPECT_TRUE(same(r.curvatureSpreadRel, e.curvatureSpreadRel));
    EXPECT_EQ(r.notes, e.notes);
    ASSERT_EQ(r.fourPatch.has_value(), e.fourPatch.has_value());
    if (r.fourPatch) {
      EXPECT_EQ(r.fourPatch->g1Relations, e.fourPatch->g1Relations);
      EXPECT_EQ(r.fourPatch->g1Residual, e.fourPatch->g1Residual);
      EXPECT_EQ(r.fourPatch->g2Relations, e.fourPatch->g2Relations);
      EXPECT_EQ(r.fourPatch->g2Residual, e.fourPatch->g2Residual);
      for (size_t s = 0; s < 4; ++s) {
        EXPECT_EQ(r.fourPatch->seams[s].lambda, e.fourPatch->seams[s].lambda);
        EXPECT_EQ(r.fourPatch->seams[s].kappa, e.fourPatch->seams[s].kappa);
        EXPECT_EQ(r.fourPatch->seams[s].g2Jump, e.fourPatch->seams[s].g2Jump);
      }
    }
  }
}

}  // namespace
}  // namespace seam
