// Tests of the scaled defect search (issues 15, 16): the linear Bezier decomposition gives the spline module's pieces
// bit for bit, and the search agrees with an independent brute-force O(n^2) route on random curves and nets with
// planted near-self-intersections, below and above the sizes where the search changes strategy.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "regularity/search_internal.h"
#include "seam/core/tolerances.h"
#include "seam/io/file.h"
#include "seam/model/model.h"
#include "seam/regularity/defect_search.h"
#include "seam/regularity/regularity.h"

namespace seam::regularity {
namespace {

/// Random non-decreasing knots of n + p + 1 values, some interior knots repeated (multiplicity up to p); clamped:
/// p + 1 equal values at both ends.
std::vector<double> randomKnots(std::mt19937_64& rng, int p, int n, bool clamped) {
  std::uniform_real_distribution<double> gap(0.1, 2.0);
  const auto total = static_cast<size_t>(n + p + 1);
  const size_t ends = clamped ? static_cast<size_t>(p + 1) : 0;
  double x = -1.3;
  std::vector<double> t(ends, x);
  while (t.size() < total - ends) {
    x += gap(rng);
    const int m = rng() % 6 < 4 ? 1 : 2 + static_cast<int>(rng() % static_cast<unsigned>(std::max(1, p - 1)));
    for (int k = 0; k < std::min(m, p) && t.size() < total - ends; ++k) t.push_back(x);
  }
  x += gap(rng);
  while (t.size() < total) t.push_back(x);
  return t;
}

bool sameBits(const Matrix& a, const Matrix& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && (a.array() == b.array()).all();
}
bool sameBits(const VecX& a, const VecX& b) { return a.size() == b.size() && (a.array() == b.array()).all(); }

TEST(RegularityLinearPieces, CurvePiecesAreBitIdenticalToBezierPieces) {
  std::mt19937_64 rng(1601);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  int valid = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int p = 1 + trial % 5;
    const int n = p + 1 + static_cast<int>(rng() % 40);
    const int dim = 1 + trial % 3;
    Matrix pts(n, dim);
    for (Eigen::Index i = 0; i < pts.size(); ++i) pts.data()[i] = u(rng);
    VecX w;
    if (trial % 4 == 3) {
      w.resize(n);
      for (int i = 0; i < n; ++i) w[i] = 0.2 + std::abs(u(rng));
    }
    Result<BSplineCurve> c = BSplineCurve::create(p, randomKnots(rng, p, n, trial % 2 == 0), pts, w);
    if (!c) continue;  // an empty domain (random knots)
    ++valid;
    const std::vector<BezierCurvePiece> want = c->bezierPieces();
    const std::vector<BezierCurvePiece> got = detail::bezierPiecesLinear(*c);
    ASSERT_EQ(got.size(), want.size()) << "trial " << trial;
    for (size_t s = 0; s < want.size(); ++s) {
      EXPECT_EQ(got[s].interval.lo, want[s].interval.lo);
      EXPECT_EQ(got[s].interval.hi, want[s].interval.hi);
      EXPECT_TRUE(sameBits(got[s].curve.points(), want[s].curve.points())) << "trial " << trial << " piece " << s;
      EXPECT_TRUE(sameBits(got[s].curve.weights(), want[s].curve.weights())) << "trial " << trial;
    }
  }
  EXPECT_GE(valid, 150);
}

TEST(RegularityLinearPieces, SurfacePatchesAreBitIdenticalToBezierPatches) {
  std::mt19937_64 rng(1602);
  std::uniform_real_distribution<double> u(-3.0, 3.0);
  int valid = 0;
  for (int trial = 0; trial < 60; ++trial) {
    const int pu = 1 + trial % 4;
    const int pv = 1 + (trial / 4) % 3;
    const int nu = pu + 1 + static_cast<int>(rng() % 9);
    const int nv = pv + 1 + static_cast<int>(rng() % 9);
    Matrix pts(nu * nv, 3);
    for (Eigen::Index i = 0; i < pts.size(); ++i) pts.data()[i] = u(rng);
    VecX w;
    if (trial % 3 == 2) {
      w.resize(nu * nv);
      for (int i = 0; i < nu * nv; ++i) w[i] = 0.2 + std::abs(u(rng));
    }
    // drawn last argument first (test_helpers.h)
    const std::vector<double> kv = randomKnots(rng, pv, nv, trial % 5 == 0);
    Result<BSplineSurface> s = BSplineSurface::create(pu, pv, randomKnots(rng, pu, nu, trial % 2 == 0), kv, nu, nv,
                                                      pts, w);
    if (!s) continue;
    ++valid;
    const std::vector<BezierPatchPiece> want = s->bezierPatches();
    const std::vector<BezierPatchPiece> got = detail::bezierPatchesLinear(*s);
    ASSERT_EQ(got.size(), want.size()) << "trial " << trial;
    for (size_t k = 0; k < want.size(); ++k) {
      EXPECT_EQ(got[k].spanU, want[k].spanU);
      EXPECT_EQ(got[k].spanV, want[k].spanV);
      EXPECT_EQ(got[k].u.lo, want[k].u.lo);
      EXPECT_EQ(got[k].v.hi, want[k].v.hi);
      EXPECT_TRUE(sameBits(got[k].patch.points(), want[k].patch.points())) << "trial " << trial << " patch " << k;
      EXPECT_TRUE(sameBits(got[k].patch.weights(), want[k].patch.weights())) << "trial " << trial;
    }
  }
  EXPECT_GE(valid, 40);
}

// =====================================================================================================================
// The search against a brute-force reference: every pair of non-adjacent Bezier pieces whose control boxes (grown by
// the distance tolerance) overlap, no hierarchy, O(n^2) box tests; the closest points of such a pair by dense
// sampling of the B-spline (de Boor, not the search's Bezier pieces) and Gauss-Newton.
// =====================================================================================================================

struct NearPair {
  double t1 = 0.0, t2 = 0.0, distance = 0.0;
};

/// Closest points of two parameter intervals of a curve: the best of 33 x 33 samples, then Gauss-Newton.
NearPair closestOnCurve(const BSplineCurve& c, Interval a, Interval b) {
  constexpr int kSamples = 33;
  NearPair best{0, 0, INFINITY};
  std::vector<Vec3> pb(kSamples);
  for (int j = 0; j < kSamples; ++j) pb[j] = c.point3(b.lo + b.length() * j / (kSamples - 1));
  for (int i = 0; i < kSamples; ++i) {
    const double s = a.lo + a.length() * i / (kSamples - 1);
    const Vec3 p = c.point3(s);
    for (int j = 0; j < kSamples; ++j) {
      const double d = (p - pb[j]).norm();
      if (d < best.distance) best = {s, b.lo + b.length() * j / (kSamples - 1), d};
    }
  }
  double s = best.t1, t = best.t2;
  for (int it = 0; it < 30; ++it) {
    Vec3 p, dp, ddp, q, dq, ddq;
    c.derivatives2(s, p, dp, ddp);
    c.derivatives2(t, q, dq, ddq);
    Eigen::Matrix<double, 3, 2> j;
    j.col(0) = dp;
    j.col(1) = -dq;
    const Eigen::Vector2d step = -(j.transpose() * j).ldlt().solve(j.transpose() * (p - q));
    if (!step.allFinite()) break;
    s = std::clamp(s + step[0], a.lo, a.hi);
    t = std::clamp(t + step[1], b.lo, b.hi);
  }
  const double d = (c.point3(s) - c.point3(t)).norm();
  if (d < best.distance) best = {s, t, d};
  return best;
}

/// All pairs of pieces at least two apart (adjacent pieces share an end point) that come closer than `reach`.
std::vector<NearPair> bruteForceNearPairs(const BSplineCurve& c, double grow, double reach) {
  const std::vector<BezierCurvePiece> pieces = c.bezierPieces();
  std::vector<Eigen::AlignedBox3d> boxes;
  for (const BezierCurvePiece& p : pieces) {
    Eigen::AlignedBox3d box;
    for (Eigen::Index i = 0; i < p.curve.points().rows(); ++i) {
      Vec3 x = Vec3::Zero();
      x.head(p.curve.points().cols()) = p.curve.points().row(i).transpose();
      box.extend(x);
    }
    box.min().array() -= grow;
    box.max().array() += grow;
    boxes.push_back(box);
  }
  std::vector<NearPair> out;
  for (size_t i = 0; i < pieces.size(); ++i) {
    for (size_t j = i + 2; j < pieces.size(); ++j) {
      if (!boxes[i].intersects(boxes[j])) continue;
      const NearPair n = closestOnCurve(c, pieces[i].interval, pieces[j].interval);
      if (n.distance <= reach) out.push_back(n);
    }
  }
  return out;
}

/// About 1.25 turns of a wavy circle in the plane z = 0 whose second lap rises to z = `lift` before it crosses the
/// first lap: the second lap's radius sweeps from 5 % outside to 5 % inside the first's (random wiggles of at most
/// 1 %), so the laps cross in the xy projection and the curve comes within about `lift` of itself there, and nowhere
/// else. n control points, uniform cubic.
BSplineCurve plantedCurve(std::mt19937_64& rng, int n, double lift) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const double amp = 0.01 * u(rng);
  const double freq = 0.5 + 3.0 * u(rng);
  const double phase = 6.0 * u(rng);
  auto smooth = [](double x) {
    x = std::clamp(x, 0.0, 1.0);
    return x * x * (3.0 - 2.0 * x);
  };
  Matrix pts(n, 3);
  for (int i = 0; i < n; ++i) {
    const double th = 2.5 * M_PI * i / (n - 1);
    const double sweep = th < 2.0 * M_PI ? smooth((th - 0.5 * M_PI) / (1.5 * M_PI)) : (2.25 * M_PI - th) / (0.25 * M_PI);
    const double r = 1.0 + amp * std::sin(freq * th + phase) + 0.05 * sweep;
    pts.row(i) << r * std::cos(th), r * std::sin(th), lift * smooth((th - M_PI) / (0.5 * M_PI));
  }
  std::vector<double> t(static_cast<size_t>(n + 4));
  for (size_t i = 0; i < t.size(); ++i) t[i] = static_cast<double>(i);
  return *BSplineCurve::create(3, t, pts);
}

