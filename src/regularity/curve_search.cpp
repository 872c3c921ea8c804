// Critical points and self-intersections of B-spline / NURBS curves by Bezier subdivision with hull pruning and
// Newton refinement (see defect_search.h).
#include <algorithm>
#include <cmath>
#include <memory>

#include "search_internal.h"
#include "separation_internal.h"
#include "seam/core/bernstein.h"
#include "seam/core/tolerances.h"
#include "seam/model/model.h"
#include "seam/regularity/defect_search.h"

namespace seam::regularity {

namespace detail {

bool positiveDirection(std::span<const Vec3> vs) {
  if (vs.empty()) return false;
  double maxNorm = 0.0;
  Vec3 sum = Vec3::Zero();
  for (const Vec3& v : vs) {
    const double n = v.norm();
    if (!(n > 0.0)) return false;
    maxNorm = std::max(maxNorm, n);
    sum += v / n;
  }
  auto works = [&](const Vec3& c) {
    const double cn = c.norm();
    if (!(cn > 0.0)) return false;
    const double margin = kConeMarginRel * cn * maxNorm;
    for (const Vec3& v : vs) {
      if (!(c.dot(v) > margin)) return false;
    }
    return true;
  };
  if (works(sum)) return true;
  const Vec3 origin = Vec3::Zero();
  const MinNormResult r = minNormPoint(vs, std::span<const Vec3>(&origin, 1));
  return r.ok && works(r.point);
}

double defaultDistance(double diagonal) { return Tolerances::forModelSize(diagonal).distance; }

}  // namespace detail

namespace {

using detail::Box3;

/// One Bezier piece in homogeneous form (w x, w y, w z, w), extra coordinates zero.
struct Piece {
  Interval iv;
  BernsteinPoly h;   // dim 4
  BernsteinPoly dh;  // derivative (local parameter)
  BernsteinPoly n;   // hodograph numerator (dim 3): A' w - A w' (A' for polynomial pieces)
  BernsteinPoly dn;
  double nScale = 0.0;  // max coefficient norm of n
  bool rational = false;
  Box3 box;  // of the control points
};

BernsteinPoly columns(const BernsteinPoly& p, int from, int count) {
  return BernsteinPoly(p.coeffs().middleCols(from, count));
}

BernsteinPoly hodographNumerator(const BernsteinPoly& h, bool rational) {
  const BernsteinPoly a = columns(h, 0, 3);
  if (!rational) return a.derivative();
  const BernsteinPoly w = columns(h, 3, 1);
  return product(a.derivative(), w) - product(a, w.derivative());
}

/// A parameter region of the curve: a run of whole pieces [first, last), or a sub-interval of one piece. The regions
/// form a bounding-volume hierarchy in parameter order; a run holds only its range and box (its hodograph
/// coefficients are gathered from the pieces when needed), so the tree is linear in memory.
struct Region {
  double a = 0.0;
  double b = 0.0;
  struct Arc {
    int piece = 0;
    double s0 = 0.0;
    double s1 = 1.0;
  };
  int first = 0;  // pieces [first, last) when last - first > 1; else the one arc `arc`
  int last = 0;
  Arc arc;
  Box3 box;
  std::vector<Vec3> hodo;  // hodograph-numerator coefficients of `arc` (single-arc regions only)
  int simple = -1;         // cached: 1 injective (cone test passed), 0 not proven
  std::unique_ptr<Region> child[2];
  [[nodiscard]] bool single() const { return last - first == 1; }
  [[nodiscard]] double relWidth() const { return single() ? arc.s1 - arc.s0 : 2.0; }
};

class CurveSearch {
 public:
  CurveSearch(const BSplineCurve& curve, const SearchOptions& options) : opt_(options) {
    dim_ = curve.dim();
    for (const BezierCurvePiece& bp : detail::bezierPiecesLinear(curve)) {
      Piece p;
      p.iv = bp.interval;
      p.rational = bp.curve.isRational();
      const int n = bp.curve.degree() + 1;
      Matrix hc = Matrix::Zero(n, 4);
      for (int i = 0; i < n; ++i) {
        const double w = p.rational ? bp.curve.weights()[i] : 1.0;
        for (int k = 0; k < dim_; ++k) hc(i, k) = w * bp.curve.points()(i, k);
        hc(i, 3) = w;
      }
      p.h = BernsteinPoly(hc);
      p.dh = p.h.derivative();
      p.n = hodographNumerator(p.h, p.rational);
      p.dn = p.n.derivative();
      p.nScale = p.n.maxCoeffNorm();
      for (int k = 0; k <= p.h.degree(); ++k) {
        const auto row = p.h.coeffs().row(k);
        p.box.add(Vec3(row[0], row[1], row[2]) / row[3]);
      }
      pieces_.push_back(std::move(p));
    }
    const BoundingBox box = controlBox(curve);
    dist_ = options.distance.value_or(detail::defaultDistance(box.diagonal()));
    domain_ = {pieces_.front().iv.lo, pieces_.back().iv.hi};
    closed_ = (curve.evaluate(domain_.lo) - curve.evaluate(domain_.hi)).norm() <= dist_;
    budget_ = std::max(options.maxWork, options.maxWorkPerPiece * static_cast<long>(pieces_.size()));
    result_.summary.resolution = options.resolution;
    result_.summary.distance = dist_;
  }

