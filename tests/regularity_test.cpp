// Tests of the regularity module (issue 5): exact hull separation, the Dyn-Levin-Yad-Shalom and Lau
// conditions, whole-curve / whole-surface verdicts, and the subdivision defect search.
//
// Expected values come from independent routes: constructions with a known defect (cusps from a hand-solved
// derivative equation, the nodal cubic, the Whitney umbrella), the paper's own statements (Theorem 2.8, W_k
// from brute-force sign patterns of Cox-de Boor B-splines), and cross-checks between the certificate and the
// search.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "seam/regularity/conditions.h"
#include "seam/regularity/defect_search.h"
#include "seam/regularity/regularity.h"
#include "seam/regularity/separation.h"
#include "test_helpers.h"

namespace seam::regularity {
namespace {

using test::uniformReal;

/// Rows of a matrix from a list of points.
Matrix rowsOf(std::initializer_list<std::initializer_list<double>> pts) {
  const int n = static_cast<int>(pts.size());
  const int d = static_cast<int>(pts.begin()->size());
  Matrix m(n, d);
  int i = 0;
  for (const auto& p : pts) {
    int k = 0;
    for (double x : p) m(i, k++) = x;
    ++i;
  }
  return m;
}

/// Uniform (unclamped) knots 0, 1, ..., n + p: the paper's setting (1.1), shifted.
std::vector<double> uniformKnotVector(int degree, int numPoints) {
  std::vector<double> t(static_cast<size_t>(numPoints + degree + 1));
  for (size_t i = 0; i < t.size(); ++i) t[i] = static_cast<double>(i);
  return t;
}

BSplineCurve uniformCurve(const Matrix& points, int degree) {
  Result<BSplineCurve> c =
      BSplineCurve::create(degree, uniformKnotVector(degree, static_cast<int>(points.rows())), points);
  EXPECT_TRUE(c.isOk()) << c.status().message();
  return *c;
}

BSplineSurface uniformSurface(const Matrix& points, int du, int dv, int nu, int nv) {
  Result<BSplineSurface> s =
      BSplineSurface::create(du, dv, uniformKnotVector(du, nu), uniformKnotVector(dv, nv), nu, nv, points);
  EXPECT_TRUE(s.isOk()) << s.status().message();
  return *s;
}

/// Max distance between sum w_i a_i and the witness (a check of the rounded exact witness).
double witnessResidual(const Matrix& set, const std::vector<double>& w, const Vec3& witness) {
  Vec3 s = Vec3::Zero();
  double sum = 0.0;
  for (Eigen::Index i = 0; i < set.rows(); ++i) {
    for (Eigen::Index k = 0; k < set.cols(); ++k) s[k] += w[i] * set(i, k);
    sum += w[i];
    EXPECT_GE(w[i], 0.0);
  }
  EXPECT_NEAR(sum, 1.0, 1e-14);
  return (s - witness).norm();
}

// =====================================================================================================================
// W_k, re-derived: for uniform B-splines the sign pattern of B_i(t1) - B_i(t2) (t1 < t2 in one span) and of
// B_i'(t) changes exactly once, at a split r that must lie in W_k (Lemma 2.1 / proofs of Theorems 2.3, 2.4).
// =====================================================================================================================

/// The split r (number of leading non-negative entries before the non-positive tail) of a vector with one
/// sign change from >= 0 to <= 0 (entries with |x| <= eps count for either side); the set of all valid r.
std::vector<int> validSplits(const std::vector<double>& d, double eps) {
  std::vector<int> out;
  const int k = static_cast<int>(d.size());
  for (int r = 1; r < k; ++r) {
    bool ok = true;
    for (int i = 0; i < r; ++i) ok = ok && d[i] >= -eps;
    for (int i = r; i < k; ++i) ok = ok && d[i] <= eps;
    if (ok) out.push_back(r);
  }
  return out;
}

TEST(RegularitySplits, PaperSplitsAreW_k) {
  EXPECT_EQ(paperSplits(3), (std::vector<int>{1, 2}));
  EXPECT_EQ(paperSplits(4), (std::vector<int>{2}));
  EXPECT_EQ(paperSplits(5), (std::vector<int>{2, 3}));
  EXPECT_EQ(paperSplits(6), (std::vector<int>{3}));
  EXPECT_EQ(allSplits(4), (std::vector<int>{1, 2, 3}));
}

TEST(RegularitySplits, BruteForceSignPatternsOfUniformBSplinesLieInW_k) {
  std::mt19937_64 rng(11);
  for (int k = 3; k <= 7; ++k) {
    const int p = k - 1;
    // Knots 0..3k; the span [p + k, p + k + 1] is interior, basis functions i = k .. k + p are non-zero
    // there.
    const std::vector<double> t = uniformKnotVector(p, 3 * k - p);
    const int span = p + k;
    const std::vector<int> w = paperSplits(k);
    for (int trial = 0; trial < 200; ++trial) {
      double t1 = span + uniformReal(rng, 0.0, 1.0);
      double t2 = span + uniformReal(rng, 0.0, 1.0);
      if (t1 > t2) std::swap(t1, t2);
      const Matrix b1 = test::basisTable(t, p, t1, 1);
      const Matrix b2 = test::basisTable(t, p, t2, 0);
      std::vector<double> diff;
      std::vector<double> deriv;
      for (int i = span - p; i <= span; ++i) {
        diff.push_back(b1(0, i) - b2(0, i));
        deriv.push_back(-b1(1, i));
      }
      // Self-intersection (Theorem 2.4): some valid split of B(t1) - B(t2) is in W_k.
      const std::vector<int> rs = validSplits(diff, 1e-14);
      ASSERT_FALSE(rs.empty());
      bool inW = false;
      for (int r : rs) inW = inW || std::find(w.begin(), w.end(), r) != w.end();
      EXPECT_TRUE(inW) << "k=" << k << " t1=" << t1 << " t2=" << t2;
      // Critical points (Theorem 2.3): the split of -B'(t) too.
      const std::vector<int> rd = validSplits(deriv, 1e-14);
      bool inWd = false;
      for (int r : rd) inWd = inWd || std::find(w.begin(), w.end(), r) != w.end();
      EXPECT_TRUE(inWd) << "k=" << k << " t=" << t1;
    }
  }
}

// =====================================================================================================================
// Exact separation
// =====================================================================================================================

TEST(RegularitySeparation, ExactCheckRejectsAPlaneThatDoublesAccept) {
  // n . x = 1e16 - 1 - 1e16 = -1 exactly, but 0 in doubles: with offset -0.5 a naive check accepts the point.
  const Hyperplane plane{Vec3(1, 1, 1), -0.5};
  const Matrix first = rowsOf({{1e16, -1.0, -1e16}});
  const Matrix second = rowsOf({{0.0, 0.0, -10.0}});
  const double naive = plane.normal.dot(Vec3(first.row(0).transpose())) - plane.offset;
  ASSERT_GT(naive, 0.0) << "the construction must fool double arithmetic";
  EXPECT_FALSE(isStrictlySeparating(plane, first, second));
  // A plane one unit in the last place away from touching is accepted; touching is rejected.
  const Matrix a = rowsOf({{1.0, 0.0}});
  const Matrix b = rowsOf({{0.0, 0.0}});
  EXPECT_FALSE(isStrictlySeparating({Vec3(1, 0, 0), 1.0}, a, b));
  EXPECT_TRUE(isStrictlySeparating({Vec3(1, 0, 0), std::nextafter(1.0, 0.0)}, a, b));
  // The pipeline still finds the true answer for the first pair: -1 > -10 is separable.
  Result<Separation> s = separateHulls(first, second);
  ASSERT_TRUE(s.isOk());
  EXPECT_TRUE(s->separated);
  EXPECT_TRUE(isStrictlySeparating(s->plane, first, second));
}

TEST(RegularitySeparation, TouchingSegmentsMeetAtTheTouchingPoint) {
  // [(0,0),(2,0)] and [(1,0),(1,1)] touch at (1,0): touching counts as meeting.
  const Matrix a = rowsOf({{0, 0}, {2, 0}});
  const Matrix b = rowsOf({{1, 0}, {1, 1}});
  for (int route = 0; route < 4; ++route) {
    SeparationOptions o;
    o.useQuickDirection = route < 1;
    o.useMinNormPoint = route < 2;
    o.useGlpk = route < 3;
    Result<Separation> s = separateHulls(a, b, o);
    ASSERT_TRUE(s.isOk());
    EXPECT_FALSE(s->separated) << "route " << route;
    EXPECT_EQ(s->witness, Vec3(1, 0, 0)) << "route " << route;
    EXPECT_LT(witnessResidual(a, s->weightsFirst, s->witness), 1e-15);
    EXPECT_LT(witnessResidual(b, s->weightsSecond, s->witness), 1e-15);
  }
  // Touching triangles in R^3 along an edge, and a point on a face.
  const Matrix t1 = rowsOf({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const Matrix t2 = rowsOf({{0.25, 0.25, 0}, {0.25, 0.25, 1}, {1, 1, 1}});
  Result<Separation> s = separateHulls(t1, t2);
  ASSERT_TRUE(s.isOk());
  EXPECT_FALSE(s->separated);
  EXPECT_EQ(s->witness, Vec3(0.25, 0.25, 0));
}

TEST(RegularitySeparation, AllRoutesAgreeOnRandomSets) {
  std::mt19937_64 rng(5);
  int separated = 0;
  int met = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int dim = test::uniformInt(rng, 1, 3);
    const int na = test::uniformInt(rng, 1, 5);
    const int nb = test::uniformInt(rng, 1, 5);
    Matrix a = test::randomMatrix(rng, na, dim);
    Matrix b = test::randomMatrix(rng, nb, dim);
    if (trial % 3 == 0) {
      // Quantised coordinates make exact touching and coplanar configurations common.
      a = (a * 2.0).array().round() / 2.0;
      b = (b * 2.0).array().round() / 2.0;
    }
    bool decision[4];
    for (int route = 0; route < 4; ++route) {
      SeparationOptions o;
      o.useQuickDirection = route < 1;
      o.useMinNormPoint = route < 2;
      o.useGlpk = route < 3;
      Result<Separation> s = separateHulls(a, b, o);
      ASSERT_TRUE(s.isOk());
      decision[route] = s->separated;
      if (s->separated) {
        EXPECT_TRUE(isStrictlySeparating(s->plane, a, b));
      } else {
        EXPECT_LT(witnessResidual(a, s->weightsFirst, s->witness), 1e-12);
        EXPECT_LT(witnessResidual(b, s->weightsSecond, s->witness), 1e-12);
      }
    }
    EXPECT_EQ(decision[0], decision[3]) << "trial " << trial;
    EXPECT_EQ(decision[1], decision[3]) << "trial " << trial;
    EXPECT_EQ(decision[2], decision[3]) << "trial " << trial;
    (decision[3] ? separated : met)++;
  }
  EXPECT_GT(separated, 30);
  EXPECT_GT(met, 30);
}

TEST(RegularitySeparation, BadInputIsReported) {
  EXPECT_FALSE(separateHulls(Matrix(0, 3), rowsOf({{0, 0, 0}})).isOk());
  EXPECT_EQ(separateHulls(Matrix::Zero(2, 4), Matrix::Zero(2, 4)).status().code(), ErrorCode::kUnsupported);
  EXPECT_FALSE(separateHulls(rowsOf({{0, 0}}), rowsOf({{0, 0, 0}})).isOk());
  Matrix nan = rowsOf({{0, 0}});
  nan(0, 0) = std::nan("");
  EXPECT_FALSE(separateHulls(nan, rowsOf({{1, 1}})).isOk());
  EXPECT_FALSE(checkCurveCondition(rowsOf({{0, 0}, {1, 0}, {2, 0}}), {3}).isOk());
}

// =====================================================================================================================
// Conditions on point sets
// =====================================================================================================================

TEST(RegularityConditions, PaperExampleK4LauFailsRegularityHolds) {
  // The k = 4 example of Section 1: the polygon turns by more than pi (Lau fails) but P1P2 and P3P4 are
  // disjoint segments (Definition 1.1 holds).
  const Matrix p = rowsOf({{0, 0}, {1, 0}, {1, 1}, {-0.5, 1}});
  Result<ConditionResult> lau = checkLau(p);
  ASSERT_TRUE(lau.isOk());
  EXPECT_FALSE(lau->holds);
  ASSERT_NE(lau->failure(), nullptr);
  // 0 = (1.5 (P2 - P1) + (P4 - P3)) / 2.5: the witness is the origin.
  EXPECT_LT(lau->failure()->separation.witness.norm(), 1e-15);
  Result<ConditionResult> reg = checkCurveCondition(p, paperSplits(4));
  ASSERT_TRUE(reg.isOk());
  EXPECT_TRUE(reg->holds);
  ASSERT_EQ(reg->checks.size(), 1u);
  EXPECT_EQ(reg->checks[0].r1, 2);
  EXPECT_TRUE(isStrictlySeparating(reg->checks[0].separation.plane, p.topRows(2), p.bottomRows(2)));

  // The curve segment is regular: certified, and the search proves it clean.
  Result<CurveRegularity> a = analyzeCurve(uniformCurve(p, 3));
  ASSERT_TRUE(a.isOk());
  ASSERT_EQ(a->segments.size(), 1u);
  EXPECT_EQ(a->segments[0].verdict, Verdict::kCertified);
  EXPECT_EQ(a->segments[0].condition, Condition::kRegularity);
  EXPECT_TRUE(a->segments[0].uniform);
  ASSERT_TRUE(a->search.has_value());
  EXPECT_TRUE(a->search->summary.provedClean(a->search->defectFound()));
  EXPECT_EQ(a->ellCertified, 0);
}

TEST(RegularityConditions, Theorem28LauImpliesRegularityOnRandomPolygons) {
  std::mt19937_64 rng(28);
  int lauHolds = 0;
  for (int trial = 0; trial < 600; ++trial) {
    const int k = test::uniformInt(rng, 3, 8);
    const int dim = test::uniformInt(rng, 2, 3);
    // Random walks whose steps stay near a random direction: Lau holds often, not always.
    Matrix p = Matrix::Zero(k, dim);
    VecX dir = test::randomMatrix(rng, 1, dim).row(0).transpose();
    const double spread = uniformReal(rng, 0.2, 2.5);
    for (int i = 1; i < k; ++i) {
      VecX step = dir + spread * test::randomMatrix(rng, 1, dim).row(0).transpose();
      p.row(i) = p.row(i - 1) + step.transpose();
    }
    Result<ConditionResult> lau = checkLau(p);
    ASSERT_TRUE(lau.isOk());
    if (!lau->holds) continue;
    ++lauHolds;
    // The proof of Theorem 2.8 works for every split, so Lau gives Definition 1.1 for all r.
    Result<ConditionResult> reg = checkCurveCondition(p, allSplits(k));
    ASSERT_TRUE(reg.isOk());
    EXPECT_TRUE(reg->holds) << "trial " << trial;
  }
  EXPECT_GT(lauHolds, 100);
}

TEST(RegularityConditions, CollinearPolygons) {
  // Monotone along a line: Lau holds. Back-tracking: the split segments overlap on [1, 2].
  const Matrix mono = rowsOf({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}});
  EXPECT_TRUE(checkLau(mono)->holds);
  const Matrix back = rowsOf({{0, 0, 0}, {2, 0, 0}, {1, 0, 0}, {3, 0, 0}});
  EXPECT_FALSE(checkLau(back)->holds);
  Result<ConditionResult> reg = checkCurveCondition(back, paperSplits(4));
  ASSERT_TRUE(reg.isOk());
  ASSERT_FALSE(reg->holds);
  const Vec3 w = reg->failure()->separation.witness;
  EXPECT_GE(w.x(), 1.0);
  EXPECT_LE(w.x(), 2.0);
  EXPECT_EQ(w.y(), 0.0);
  EXPECT_EQ(w.z(), 0.0);
  // Repeated points: P2 == P3 makes the hulls touch.
  const Matrix rep = rowsOf({{0, 0}, {1, 0}, {1, 0}, {2, 1}});
  Result<ConditionResult> r2 = checkCurveCondition(rep, paperSplits(4));
  ASSERT_TRUE(r2.isOk());
  EXPECT_FALSE(r2->holds);
  EXPECT_EQ(r2->failure()->separation.witness, Vec3(1, 0, 0));
}

TEST(RegularityConditions, PlanarAndDegenerateNets) {
  // A flat, regular 4 x 4 grid in z = 0: Theorem 3.7 holds (S_u, S_v in two fixed independent directions).
  Matrix flat(16, 3);
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) flat.row(i * 4 + j) << i + 0.1 * j, j, 0.0;
  }
  Result<ConditionResult> lau = checkNetLau(flat, 4, 4);
  ASSERT_TRUE(lau.isOk());
  EXPECT_TRUE(lau->holds);
  Result<ConditionResult> def = checkNetCondition(flat, 4, 4, paperSplits(4), paperSplits(4));
  ASSERT_TRUE(def.isOk());
  EXPECT_TRUE(def->holds);
  EXPECT_EQ(def->checks.size(), 4u);  // (1.7), (1.8), (1.9) two halves
  // Every point on one line (a degenerate net): the row groups overlap on the line, (1.7) fails.
  Matrix line(16, 3);
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) line.row(i * 4 + j) << i + 2.0 * j, 0.0, 0.0;
  }
  EXPECT_FALSE(checkNetLau(line, 4, 4)->holds);
  Result<ConditionResult> d2 = checkNetCondition(line, 4, 4, paperSplits(4), paperSplits(4));
  ASSERT_TRUE(d2.isOk());
  ASSERT_FALSE(d2->holds);
  const Check* f = d2->failure();
  ASSERT_NE(f, nullptr);
  EXPECT_EQ(f->kind, CheckKind::kSplitU);
  EXPECT_EQ(f->separation.witness.y(), 0.0);
  EXPECT_EQ(f->separation.witness.z(), 0.0);
  // Rows and columns separated, but S_u and S_v parallel in the middle (a crease folded flat): only (1.9)
  // fails. P_ij = (i, j, 0) with the two middle columns moved onto the u-direction of the middle rows.
  Matrix crease(16, 3);
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) crease.row(i * 4 + j) << 3.0 * i + j, j, 0.0;
  }
  Result<ConditionResult> d3 = checkNetCondition(crease, 4, 4, paperSplits(4), paperSplits(4));
  ASSERT_TRUE(d3.isOk());
  EXPECT_TRUE(d3->holds);  // a sheared grid is regular
  // Mixed orders (Remark 3.8): a 3 x 4 sheet.
  Matrix mixed(12, 3);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 4; ++j) mixed.row(i * 4 + j) << i, j, 0.2 * i * j;
  }
  EXPECT_TRUE(checkNetCondition(mixed, 3, 4, paperSplits(3), paperSplits(4))->holds);
}