TEST(RegularitySearchProperty, CurveSearchAgreesWithBruteForceOnPlantedNearMisses) {
  std::mt19937_64 rng(160016);
  int found = 0, clean = 0;
  // 6 000 segments: above the size where the work budget starts to grow with the pieces (300 000 / 64).
  for (int n : {40, 400, 6000}) {
    for (int trial = 0; trial < 4; ++trial) {
      // Lifts of 0.1 and 30 distance tolerances (found / not found); the tolerance is 1e-6 of the box diagonal.
      const unsigned seed = static_cast<unsigned>(rng());
      std::mt19937_64 first(seed);
      const BSplineCurve probe = plantedCurve(first, n, 0.0);
      const double dist = Tolerances::forModelSize(controlBox(probe).diagonal()).distance;
      const double lift = (trial % 2 == 0 ? 0.1 : 30.0) * dist;
      std::mt19937_64 again(seed);
      const BSplineCurve c = plantedCurve(again, n, lift);
      Result<CurveSearchResult> r = searchCurveDefects(c);
      ASSERT_TRUE(r.isOk());
      const double usedDist = r->summary.distance;
      const std::vector<NearPair> near = bruteForceNearPairs(c, usedDist, 3.0 * usedDist);
      EXPECT_TRUE(r->criticalPoints.empty()) << "n " << n << " trial " << trial;
      EXPECT_TRUE(r->summary.complete && r->summary.unresolved == 0) << "n " << n << " trial " << trial;
      // Every brute-force pair clearly within the tolerance is reported (near its parameters), and every reported
      // point is a pair that brute force finds within the tolerance.
      for (const NearPair& p : near) {
        if (p.distance > 0.5 * usedDist) continue;
        bool reported = false;
        for (const CurveSelfIntersection& x : r->selfIntersections) {
          reported = reported || (std::abs(x.t1 - p.t1) < 1.0 && std::abs(x.t2 - p.t2) < 1.0);
        }
        EXPECT_TRUE(reported) << "n " << n << " trial " << trial << ": brute force finds t = " << p.t1 << ", "
                              << p.t2 << " at distance " << p.distance << " (tolerance " << usedDist << ")";
      }
      for (const CurveSelfIntersection& x : r->selfIntersections) {
        bool confirmed = false;
        for (const NearPair& p : near) {
          confirmed = confirmed || (std::abs(x.t1 - p.t1) < 1.0 && std::abs(x.t2 - p.t2) < 1.0 &&
                                    p.distance <= usedDist * (1.0 + 1e-6));
        }
        EXPECT_TRUE(confirmed) << "n " << n << " trial " << trial << ": search reports t = " << x.t1 << ", " << x.t2
                               << " at distance " << x.distance;
      }
      if (near.empty()) {
        EXPECT_TRUE(r->summary.provedClean(r->defectFound())) << "n " << n;
      }
      (r->selfIntersections.empty() ? clean : found) += 1;
    }
  }
  EXPECT_GE(found, 5);  // both outcomes occur at every size
  EXPECT_GE(clean, 5);
}

