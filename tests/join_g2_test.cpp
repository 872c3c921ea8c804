// G2 joins of one seam (issue 14 §1): random pairs whose seam is G1 with a curvature jump of 10-100 % come out G2,
// by the certified check AND by an independent comparison, written here, of the normal curvatures of both sides in
// three tangent directions at 61 points along the seam. Polynomial and rational patches, the neighbour mirrored
// (its edge running the other way), connecting function lambda > 0, rows beyond the third untouched.
//
// Construction (exact, independent of the code under test): A is a random bicubic B-spline patch (Bezier in u,
// interior knots in v). B's first two rows along its U0 edge are A's C1 reflection across A's U1 edge, in
// homogeneous coordinates (b0 = a3, b1 = 2 a3 - a2), so the seam is C1, hence G1, by construction; B's third row is
// the C2 reflection (a1 - 4 a2 + 4 a3) plus a random offset, which makes the curvature jump.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "seam/repair/join.h"
#include "seam_test_support.h"
#include "test_helpers.h"

namespace seam {
namespace {

using test::uniformReal;

/// After a G2 join the curvatures on the two sides agree to this fraction of the curvature scale (second
/// derivatives of the least-squares solution lose ~2 digits more than points; the join tests use the same bound).
constexpr double kJoinedCurvatureRel = 1e-6;
/// After a join: gap relative to the patch size, and angle in degrees (round-off of the solve).
constexpr double kJoinedGapRel = 1e-9;
constexpr double kJoinedAngleDeg = 1e-6;
/// Points along the seam where the test compares curvatures (the issue asks for at least 50).
constexpr int kSeamSamples = 61;
/// The random offset of B's third row is accepted when the seam's curvature jump before the join is within
/// [kMinJumpBefore, kMaxJumpBefore] of the curvature scale (the "10-100 %").
constexpr double kMinJumpBefore = 0.10, kMaxJumpBefore = 1.00;

struct Pair {
  BSplineSurface a, b;  // the seam: A's U1 edge against B's U0 edge (B possibly reversed along it)
  bool mirrored = false;
  bool valid = true;
};

/// Homogeneous control net (x w, y w, z w, w) of a 3-D patch, or the points themselves when polynomial.
Matrix homogeneousOf(const BSplineSurface& s) { return s.isRational() ? s.homogeneous() : s.points(); }

BSplineSurface fromRows(const BSplineSurface& like, int numU, const Matrix& h, bool rational) {
  return BSplineSurface::fromHomogeneous(3, like.degreeV(), KnotVector::clampedUniform(3, numU), like.knotsV(), numU,
                                         like.numV(), h, rational);
}

/// Rational pairs whose reflected weights fall below this are not used (B's weights must be positive).
constexpr double kMinWeight = 0.2;

/// B's homogeneous net multiplied by the linear function g(v) = (1 - v) g0 + v g1 (a Bezier patch in v, degree 3 ->
/// 4, exact Bernstein product (g h)_k = ((4 - k) g0 h_k + k g1 h_{k-1}) / 4). The surface is the same point set:
/// the factor cancels in x / w. Along the seam the homogeneous G0 factor rho = w_B / w_A becomes g, which varies.
struct VaryingRho {
  double g0 = 1.0, g1 = 1.0;
};

BSplineSurface timesLinearInV(const Matrix& hb, bool rational, const VaryingRho& g) {
  constexpr int kRows = 4, kCols = 4;  // bicubic Bezier
  Matrix h(kRows * (kCols + 1), 4);
  for (int i = 0; i < kRows; ++i) {
    auto homog = [&](int j) {
      Eigen::RowVector4d r;
      if (rational) r = hb.row(i * kCols + j);
      else r << hb.row(i * kCols + j), 1.0;
      return r;
    };
    for (int k = 0; k <= kCols; ++k) {
      Eigen::RowVector4d c = Eigen::RowVector4d::Zero();
      if (k < kCols) c += (kCols - k) * g.g0 * homog(k);
      if (k > 0) c += k * g.g1 * homog(k - 1);
      h.row(i * (kCols + 1) + k) = c / kCols;
    }
  }
  return BSplineSurface::fromHomogeneous(3, 4, KnotVector::clampedUniform(3, kRows), KnotVector::clampedUniform(4, 5),
                                         kRows, kCols + 1, h, true);
}

/// A random pair with a G1 seam and a curvature jump scaled by `offset` (valid = false when B's weights would not
/// be positive). With `rho`, A is a Bezier patch in v and B's net is multiplied by rho's linear function of v.
Pair makePair(std::mt19937_64& rng, bool rational, bool mirrored, double offset, double weightScaleB,
              const std::optional<VaryingRho>& rho = std::nullopt,
              const std::optional<KnotVector>& knotsV = std::nullopt) {
  // Cubic in v: 1-3 spans (one with rho), or the given knots.
  const int nv = knotsV ? knotsV->size() - 4 : rho ? 4 : test::uniformInt(rng, 4, 6);
  Matrix p(4 * nv, 3);
  VecX w(rational ? 4 * nv : 0);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < nv; ++j) {
      const double x = i / 3.0, y = static_cast<double>(j) / (nv - 1);
      p.row(i * nv + j) << x + uniformReal(rng, -0.05, 0.05), y + uniformReal(rng, -0.05, 0.05),
          0.3 * std::sin(2.0 * x + 1.3 * y) + uniformReal(rng, -0.05, 0.05);
      if (rational) w[i * nv + j] = uniformReal(rng, 0.8, 1.25);  // 2 w3 - w2 > 0: B's weights stay positive
    }
  const BSplineSurface a(3, 3, KnotVector::clampedUniform(3, 4), knotsV ? *knotsV : KnotVector::clampedUniform(3, nv),
                         4, nv, p, w);
  const Matrix ha = homogeneousOf(a);
  const int cols = static_cast<int>(ha.cols());
  Matrix hb(4 * nv, cols);
  for (int j = 0; j < nv; ++j) {
    const auto a1 = ha.row(1 * nv + j), a2 = ha.row(2 * nv + j), a3 = ha.row(3 * nv + j);
    hb.row(0 * nv + j) = a3;
    hb.row(1 * nv + j) = 2.0 * a3 - a2;
    hb.row(2 * nv + j) = a1 - 4.0 * a2 + 4.0 * a3;  // C2 reflection ...
    const double wj = rational ? hb(2 * nv + j, 3) : 1.0;
    for (int c = 0; c < 3; ++c) hb(2 * nv + j, c) += wj * offset * uniformReal(rng, -1.0, 1.0);  // ... plus a jump
    hb(2 * nv + j, 2) += wj * offset;  // a definite bend across the seam
    // Row 3 (no influence on the seam): row 2's point continued by the step from row 1, with row 2's weight.
    const double w1 = rational ? hb(1 * nv + j, 3) : 1.0;
    for (int c = 0; c < 3; ++c)
      hb(3 * nv + j, c) = wj * (2.0 * hb(2 * nv + j, c) / wj - hb(1 * nv + j, c) / w1);
    if (rational) hb(3 * nv + j, 3) = wj;
  }
  if (rational && !(hb.col(3).minCoeff() >= kMinWeight)) return {a, a, mirrored, false};  // B's weights must stay positive
  if (rational) hb *= weightScaleB;  // the same surface B, with all its weights scaled (rho = weightScaleB)
  BSplineSurface b = rho ? timesLinearInV(hb, rational, *rho) : fromRows(a, 4, hb, rational);
  if (mirrored) b = b.reversedV();
  return {a, b, mirrored};
}

/// Point, first and second derivatives of s at (u, v), from the evaluator.
struct Jet {
  Vec3 p, su, sv, suu, suv, svv;
};
Jet jetAt(const BSplineSurface& s, double u, double v) {
  const auto d = s.derivatives(u, v, 2);
  auto v3 = [](const VecX& x) { return Vec3(x[0], x[1], x[2]); };
  return {v3(d[0][0]), v3(d[1][0]), v3(d[0][1]), v3(d[2][0]), v3(d[1][1]), v3(d[0][2])};
}

/// Normal curvature of the surface with jet j in the 3-D tangent direction d, measured against the unit normal n:
/// (du, dv) solves S_u du + S_v dv = d in the least-squares sense (exact when d is tangent), and
/// k = n . (S_uu du^2 + 2 S_uv du dv + S_vv dv^2) / |d|^2.
double normalCurvature(const Jet& j, const Vec3& d, const Vec3& n) {
  Eigen::Matrix<double, 3, 2> J;
  J.col(0) = j.su;
  J.col(1) = j.sv;
  const Eigen::Vector2d uv = (J.transpose() * J).ldlt().solve(J.transpose() * d);
  const Vec3 second = j.suu * uv[0] * uv[0] + 2.0 * j.suv * uv[0] * uv[1] + j.svv * uv[1] * uv[1];
  return n.dot(second) / d.squaredNorm();
}

/// Distance (fraction of the seam's parameter range) of the samples taken on both sides of an interior knot.
constexpr double kKnotSampleShift = 1e-9;

struct Comparison {
  double gap = 0.0, angleDeg = 0.0, jumpRel = 0.0;
};

/// The test's own measure of the seam: at kSeamSamples points, the gap, the angle between the normals and the
/// largest difference of the normal curvatures in the edge direction, across it and diagonally, relative to the
/// curvature scale (largest |curvature| seen, at least 1 / the patch size).
Comparison compareAlongSeam(const Pair& pr, double size) {
  Comparison out;
  double scale = 1.0 / size, worstJump = 0.0;
  const Interval va = pr.a.domainV(), vb = pr.b.domainV();
  // Samples at an interior knot of the seam's direction are taken just before and just after it: with a double or
  // triple knot the edge is only C1 or C0 there, and the two sides' one-sided limits are what must agree.
  std::vector<double> ts;
  const std::vector<double>& knots = pr.a.knotsV().values();
  for (int k = 0; k < kSeamSamples; ++k) {
    const double t = static_cast<double>(k) / (kSeamSamples - 1);
    const bool atKnot = std::any_of(knots.begin(), knots.end(), [&](double x) {
      return x > va.lo && x < va.hi && std::abs(va.lo + t * va.length() - x) < kKnotSampleShift * va.length();
    });
    if (atKnot) {
      ts.push_back(t - kKnotSampleShift);
      ts.push_back(t + kKnotSampleShift);
    } else {
      ts.push_back(t);
    }
  }
  for (const double t : ts) {
    const double v1 = va.lo + t * va.length();
    const double v2 = pr.mirrored ? vb.hi - t * vb.length() : vb.lo + t * vb.length();
    const Jet ja = jetAt(pr.a, pr.a.domainU().hi, v1), jb = jetAt(pr.b, pr.b.domainU().lo, v2);
    out.gap = std::max(out.gap, (ja.p - jb.p).norm());
    const Vec3 na = ja.su.cross(ja.sv).normalized();
    Vec3 nb = jb.su.cross(jb.sv).normalized();
    if (na.dot(nb) < 0.0) nb = -nb;  // the mirrored neighbour's normal points the other way
    out.angleDeg = std::max(out.angleDeg, std::atan2(na.cross(nb).norm(), na.dot(nb)) * 180.0 / M_PI);
    const Vec3 along = ja.sv.normalized();
    const Vec3 across = (ja.su - ja.su.dot(along) * along).normalized();
    for (const Vec3& d : {along, across, Vec3((along + across).normalized())}) {
      const double ka = normalCurvature(ja, d, na), kb = normalCurvature(jb, d, na);
      scale = std::max({scale, std::abs(ka), std::abs(kb)});
      worstJump = std::max(worstJump, std::abs(ka - kb));
    }
  }
  out.jumpRel = worstJump / scale;
  return out;
}

double patchSize(const BSplineSurface& s) { return test::controlScale(s.points()); }

JoinOptions g2Options() {
  JoinOptions o;
  o.continuity = GeometricClass::kG2;
  return o;
}

void runTrials(bool rational, std::uint64_t seed, double weightScaleB = 1.0, bool varyingRho = false,
               const std::optional<KnotVector>& knotsV = std::nullopt) {
  std::mt19937_64 rng(seed);
  int accepted = 0, achieved = 0, refusedAsFolds = 0;
  for (int trial = 0; trial < 200 && accepted < 12; ++trial) {
    const bool mirrored = trial % 2 == 1;
    const double offset = uniformReal(rng, 0.005, 0.08);
    std::optional<VaryingRho> rho;
    if (varyingRho) rho = VaryingRho{uniformReal(rng, 0.5, 1.0), uniformReal(rng, 1.5, 3.0)};  // rho: g0 -> g1
    const Pair pr = makePair(rng, rational, mirrored, offset, weightScaleB, rho, knotsV);
    if (!pr.valid) continue;
    const double size = std::max(patchSize(pr.a), patchSize(pr.b));
    const Comparison before = compareAlongSeam(pr, size);
    // The construction is G1 exactly; keep the pairs whose jump is in the 10-100 % band.
    ASSERT_LE(before.gap, kJoinedGapRel * size);
    ASSERT_LE(before.angleDeg, kJoinedAngleDeg);
    if (before.jumpRel < kMinJumpBefore || before.jumpRel > kMaxJumpBefore) continue;
    ++accepted;
    SCOPED_TRACE("trial " + std::to_string(trial) + (mirrored ? " (mirrored)" : "") + ", jump before " +
                 std::to_string(before.jumpRel));

    Model m;
    m.patches.push_back({"A", PatchKind::kBSpline, pr.a});
    m.patches.push_back({"B", PatchKind::kBSpline, pr.b});
    auto r = joinSeam(m, "B", Edge::U0, "A", Edge::U1, g2Options());
    ASSERT_TRUE(r.isOk()) << r.status().message();
    const JoinReport& rep = r->report;
    EXPECT_EQ(rep.before.geometric, GeometricClass::kG1);
    // A is never touched.
    EXPECT_EQ(r->model.patches[0].surface.points(), pr.a.points());
    if (!rep.achieved) {
      // A join that cannot reach G2 must leave B as it was (never half-done) and say so.
      EXPECT_TRUE(rep.reverted || rep.after.geometric == rep.before.geometric);
      EXPECT_EQ(r->model.patches[1].surface.points(), pr.b.points());
      const bool fold = std::any_of(rep.notes.begin(), rep.notes.end(), [](const std::string& n) {
        return n.find("would turn over") != std::string::npos || n.find("would fold") != std::string::npos;
      });
      if (fold) {
        // Refused as a fold (issue 36 goal 2; these random B are often folded already, cusps and
        // self-intersections): with the fold test off, the join turns B's normal over somewhere (dense sampling).
        JoinOptions off = g2Options();
        off.refuseFolds = false;
        auto f = joinSeam(m, "B", Edge::U0, "A", Edge::U1, off);
        ASSERT_TRUE(f.isOk());
        EXPECT_GT(seamtest::sampledTurn(pr.b, f->model.patches[1].surface, 121).angleDeg, 90.0);
        ++refusedAsFolds;
      }
      continue;
    }
    ++achieved;
    if (varyingRho) {  // the join saw the varying ratio (else the construction did not exercise it)
      EXPECT_TRUE(std::any_of(rep.notes.begin(), rep.notes.end(), [](const std::string& n) {
        return n.find("weight ratio rho") != std::string::npos;
      }));
    }
    const Pair after{pr.a, r->model.patches[1].surface, pr.mirrored};
    // The certified check: G2, certified, with its bound next to G0 and G1.
    EXPECT_EQ(rep.after.geometric, GeometricClass::kG2);
    EXPECT_TRUE(rep.after.certified);
    EXPECT_LE(rep.after.g2RelMax, kJoinedCurvatureRel);
    ASSERT_TRUE(rep.lambdaMin.has_value());
    EXPECT_GT(*rep.lambdaMin, 0.0);
    // The test's own comparison agrees.
    const Comparison c = compareAlongSeam(after, size);
    EXPECT_LE(c.gap, kJoinedGapRel * size);
    EXPECT_LE(c.angleDeg, kJoinedAngleDeg);
    EXPECT_LE(c.jumpRel, kJoinedCurvatureRel) << "before " << before.jumpRel;
    // Rows beyond the third are untouched: with no knot inserted along u, B's rows i >= 3 are the input's.
    const BSplineSurface& nb = after.b;
    if (nb.numU() == pr.b.numU() && nb.numV() == pr.b.numV() && nb.degreeU() == pr.b.degreeU() &&
        !nb.isRational() == !pr.b.isRational()) {
      for (int j = 0; j < nb.numV(); ++j) {
        EXPECT_EQ(nb.point(3, j), pr.b.point(3, j)) << "row 3, column " << j;
      }
    }
  }
  EXPECT_GE(accepted, 10) << "too few random pairs in the 10-100 % band: the construction changed";
  EXPECT_EQ(achieved + refusedAsFolds, accepted) << "G2 joins that were declined";
  // The random B of these pairs are often folded already (a cusp and several self-intersections by `seam
  // regularity`); a G2 join that only moves rows 0-2 of a 4-row B then turns B's normal over near its far edge.
  // Every such refusal is confirmed above; most pairs must still come out G2.
  EXPECT_GE(achieved, 2) << refusedAsFolds << " refused as folds";
  std::printf("G2 joins: %d of %d achieved, %d refused as folds (confirmed by sampling)\n", achieved, accepted,
              refusedAsFolds);
}

TEST(G2Join, PolynomialPairsWithACurvatureJumpComeOutG2) { runTrials(false, 14001); }

TEST(G2Join, RationalPairsWithACurvatureJumpComeOutG2) { runTrials(true, 14002); }

// B's weights all scaled by 2.5 (the same surface): the homogeneous G0 factor rho is 2.5, not 1, and the quadratic
// terms of the G2 equations carry 1 / rho.
TEST(G2Join, RationalPairsWithScaledWeightsComeOutG2) { runTrials(true, 14003, 2.5); }

// B's homogeneous net multiplied by a linear function of v (the same surface, degree 4 along the seam): rho = w_B /
// w_A varies along the seam by a factor 1.5-6, and the G2 equations are multiplied through by it. A polynomial and
// A rational.
TEST(G2Join, PairsWhoseWeightRatioVariesAlongTheSeamComeOutG2) {
  runTrials(false, 14004, 1.0, true);
  runTrials(true, 14005, 1.0, true);
}

// Double and triple interior knots along the seam (issue 14 §2, the thesis' Theorems 9 and 10): the edge curve is
// only C1 (double) or C0 (triple) at the knot, so the blending functions may jump there. Both patches share the
// knots; the G2 conditions hold span by span.
TEST(G2Join, PairsWithDoubleAndTripleInteriorKnotsAlongTheSeamComeOutG2) {
  const KnotVector twice({0, 0, 0, 0, 0.5, 0.5, 1, 1, 1, 1});
  const KnotVector thrice({0, 0, 0, 0, 0.4, 0.4, 0.4, 1, 1, 1, 1});
  const KnotVector mixed({0, 0, 0, 0, 0.3, 0.6, 0.6, 0.6, 1, 1, 1, 1});
  runTrials(false, 14006, 1.0, false, twice);
  runTrials(true, 14007, 1.0, false, thrice);
  runTrials(false, 14008, 1.0, false, mixed);
  runTrials(true, 14009, 2.5, false, mixed);
}

}  // namespace
}  // namespace seam