// =====================================================================================================================
// Constructed defects
// =====================================================================================================================

TEST(RegularityCurves, ConstructedCuspIsFoundAtTheKnownParameter) {
  // Uniform cubic segment: C'(s) = D0 N0(s) + D1 N1(s) + D2 N2(s) with quadratic uniform B-splines, which are
  // (1/8, 6/8, 1/8) at s = 1/2. D0 = (1,1), D2 = (1,-1), D1 = -(D0 + D2)/6 makes C'(1/2) = 0.
  const Matrix p = rowsOf({{0, 0}, {1, 1}, {2.0 / 3.0, 1}, {5.0 / 3.0, 0}});
  Result<CurveRegularity> a = analyzeCurve(uniformCurve(p, 3));
  ASSERT_TRUE(a.isOk());
  ASSERT_EQ(a->segments.size(), 1u);
  const SegmentVerdict& s = a->segments[0];
  EXPECT_EQ(s.verdict, Verdict::kFails);
  EXPECT_EQ(s.condition, Condition::kRegularity);
  ASSERT_NE(s.result.failure(), nullptr);
  // The segments P1P2 and P3P4 cross at (5/6, 5/6) -- also the point (P1 + 5 P2)/6 of the proof of
  // Theorem 2.3.
  EXPECT_LT((s.result.failure()->separation.witness - Vec3(5.0 / 6.0, 5.0 / 6.0, 0)).norm(), 1e-15);
  EXPECT_TRUE(s.defectNearby);
  ASSERT_TRUE(a->search.has_value());
  ASSERT_EQ(a->search->criticalPoints.size(), 1u);
  EXPECT_NEAR(a->search->criticalPoints[0].t, 3.5, 1e-9);  // knots 0..7, segment [3, 4]
  EXPECT_LT(a->search->criticalPoints[0].speed, 1e-8);
  EXPECT_TRUE(a->anyFails());
  EXPECT_FALSE(a->ellCertified.has_value());
}