// =====================================================================================================================
// Poles (issue 39 goal 1): a side of a patch along which S_u x S_v vanishes. A cone or disk parametrised from its apex
// is S(u, v) = apex + u C(v): n = u (C x C'), zero along the whole side u = 0 and nowhere else when C is star-shaped
// seen from the apex. Built exactly (the rows of the net are the Greville abscissae times C's net, so S is linear in
// u), with the pole on each of the four sides, uneven knots in v and sometimes a sliver span (trj3's F6: 1.5e-5 of
// its neighbours). Expected by construction: one critical point, at the apex; no self-intersection; the search
// complete with nothing unresolved. Before pole sides were divided out, the search subdivided along the side to the
// resolution and stopped on its budget, with spurious self-intersections between points of the pole.
// =====================================================================================================================

/// The cone apex + u C(v) with the pole on `side` (0: u = 0, 1: u = 1, 2: v = 0, 3: v = 1), C a random star-shaped
/// closed-ish B-spline curve at height h over the apex (h = 0: a flat disk), degrees pu (u) and pv.
BSplineSurface poleSurface(std::mt19937_64& rng, int side, int pu, int pv, double h, bool sliver, Vec3& apex) {
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const int nc = pv + 3 + static_cast<int>(rng() % 5);  // control points of C
  std::vector<double> kv = randomKnots(rng, pv, nc, true);
  if (sliver) {  // the last interior span becomes a sliver of 1.5e-5 of the one before
    const size_t last = kv.size() - static_cast<size_t>(pv) - 1;
    double prev = kv[last - 1];
    size_t k = last - 1;
    while (k > 0 && kv[k] == prev) --k;
    const double span = prev - kv[k];
    for (size_t m = last; m < kv.size(); ++m) kv[m] = prev + 1.5e-5 * span;
  }
  const int nu = pu + 1 + static_cast<int>(rng() % 3);
  std::vector<double> ku(static_cast<size_t>(nu + pu + 1));
  for (int i = 0; i < static_cast<int>(ku.size()); ++i) ku[i] = std::clamp(i - pu, 0, nu - pu) / double(nu - pu);
  const double z = u01(rng), y = u01(rng), x = u01(rng);  // drawn last argument first (test_helpers.h)
  apex = Vec3(x, y, z) * 10.0;
  const double scale = std::pow(10.0, -3.0 + 7.0 * u01(rng));  // 1e-3 .. 1e4
  Matrix q(nc, 3);
  for (int j = 0; j < nc; ++j) {  // angles increasing over at most 300 degrees, radii 0.5 .. 1.5
    const double th = (5.0 / 3.0) * M_PI * (j + 0.3 * u01(rng)) / nc;
    const double r = 0.5 + u01(rng);
    q.row(j) << scale * r * std::cos(th), scale * r * std::sin(th), scale * h;
  }
  Matrix pts(nu * nc, 3);
  for (int i = 0; i < nu; ++i) {
    double g = 0.0;  // Greville abscissa: S is linear in u
    for (int k = 1; k <= pu; ++k) g += ku[static_cast<size_t>(i + k)];
    g /= pu;
    for (int j = 0; j < nc; ++j) pts.row(i * nc + j) = apex.transpose() + g * q.row(j);
  }
  // The pole on `side`: reverse u (side 1), or swap u and v (sides 2, 3).
  const BSplineSurface s = *BSplineSurface::create(pu, pv, ku, kv, nu, nc, pts);
  switch (side) {
    case 0: return s;
    case 1: return s.reversedU();
    case 2: return s.swappedUV();
    default: return s.reversedU().swappedUV();
  }
}

