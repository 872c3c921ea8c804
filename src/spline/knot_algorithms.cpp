// Generic knot algorithms on rows of coefficients (any number of columns). Curves use them directly; surfaces
// apply them to one parameter direction at a time with whole rows of control points as "coefficients".
#include <Eigen/QR>
#include <algorithm>
#include <cassert>

#include "seam/core/bernstein.h"
#include "seam/spline/bspline_curve.h"
#include "spline/spline_internal.h"

namespace seam::detail {

namespace {

int spanOf(int degree, const std::vector<double>& knots, double t) { return KnotVector::findSpan(knots, degree, t); }

/// KnotVector(knots).domain(degree) without the copy.
Interval domainOf(int degree, const std::vector<double>& knots) {
  const int n = static_cast<int>(knots.size()) - degree - 1;
  if (n <= degree || degree < 0) return {0.0, 0.0};
  return {knots[static_cast<size_t>(degree)], knots[static_cast<size_t>(n)]};
}

int exactMultiplicity(const std::vector<double>& knots, double t) {
  return static_cast<int>(std::count(knots.begin(), knots.end(), t));
}

// Distinct knot values strictly inside the domain, compared exactly (knot insertion counts multiplicities exactly,
// so decomposition must too: two knots 1e-14 apart are two breakpoints, however close).
std::vector<double> exactInteriorBreakpoints(int degree, const std::vector<double>& knots) {
  const Interval dom = domainOf(degree, knots);
  std::vector<double> out;
  for (double k : knots)
    if (k > dom.lo && k < dom.hi && (out.empty() || k != out.back())) out.push_back(k);
  return out;
}

// One Boehm insertion of t (t inside the domain, span k with t_k <= t <= t_{k+1}, t_k < t_{k+1}).
void insertOnce(int p, std::vector<double>& knots, Matrix& rows, double t) {
  const int k = spanOf(p, knots, t);
  const auto n = rows.rows();
  Matrix out(n + 1, rows.cols());
  for (int i = 0; i <= k - p; ++i) out.row(i) = rows.row(i);
  for (int i = k - p + 1; i <= k; ++i) {
    const double ti = knots[static_cast<size_t>(i)];
    const double a = (t - ti) / (knots[static_cast<size_t>(i + p)] - ti);
    out.row(i) = (1.0 - a) * rows.row(i - 1) + a * rows.row(i);
  }
  for (Eigen::Index i = k + 1; i <= n; ++i) out.row(i) = rows.row(i - 1);
  knots.insert(knots.begin() + k + 1, t);
  rows = std::move(out);
}

// insertOnce on the first n rows of `buf` (at least n + 1 rows), in place: the rows after the span move down by one,
// the p new ones are formed from the highest down, each from two rows not yet overwritten. The same values as
// insertOnce (the same operations), without a new matrix per insertion.
void insertOnceInPlace(int p, std::vector<double>& knots, Matrix& buf, Eigen::Index n, double t) {
  assert(buf.rows() > n);
  const int k = spanOf(p, knots, t);
  for (Eigen::Index i = n; i >= k + 1; --i) buf.row(i) = buf.row(i - 1);
  for (int i = k; i >= k - p + 1; --i) {
    const double ti = knots[static_cast<size_t>(i)];
    const double a = (t - ti) / (knots[static_cast<size_t>(i + p)] - ti);
    buf.row(i) = (1.0 - a) * buf.row(i - 1) + a * buf.row(i);
  }
  knots.insert(knots.begin() + k + 1, t);
}

}  // namespace

void insertKnot(int degree, std::vector<double>& knots, Matrix& rows, double t, int times) {
  const Interval dom = domainOf(degree, knots);
  if (t < dom.lo || t > dom.hi || times <= 0) return;
  const bool atEnd = (t == dom.lo || t == dom.hi);
  const int cap = atEnd ? degree + 1 : degree;
  const int s = exactMultiplicity(knots, t);
  const int r = std::min(times, cap - s);
  for (int i = 0; i < r; ++i) insertOnce(degree, knots, rows, t);
}

void refineKnots(int degree, std::vector<double>& knots, Matrix& rows, const std::vector<double>& newKnots) {
  for (double t : newKnots) insertKnot(degree, knots, rows, t, 1);
}

void clampEnds(int degree, std::vector<double>& knots, Matrix& rows) {
  const Interval dom = domainOf(degree, knots);
  const int p = degree;
  for (double t : {dom.lo, dom.hi}) {
    const int s = exactMultiplicity(knots, t);
    for (int i = s; i < p; ++i) insertOnce(p, knots, rows, t);
  }
  // Now both ends have multiplicity >= p: keep the control points of the domain spans only.
  const int first = spanOf(p, knots, dom.lo) - p;
  const int last = spanOf(p, knots, dom.hi);
  Matrix trimmed = rows.middleRows(first, last - first + 1);
  std::vector<double> t(knots.begin() + first, knots.begin() + last + p + 2);
  t.front() = dom.lo;
  t.back() = dom.hi;
  knots = std::move(t);
  rows = std::move(trimmed);
}

std::vector<Interval> decompose(int degree, std::vector<double>& knots, Matrix& rows) {
  // Already one clamped Bezier span (the common case of a patch edge): nothing to insert or trim, and the general
  // route below would return these very knots, rows and span.
  const size_t p1 = static_cast<size_t>(degree) + 1;
  if (degree >= 1 && knots.size() == 2 * p1 && rows.rows() == static_cast<Eigen::Index>(p1) &&
      knots[p1 - 1] < knots[p1] && std::all_of(knots.begin(), knots.begin() + static_cast<std::ptrdiff_t>(p1),
                                               [&](double k) { return k == knots.front(); }) &&
      std::all_of(knots.begin() + static_cast<std::ptrdiff_t>(p1), knots.end(),
                  [&](double k) { return k == knots.back(); }))
    return {Interval{knots[p1 - 1], knots[p1]}};
  clampEnds(degree, knots, rows);
  const std::vector<double> interior = exactInteriorBreakpoints(degree, knots);
  // Each interior breakpoint raised to multiplicity `degree` (insertKnot(degree, knots, rows, b, degree): b is
  // inside the domain, and inserting one breakpoint leaves the others' multiplicities), in one matrix of the final
  // size.
  std::vector<int> times(interior.size());
  Eigen::Index added = 0;
  for (size_t i = 0; i < interior.size(); ++i) {
    times[i] = std::max(0, degree - exactMultiplicity(knots, interior[i]));
    added += times[i];
  }
  if (added > 0) {
    Matrix buf(rows.rows() + added, rows.cols());
    buf.topRows(rows.rows()) = rows;
    Eigen::Index n = rows.rows();
    knots.reserve(knots.size() + static_cast<size_t>(added));
    for (size_t i = 0; i < interior.size(); ++i)
      for (int r = 0; r < times[i]; ++r) insertOnceInPlace(degree, knots, buf, n++, interior[i]);
    rows = std::move(buf);
  }
  std::vector<Interval> spans;
  const Interval dom = domainOf(degree, knots);
  double lo = dom.lo;
  for (double b : interior) {
    spans.push_back({lo, b});
    lo = b;
  }
  spans.push_back({lo, dom.hi});
  assert(rows.rows() == static_cast<Eigen::Index>(spans.size()) * degree + 1);
  return spans;
}

namespace {

/// The blossom of the polynomial piece of span s (knots[s] < knots[s+1]) of a degree-p B-spline at x[0..p-1]:
/// de Boor's algorithm with argument x[r-1] at level r. The blossom is symmetric and affine in each argument, so
/// arguments outside the span continue the piece's polynomial.
Matrix blossomOfSpan(int p, const std::vector<double>& t, const Matrix& rows, int s, const double* x) {
  Matrix d = rows.middleRows(s - p, p + 1);
  for (int r = 1; r <= p; ++r)
    for (int j = p; j >= r; --j) {
      const int i = s - p + j;
      const double a = (x[r - 1] - t[static_cast<size_t>(i)]) /
                       (t[static_cast<size_t>(i + p + 1 - r)] - t[static_cast<size_t>(i)]);
      d.row(j) = (1.0 - a) * d.row(j - 1) + a * d.row(j);
    }
  return d.row(p);
}

}  // namespace

void extendDomain(int degree, std::vector<double>& knots, Matrix& rows, double lo, double hi) {
  const int p = degree;
  clampEnds(p, knots, rows);
  const int n = static_cast<int>(rows.rows());
  const auto at = [](int i) { return static_cast<size_t>(i); };
  // Control point i is the blossom of any piece in its support at knots i+1..i+p. Moving the end knots k0..k1 to
  // `to` changes the control points [i0, i1) that see them: blossoms of the end piece s at their new knots. The
  // others keep their knots and so their values.
  auto continueEnd = [&](int s, int k0, int k1, int i0, int i1, double to) {
    const std::vector<double> t = knots;
    for (int k = k0; k <= k1; ++k) knots[at(k)] = to;
    Matrix out = rows;
    for (int i = i0; i < i1; ++i) out.row(i) = blossomOfSpan(p, t, rows, s, &knots[at(i + 1)]);
    rows = std::move(out);
  };
  if (hi > knots[at(n)]) {
    int s = n - 1;  // the last non-empty span
    while (s > p && knots[at(s)] >= knots[at(s + 1)]) --s;
    continueEnd(s, n, n + p, std::max(0, n - p), n, hi);
  }
  if (lo < knots[at(p)]) {
    int s = p;  // the first non-empty span
    while (s < n - 1 && knots[at(s + 1)] <= knots[at(s)]) ++s;
    continueEnd(s, 0, p, 0, std::min(p, n), lo);
  }
}

void elevateDegree(int degree, std::vector<double>& knots, Matrix& rows, int by) {
  if (by <= 0) return;
  const int p = degree, q = degree + by;
  clampEnds(p, knots, rows);
  const KnotVector kv(knots);
  const Interval dom = kv.domain(p);

  // Target knot vector: every multiplicity rises by `by`.
  std::vector<double> target;
  for (int i = 0; i <= q; ++i) target.push_back(dom.lo);
  for (double b : exactInteriorBreakpoints(p, knots))
    for (int i = 0; i < exactMultiplicity(knots, b) + by; ++i) target.push_back(b);
  for (int i = 0; i <= q; ++i) target.push_back(dom.hi);
  const auto nNew = static_cast<Eigen::Index>(target.size()) - q - 1;

  // Elevated Bezier coefficients of the curve, piece by piece (adjacent pieces share their end row).
  std::vector<double> kd = knots;
  Matrix bez = rows;
  const auto spans = decompose(p, kd, bez);
  const auto pieces = static_cast<Eigen::Index>(spans.size());
  Matrix B(pieces * q + 1, rows.cols());
  for (Eigen::Index k = 0; k < pieces; ++k) {
    const BernsteinPoly piece(Matrix(bez.middleRows(k * p, p + 1)));
    B.middleRows(k * q, q + 1) = piece.elevated(by).coeffs();
  }

  // Decomposition matrix of the target space: Bezier rows as linear combinations of the new control points.
  // The elevated curve lies in that space, so M X = B is consistent; QR solves it to round-off.
  std::vector<double> kt = target;
  Matrix M = Matrix::Identity(nNew, nNew);
  decompose(q, kt, M);
  assert(M.rows() == B.rows());
  const Eigen::MatrixXd X = Eigen::MatrixXd(M).householderQr().solve(Eigen::MatrixXd(B));
  knots = std::move(target);
  rows = X;
}

BSplineCurve curveFromBezierPieces(const std::vector<BernsteinPoly>& pieces, const std::vector<Interval>& spans,
                                   bool rational) {
  assert(!pieces.empty() && pieces.size() == spans.size());
  const int d = pieces.front().degree();
  std::vector<double> knots;
  for (int i = 0; i <= d; ++i) knots.push_back(spans.front().lo);
  for (size_t k = 1; k < spans.size(); ++k)
    for (int i = 0; i < d; ++i) knots.push_back(spans[k].lo);
  for (int i = 0; i <= d; ++i) knots.push_back(spans.back().hi);
  const auto n = static_cast<Eigen::Index>(pieces.size()) * d + 1;
  Matrix rows(n, pieces.front().dim());
  for (size_t k = 0; k < pieces.size(); ++k) {
    const auto base = static_cast<Eigen::Index>(k) * d;
    assert(pieces[k].degree() == d);
    rows.middleRows(base, d + 1) = pieces[k].coeffs();
  }
  return BSplineCurve::fromHomogeneous(d, KnotVector(std::move(knots)), rows, rational);
}

}  // namespace seam::detail