  CurveSearchResult run() {
    findCriticalPoints();
    Region top;
    top.a = domain_.lo;
    top.b = domain_.hi;  // the pieces cover exactly this interval (see the constructor)
    top.first = 0;
    top.last = static_cast<int>(pieces_.size());
    top.arc = {0, 0.0, 1.0};
    finish(top);
    selfCheck(top);
    std::sort(result_.criticalPoints.begin(), result_.criticalPoints.end(),
              [](const auto& x, const auto& y) { return x.t < y.t; });
    std::sort(result_.selfIntersections.begin(), result_.selfIntersections.end(),
              [](const auto& x, const auto& y) { return x.t1 < y.t1 || (x.t1 == y.t1 && x.t2 < y.t2); });
    return std::move(result_);
  }

 private:
  // ---- evaluation ----
  int pieceAt(double t) const {
    int lo = 0;
    int hi = static_cast<int>(pieces_.size()) - 1;
    while (lo < hi) {
      const int mid = (lo + hi) / 2;
      if (t < pieces_[mid].iv.hi) {
        hi = mid;
      } else {
        lo = mid + 1;
      }
    }
    return lo;
  }
  /// Point and first derivative (global parameter) at t.
  void eval(double t, Vec3& point, Vec3& deriv) const {
    const Piece& p = pieces_[pieceAt(t)];
    const double len = p.iv.length();
    const double s = (t - p.iv.lo) / len;
    const VecX h = p.h(s);
    const VecX dh = p.dh(s) / len;
    const Vec3 a = h.head<3>();
    const Vec3 da = dh.head<3>();
    point = a / h[3];
    deriv = (da * h[3] - a * dh[3]) / (h[3] * h[3]);
  }