TEST(RegularitySearchPoles, APoleSideIsOneCriticalPointAndTheSearchCompletes) {
  std::mt19937_64 rng(390001);
  int trials = 0, slivers = 0;
  for (int trial = 0; trial < 48; ++trial) {
    const int side = trial % 4;
    const int pu = 1 + static_cast<int>(rng() % 3), pv = 2 + static_cast<int>(rng() % 2);
    const double h = trial % 3 == 0 ? 0.0 : 0.3 + 0.7 * std::uniform_real_distribution<double>(0, 1)(rng);
    const bool sliver = trial % 5 == 1;
    Vec3 apex;
    const BSplineSurface s = poleSurface(rng, side, pu, pv, h, sliver, apex);
    Result<SurfaceSearchResult> r = searchSurfaceDefects(s);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    const std::string where = "trial " + std::to_string(trial) + " side " + std::to_string(side);
    EXPECT_TRUE(r->summary.complete) << where << ": work " << r->summary.work;
    EXPECT_EQ(r->summary.unresolved, 0) << where;
    EXPECT_TRUE(r->selfIntersections.empty()) << where << ": " << r->selfIntersections.size();
    ASSERT_EQ(r->criticalPoints.size(), 1u) << where;
    EXPECT_LE((r->criticalPoints[0].point - apex).norm(), r->summary.distance) << where;
    // On the pole side, by the parameters.
    const SurfaceCriticalPoint& c = r->criticalPoints[0];
    const double onSide = side == 0 ? c.u - s.knotsU().values().front() : side == 1 ? s.knotsU().values().back() - c.u
                          : side == 2 ? c.v - s.knotsV().values().front() : s.knotsV().values().back() - c.v;
    EXPECT_EQ(onSide, 0.0) << where;
    ++trials;
    slivers += sliver ? 1 : 0;
  }
  EXPECT_EQ(trials, 48);
  EXPECT_GE(slivers, 8);
}

