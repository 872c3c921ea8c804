// Bezier pieces of a curve / surface in time linear in the number of spans, with the same floating-point values as
// BSplineCurve::bezierPieces() and BSplineSurface::bezierPatches() (see search_internal.h).
#include <algorithm>

#include "search_internal.h"
#include "seam/core/knot_vector.h"
#include "spline/spline_internal.h"

namespace seam::regularity::detail {

namespace {

/// detail::decompose of the spline module (clamp both ends, then insert every interior breakpoint, left to right,
/// up to multiplicity `degree`, one Boehm step at a time), but the steps run on a short window of the current
/// knots and rows: every Boehm step touches rows k-p..k and knots k-p+1..k+p only, and once a breakpoint is
/// inserted nothing left of it changes again. Each step computes its rows with the same expression, in the same
/// order, on the same values, so the result is bit-identical; the cost is O(rows x degree) instead of
/// O(rows^2 x degree) (each step of `decompose` copies all rows and all knots).
std::vector<Interval> decomposeLinear(int p, std::vector<double>& knots, Matrix& rows) {
  seam::detail::clampEnds(p, knots, rows);
  const Interval dom = KnotVector(knots).domain(p);
  const auto cols = static_cast<size_t>(rows.cols());
  std::vector<double> out;  // finished rows, row-major
  out.reserve(static_cast<size_t>(rows.size()) * 2);
  std::vector<double> wk;   // current knots [kb, kb + wk.size())
  std::vector<double> wr;   // current rows [rb, rb + wr.size() / cols), row-major
  long kb = 0, rb = 0;
  size_t tk = 0, tr = 0;    // next original knot / row not yet in the window
  auto pullKnots = [&](long upTo) {
    while (kb + static_cast<long>(wk.size()) <= upTo) wk.push_back(knots[tk++]);
  };
  auto pullRows = [&](long upTo) {
    while (rb + static_cast<long>(wr.size() / cols) <= upTo) {
      const auto r = rows.row(static_cast<Eigen::Index>(tr++));
      for (size_t c = 0; c < cols; ++c) wr.push_back(r[static_cast<Eigen::Index>(c)]);
    }
  };
  std::vector<Interval> spans;
  double lo = dom.lo;
  long inserted = 0;
  std::vector<double> alpha(static_cast<size_t>(p));
  for (size_t i = 0; i < knots.size();) {
    const double b = knots[i];
    size_t last = i;
    while (last + 1 < knots.size() && knots[last + 1] == b) ++last;
    const int s = static_cast<int>(last - i + 1);
    i = last + 1;
    if (!(b > dom.lo && b < dom.hi)) continue;
    spans.push_back({lo, b});
    lo = b;
    long k = static_cast<long>(last) + inserted;  // findSpan(b): the last copy of b in the current knots
    for (int step = 0; step < p - s; ++step, ++k, ++inserted) {
      pullKnots(k + p);
      pullRows(k);
      for (long j = k - p + 1; j <= k; ++j) {  // insertOnce: a from the knots before the insertion
        const double tj = wk[static_cast<size_t>(j - kb)];
        alpha[static_cast<size_t>(j - (k - p + 1))] = (b - tj) / (wk[static_cast<size_t>(j + p - kb)] - tj);
      }
      const auto at = static_cast<long>(cols) * (k - rb);
      wr.insert(wr.begin() + at + static_cast<long>(cols), wr.begin() + at, wr.begin() + at + static_cast<long>(cols));
      for (long j = k; j >= k - p + 1; --j) {
        const double a = alpha[static_cast<size_t>(j - (k - p + 1))];
        double* rj = wr.data() + cols * static_cast<size_t>(j - rb);
        const double* rm = rj - cols;
        for (size_t c = 0; c < cols; ++c) rj[c] = (1.0 - a) * rm[c] + a * rj[c];
      }
      wk.insert(wk.begin() + (k + 1 - kb), b);
    }
    // Later steps (breakpoints right of b) use knots from k-p+2 and rows from k-p+1 on.
    const long keepKnot = k - p + 2;
    if (keepKnot > kb) {
      const long drop = std::min<long>(keepKnot - kb, static_cast<long>(wk.size()));
      wk.erase(wk.begin(), wk.begin() + drop);
      kb += drop;
    }
    const long keepRow = k - p + 1;
    if (keepRow > rb) {
      const long drop = std::min<long>(keepRow - rb, static_cast<long>(wr.size() / cols));
      out.insert(out.end(), wr.begin(), wr.begin() + drop * static_cast<long>(cols));
      wr.erase(wr.begin(), wr.begin() + drop * static_cast<long>(cols));
      rb += drop;
    }
  }
  spans.push_back({lo, dom.hi});
  out.insert(out.end(), wr.begin(), wr.end());
  for (; tr < static_cast<size_t>(rows.rows()); ++tr) {
    const auto r = rows.row(static_cast<Eigen::Index>(tr));
    for (size_t c = 0; c < cols; ++c) out.push_back(r[static_cast<Eigen::Index>(c)]);
  }
  rows = Eigen::Map<const Matrix>(out.data(), static_cast<Eigen::Index>(out.size() / cols),
                                  static_cast<Eigen::Index>(cols));
  return spans;
}

}  // namespace

std::vector<BezierCurvePiece> bezierPiecesLinear(const BSplineCurve& curve) {
  const int p = curve.degree();
  std::vector<double> k = curve.knots().values();
  Matrix h = curve.homogeneous();
  const std::vector<Interval> spans = decomposeLinear(p, k, h);
  std::vector<BezierCurvePiece> out;
  out.reserve(spans.size());
  for (size_t s = 0; s < spans.size(); ++s) {
    const BernsteinPoly piece(Matrix(h.middleRows(static_cast<Eigen::Index>(s) * p, p + 1)));
    out.push_back({curve.isRational() ? BezierCurve::fromHomogeneous(piece) : BezierCurve(piece.coeffs()), spans[s]});
  }
  return out;
}

std::vector<BezierPatchPiece> bezierPatchesLinear(const BSplineSurface& surface) {
  const int pu = surface.degreeU();
  const int pv = surface.degreeV();
  std::vector<double> kU = surface.knotsU().values();
  std::vector<double> kV = surface.knotsV().values();
  Matrix h = surface.homogeneous();
  const auto d = h.cols();
  int nu = surface.numU();
  int nv = surface.numV();
  // u: each of the nu rows holds a whole u line (nv points); v: the same on the transposed grid.
  Matrix rows = Eigen::Map<const Matrix>(h.data(), nu, h.size() / nu);
  const std::vector<Interval> spansU = decomposeLinear(pu, kU, rows);
  nu = static_cast<int>(rows.rows());
  h = Eigen::Map<const Matrix>(rows.data(), rows.size() / d, d);
  Matrix t = seam::detail::transposeGrid(h, nu, nv);
  rows = Eigen::Map<const Matrix>(t.data(), nv, t.size() / nv);
  const std::vector<Interval> spansV = decomposeLinear(pv, kV, rows);
  nv = static_cast<int>(rows.rows());
  t = Eigen::Map<const Matrix>(rows.data(), rows.size() / d, d);
  h = seam::detail::transposeGrid(t, nv, nu);
  std::vector<BezierPatchPiece> out;
  out.reserve(spansU.size() * spansV.size());
  for (size_t a = 0; a < spansU.size(); ++a) {
    for (size_t b = 0; b < spansV.size(); ++b) {
      Matrix c((pu + 1) * (pv + 1), d);
      for (int i = 0; i <= pu; ++i) {
        for (int j = 0; j <= pv; ++j) {
          c.row(i * (pv + 1) + j) =
              h.row((static_cast<Eigen::Index>(a) * pu + i) * nv + static_cast<Eigen::Index>(b) * pv + j);
        }
      }
      const BernsteinPatch bp(pu, pv, std::move(c));
      out.push_back({surface.isRational() ? BezierPatch::fromHomogeneous(bp) : BezierPatch(pu, pv, bp.coeffs()),
                     spansU[a], spansV[b], static_cast<int>(a), static_cast<int>(b)});
    }
  }
  return out;
}

}  // namespace seam::regularity::detail