TEST(RegularityCurves, BezierCuspAndCollinearBacktrack) {
  // (t^2, t^3) on [-1, 1] as a Bezier cubic: cusp at s = 1/2. Clamped knots: the segment is not uniform.
  // Power basis in s (t = 2s - 1): x = 4s^2 - 4s + 1, y = 8s^3 - 12s^2 + 6s - 1.
  VecX px(4), py(4);
  px << 1, -4, 4, 0;
  py << -1, 6, -12, 8;
  const BernsteinPoly bx = BernsteinPoly::fromPowerBasis(px).elevatedTo(3);
  const BernsteinPoly by = BernsteinPoly::fromPowerBasis(py).elevatedTo(3);
  Matrix pts(4, 2);
  pts.col(0) = bx.coeffs().col(0);
  pts.col(1) = by.coeffs().col(0);
  Result<BSplineCurve> c = BSplineCurve::create(3, {0, 0, 0, 0, 1, 1, 1, 1}, pts);
  ASSERT_TRUE(c.isOk());
  Result<CurveRegularity> a = analyzeCurve(*c);
  ASSERT_TRUE(a.isOk());
  EXPECT_FALSE(a->segments[0].uniform);
  EXPECT_EQ(a->segments[0].verdict, Verdict::kNotApplicable);
  ASSERT_EQ(a->search->criticalPoints.size(), 1u);
  EXPECT_NEAR(a->search->criticalPoints[0].t, 0.5, 1e-9);

  // x-values 0, 2, 1, 3 on a line: C'(s) = 3s^2 - 3s + 1/2 vanishes at s = (3 -+ sqrt 3)/6 (two reversals).
  Result<CurveRegularity> b =
      analyzeCurve(uniformCurve(rowsOf({{0, 0, 0}, {2, 0, 0}, {1, 0, 0}, {3, 0, 0}}), 3));
  ASSERT_TRUE(b.isOk());
  EXPECT_EQ(b->segments[0].verdict, Verdict::kFails);
  ASSERT_EQ(b->search->criticalPoints.size(), 2u);
  EXPECT_NEAR(b->search->criticalPoints[0].t, 3.0 + (3.0 - std::sqrt(3.0)) / 6.0, 1e-9);
  EXPECT_NEAR(b->search->criticalPoints[1].t, 3.0 + (3.0 + std::sqrt(3.0)) / 6.0, 1e-9);
}