TEST(RegularitySearchPoles, ADegenerateSideThatIsNotAPointIsStillReported) {
  // The same cone, with C's first two control points equal: C'(v0) = 0 on the clamped end, so n also vanishes all
  // along the side v = v0, whose points are u C(v0), not one point. Both sides are reported: the apex and a point of
  // that side away from it.
  std::mt19937_64 rng(390002);
  for (int trial = 0; trial < 8; ++trial) {
    Vec3 apex;
    BSplineSurface s = poleSurface(rng, 0, 1 + trial % 3, 3, 0.5, false, apex);
    Matrix pts = s.points();
    for (int i = 0; i < s.numU(); ++i) pts.row(i * s.numV() + 1) = pts.row(i * s.numV());
    const std::vector<double> ku = s.knotsU().values(), kv = s.knotsV().values();
    s = *BSplineSurface::create(s.degreeU(), s.degreeV(), ku, kv, s.numU(), s.numV(), pts);
    Result<SurfaceSearchResult> r = searchSurfaceDefects(s);
    ASSERT_TRUE(r.isOk());
    bool atApex = false, onSide = false;
    for (const SurfaceCriticalPoint& c : r->criticalPoints) {
      atApex = atApex || (c.point - apex).norm() <= r->summary.distance;
      onSide = onSide || (c.v == kv.front() && (c.point - apex).norm() > 100.0 * r->summary.distance);
    }
    EXPECT_TRUE(atApex) << "trial " << trial;
    EXPECT_TRUE(onSide) << "trial " << trial;
  }
}

TEST(RegularitySearchPoles, ACoverOfTheConeThatFoldsBackOverItselfIsStillFound) {
  // Regions that reach the same pole are settled when their directions from the apex are separated by a plane. Here
  // C runs round 1.5 times over control points at angles 2 pi j / 8 (uniform cubic): the control points j and j + 8
  // are the same, so the second lap retraces the first exactly and the cone apex + u C(v) covers part of itself twice.
  // Those regions share their directions from the apex: the search must still report self-intersections there.
  for (const double h : {0.0, 0.6}) {
    const int nc = 15;
    Matrix pts(2 * nc, 3);
    const Vec3 apex(1.0, -2.0, 0.5);
    for (int i = 0; i < 2; ++i)
      for (int j = 0; j < nc; ++j) {
        const double th = 2.0 * M_PI * j / 8.0;
        pts.row(i * nc + j) = (apex + i * Vec3(std::cos(th), std::sin(th), h)).transpose();
      }
    std::vector<double> kv(static_cast<size_t>(nc + 4));
    for (size_t k = 0; k < kv.size(); ++k) kv[k] = static_cast<double>(k);
    const BSplineSurface s = *BSplineSurface::create(1, 3, {0, 0, 1, 1}, kv, 2, nc, pts);
    Result<SurfaceSearchResult> r = searchSurfaceDefects(s);
    ASSERT_TRUE(r.isOk());
    EXPECT_FALSE(r->selfIntersections.empty()) << "h " << h;
    bool atApex = false;
    for (const SurfaceCriticalPoint& c : r->criticalPoints) atApex = atApex || (c.point - apex).norm() <= r->summary.distance;
    EXPECT_TRUE(atApex) << "h " << h;
    for (const SurfaceSelfIntersection& x : r->selfIntersections)  // each a true double point, away from the apex
      EXPECT_LE((s.evaluate(x.u1, x.v1) - s.evaluate(x.u2, x.v2)).norm(), r->summary.distance) << "h " << h;
  }
}