  // ---- critical points ----
  void findCriticalPoints() {
    for (int i = 0; i < static_cast<int>(pieces_.size()); ++i) {
      if (!(pieces_[i].nScale > 0.0)) {
        // C' vanishes identically on this piece (all control points equal): report its midpoint.
        addCritical(i, 0.5);
        continue;
      }
      critical(i, 0.0, 1.0);
    }
  }
  void critical(int i, double s0, double s1) {
    if (!spend()) return;
    const Piece& p = pieces_[i];
    const BernsteinPoly sub = p.n.restricted(s0, s1);
    std::vector<Vec3> vs(static_cast<size_t>(sub.degree()) + 1);
    for (int k = 0; k <= sub.degree(); ++k) vs[k] = sub.coeffs().row(k).transpose();
    if (detail::positiveDirection(vs)) return;
    const double w = s1 - s0;
    if (w <= opt_.newtonWidth) {
      double s = 0.5 * (s0 + s1);
      for (int it = 0; it < 40; ++it) {
        const Vec3 nv = p.n(s);
        const Vec3 dv = p.dn(s);
        const double den = dv.squaredNorm();
        if (!(den > 0.0)) break;
        const double step = -nv.dot(dv) / den;
        s = std::clamp(s + step, 0.0, 1.0);
        if (std::abs(step) < 1e-15) break;
      }
      if (s >= s0 - w && s <= s1 + w && p.n(s).norm() <= opt_.criticalRelTol * p.nScale) {
        addCritical(i, s);
        return;
      }
    }
    if (w <= opt_.resolution) {
      ++result_.summary.unresolved;
      return;
    }
    const double m = 0.5 * (s0 + s1);
    critical(i, s0, m);
    critical(i, m, s1);
  }
  void addCritical(int i, double s) {
    const Piece& p = pieces_[i];
    const double t = p.iv.lo + s * p.iv.length();
    const double dedupe = 1e3 * opt_.resolution * p.iv.length();
    for (const CurveCriticalPoint& c : result_.criticalPoints) {
      if (std::abs(c.t - t) <= dedupe) return;
    }
    if (static_cast<int>(result_.criticalPoints.size()) >= opt_.maxReported) {
      result_.summary.truncated = true;
      return;
    }
    CurveCriticalPoint c;
    c.t = t;
    Vec3 d;
    eval(t, c.point, d);
    c.speed = d.norm();
    result_.criticalPoints.push_back(c);
  }
  /// A region is near a found critical point when the point lies within the region grown by its width, or by the
  /// Newton width of the span (near a cusp the two branches are close, and pairs there cannot be settled).
  /// C' == 0 on the whole piece of a single-arc region (reported as one critical point; not searched further).
  bool degenerate(const Region& r) const { return r.single() && !(pieces_[r.arc.piece].nScale > 0.0); }
  bool nearCritical(double a, double b) const {
    const double w = std::max(b - a, opt_.newtonWidth * (domain_.hi - domain_.lo) / static_cast<double>(pieces_.size()));
    for (const CurveCriticalPoint& c : result_.criticalPoints) {
      if (c.t >= a - w && c.t <= b + w) return true;
    }
    return false;
  }

  // ---- regions ----
  void finish(Region& r) const {
    if (!r.single()) {
      for (int i = r.first; i < r.last; ++i) r.box.add(pieces_[i].box);
      return;
    }
    const Region::Arc& arc = r.arc;
    const Piece& p = pieces_[arc.piece];
    const bool whole = arc.s0 == 0.0 && arc.s1 == 1.0;
    const BernsteinPoly h = whole ? p.h : p.h.restricted(arc.s0, arc.s1);
    for (int k = 0; k <= h.degree(); ++k) {
      const auto row = h.coeffs().row(k);
      r.box.add(Vec3(row[0], row[1], row[2]) / row[3]);
    }
    const BernsteinPoly n = whole ? p.n : hodographNumerator(h, p.rational);
    for (int k = 0; k <= n.degree(); ++k) r.hodo.push_back(n.coeffs().row(k).transpose());
  }
  /// Appends the hodograph-numerator coefficients of a region, piece by piece, to `out`.
  void gatherHodo(const Region& r, std::vector<Vec3>& out) const {
    if (r.single()) {
      out.insert(out.end(), r.hodo.begin(), r.hodo.end());
      return;
    }
    for (int i = r.first; i < r.last; ++i) {
      const Matrix& c = pieces_[i].n.coeffs();
      for (Eigen::Index k = 0; k < c.rows(); ++k) out.push_back(c.row(k).transpose());
    }
  }
  bool isSimple(Region& r) const {
    if (r.simple < 0) {
      thread_local std::vector<Vec3> all;
      all.clear();
      gatherHodo(r, all);
      r.simple = detail::positiveDirection(all) ? 1 : 0;
    }
    return r.simple == 1;
  }
  Region& child(Region& r, int c) {
    if (!r.child[0]) {
      auto c0 = std::make_unique<Region>();
      auto c1 = std::make_unique<Region>();
      double mid = 0.0;
      if (!r.single()) {
        const int m = r.first + (r.last - r.first) / 2;
        c0->first = r.first;
        c0->last = m;
        c1->first = m;
        c1->last = r.last;
        c0->arc = {c0->first, 0.0, 1.0};
        c1->arc = {c1->first, 0.0, 1.0};
        mid = pieces_[m].iv.lo;
      } else {
        const Region::Arc& a = r.arc;
        const double sm = 0.5 * (a.s0 + a.s1);
        c0->first = c1->first = r.first;
        c0->last = c1->last = r.last;
        c0->arc = {a.piece, a.s0, sm};
        c1->arc = {a.piece, sm, a.s1};
        const Piece& p = pieces_[a.piece];
        mid = p.iv.lo + sm * p.iv.length();
      }
      c0->a = r.a;
      c0->b = mid;
      c1->a = mid;
      c1->b = r.b;
      finish(*c0);
      finish(*c1);
      r.child[0] = std::move(c0);
      r.child[1] = std::move(c1);
    }
    return *r.child[c];
  }
  bool spend() {
    if (++result_.summary.work > budget_) {
      result_.summary.complete = false;
      return false;
    }
    return true;
  }