TEST(RegularityCurves, NodalCubicLoopIsFound) {
  // (t^2 - 1, t (t^2 - 1)), t = 4s - 2 in [-2, 2]: the double point is the origin at t = -1, 1 (s = 1/4,
  // 3/4).
  VecX px(3), py(4);
  px << 3, -16, 16;
  py << -6, 44, -96, 64;
  const BernsteinPoly bx = BernsteinPoly::fromPowerBasis(px).elevatedTo(3);
  const BernsteinPoly by = BernsteinPoly::fromPowerBasis(py);
  Matrix pts(4, 2);
  pts.col(0) = bx.coeffs().col(0);
  pts.col(1) = by.coeffs().col(0);
  Result<BSplineCurve> c = BSplineCurve::create(3, {0, 0, 0, 0, 1, 1, 1, 1}, pts);
  ASSERT_TRUE(c.isOk());
  Result<CurveSearchResult> r = searchCurveDefects(*c);
  ASSERT_TRUE(r.isOk());
  EXPECT_TRUE(r->criticalPoints.empty());
  ASSERT_EQ(r->selfIntersections.size(), 1u);
  EXPECT_NEAR(r->selfIntersections[0].t1, 0.25, 1e-9);
  EXPECT_NEAR(r->selfIntersections[0].t2, 0.75, 1e-9);
  EXPECT_LT(r->selfIntersections[0].point.norm(), 1e-9);

  // The same loop split into a uniform B-spline: the loop spans several segments; each segment may be
  // regular, but ell cannot cover the loop. Insert knots 0.25, 0.5, 0.75 (then the knots are not uniform:
  // clamped).
  const BSplineCurve refined = c->refined({0.25, 0.5, 0.75});
  Result<CurveRegularity> a = analyzeCurve(refined);
  ASSERT_TRUE(a.isOk());
  EXPECT_TRUE(a->anyFails());
  ASSERT_EQ(a->search->selfIntersections.size(), 1u);
  if (a->ellCertified) {
    EXPECT_LT(*a->ellCertified, static_cast<int>(a->segments.size()) - 1);
  }
}

