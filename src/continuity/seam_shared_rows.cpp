// Seams that share their control rows (C^k splits: two patches cut from one surface at a knot line, issue 16 goal
// 2): bounds straight from the row differences (continuity/seam_correspondence.h, sharedRowBounds).
// docs/algorithms/seam-measures.md, "Seams that share their control rows", derives the bounds.
#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "continuity/seam_correspondence.h"
#include "seam/core/tolerances.h"

namespace seam::detail {

namespace {

/// Rounding allowance of the shared-row test, in units of the machine epsilon times (degree + 1) times the magnitude
/// of the coordinates the rows were computed from: rows that differ by more are not "the same row up to rounding"
/// (a perturbation of 1e-12 of the coordinates is 70 times above it for cubics) and take the general route.
constexpr double kSharedRowUlps = 16.0;
/// Relative inflation of the shared-row bounds: covers the rounding of the few dozen operations that form them.
constexpr double kSharedRowSafety = 1.0 + 1e-12;

/// Factors d/du and d^2/du^2 of the cross-derivative rows at edge e per unit of the control points' coordinates:
/// p / h and p (p - 1) / h^2 with h the knot span next to the edge (the rows are differences of control points
/// scaled by them, so their rounding is epsilon x coordinates x these factors).
std::pair<double, double> crossRowFactors(const BSplineSurface& surf, Edge e) {
  const bool uEdge = isUEdge(e);
  const int p = uEdge ? surf.degreeU() : surf.degreeV();
  const KnotVector& kv = uEdge ? surf.knotsU() : surf.knotsV();
  const Interval dom = kv.domain(p);
  const bool atStart = e == Edge::U0 || e == Edge::V0;
  double h = dom.length();
  for (int i = 0; i < kv.size(); ++i) {
    const double k = kv[i];
    const double d = atStart ? k - dom.lo : dom.hi - k;
    if (d > kKnotRelTol * dom.length()) h = std::min(h, d);
  }
  if (!(h > 0.0)) return {0.0, 0.0};
  return {p / h, p * (p - 1) / (h * h)};
}

/// The Bernstein weights of sharedRowBounds' product n_A = A_t x A_out for each degree n <= kJetStackDegree, computed
/// once: product[n][i][j] = C(n-1, i) C(n, j) / C(2n-1, i+j) and binomial[n][l] = C(2n-1, l), the same expressions
/// (so the same doubles) that were evaluated per coefficient.
struct ProductWeights {
  std::array<std::array<std::array<double, kJetStackDegree + 1>, kJetStackDegree>, kJetStackDegree + 1> product{};
  std::array<std::array<double, 2 * kJetStackDegree>, kJetStackDegree + 1> binomial{};
};

const ProductWeights& productWeights() {
  static const ProductWeights w = [] {
    ProductWeights r;
    for (int n = 1; n <= kJetStackDegree; ++n) {
      const int dn = 2 * n - 1;
      for (int i = 0; i < n; ++i)
        for (int j = 0; j <= n; ++j)
          r.product[static_cast<size_t>(n)][static_cast<size_t>(i)][static_cast<size_t>(j)] =
              binomial(n - 1, i) * binomial(n, j) / binomial(dn, i + j);
      for (int l = 0; l <= dn; ++l) r.binomial[static_cast<size_t>(n)][static_cast<size_t>(l)] = binomial(dn, l);
    }
    return r;
  }();
  return w;
}

/// Coefficient j of span i of the k-th cross derivative of a side (polynomial: three coordinates).
Vec3 row(const Side& s, size_t k, size_t i, int j) { return Vec3(Eigen::Map<const Vec3>(s.coeff(k, i, j))); }

/// The spans correspond one to one: same normalised breakpoints (B's mirrored when reversed).
bool spansCorrespond(const Side& A, const Side& B, bool reversed) {
  const size_t m = A.spans.size();
  for (size_t k = 0; k < m; ++k) {
    const size_t kb = reversed ? m - 1 - k : k;
    const double na = (A.spans[k].lo - A.dom.lo) / A.dom.length();
    const double nb = reversed ? (B.dom.hi - B.spans[kb].hi) / B.dom.length()
                               : (B.spans[kb].lo - B.dom.lo) / B.dom.length();
    if (!(std::abs(na - nb) <= kKnotRelTol)) return false;
  }
  return true;
}

/// lambda by least squares over all coefficients of the first rows (B_1 = lambda A_out = -lambda A_1), and the
/// largest coordinate magnitude of the boundary rows. nullopt when lambda is not positive and finite.
struct RowScale {
  double lambda = 1.0, mag0 = 0.0;
};
std::optional<RowScale> rowScale(const Side& A, const Side& B, bool reversed) {
  const int n = A.degree;
  const size_t m = A.spans.size();
  double num = 0.0, den = 0.0, mag0 = 0.0;
  for (size_t k = 0; k < m; ++k) {
    const size_t kb = reversed ? m - 1 - k : k;
    for (int j = 0; j <= n; ++j) {
      const int jb = reversed ? n - j : j;
      const Vec3 o = -row(A, 1, k, j), b1 = row(B, 1, kb, jb);
      num += b1.dot(o);
      den += o.squaredNorm();
      mag0 = std::max({mag0, row(A, 0, k, j).cwiseAbs().maxCoeff(), row(B, 0, kb, jb).cwiseAbs().maxCoeff()});
    }
  }
  if (!(den > 0.0)) return std::nullopt;
  const double lambda = num / den;
  if (!(lambda > 0.0) || !std::isfinite(lambda)) return std::nullopt;
  return RowScale{lambda, mag0};
}

/// The largest coefficient differences of the rows (d0, d1, d2 against B_0 = A_0, B_1 = lambda A_out,
/// B_2 = lambda^2 A_oo; dT of the along-edge derivative of the gap; c1, c2 against the parametric identities), the
/// coefficient maxima of A_t, A_out, A_oo, A_ot, A_tt and the lower bound nMin of |n_A|, over the spans seen so far.
struct RowMaxima {
  double d0 = 0.0, d1 = 0.0, d2 = 0.0, dT = 0.0, c1 = 0.0, c2 = 0.0;
  double tMax = 0.0, oMax = 0.0, aooMax = 0.0, aotMax = 0.0, attMax = 0.0;
  double nMin = std::numeric_limits<double>::infinity();
};
constexpr int kMaxSharedDegree = kJetStackDegree;

/// Adds span k of A (kb of B) to the maxima of the rows: false when the rows differ by more than the rounding
/// allowances eps0, eps1, eps2 (the spans so far) or n_A vanishes at the span's middle.
bool addSpan(const Side& A, const Side& B, size_t k, bool reversed, double lambda, const std::array<double, 3>& eps,
             RowMaxima& r) {
  const int n = A.degree;
  const size_t kb = reversed ? A.spans.size() - 1 - k : k;
  std::array<Vec3, kMaxSharedDegree + 1> diff;
  std::array<Vec3, kMaxSharedDegree> T, O1;          // A_t and the along-edge derivative of A_1 (coefficients)
  std::array<Vec3, 2 * kMaxSharedDegree> NA;         // n_A = A_t x A_out, degree 2n - 1
  std::array<Vec3, kMaxSharedDegree + 1> O;          // A_out = -A_1 (coefficients)
  for (int j = 0; j <= n; ++j) {
    const int jb = reversed ? n - j : j;
    const Vec3 pa = row(A, 0, k, j), pb = row(B, 0, kb, jb);
    const Vec3 ra1 = row(A, 1, k, j), rb1 = row(B, 1, kb, jb);
    const Vec3 ra2 = row(A, 2, k, j), rb2 = row(B, 2, kb, jb);
    diff[static_cast<size_t>(j)] = pb - pa;
    r.d0 = std::max(r.d0, (pb - pa).norm());
    r.d1 = std::max(r.d1, (rb1 + lambda * ra1).norm());
    r.d2 = std::max(r.d2, (rb2 - lambda * lambda * ra2).norm());
    r.c1 = std::max(r.c1, (rb1 + ra1).norm());
    r.c2 = std::max(r.c2, (rb2 - ra2).norm());
    r.oMax = std::max(r.oMax, ra1.norm());
    r.aooMax = std::max(r.aooMax, ra2.norm());
    if (j >= 2) {
      const Vec3 att = n * (n - 1) * (pa - 2.0 * row(A, 0, k, j - 1) + row(A, 0, k, j - 2));
      r.attMax = std::max(r.attMax, att.norm());
    }
  }
  if (!(r.d0 <= eps[0]) || !(r.d1 <= eps[1]) || !(r.d2 <= eps[2])) return false;
  for (int j = 0; j < n; ++j) {
    const size_t u = static_cast<size_t>(j);
    T[u] = n * (row(A, 0, k, j + 1) - row(A, 0, k, j));
    O1[u] = n * (row(A, 1, k, j + 1) - row(A, 1, k, j));
    r.tMax = std::max(r.tMax, T[u].norm());
    r.aotMax = std::max(r.aotMax, O1[u].norm());
    r.dT = std::max(r.dT, (n * (diff[u + 1] - diff[u])).norm());
  }
  // n_A = A_t x A_out in Bernstein form of degree 2n - 1: sum over i + j = l of C(n-1, i) C(n, j) / C(2n-1, l).
  const int dn = 2 * n - 1;
  const ProductWeights& weights = productWeights();
  for (int j = 0; j <= n; ++j) O[static_cast<size_t>(j)] = -row(A, 1, k, j);
  for (int l = 0; l <= dn; ++l) NA[static_cast<size_t>(l)].setZero();
  for (int i = 0; i < n; ++i)
    for (int j = 0; j <= n; ++j)
      NA[static_cast<size_t>(i + j)] += weights.product[static_cast<size_t>(n)][static_cast<size_t>(i)]
                                                       [static_cast<size_t>(j)] *
                                        T[static_cast<size_t>(i)].cross(O[static_cast<size_t>(j)]);
  // |n_A| >= min_l <m, N_l> for the unit direction m of n_A at the middle (the hull of a scalar polynomial).
  Vec3 mid = Vec3::Zero();
  for (int l = 0; l <= dn; ++l)  // 2^dn n_A(1/2)
    mid += weights.binomial[static_cast<size_t>(n)][static_cast<size_t>(l)] * NA[static_cast<size_t>(l)];
  if (!(mid.norm() > 0.0)) return false;
  mid.normalize();
  for (int l = 0; l <= dn; ++l) {
    r.nMin = std::min(r.nMin, mid.dot(NA[static_cast<size_t>(l)]));
  }
  return true;
}

/// The bounds from the rows' maxima (docs/algorithms/seam-measures.md); nullopt when they are not at round-off
/// level (or a denominator is not positive).
std::optional<SharedRowBounds> boundsFromMaxima(const RowMaxima& m, double lambda) {
  const double d1 = m.d1, dT = m.dT, nMin = m.nMin, tMax = m.tMax, oMax = m.oMax;
  SharedRowBounds r;
  r.lambda = lambda;
  r.g0 = m.d0 * kSharedRowSafety;
  r.c1 = m.c1;
  r.c2 = m.c2;
  // G1: n_B = lambda n_A + e with |e| <= lambda dT |O| + |T| d1 + dT d1; sin(angle) <= |e| / (lambda |n_A|).
  const double e = lambda * dT * oMax + tMax * d1 + dT * d1;
  const double sinBound = kSharedRowSafety * e / (lambda * nMin);
  if (!(sinBound < 1.0)) return std::nullopt;
  r.g1 = std::asin(sinBound) * kSharedRowSafety;
  // G2 (the quotient of g2Bound, pointwise): with L = lambda D + e_L', |e_L'| <= d1 |T| |n_A|, |K| <= |O| d1 |n_A|,
  // D = -|n_A|^2 and B_cc = lambda^2 A_oo + e2, |V| / |n_A|^4 <= d2 + d1 |T| (2 lambda |n_A| + d1 |T|) |A_oo| / |n_A|^2
  // + 2 (lambda |n_A| + d1 |T|) |O| d1 |A_ot| / |n_A|^2 + |O|^2 d1^2 |A_tt| / |n_A|^2 and |y| <= that x |T|^2 /
  // |B_c x T|^2, |B_c x T| >= lambda |n_A| - d1 |T|: every term decreases with |n_A|, so |n_A| = nMin bounds it.
  const double bLow = lambda * nMin - d1 * tMax;
  if (!(bLow > 0.0)) return std::nullopt;
  const double n2 = nMin * nMin, dt = d1 * tMax;
  const double V = m.d2 + dt * (2.0 * lambda * nMin + dt) * m.aooMax / n2 +
                   2.0 * (lambda * nMin + dt) * oMax * d1 * m.aotMax / n2 + oMax * oMax * d1 * d1 * m.attMax / n2;
  r.g2 = kSharedRowSafety * V * tMax * tMax / (bLow * bLow);
  if (!(r.g1 <= kIdentityBoundFactor * kAngleBoundFloor) || !std::isfinite(r.g2)) return std::nullopt;
  return r;
}

}  // namespace

std::optional<SharedRowBounds> sharedRowBounds(const Side& A, const Side& B, bool reversed) {
  if (A.rational || B.rational || A.degree != B.degree || A.spans.size() != B.spans.size() || A.degree < 1)
    return std::nullopt;
  if (!spansCorrespond(A, B, reversed)) return std::nullopt;
  const std::optional<RowScale> scale = rowScale(A, B, reversed);
  if (!scale) return std::nullopt;
  const int n = A.degree;
  const double lambda = scale->lambda;
  // Rounding allowances from the coordinates' magnitude.
  const auto [fa1, fa2] = crossRowFactors(A.patch->surface, A.edge);
  const auto [fb1, fb2] = crossRowFactors(B.patch->surface, B.edge);
  const double ulp = kSharedRowUlps * (n + 1) * std::numeric_limits<double>::epsilon() * scale->mag0;
  const std::array<double, 3> eps{ulp, ulp * (lambda * fa1 + fb1), ulp * (lambda * lambda * fa2 + fb2)};
  if (n > kMaxSharedDegree) return std::nullopt;
  RowMaxima maxima;
  for (size_t k = 0; k < A.spans.size(); ++k)
    if (!addSpan(A, B, k, reversed, lambda, eps, maxima)) return std::nullopt;
  if (!(maxima.nMin > 0.0)) return std::nullopt;
  return boundsFromMaxima(maxima, lambda);
}

}  // namespace seam::detail