  // ---- self-intersections ----
  /// selfCheckInner, counting the pieces whose own check is done for the progress callback.
  void selfCheck(Region& r) {
    const bool recursed = selfCheckInner(r);
    if (r.single() && r.relWidth() == 1.0) {
      ++settled_;
    } else if (!r.single() && !recursed) {
      settled_ += r.last - r.first;
    }
    if (opt_.progress && !r.single() && r.last - r.first >= 256) {
      opt_.progress("search", settled_, static_cast<long>(pieces_.size()));
    }
  }
  /// True when it went on to the two halves.
  bool selfCheckInner(Region& r) {
    if (!spend() || isSimple(r)) return false;
    if (degenerate(r) || (r.single() && r.relWidth() <= opt_.newtonWidth && nearCritical(r.a, r.b))) return false;
    if (r.single() && r.relWidth() <= opt_.resolution) {
      ++result_.summary.unresolved;
      return false;
    }
    selfCheck(child(r, 0));
    selfCheck(child(r, 1));
    pairCheck(child(r, 0), child(r, 1));
    return true;
  }
  bool touching(const Region& x, const Region& y) const {
    return x.b == y.a || (closed_ && x.a == domain_.lo && y.b == domain_.hi);
  }
  void pairCheck(Region& x, Region& y) {  // x before y in parameter
    if (!spend()) return;
    if (degenerate(x) || degenerate(y)) return;
    const bool touch = touching(x, y);
    if (!touch && !x.box.overlaps(y.box, dist_)) return;
    if (touch) {
      thread_local std::vector<Vec3> both;
      both.clear();
      gatherHodo(x, both);
      gatherHodo(y, both);
      if (detail::positiveDirection(both)) return;
    }
    const bool small = x.single() && y.single() && x.relWidth() <= opt_.newtonWidth &&
                       y.relWidth() <= opt_.newtonWidth;
    if (small && newton(x, y)) return;
    // Both regions at a found critical point: the branches through it are close, the pair cannot be settled and
    // is not counted (the critical point is reported).
    if (small && nearCritical(x.a, x.b) && nearCritical(y.a, y.b)) return;
    if (small && x.relWidth() <= opt_.resolution && y.relWidth() <= opt_.resolution) {
      ++result_.summary.unresolved;
      return;
    }
    if (x.relWidth() >= y.relWidth()) {
      pairCheck(child(x, 0), y);
      pairCheck(child(x, 1), y);
    } else {
      pairCheck(x, child(y, 0));
      pairCheck(x, child(y, 1));
    }
  }
  bool newton(const Region& x, const Region& y) {
    double s = 0.5 * (x.a + x.b);
    double t = 0.5 * (y.a + y.b);
    Vec3 p, dp, q, dq;
    double err = INFINITY;
    for (int it = 0; it < 40; ++it) {
      eval(s, p, dp);
      eval(t, q, dq);
      const Vec3 f = p - q;
      err = f.norm();
      if (err <= 1e-3 * dist_) break;
      Eigen::Matrix<double, 3, 2> j;
      j.col(0) = dp;
      j.col(1) = -dq;
      const Eigen::Matrix2d g = j.transpose() * j;
      if (!(std::abs(g.determinant()) > 1e-300)) break;
      const Eigen::Vector2d step = -g.ldlt().solve(j.transpose() * f);
      if (!step.allFinite()) break;
      s = std::clamp(s + step[0], domain_.lo, domain_.hi);
      t = std::clamp(t + step[1], domain_.lo, domain_.hi);
      if (step.norm() < 1e-15 * (domain_.hi - domain_.lo)) {
        eval(s, p, dp);
        eval(t, q, dq);
        err = (p - q).norm();
        break;
      }
    }
    if (!(err <= dist_)) return false;
    const double wx = x.b - x.a;
    const double wy = y.b - y.a;
    if (s < x.a - wx || s > x.b + wx || t < y.a - wy || t > y.b + wy) return false;
    const double minSep = 1e3 * opt_.resolution * (domain_.hi - domain_.lo) / static_cast<double>(pieces_.size());
    if (s > t) std::swap(s, t);
    if (t - s <= minSep) return false;  // the trivial solution s = t
    if (closed_ && s - domain_.lo <= minSep && domain_.hi - t <= minSep) return false;  // the closing point
    for (const CurveSelfIntersection& c : result_.selfIntersections) {
      if (std::abs(c.t1 - s) + std::abs(c.t2 - t) <= minSep) return true;
    }
    if (static_cast<int>(result_.selfIntersections.size()) >= opt_.maxReported) {
      result_.summary.truncated = true;
      return true;
    }
    CurveSelfIntersection c;
    c.t1 = s;
    c.t2 = t;
    c.point = 0.5 * (p + q);
    c.distance = (p - q).norm();
    result_.selfIntersections.push_back(c);
    return true;
  }