TEST(RegularitySurfaces, WhitneyUmbrellaCriticalPointAndSelfIntersection) {
  // S = (u v, u, v^2) on [-1, 1]^2 (u = 2a - 1, v = 2b - 1): S_u x S_v = (2v, -2v^2, -u) vanishes only at the
  // centre; S(0, v) = S(0, -v) is a line of double points. Degrees (1, 2): Bernstein coefficients of u: (-1,
  // 1); of v: (-1, 0, 1); of v^2: (1, -1, 1).
  const double cu[2] = {-1, 1};
  const double cv[3] = {-1, 0, 1};
  const double cv2[3] = {1, -1, 1};
  Matrix pts(6, 3);
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 3; ++j) pts.row(i * 3 + j) << cu[i] * cv[j], cu[i], cv2[j];
  }
  Result<BSplineSurface> s = BSplineSurface::create(1, 2, {0, 0, 1, 1}, {0, 0, 0, 1, 1, 1}, 2, 3, pts);
  ASSERT_TRUE(s.isOk());
  Result<SurfaceSearchResult> r = searchSurfaceDefects(*s);
  ASSERT_TRUE(r.isOk());
  EXPECT_TRUE(r->summary.complete);
  ASSERT_EQ(r->criticalPoints.size(), 1u);
  EXPECT_NEAR(r->criticalPoints[0].u, 0.5, 1e-8);
  EXPECT_NEAR(r->criticalPoints[0].v, 0.5, 1e-8);
  ASSERT_FALSE(r->selfIntersections.empty());
  for (const SurfaceSelfIntersection& x : r->selfIntersections) {
    EXPECT_NEAR(x.u1, 0.5, 1e-6);
    EXPECT_NEAR(x.u2, 0.5, 1e-6);
    EXPECT_NEAR(x.v1 + x.v2, 1.0, 1e-6);
    EXPECT_LT(x.distance, 1e-6);
  }
  Result<SurfaceRegularity> a = analyzeSurface(*s);
  ASSERT_TRUE(a.isOk());
  EXPECT_TRUE(a->anyFails());
  EXPECT_NE(a->subnets[0].verdict, Verdict::kCertified);
  EXPECT_TRUE(a->subnets[0].defectNearby);
}

TEST(RegularitySurfaces, CollinearNetIsCriticalEverywhere) {
  Matrix line(16, 3);
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) line.row(i * 4 + j) << i + 2.0 * j, 0.0, 0.0;
  }
  Result<SurfaceRegularity> a = analyzeSurface(uniformSurface(line, 3, 3, 4, 4));
  ASSERT_TRUE(a.isOk());
  EXPECT_EQ(a->subnets[0].verdict, Verdict::kFails);
  ASSERT_TRUE(a->search.has_value());
  EXPECT_FALSE(a->search->criticalPoints.empty());
  EXPECT_TRUE(a->subnets[0].defectNearby);
}