// A real face with a near-fold (linkrods.step's F27 in tests/data/regularity: rational, degrees (6, 8), 65 spans
// in v): S_u x S_v vanishes at points of a curve and nearly vanishes along it, so the search can settle neither
// the curve nor the pairs across it. Every critical point it reports must be a zero of S_u x S_v by the B-spline's
// own derivatives (de Boor, not the Bernstein quotient Newton runs on), within ten times the search's critical
// tolerance (1e-9, of another scale) of the face's largest |S_u| |S_v|, and its point must be S there; and the
// search must say that it is incomplete. The budget is small here (the critical points come first; the whole budget takes seconds).
TEST(RegularitySearchNearFold, ARealFacesCriticalPointsAreZerosOfItsNormalAndTheSearchSaysItIsIncomplete) {
  const Result<Model> model =
      io::readModel(std::filesystem::path(SEAM_TEST_DATA_DIR) / "regularity" / "near_fold_linkrods_F27.json");
  ASSERT_TRUE(model.isOk()) << model.status().message();
  ASSERT_EQ(model->patches.size(), 1u);
  const BSplineSurface& s = model->patches[0].surface;
  double scale = 0.0;  // the largest |S_u| |S_v| on a 41 x 41 grid: what |S_u x S_v| is measured against
  const auto& ku = s.knotsU().values();
  const auto& kv = s.knotsV().values();
  for (int a = 0; a <= 40; ++a)
    for (int b = 0; b <= 40; ++b) {
      const auto d = s.derivatives(ku.front() + (ku.back() - ku.front()) * a / 40.0,
                                   kv.front() + (kv.back() - kv.front()) * b / 40.0, 1);
      scale = std::max(scale, d[1][0].norm() * d[0][1].norm());
    }
  SearchOptions options;
  options.maxWork = 20'000;
  const Result<SurfaceSearchResult> r = searchSurfaceDefects(s, options);
  ASSERT_TRUE(r.isOk()) << r.status().message();
  EXPECT_FALSE(r->summary.complete);
  EXPECT_GT(r->summary.unresolved, 0);
  ASSERT_GE(r->criticalPoints.size(), 2u);
  for (const SurfaceCriticalPoint& c : r->criticalPoints) {
    const auto d = s.derivatives(c.u, c.v, 1);
    const Vec3 su = d[1][0].head<3>(), sv = d[0][1].head<3>();
    EXPECT_LE(su.cross(sv).norm(), 1e-8 * scale) << "at (" << c.u << ", " << c.v << ")";
    EXPECT_LE((c.point - Vec3(d[0][0].head<3>())).norm(), 1e-12 * std::sqrt(scale)) << "at (" << c.u << ", " << c.v << ")";
  }
}

TEST(RegularitySearchLimits, HighDegreesAreRefusedWithTheirDegree) {
  // A 200 x 200 Bezier net (issue 15 section 2): refused at once instead of minutes in the O(degree^4) product.
  const int n = 200;
  Matrix pts(n * n, 3);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) pts.row(i * n + j) << i, j, 0.0;
  }
  std::vector<double> k(2 * n, 0.0);
  std::fill(k.begin() + n, k.end(), 1.0);
  const BSplineSurface s = *BSplineSurface::create(n - 1, n - 1, k, k, n, n, pts);
  Result<SurfaceSearchResult> r = searchSurfaceDefects(s);
  ASSERT_FALSE(r.isOk());
  EXPECT_EQ(r.status().code(), ErrorCode::kUnsupported);
  EXPECT_NE(r.status().message().find("degree 199 x 199"), std::string::npos) << r.status().message();
  // A degree-1000 polynomial curve is searched (its hodograph needs no product).
  const int m = 1001;
  Matrix cp(m, 3);
  for (int i = 0; i < m; ++i) cp.row(i) << i, std::sin(0.01 * i), 0.0;
  std::vector<double> t(2 * m, 0.0);
  std::fill(t.begin() + m, t.end(), 1.0);
  Result<CurveSearchResult> c = searchCurveDefects(*BSplineCurve::create(m - 1, t, cp));
  ASSERT_TRUE(c.isOk()) << c.status().message();
  EXPECT_TRUE(c->summary.provedClean(c->defectFound()));
}

}  // namespace
}  // namespace seam::regularity