  SearchOptions opt_;
  long budget_ = 0;
  long settled_ = 0;  // pieces whose own self-intersection check is done (progress)
  int dim_ = 3;
  std::vector<Piece> pieces_;
  double dist_ = 0.0;
  Interval domain_;
  bool closed_ = false;
  CurveSearchResult result_;
};

}  // namespace

Result<CurveSearchResult> searchCurveDefects(const BSplineCurve& curve, const SearchOptions& options) {
  if (curve.dim() < 1 || curve.dim() > 3) {
    return Status(ErrorCode::kUnsupported, "the curve has " + std::to_string(curve.dim()) +
                                               " coordinates (1, 2 or 3 are supported)");
  }
  if (!(options.resolution > 0.0 && options.resolution < 1.0) || !(options.newtonWidth > 0.0)) {
    return invalidInput("search resolution must be in (0, 1) and the Newton width positive");
  }
  if (curve.numPoints() < 2) return invalidInput("the curve has fewer than 2 control points");
  const int maxDegree = curve.isRational() ? kMaxSearchCurveDegree / 2 : kMaxSearchCurveDegree;
  if (curve.degree() > maxDegree) {
    return Status(ErrorCode::kUnsupported,
                  "the defect search takes " + std::string(curve.isRational() ? "rational " : "") +
                      "curves of degree up to " + std::to_string(maxDegree) + "; this one has degree " +
                      std::to_string(curve.degree()) + " (split it into pieces of lower degree)");
  }
  CurveSearch search(curve, options);
  return search.run();
}

}  // namespace seam::regularity