// =====================================================================================================================
// Certificates against the search on random input
// =====================================================================================================================

SearchOptions fastSearch() {
  SearchOptions o;
  o.resolution = 1e-5;
  o.maxWork = 200000;
  return o;
}

TEST(RegularityProperty, CertifiedRandomCurveSegmentsHaveNoDefects) {
  std::mt19937_64 rng(2024);
  RegularityOptions opt;
  opt.search = fastSearch();
  int certified = 0;
  int defective = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    const int k = test::uniformInt(rng, 3, 6);
    const int dim = test::uniformInt(rng, 2, 3);
    Matrix p = test::randomMatrix(rng, k, dim);
    Result<CurveRegularity> a = analyzeCurve(uniformCurve(p, k - 1), opt);
    ASSERT_TRUE(a.isOk());
    ASSERT_EQ(a->segments.size(), 1u);
    const bool found = a->search->defectFound();
    defective += found ? 1 : 0;
    if (a->segments[0].verdict != Verdict::kCertified) continue;
    ++certified;
    EXPECT_FALSE(found) << "trial " << trial << ": certified segment with a defect";
    EXPECT_TRUE(a->search->criticalPoints.empty());
    EXPECT_TRUE(a->search->selfIntersections.empty());
  }
  std::printf("random segments: %d certified, %d with a defect found\n", certified, defective);
  EXPECT_GT(certified, 600);
  EXPECT_GT(defective, 0);
}

TEST(RegularityProperty, EllCertifiedCurvesDoNotIntersectWithinEll) {
  // n = k + l points with ell_certified == l == number of segments - 1: the whole curve is injective.
  std::mt19937_64 rng(27);
  RegularityOptions opt;
  opt.maxEll = 3;
  opt.search = fastSearch();
  int wholeCurves = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    const int k = test::uniformInt(rng, 3, 5);
    const int l = test::uniformInt(rng, 1, 3);
    const int dim = test::uniformInt(rng, 2, 3);
    Matrix p = Matrix::Zero(k + l, dim);
    VecX dir = test::randomMatrix(rng, 1, dim).row(0).transpose();
    for (int i = 1; i < k + l; ++i) {
      p.row(i) = p.row(i - 1) + (dir + 1.5 * test::randomMatrix(rng, 1, dim).row(0).transpose()).transpose();
    }
    Result<CurveRegularity> a = analyzeCurve(uniformCurve(p, k - 1), opt);
    ASSERT_TRUE(a.isOk());
    if (!a->ellCertified) continue;
    for (const CurveSelfIntersection& x : a->search->selfIntersections) {
      EXPECT_GT(x.t2 - x.t1, *a->ellCertified) << "trial " << trial;
    }
    EXPECT_TRUE(a->search->criticalPoints.empty());
    if (*a->ellCertified == l) {
      ++wholeCurves;
      EXPECT_TRUE(a->search->selfIntersections.empty()) << "trial " << trial;
    }
  }
  EXPECT_GT(wholeCurves, 50);
}

TEST(RegularityProperty, CertifiedRandomNetsHaveNoDefects) {
  std::mt19937_64 rng(35);
  RegularityOptions opt;
  opt.search = fastSearch();
  int certified = 0;
  int byDefinition = 0;
  int coneFailures = 0;
  for (int trial = 0; trial < 1000; ++trial) {
    const int k1 = test::uniformInt(rng, 3, 4);
    const int k2 = test::uniformInt(rng, 3, 4);
    // A gently curved sheet plus noise: some nets pass, some fold.
    const double noise = uniformReal(rng, 0.05, 0.9);
    Matrix p(k1 * k2, 3);
    for (int i = 0; i < k1; ++i) {
      for (int j = 0; j < k2; ++j) {
        p.row(i * k2 + j) << i + noise * uniformReal(rng, -1, 1), j + noise * uniformReal(rng, -1, 1),
            0.3 * (i - 1) * (j - 1) + noise * uniformReal(rng, -1, 1);
      }
    }
    Result<SurfaceRegularity> a = analyzeSurface(uniformSurface(p, k1 - 1, k2 - 1, k1, k2), opt);
    ASSERT_TRUE(a.isOk());
    ASSERT_EQ(a->subnets.size(), 1u);
    if (const Check* f = a->subnets[0].result.failure()) {
      if (f->kind == CheckKind::kConeSame || f->kind == CheckKind::kConeOpposite) {
        ++coneFailures;
        EXPECT_GT(f->coneDirection.norm(), 0.0);
      }
    }
    if (a->subnets[0].verdict != Verdict::kCertified) continue;
    ++certified;
    byDefinition += a->subnets[0].condition == Condition::kRegularity ? 1 : 0;
    EXPECT_TRUE(a->search->criticalPoints.empty()) << "trial " << trial;
    EXPECT_TRUE(a->search->selfIntersections.empty()) << "trial " << trial;
  }
  std::printf("random nets: %d certified (%d by Definition 1.2), %d failing (1.9)\n", certified, byDefinition,
              coneFailures);
  EXPECT_GT(certified, 200);
  EXPECT_GT(byDefinition, 20);
}

// =====================================================================================================================
// Whole objects: knots, ell, options
// =====================================================================================================================

TEST(RegularityCurves, HelixIsCertifiedEverywhereWithClampedKnots) {
  const int n = 12;
  Matrix p(n, 3);
  for (int i = 0; i < n; ++i) p.row(i) << std::cos(0.5 * i), std::sin(0.5 * i), 0.2 * i;
  Result<BSplineCurve> c = BSplineCurve::create(3, KnotVector::clampedUniform(3, n).values(), p);
  ASSERT_TRUE(c.isOk());
  Result<CurveRegularity> a = analyzeCurve(*c);
  ASSERT_TRUE(a.isOk());
  ASSERT_EQ(a->segments.size(), static_cast<size_t>(n - 3));
  int uniform = 0;
  for (const SegmentVerdict& s : a->segments) {
    EXPECT_EQ(s.verdict, Verdict::kCertified);
    EXPECT_EQ(s.condition, Condition::kLau);
    uniform += s.uniform ? 1 : 0;
  }
  EXPECT_EQ(uniform, n - 3 - 2 * 3);  // the 2k knots around a span avoid the clamped ends
  EXPECT_EQ(a->ellCertified, 2);
  EXPECT_TRUE(a->search->summary.provedClean(a->search->defectFound()));
  // Without the extension, non-uniform segments that fail Lau are not-applicable (here Lau holds everywhere).
  RegularityOptions strict;
  strict.allSplitsForNonUniform = false;
  EXPECT_EQ(analyzeCurve(*c, strict)->segments[0].verdict, Verdict::kCertified);
}

TEST(RegularityMany, EveryObjectGetsItsOwnResultInOrderFromAllThreads) {
  // analyzeCurves / analyzeSurfaces (on TBB's threads) against analyzeCurve / analyzeSurface one at a time: the same
  // verdicts, search findings and errors, object by object, and each object's progress callback.
  std::mt19937_64 rng(3901);
  RegularityOptions opt;
  opt.search = fastSearch();
  std::vector<BSplineSurface> surfaces;
  std::vector<BSplineCurve> curves;
  for (int trial = 0; trial < 24; ++trial) {
    const int k1 = test::uniformInt(rng, 3, 4), k2 = test::uniformInt(rng, 3, 4);
    const double noise = trial % 3 == 0 ? 0.9 : 0.1;  // some fold
    Matrix p(k1 * k2, 3);
    for (int i = 0; i < k1; ++i)
      for (int j = 0; j < k2; ++j) {
        const double x = uniformReal(rng, -1, 1), y = uniformReal(rng, -1, 1), z = uniformReal(rng, -1, 1);
        p.row(i * k2 + j) << i + noise * x, j + noise * y, 0.3 * (i - 1) * (j - 1) + noise * z;
      }
    surfaces.push_back(uniformSurface(p, k1 - 1, k2 - 1, k1, k2));
    Matrix c(5, 2);
    for (int i = 0; i < 5; ++i) {
      const double x = uniformReal(rng, -1, 1), y = uniformReal(rng, -1, 1);
      c.row(i) << i + noise * x, noise * y;
    }
    curves.push_back(uniformCurve(c, 3));
  }
  Result<BSplineCurve> c4 = BSplineCurve::create(1, {0, 0, 1, 1}, Matrix::Zero(2, 4));  // 4 coordinates: refused
  ASSERT_TRUE(c4.isOk());
  curves.insert(curves.begin() + 7, *c4);
  std::vector<const BSplineSurface*> sp;
  std::vector<const BSplineCurve*> cp;
  for (const BSplineSurface& s : surfaces) sp.push_back(&s);
  for (const BSplineCurve& c : curves) cp.push_back(&c);
  std::mutex m;
  std::vector<int> called(surfaces.size(), 0);
  const std::vector<Result<SurfaceRegularity>> all = analyzeSurfaces(sp, opt, [&](size_t i) -> ProgressCallback {
    const std::lock_guard<std::mutex> lock(m);
    ++called[i];
    return {};
  });
  const std::vector<Result<CurveRegularity>> allCurves = analyzeCurves(cp, opt);
  ASSERT_EQ(all.size(), surfaces.size());
  ASSERT_EQ(allCurves.size(), curves.size());
  int folds = 0;
  for (size_t i = 0; i < surfaces.size(); ++i) {
    SCOPED_TRACE(::testing::Message() << "surface " << i);
    EXPECT_EQ(called[i], 1);
    const Result<SurfaceRegularity> one = analyzeSurface(surfaces[i], opt);
    ASSERT_TRUE(one.isOk() && all[i].isOk());
    EXPECT_EQ(one->anyFails(), all[i]->anyFails());
    folds += one->anyFails() ? 1 : 0;
    ASSERT_EQ(one->subnets.size(), all[i]->subnets.size());
    for (size_t k = 0; k < one->subnets.size(); ++k) EXPECT_EQ(one->subnets[k].verdict, all[i]->subnets[k].verdict);
    ASSERT_EQ(one->search.has_value(), all[i]->search.has_value());
    if (one->search) {
      EXPECT_EQ(one->search->criticalPoints.size(), all[i]->search->criticalPoints.size());
      EXPECT_EQ(one->search->selfIntersections.size(), all[i]->search->selfIntersections.size());
    }
  }
  EXPECT_GT(folds, 0);
  EXPECT_LT(folds, static_cast<int>(surfaces.size()));
  for (size_t i = 0; i < curves.size(); ++i) {
    SCOPED_TRACE(::testing::Message() << "curve " << i);
    const Result<CurveRegularity> one = analyzeCurve(curves[i], opt);
    ASSERT_EQ(one.isOk(), allCurves[i].isOk());
    if (!one.isOk()) {
      EXPECT_EQ(i, 7u);
      EXPECT_EQ(one.status().code(), allCurves[i].status().code());
      continue;
    }
    EXPECT_EQ(one->anyFails(), allCurves[i]->anyFails());
    ASSERT_EQ(one->segments.size(), allCurves[i]->segments.size());
    for (size_t k = 0; k < one->segments.size(); ++k)
      EXPECT_EQ(one->segments[k].verdict, allCurves[i]->segments[k].verdict);
  }
}

TEST(RegularityCurves, UniformityUsesTheNamedTolerance) {
  std::vector<double> t = {0, 0.1, 0.2, 0.30000000000000004, 0.4, 0.5};
  EXPECT_TRUE(uniformKnots(t, 0, 5));
  t[3] = 0.31;
  EXPECT_FALSE(uniformKnots(t, 0, 5));
  EXPECT_TRUE(uniformKnots(t, 0, 5, 0.2));
}

TEST(RegularityCurves, OptionsAndInputErrors) {
  const BSplineCurve c = uniformCurve(rowsOf({{0, 0}, {1, 0}, {2, 1}, {3, 3}}), 3);
  RegularityOptions bad;
  bad.maxEll = -1;
  EXPECT_EQ(analyzeCurve(c, bad).status().code(), ErrorCode::kInvalidInput);
  SearchOptions s;
  s.resolution = 0.0;
  EXPECT_EQ(searchCurveDefects(c, s).status().code(), ErrorCode::kInvalidInput);
  Result<BSplineCurve> c4 = BSplineCurve::create(1, {0, 0, 1, 1}, Matrix::Zero(2, 4));
  if (c4.isOk()) {
    EXPECT_EQ(analyzeCurve(*c4).status().code(), ErrorCode::kUnsupported);
  }
}

TEST(RegularityCurves, RationalCurvesUseAllSplits) {
  // A quarter circle (rational quadratic): Lau holds for any knots and weights.
  Matrix p = rowsOf({{1, 0}, {1, 1}, {0, 1}});
  VecX w(3);
  w << 1, std::sqrt(0.5), 1;
  Result<BSplineCurve> c = BSplineCurve::create(2, {0, 0, 0, 1, 1, 1}, p, w);
  ASSERT_TRUE(c.isOk());
  Result<CurveRegularity> a = analyzeCurve(*c);
  ASSERT_TRUE(a.isOk());
  EXPECT_TRUE(a->rational);
  EXPECT_EQ(a->segments[0].verdict, Verdict::kCertified);
  EXPECT_FALSE(a->segments[0].uniform);
  EXPECT_FALSE(a->search->defectFound());
}

}  // namespace
}  // namespace seam::regularity

// =====================================================================================================================
// The command line (runs the built binary on tests/data/regularity)
// =====================================================================================================================

#ifdef SEAM_CLI_PATH
namespace seam::regularity {
namespace {

struct CliRun {
  int exitCode = -1;
  std::string out;
};

CliRun runCli(const std::string& args) {
  CliRun r;
  const std::string cmd = std::string(SEAM_CLI_PATH) + " " + args + " 2>/dev/null";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return r;
  char buf[4096];
  size_t n = 0;
  while ((n = fread(buf, 1, sizeof buf, pipe)) > 0) r.out.append(buf, n);
  const int status = pclose(pipe);
  r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

const std::string kData = std::string(SEAM_TEST_DATA_DIR) + "/regularity/";

TEST(RegularityCli, RegularModelExitsZeroWithTheIssueSchema) {
  const CliRun r = runCli("regularity " + kData + "regular.json --json");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["curves"].size(), 2u);
  const auto& helix = j["curves"][0];
  EXPECT_EQ(helix["name"], "helix");
  EXPECT_EQ(helix["segments"].size(), 9u);
  for (const auto& s : helix["segments"]) {
    EXPECT_EQ(s["verdict"], "certified");
    EXPECT_EQ(s["condition"], "lau");
    EXPECT_TRUE(s["certificate"]["checks"][0].contains("normal"));
  }
  EXPECT_EQ(helix["ell_certified"], 2);
  EXPECT_TRUE(helix["critical_points"].empty());
  EXPECT_TRUE(helix["self_intersections"].empty());
  const auto& paper = j["curves"][1];
  EXPECT_EQ(paper["segments"][0]["condition"], "regularity");
  ASSERT_EQ(j["patches"].size(), 1u);
  EXPECT_EQ(j["patches"][0]["subnets"].size(), 6u);
  // --curve selects one curve, --ell changes the ell search, and the table mode prints a summary.
  const CliRun one = runCli("regularity " + kData + "regular.json --curve helix --ell 1 --json");
  ASSERT_EQ(one.exitCode, 0);
  const nlohmann::json k = nlohmann::json::parse(one.out);
  EXPECT_EQ(k["curves"].size(), 1u);
  EXPECT_TRUE(k["patches"].empty());
  EXPECT_EQ(k["curves"][0]["ell_certified"], 1);
  const CliRun table = runCli("regularity " + kData + "regular.json");
  EXPECT_EQ(table.exitCode, 0);
  EXPECT_NE(table.out.find("result: no problem found"), std::string::npos);
}

TEST(RegularityCli, CuspExitsOneAndBadInputTwo) {
  const CliRun r = runCli("regularity " + kData + "cusp.json --json");
  EXPECT_EQ(r.exitCode, 1);
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const auto& cusp = j["curves"][1];
  EXPECT_EQ(cusp["segments"][0]["verdict"], "fails");
  EXPECT_EQ(cusp["segments"][0]["witness"].size(), 2u);
  EXPECT_EQ(cusp["segments"][0]["defect_nearby"], true);
  ASSERT_EQ(cusp["critical_points"].size(), 1u);
  EXPECT_NEAR(cusp["critical_points"][0]["t"].get<double>(), 3.5, 1e-9);
  EXPECT_EQ(runCli("regularity " + kData + "cusp.json --curve nosuch").exitCode, 2);
  EXPECT_EQ(runCli("regularity " + kData + "missing.json").exitCode, 2);
  EXPECT_EQ(runCli("regularity " + kData + "cusp.json --curve cusp --patch x").exitCode, 2);
}

}  // namespace
}  // namespace seam::regularity
#endif
