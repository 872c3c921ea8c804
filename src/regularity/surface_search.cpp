// Points with S_u x S_v = 0 and self-intersections of B-spline / NURBS surfaces by Bezier subdivision with hull
// pruning and Newton refinement (see defect_search.h).
#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <unordered_map>

#include "core/bernstein_internal.h"
#include "search_internal.h"
#include "seam/core/bernstein.h"
#include "seam/model/model.h"
#include "seam/regularity/defect_search.h"

namespace seam::regularity {

namespace {

using detail::Box3;

struct Piece {
  Interval u, v;
  bool rational = false;
  BernsteinPatch h;  // homogeneous (dim 4); eval takes its partials in one pass (homogeneousJet)
  BernsteinPatch n;  // the normal numerator (dim 3)
  double nScale = 0.0;
  /// Index into SurfaceSearch::poles_ when a side of the piece is a pole (S_u x S_v zero all along it), else -1:
  /// pieces without one (nearly all) carry nothing more.
  int pole = -1;
  Box3 box;                  // of the control points
  std::vector<Vec3> du, dv;  // coefficients of the S_u / S_v numerators of the whole piece
  int duDeg[2] = {0, 0}, dvDeg[2] = {0, 0};  // their Bernstein degrees (u, v)
};

/// A piece with sides along which n = S_u x S_v vanishes (a pole: a boundary collapsed to a point, or any edge along
/// which S_u x S_v is zero all along). Every point of such a side is critical; the search for the other critical
/// points looks for the zeros of m, n with the factors of those sides divided out (n = u^a (1-u)^b v^c (1-v)^d m),
/// which are n's off them, instead of subdividing along the whole side down to the resolution.
struct PoleSides {
  bool side[4] = {false, false, false, false};  ///< u = 0, u = 1, v = 0, v = 1 (local)
  BernsteinPatch m;
  double mScale = 0.0;
  /// Sides that are one point `apex` (within criticalRelTol x the piece's box), with `spokes`: the numerator of
  /// S - apex divided by the side's factor, whose Bernstein coefficients bound the directions from the apex.
  bool strict[4] = {false, false, false, false};
  Vec3 apex[4];
  BernsteinPatch spokes[4];
};

/// The partial derivatives of a piece's quotient (PoleSides::m, or n), for the Newton refinement of critical points.
struct NewtonPartials {
  BernsteinPatch u, v;
};

struct Part {
  int piece = 0;
  double u0 = 0.0, u1 = 1.0, v0 = 0.0, v1 = 1.0;  // local box of the piece
};

/// A parameter region: a block of whole pieces [u0, u1) x [v0, v1) (piece indices), or a sub-box of one piece
/// (`part`). The regions form a bounding-volume hierarchy; a block holds only its index ranges and box (its
/// derivative coefficients are gathered from the pieces when needed), so the tree is linear in memory.
struct Region {
  Interval u, v;  // global
  int u0 = 0, u1 = 0, v0 = 0, v1 = 0;
  Part part;
  Box3 box;
  std::vector<Vec3> du, dv;  // coefficients of the S_u / S_v numerators of `part` (single-part regions only)
  int simple = -1;
  std::unique_ptr<Region> child[2];
  [[nodiscard]] bool single() const { return u1 - u0 == 1 && v1 - v0 == 1; }
  [[nodiscard]] double relWidth() const {
    return single() ? std::max(part.u1 - part.u0, part.v1 - part.v0) : 2.0;
  }
};

/// Injective-immersion test of a parameter rectangle (or of two touching rectangles): 0 outside conv(Du u Dv) and
/// outside conv(Du u -Dv) (Theorem 3.7 in Bezier form, see the docs).
bool conesSeparate(const std::vector<Vec3>& du, const std::vector<Vec3>& dv) {
  thread_local std::vector<Vec3> all;
  all.assign(du.begin(), du.end());
  all.insert(all.end(), dv.begin(), dv.end());
  if (!detail::positiveDirection(all)) return false;
  all.resize(du.size());
  for (const Vec3& x : dv) all.push_back(-x);
  return detail::positiveDirection(all);
}

/// The parameter hull of two small regions is tested for injectivity over at most this many Bezier pieces (two
/// regions of a pair that far apart are a candidate self-intersection, not a neighbourhood).
constexpr int kMaxHullPieces = 4;

class SurfaceSearch {
 public:
  SurfaceSearch(const BSplineSurface& s, const SearchOptions& options) : opt_(options) {
    const int dim = s.dim();
    const std::vector<BezierPatchPiece> bps = detail::bezierPatchesLinear(s);
    for (const BezierPatchPiece& bp : bps) {
      nu_ = std::max(nu_, bp.spanU + 1);
      nv_ = std::max(nv_, bp.spanV + 1);
    }
    pieces_.resize(static_cast<size_t>(nu_) * nv_);
    for (const BezierPatchPiece& bp : bps) {
      Piece& p = pieces_[static_cast<size_t>(bp.spanU) * nv_ + bp.spanV];
      p.u = bp.u;
      p.v = bp.v;
      p.rational = bp.patch.isRational();
      const int du = bp.patch.degreeU();
      const int dv = bp.patch.degreeV();
      Matrix hc = Matrix::Zero((du + 1) * (dv + 1), 4);
      for (int i = 0; i <= du; ++i) {
        for (int j = 0; j <= dv; ++j) {
          const int r = i * (dv + 1) + j;
          const double w = bp.patch.weight(i, j);
          for (int k = 0; k < dim; ++k) hc(r, k) = w * bp.patch.point(i, j)[k];
          hc(r, 3) = w;
        }
      }
      p.h = BernsteinPatch(du, dv, hc);
      const auto [su, sv] = partialNumerators(p.h, p.rational);
      p.n = cross(su, sv);
      for (Eigen::Index r = 0; r < p.n.coeffs().rows(); ++r) {
        p.nScale = std::max(p.nScale, p.n.coeffs().row(r).norm());
      }
      const Matrix& c = p.h.coeffs();
      for (Eigen::Index k = 0; k < c.rows(); ++k) p.box.add(Vec3(c(k, 0), c(k, 1), c(k, 2)) / c(k, 3));
      if (std::optional<PoleSides> ps = poleSidesOf(p, options.criticalRelTol)) {
        p.pole = static_cast<int>(poles_.size());
        poles_.push_back(std::move(*ps));
      }
      for (Eigen::Index k = 0; k < su.coeffs().rows(); ++k) p.du.push_back(su.coeffs().row(k).transpose());
      for (Eigen::Index k = 0; k < sv.coeffs().rows(); ++k) p.dv.push_back(sv.coeffs().row(k).transpose());
      p.duDeg[0] = su.degreeU();
      p.duDeg[1] = su.degreeV();
      p.dvDeg[0] = sv.degreeU();
      p.dvDeg[1] = sv.degreeV();
    }
    dist_ = options.distance.value_or(detail::defaultDistance(controlBox(s).diagonal()));
    domU_ = {pieces_.front().u.lo, pieces_.back().u.hi};
    domV_ = {pieces_.front().v.lo, pieces_.back().v.hi};
    // Closed in u (v): the boundary curves u = lo and u = hi coincide (checked at a few parameters).
    closedU_ = closedV_ = true;
    for (int k = 0; k <= 8; ++k) {
      const double t = k / 8.0;
      const double v = domV_.lo + t * domV_.length();
      const double u = domU_.lo + t * domU_.length();
      closedU_ = closedU_ && (s.evaluate(domU_.lo, v) - s.evaluate(domU_.hi, v)).norm() <= dist_;
      closedV_ = closedV_ && (s.evaluate(u, domV_.lo) - s.evaluate(u, domV_.hi)).norm() <= dist_;
    }
    budget_ = std::max(options.maxWork, options.maxWorkPerPiece * static_cast<long>(pieces_.size()));
    result_.summary.resolution = options.resolution;
    result_.summary.distance = dist_;
  }

  SurfaceSearchResult run() {
    for (int i = 0; i < static_cast<int>(pieces_.size()); ++i) {
      const Piece& p = pieces_[i];
      if (!(p.nScale > 0.0) || !(scaleOfQuotient(p) > 0.0)) {
        addCritical(i, 0.5, 0.5);
        continue;
      }
      // A vanishing side is reported by its middle (a collapsed boundary once: its points are one point), and the
      // rest of the piece is searched through m.
      if (p.pole >= 0) {
        const double mid[4][2] = {{0.0, 0.5}, {1.0, 0.5}, {0.5, 0.0}, {0.5, 1.0}};
        for (int side = 0; side < 4; ++side) {
          if (!poles_[p.pole].side[side]) continue;
          poleLines_.push_back(poleLine(p, side));
          addCritical(i, mid[side][0], mid[side][1], /*pole=*/true);
        }
      }
      critical(i, 0.0, 1.0, 0.0, 1.0, quotient(p));
    }
    Region top;
    top.u = domU_;
    top.v = domV_;
    top.u1 = nu_;
    top.v1 = nv_;
    top.part = {0};
    finish(top);
    selfCheck(top);
    return std::move(result_);
  }

 private:
  // ---- evaluation ----
  int pieceAt(double u, double v) const {
    int iu = 0;
    while (iu + 1 < nu_ && u >= pieces_[static_cast<size_t>(iu + 1) * nv_].u.lo) ++iu;
    int iv = 0;
    while (iv + 1 < nv_ && v >= pieces_[static_cast<size_t>(iv + 1)].v.lo) ++iv;
    return iu * nv_ + iv;
  }
  void eval(double u, double v, Vec3& point, Vec3& su, Vec3& sv) const {
    const Piece& p = pieces_[static_cast<size_t>(pieceAt(u, v))];
    const double a = (u - p.u.lo) / p.u.length();
    const double b = (v - p.v.lo) / p.v.length();
    Eigen::Vector4d h, hu, hv;
    homogeneousJet(p.h, a, b, h, hu, hv);
    hu /= p.u.length();
    hv /= p.v.length();
    const Vec3 x = h.head<3>();
    point = x / h[3];
    su = (Vec3(hu.head<3>()) * h[3] - x * hu[3]) / (h[3] * h[3]);
    sv = (Vec3(hv.head<3>()) * h[3] - x * hv[3]) / (h[3] * h[3]);
  }
  /// h(a, b) and its two partial derivatives, by one tensor de Casteljau: each row (fixed i) is reduced in v to its
  /// last two points, which give the row's value and v-derivative; the values are reduced in u to their last two
  /// points (the value and the u-derivative), the v-derivatives all the way. No allocation after the first call on
  /// a thread (Newton calls this about a million times on a near-singular face).
  static void homogeneousJet(const BernsteinPatch& h, double a, double b, Eigen::Vector4d& value,
                             Eigen::Vector4d& du, Eigen::Vector4d& dv) {
    const int m = h.degreeU(), n = h.degreeV();
    const Matrix& c = h.coeffs();
    thread_local std::vector<Eigen::Vector4d> row, vals, ders;
    vals.resize(static_cast<size_t>(m + 1));
    ders.resize(static_cast<size_t>(m + 1));
    row.resize(static_cast<size_t>(n + 1));
    for (int i = 0; i <= m; ++i) {
      for (int j = 0; j <= n; ++j) row[static_cast<size_t>(j)] = c.row(i * (n + 1) + j).transpose();
      for (int level = n; level > 1; --level)
        for (int j = 0; j < level; ++j)
          row[static_cast<size_t>(j)] = (1.0 - b) * row[static_cast<size_t>(j)] + b * row[static_cast<size_t>(j + 1)];
      if (n == 0) {
        vals[static_cast<size_t>(i)] = row[0];
        ders[static_cast<size_t>(i)].setZero();
      } else {
        vals[static_cast<size_t>(i)] = (1.0 - b) * row[0] + b * row[1];
        ders[static_cast<size_t>(i)] = n * (row[1] - row[0]);
      }
    }
    for (int level = m; level > 0; --level)
      for (int i = 0; i < level; ++i)
        ders[static_cast<size_t>(i)] = (1.0 - a) * ders[static_cast<size_t>(i)] + a * ders[static_cast<size_t>(i + 1)];
    for (int level = m; level > 1; --level)
      for (int i = 0; i < level; ++i)
        vals[static_cast<size_t>(i)] = (1.0 - a) * vals[static_cast<size_t>(i)] + a * vals[static_cast<size_t>(i + 1)];
    dv = ders[0];
    if (m == 0) {
      value = vals[0];
      du.setZero();
    } else {
      value = (1.0 - a) * vals[0] + a * vals[1];
      du = m * (vals[1] - vals[0]);
    }
  }

  bool spend() {
    if (++result_.summary.work > budget_) {
      result_.summary.complete = false;
      return false;
    }
    return true;
  }

  // ---- critical points ----
  /// The critical points of piece i in its local box [u0, u1] x [v0, v1], on which its quotient is `sub`: the box
  /// is settled when the coefficients of `sub` lie in an open half-space (no zero), or by Newton; else it is halved
  /// along its longer side, each half's coefficients from one de Casteljau triangle at 1/2 of `sub` (not a new
  /// restriction of the whole piece: a quarter of the work at degrees (11, 15)).
  void critical(int i, double u0, double u1, double v0, double v1, const BernsteinPatch& sub) {
    if (!spend()) return;
    thread_local std::vector<Vec3> vs;
    vs.resize(static_cast<size_t>(sub.coeffs().rows()));
    for (Eigen::Index k = 0; k < sub.coeffs().rows(); ++k) vs[k] = sub.coeffs().row(k).transpose();
    if (detail::positiveDirection(vs)) return;
    const double w = std::max(u1 - u0, v1 - v0);
    if (w <= opt_.newtonWidth && criticalNewton(i, u0, u1, v0, v1)) return;
    if (w <= opt_.resolution) {
      ++result_.summary.unresolved;
      return;
    }
    const bool alongU = u1 - u0 >= v1 - v0;
    BernsteinPatch first, second;
    halves(sub, alongU, first, second);
    if (alongU) {
      const double m = 0.5 * (u0 + u1);
      critical(i, u0, m, v0, v1, first);
      critical(i, m, u1, v0, v1, second);
    } else {
      const double m = 0.5 * (v0 + v1);
      critical(i, u0, u1, v0, m, first);
      critical(i, u0, u1, m, v1, second);
    }
  }
  /// The halves of p at u = 1/2 (alongU) or v = 1/2, reparametrised to [0, 1]^2.
  static void halves(const BernsteinPatch& p, bool alongU, BernsteinPatch& first, BernsteinPatch& second) {
    const int du = p.degreeU(), dv = p.degreeV();
    const Eigen::Index dim = p.dim();
    Matrix a(p.coeffs().rows(), dim), b(p.coeffs().rows(), dim);
    if (alongU) {
      // The rows of p (row-major, index i (dv + 1) + j) as a curve in u whose coefficients are whole v-rows.
      seam::detail::splitHalves(p.coeffs().data(), du, (dv + 1) * dim, a.data(), b.data());
    } else {
      const Eigen::Index block = (dv + 1) * dim;
      for (int i = 0; i <= du; ++i)
        seam::detail::splitHalves(p.coeffs().data() + i * block, dv, dim, a.data() + i * block, b.data() + i * block);
    }
    first = BernsteinPatch(du, dv, std::move(a));
    second = BernsteinPatch(du, dv, std::move(b));
  }
  /// Gauss-Newton on the quotient of piece i from the middle of the local box [u0, u1] x [v0, v1]; a zero found
  /// within one box width of it is reported (addCritical) and settles the box: the last iterate near the box at
  /// the critical tolerance (the steps after it take the point to round-off; reported zeros are few). The iteration
  /// stops once it has left that neighbourhood: a zero it goes on to find there is another box's (near a curve of
  /// small |q| it ran to a known zero far away, and 40 iterations were spent there in every box of the curve:
  /// linkrods' F26, 36 s of its 45 s).
  bool criticalNewton(int i, double u0, double u1, double v0, double v1) {
    const Piece& p = pieces_[i];
    const BernsteinPatch& q = quotient(p);
    const NewtonPartials& d = partials(i);
    const double w = std::max(u1 - u0, v1 - v0);
    const double zero = opt_.criticalRelTol * scaleOfQuotient(p);
    const auto near = [&](const Eigen::Vector2d& x) {
      return x[0] >= u0 - w && x[0] <= u1 + w && x[1] >= v0 - w && x[1] <= v1 + w;
    };
    Eigen::Vector2d x(0.5 * (u0 + u1), 0.5 * (v0 + v1));
    std::optional<Eigen::Vector2d> found;  // the last iterate at the tolerance and near the box
    for (int it = 0; it < 40; ++it) {
      const Vec3 f = q(x[0], x[1]);
      if (f.norm() <= zero && near(x)) found = x;
      Eigen::Matrix<double, 3, 2> j;
      j.col(0) = d.u(x[0], x[1]);
      j.col(1) = d.v(x[0], x[1]);
      const Eigen::Matrix2d g = j.transpose() * j;
      if (!(std::abs(g.determinant()) > 1e-300)) break;
      const Eigen::Vector2d step = -g.ldlt().solve(j.transpose() * f);
      if (!step.allFinite()) break;
      x = (x + step).cwiseMax(0.0).cwiseMin(1.0);
      if (step.norm() < 1e-15 || !near(x)) break;
    }
    if (near(x) && q(x[0], x[1]).norm() <= zero) found = x;
    if (!found) return false;
    addCritical(i, (*found)[0], (*found)[1]);
    return true;
  }
  /// The partial derivatives of piece i's quotient, made the first time Newton needs them on that piece.
  const NewtonPartials& partials(int i) {
    const auto [at, made] = partials_.try_emplace(i);
    if (made) {
      const BernsteinPatch& q = quotient(pieces_[static_cast<size_t>(i)]);
      at->second = NewtonPartials{q.derivative(1, 0), q.derivative(0, 1)};
    }
    return at->second;  // unordered_map: the reference stays valid as other pieces are added
  }
  void addCritical(int i, double a, double b, bool pole = false) {
    const Piece& p = pieces_[i];
    const double u = p.u.lo + a * p.u.length();
    const double v = p.v.lo + b * p.v.length();
    const double dedupe = 1e3 * opt_.resolution;
    for (const SurfaceCriticalPoint& c : result_.criticalPoints) {
      if (std::abs(c.u - u) <= dedupe * p.u.length() && std::abs(c.v - v) <= dedupe * p.v.length()) return;
    }
    SurfaceCriticalPoint c;
    c.u = u;
    c.v = v;
    Vec3 su, sv;
    eval(u, v, c.point, su, sv);
    c.normalNorm = su.cross(sv).norm();
    // The pieces along a collapsed boundary all reach the same point: one pole, reported once.
    if (pole)
      for (const size_t k : poleReports_)
        if ((result_.criticalPoints[k].point - c.point).norm() <= dist_) return;
    if (static_cast<int>(result_.criticalPoints.size()) >= opt_.maxReported) {
      result_.summary.truncated = true;
      return;
    }
    if (pole) poleReports_.push_back(result_.criticalPoints.size());
    result_.criticalPoints.push_back(c);
  }
  /// n of a piece with the factors of its vanishing sides divided out (n itself when none vanishes), and its scale.
  const BernsteinPatch& quotient(const Piece& p) const { return p.pole >= 0 ? poles_[p.pole].m : p.n; }
  double scaleOfQuotient(const Piece& p) const { return p.pole >= 0 ? poles_[p.pole].mScale : p.nScale; }
  /// The sides of p along which n vanishes (its Bernstein coefficients on that side at or below relTol x nScale, so
  /// that |n| is that small all along the side), n divided by their factors, and the strict poles among them; nothing
  /// when no side vanishes. In Bernstein form, exactly: B^d_j(v) = v (d / j) B^(d-1)_(j-1)(v), so with the row
  /// j = 0 zero the coefficients of n / v are c_(i,j) d / j for j = 1..d; B^d_j(v) = (1 - v) (d / (d - j))
  /// B^(d-1)_j(v), so with the row j = d zero those of n / (1 - v) are c_(i,j) d / (d - j) for j = 0..d-1 (the same
  /// in u). See docs/algorithms/dyn-levin-yadshalom.md, "Poles and thin spans".
  static std::optional<PoleSides> poleSidesOf(const Piece& p, double relTol) {
    if (!(p.nScale > 0.0)) return std::nullopt;
    const double zero = relTol * p.nScale;
    PoleSides ps;
    ps.m = p.n;
    bool any = false;
    for (int side = 0; side < 4; ++side) {
      if (!vanishesOn(ps.m, side, zero)) continue;
      ps.m = dividedBySide(ps.m, side);
      ps.side[side] = any = true;
    }
    if (!any) return std::nullopt;
    for (Eigen::Index r = 0; r < ps.m.coeffs().rows(); ++r) ps.mScale = std::max(ps.mScale, ps.m.coeffs().row(r).norm());
    // Sides that are one point (a pole in the strict sense): the directions of S - apex there, for the pair test.
    const Matrix& h = p.h.coeffs();
    for (int side = 0; side < 4; ++side) {
      if (!ps.side[side]) continue;
      auto at = [&](int k) {  // the k-th control point on the side
        const auto c = sideCoeff(p.h, side, k);
        return Vec3(Vec3(c(0), c(1), c(2)) / c(3));
      };
      const Vec3 apex = at(0);
      double spread = 0.0;
      for (int k = 1; k < sideCount(p.h, side); ++k) spread = std::max(spread, (at(k) - apex).norm());
      if (!(spread <= (p.box.hi - p.box.lo).norm() * relTol)) continue;
      Matrix g(h.rows(), 3);  // S - apex = G / w with G = H - apex w, zero on the side
      for (Eigen::Index r = 0; r < h.rows(); ++r) g.row(r) = h.row(r).head<3>() - apex.transpose() * h(r, 3);
      ps.apex[side] = apex;
      ps.spokes[side] = dividedBySide(BernsteinPatch(p.h.degreeU(), p.h.degreeV(), std::move(g)), side);
      ps.strict[side] = true;
    }
    return ps;
  }
  /// The number of Bernstein coefficients of `b` on `side` (0: u = 0, 1: u = 1, 2: v = 0, 3: v = 1), and the k-th.
  static int sideCount(const BernsteinPatch& b, int side) { return (side >= 2 ? b.degreeU() : b.degreeV()) + 1; }
  static Eigen::RowVectorXd sideCoeff(const BernsteinPatch& b, int side, int k) {
    const int across = side >= 2 ? b.degreeV() : b.degreeU();  // the side is v = const: row j = 0 or j = dv
    const int fixed = side % 2 == 1 ? across : 0;
    return side >= 2 ? b.coeff(k, fixed) : b.coeff(fixed, k);
  }
  /// The Bernstein coefficients of `b` on `side` are all at most `zero` (and b has a degree across it to divide).
  static bool vanishesOn(const BernsteinPatch& b, int side, double zero) {
    if ((side >= 2 ? b.degreeV() : b.degreeU()) == 0) return false;
    for (int k = 0; k < sideCount(b, side); ++k)
      if (sideCoeff(b, side, k).norm() > zero) return false;
    return true;
  }
  /// b divided by the factor of `side` (u, 1 - u, v or 1 - v), its coefficients on that side taken as zero.
  static BernsteinPatch dividedBySide(const BernsteinPatch& b, int side) {
    const bool alongV = side >= 2;
    const bool atOne = side % 2 == 1;
    const int du = b.degreeU(), dv = b.degreeV();
    const int d = alongV ? dv : du;
    const int ndu = alongV ? du : du - 1, ndv = alongV ? dv - 1 : dv;
    Matrix c = Matrix::Zero((ndu + 1) * (ndv + 1), b.dim());
    for (int i = 0; i <= ndu; ++i)
      for (int j = 0; j <= ndv; ++j) {
        const int t = alongV ? j : i;      // the index in the reduced direction
        const int src = atOne ? t : t + 1;  // the coefficient it comes from
        const double scale = atOne ? static_cast<double>(d) / (d - t) : static_cast<double>(d) / (t + 1);
        c.row(i * (ndv + 1) + j) = (alongV ? b.coeff(i, src) : b.coeff(src, j)) * scale;
      }
    return BernsteinPatch(ndu, ndv, std::move(c));
  }
  struct PoleLine {
    Interval u, v;  // global parameters: one of them a single value
  };
  static PoleLine poleLine(const Piece& p, int side) {
    switch (side) {
      case 0: return {{p.u.lo, p.u.lo}, p.v};
      case 1: return {{p.u.hi, p.u.hi}, p.v};
      case 2: return {p.u, {p.v.lo, p.v.lo}};
      default: return {p.u, {p.v.hi, p.v.hi}};
    }
  }
  /// Parameter distances (u, v) below which two Newton solutions are one point.
  [[nodiscard]] std::pair<double, double> separation() const {
    return {1e3 * opt_.resolution * domU_.length() / nu_, 1e3 * opt_.resolution * domV_.length() / nv_};
  }
  /// (u, v) on a pole line (within the separation of the Newton solutions).
  bool onPole(double u, double v) const {
    const auto [sepU, sepV] = separation();
    for (const PoleLine& l : poleLines_)
      if (u >= l.u.lo - sepU && u <= l.u.hi + sepU && v >= l.v.lo - sepV && v <= l.v.hi + sepV) return true;
    return false;
  }
  /// The region grown by its size, or by the Newton width of a span, contains a found critical point.
  /// S_u x S_v == 0 on a whole piece of the region (reported as one critical point; not searched further).
  bool degenerate(const Region& r) const {
    for (int iu = r.u0; iu < r.u1; ++iu) {
      for (int iv = r.v0; iv < r.v1; ++iv) {
        if (!(pieces_[static_cast<size_t>(iu) * nv_ + iv].nScale > 0.0)) return true;
      }
    }
    return false;
  }
  bool nearCritical(const Region& r) const {
    const double wu = std::max(r.u.length(), opt_.newtonWidth * domU_.length() / nu_);
    const double wv = std::max(r.v.length(), opt_.newtonWidth * domV_.length() / nv_);
    for (const SurfaceCriticalPoint& c : result_.criticalPoints) {
      if (c.u >= r.u.lo - wu && c.u <= r.u.hi + wu && c.v >= r.v.lo - wv && c.v <= r.v.hi + wv) return true;
    }
    for (const PoleLine& l : poleLines_) {  // every point of a pole line is critical
      if (l.u.lo <= r.u.hi + wu && r.u.lo - wu <= l.u.hi && l.v.lo <= r.v.hi + wv && r.v.lo - wv <= l.v.hi) return true;
    }
    return false;
  }

  // ---- regions ----
  void finish(Region& r) const {
    if (!r.single()) {
      for (int iu = r.u0; iu < r.u1; ++iu) {
        for (int iv = r.v0; iv < r.v1; ++iv) r.box.add(pieces_[static_cast<size_t>(iu) * nv_ + iv].box);
      }
      return;
    }
    const Part& part = r.part;
    const Piece& p = pieces_[part.piece];
    const bool whole = part.u0 == 0.0 && part.u1 == 1.0 && part.v0 == 0.0 && part.v1 == 1.0;
    if (whole) {
      r.box = p.box;
      r.du = p.du;
      r.dv = p.dv;
      return;
    }
    const BernsteinPatch h = p.h.restricted(part.u0, part.u1, part.v0, part.v1);
    const Matrix& c = h.coeffs();
    for (Eigen::Index k = 0; k < c.rows(); ++k) r.box.add(Vec3(c(k, 0), c(k, 1), c(k, 2)) / c(k, 3));
    // The numerators of the part are those of the piece restricted to it, times the chain rule's factor (the
    // numerator of the restricted h, without forming its products again).
    appendRestricted(p.du, p.duDeg, part, part.u1 - part.u0, r.du);
    appendRestricted(p.dv, p.dvDeg, part, part.v1 - part.v0, r.dv);
  }
  /// Appends the coefficients of the patch `from` (Bernstein degrees deg) restricted to the local box of `part`,
  /// times `factor`, to `to`.
  static void appendRestricted(const std::vector<Vec3>& from, const int deg[2], const Part& part, double factor,
                               std::vector<Vec3>& to) {
    Matrix c(static_cast<Eigen::Index>(from.size()), 3);
    for (size_t k = 0; k < from.size(); ++k) c.row(static_cast<Eigen::Index>(k)) = from[k].transpose();
    const BernsteinPatch restricted =
        BernsteinPatch(deg[0], deg[1], std::move(c)).restricted(part.u0, part.u1, part.v0, part.v1);
    for (Eigen::Index k = 0; k < restricted.coeffs().rows(); ++k)
      to.push_back(factor * restricted.coeffs().row(k).transpose());
  }
  /// Appends the S_u / S_v numerator coefficients of a region, piece by piece in row-major order, to du / dv.
  void gather(const Region& r, std::vector<Vec3>& du, std::vector<Vec3>& dv) const {
    if (r.single()) {
      du.insert(du.end(), r.du.begin(), r.du.end());
      dv.insert(dv.end(), r.dv.begin(), r.dv.end());
      return;
    }
    for (int iu = r.u0; iu < r.u1; ++iu) {
      for (int iv = r.v0; iv < r.v1; ++iv) {
        const Piece& p = pieces_[static_cast<size_t>(iu) * nv_ + iv];
        du.insert(du.end(), p.du.begin(), p.du.end());
        dv.insert(dv.end(), p.dv.begin(), p.dv.end());
      }
    }
  }
  bool isSimple(Region& r) const {
    if (r.simple < 0) {
      thread_local std::vector<Vec3> du, dv;
      du.clear();
      dv.clear();
      gather(r, du, dv);
      r.simple = conesSeparate(du, dv) ? 1 : 0;
    }
    return r.simple == 1;
  }
  Region& child(Region& r, int c) {
    if (!r.child[0]) {
      auto c0 = std::make_unique<Region>();
      auto c1 = std::make_unique<Region>();
      c0->u = c1->u = r.u;
      c0->v = c1->v = r.v;
      if (!r.single()) {
        const bool alongU = r.u1 - r.u0 >= r.v1 - r.v0;
        for (Region* x : {c0.get(), c1.get()}) {
          x->u0 = r.u0;
          x->u1 = r.u1;
          x->v0 = r.v0;
          x->v1 = r.v1;
        }
        const int cut = alongU ? (r.u0 + r.u1) / 2 : (r.v0 + r.v1) / 2;
        (alongU ? c0->u1 : c0->v1) = cut;
        (alongU ? c1->u0 : c1->v0) = cut;
        c0->part = {c0->u0 * nv_ + c0->v0};
        c1->part = {c1->u0 * nv_ + c1->v0};
        const double mid = alongU ? pieces_[static_cast<size_t>(cut) * nv_].u.lo : pieces_[cut].v.lo;
        (alongU ? c0->u.hi : c0->v.hi) = mid;
        (alongU ? c1->u.lo : c1->v.lo) = mid;
      } else {
        const Part& part = r.part;
        const Piece& p = pieces_[part.piece];
        Part a = part;
        Part b = part;
        if (part.u1 - part.u0 >= part.v1 - part.v0) {
          a.u1 = b.u0 = 0.5 * (part.u0 + part.u1);
          c0->u.hi = c1->u.lo = p.u.lo + a.u1 * p.u.length();
        } else {
          a.v1 = b.v0 = 0.5 * (part.v0 + part.v1);
          c0->v.hi = c1->v.lo = p.v.lo + a.v1 * p.v.length();
        }
        c0->u0 = c1->u0 = r.u0;
        c0->u1 = c1->u1 = r.u1;
        c0->v0 = c1->v0 = r.v0;
        c0->v1 = c1->v1 = r.v1;
        c0->part = a;
        c1->part = b;
      }
      finish(*c0);
      finish(*c1);
      r.child[0] = std::move(c0);
      r.child[1] = std::move(c1);
    }
    return *r.child[c];
  }

  // ---- self-intersections ----
  /// selfCheckInner, counting the pieces whose own check is done for the progress callback.
  void selfCheck(Region& r) {
    const bool recursed = selfCheckInner(r);
    if (r.single() && r.relWidth() == 1.0) {
      ++settled_;
    } else if (!r.single() && !recursed) {
      settled_ += (r.u1 - r.u0) * (r.v1 - r.v0);
    }
    if (opt_.progress && !r.single() && (r.u1 - r.u0) * (r.v1 - r.v0) >= 256) {
      opt_.progress("search", settled_, static_cast<long>(pieces_.size()));
    }
  }
  /// True when it went on to the two halves.
  bool selfCheckInner(Region& r) {
    if (!spend() || isSimple(r)) return false;
    if (r.single() && (degenerate(r) || (r.relWidth() <= opt_.newtonWidth && nearCritical(r)))) return false;
    if (r.single() && r.relWidth() <= opt_.resolution) {
      ++result_.summary.unresolved;
      return false;
    }
    selfCheck(child(r, 0));
    selfCheck(child(r, 1));
    pairCheck(child(r, 0), child(r, 1));
    return true;
  }
  static bool meets(const Interval& a, const Interval& b) { return a.lo <= b.hi && b.lo <= a.hi; }
  bool touching(const Region& x, const Region& y) const {
    if (meets(x.u, y.u) && meets(x.v, y.v)) return true;
    const bool acrossU = closedU_ && meets(x.v, y.v) &&
                         ((x.u.lo == domU_.lo && y.u.hi == domU_.hi) || (y.u.lo == domU_.lo && x.u.hi == domU_.hi));
    const bool acrossV = closedV_ && meets(x.u, y.u) &&
                         ((x.v.lo == domV_.lo && y.v.hi == domV_.hi) || (y.v.lo == domV_.lo && x.v.hi == domV_.hi));
    return acrossU || acrossV;
  }
  void pairCheck(Region& x, Region& y) {
    if (!spend()) return;
    if ((x.single() && degenerate(x)) || (y.single() && degenerate(y))) return;
    const bool touch = touching(x, y);
    if (!touch && !x.box.overlaps(y.box, dist_)) return;
    if (apartFromTheirPole(x, y)) return;
    if (touch) {
      thread_local std::vector<Vec3> du, dv;
      du.clear();
      dv.clear();
      gather(x, du, dv);
      gather(y, du, dv);
      if (conesSeparate(du, dv)) return;
    }
    const bool small = x.single() && y.single() && x.relWidth() <= opt_.newtonWidth &&
                       y.relWidth() <= opt_.newtonWidth;
    if (small && hullInjective(x, y)) return;
    if (small && newton(x, y)) return;
    if (small && nearCritical(x) && nearCritical(y)) return;  // settled by the reported critical point
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
  /// Two regions that both reach the same pole (a side of their pieces that is one point) and whose directions from
  /// it are strictly separated (a plane through the apex has one region's spokes on one side and the other's on the
  /// other: positiveDirection of Cx and -Cy): they meet at the pole and nowhere else. Every region along a pole
  /// touches every other in space, so without this each pair was refined until both were small: quadratic in the
  /// pieces along the pole (a 97-span cone ran out of its budget).
  bool apartFromTheirPole(const Region& x, const Region& y) const {
    if (!x.single() || !y.single()) return false;
    const auto reaches = [](const Part& part, int side) {
      return side == 0 ? part.u0 == 0.0 : side == 1 ? part.u1 == 1.0 : side == 2 ? part.v0 == 0.0 : part.v1 == 1.0;
    };
    const int ix = pieces_[x.part.piece].pole, iy = pieces_[y.part.piece].pole;
    if (ix < 0 || iy < 0) return false;
    const PoleSides& px = poles_[ix];
    const PoleSides& py = poles_[iy];
    for (int sx = 0; sx < 4; ++sx) {
      if (!px.strict[sx] || !reaches(x.part, sx)) continue;
      for (int sy = 0; sy < 4; ++sy) {
        if (!py.strict[sy] || !reaches(y.part, sy) || (px.apex[sx] - py.apex[sy]).norm() > dist_) continue;
        thread_local std::vector<Vec3> all;
        all.clear();
        for (int k = 0; k < 2; ++k) {
          const Part& part = k == 0 ? x.part : y.part;
          const BernsteinPatch c =
              (k == 0 ? px.spokes[sx] : py.spokes[sy]).restricted(part.u0, part.u1, part.v0, part.v1);
          for (Eigen::Index r = 0; r < c.coeffs().rows(); ++r)
            all.push_back((k == 0 ? 1.0 : -1.0) * c.coeffs().row(r).transpose());
        }
        if (detail::positiveDirection(all)) return true;
      }
    }
    return false;
  }
  /// Two small regions whose parameter hull (the rectangle spanning both, over at most kMaxHullPieces pieces) is
  /// injective by the cone test (conesSeparate on the S_u / S_v numerators of every piece restricted to it: the
  /// argument of Theorem 3.7 holds on any convex domain the cones bound): no point of one meets a point of the other. Two
  /// regions a few cells apart inside a thin span are within the distance tolerance of each other in space, and
  /// Newton finds only the trivial solution between them; without this they were searched down to the resolution
  /// and left unresolved (trj3's F6: a knot span of 1.5e-5 of its neighbours, 114 240 pairs, budget exhausted).
  bool hullInjective(const Region& x, const Region& y) const {
    if (!x.single() || !y.single()) return false;
    const Interval u{std::min(x.u.lo, y.u.lo), std::max(x.u.hi, y.u.hi)};
    const Interval v{std::min(x.v.lo, y.v.lo), std::max(x.v.hi, y.v.hi)};
    const int iu0 = std::min(x.part.piece, y.part.piece) / nv_, iu1 = std::max(x.part.piece, y.part.piece) / nv_;
    const int ivx = x.part.piece % nv_, ivy = y.part.piece % nv_;
    const int iv0 = std::min(ivx, ivy), iv1 = std::max(ivx, ivy);
    if ((iu1 - iu0 + 1) * (iv1 - iv0 + 1) > kMaxHullPieces) return false;
    thread_local std::vector<Vec3> du, dv;
    du.clear();
    dv.clear();
    for (int iu = iu0; iu <= iu1; ++iu)
      for (int iv = iv0; iv <= iv1; ++iv) {
        const Piece& p = pieces_[static_cast<size_t>(iu) * nv_ + iv];
        const auto local = [](const Interval& global, const Interval& piece, double& a, double& b) {
          a = std::clamp((global.lo - piece.lo) / piece.length(), 0.0, 1.0);
          b = std::clamp((global.hi - piece.lo) / piece.length(), 0.0, 1.0);
        };
        double u0, u1, v0, v1;
        local(u, p.u, u0, u1);
        local(v, p.v, v0, v1);
        if (!(u1 > u0) || !(v1 > v0)) continue;
        // The piece's S_u / S_v numerators restricted to the hull (no product: they are kept per piece).
        const Part hull{0, u0, u1, v0, v1};
        appendRestricted(p.du, p.duDeg, hull, 1.0, du);
        appendRestricted(p.dv, p.dvDeg, hull, 1.0, dv);
      }
    return !du.empty() && conesSeparate(du, dv);
  }
  bool newton(const Region& x, const Region& y) {
    Eigen::Vector4d q(0.5 * (x.u.lo + x.u.hi), 0.5 * (x.v.lo + x.v.hi), 0.5 * (y.u.lo + y.u.hi),
                      0.5 * (y.v.lo + y.v.hi));
    Vec3 p1, p2, su1, sv1, su2, sv2;
    double err = INFINITY;
    for (int it = 0; it < 40; ++it) {
      eval(q[0], q[1], p1, su1, sv1);
      eval(q[2], q[3], p2, su2, sv2);
      const Vec3 f = p1 - p2;
      err = f.norm();
      if (err <= 1e-3 * dist_) break;
      Eigen::Matrix<double, 3, 4> j;
      j << su1, sv1, -su2, -sv2;
      const Eigen::Matrix3d g = j * j.transpose();
      Eigen::LDLT<Eigen::Matrix3d> ldlt(g);
      if (ldlt.info() != Eigen::Success) break;
      const Eigen::Vector4d step = -j.transpose() * ldlt.solve(f);
      if (!step.allFinite()) break;
      q += step;
      q[0] = std::clamp(q[0], domU_.lo, domU_.hi);
      q[2] = std::clamp(q[2], domU_.lo, domU_.hi);
      q[1] = std::clamp(q[1], domV_.lo, domV_.hi);
      q[3] = std::clamp(q[3], domV_.lo, domV_.hi);
    }
    eval(q[0], q[1], p1, su1, sv1);
    eval(q[2], q[3], p2, su2, sv2);
    err = (p1 - p2).norm();
    if (!(err <= dist_)) return false;
    const double wu = std::max(x.u.length(), y.u.length());
    const double wv = std::max(x.v.length(), y.v.length());
    if (q[0] < x.u.lo - wu || q[0] > x.u.hi + wu || q[1] < x.v.lo - wv || q[1] > x.v.hi + wv ||
        q[2] < y.u.lo - wu || q[2] > y.u.hi + wu || q[3] < y.v.lo - wv || q[3] > y.v.hi + wv) {
      return false;
    }
    const auto [sepU, sepV] = separation();
    const double du = std::abs(q[0] - q[2]);
    const double dv = std::abs(q[1] - q[3]);
    if (du <= sepU && dv <= sepV) return false;  // the trivial solution
    if (onPole(q[0], q[1]) && onPole(q[2], q[3])) return false;  // two points of a pole (a critical point)
    if (closedU_ && dv <= sepV && domU_.length() - du <= sepU) return false;  // the seam of a closed surface
    if (closedV_ && du <= sepU && domV_.length() - dv <= sepV) return false;
    if ((q[0] > q[2]) || (q[0] == q[2] && q[1] > q[3])) {
      std::swap(q[0], q[2]);
      std::swap(q[1], q[3]);
    }
    for (const SurfaceSelfIntersection& c : result_.selfIntersections) {
      if (std::abs(c.u1 - q[0]) <= wu && std::abs(c.v1 - q[1]) <= wv && std::abs(c.u2 - q[2]) <= wu &&
          std::abs(c.v2 - q[3]) <= wv) {
        return true;
      }
    }
    if (static_cast<int>(result_.selfIntersections.size()) >= opt_.maxReported) {
      result_.summary.truncated = true;
      return true;
    }
    SurfaceSelfIntersection c;
    c.u1 = q[0];
    c.v1 = q[1];
    c.u2 = q[2];
    c.v2 = q[3];
    c.point = 0.5 * (p1 + p2);
    c.distance = err;
    result_.selfIntersections.push_back(c);
    return true;
  }

  SearchOptions opt_;
  long budget_ = 0;
  long settled_ = 0;  // pieces whose own self-intersection check is done (progress)
  int nu_ = 0;
  int nv_ = 0;
  std::vector<Piece> pieces_;
  std::vector<PoleSides> poles_;  // of the pieces with a pole side (Piece::pole)
  double dist_ = 0.0;
  Interval domU_, domV_;
  bool closedU_ = false;
  bool closedV_ = false;
  SurfaceSearchResult result_;
  std::vector<PoleLine> poleLines_;
  std::vector<size_t> poleReports_;  // indices of the critical points that report a pole
  // Partials of the quotients, of the pieces the critical-point Newton ran on (few: a million pieces would hold
  // gigabytes of them).
  std::unordered_map<int, NewtonPartials> partials_;
};

}  // namespace

Result<SurfaceSearchResult> searchSurfaceDefects(const BSplineSurface& surface, const SearchOptions& options) {
  if (surface.dim() < 2 || surface.dim() > 3) {
    return Status(ErrorCode::kUnsupported, "the surface has " + std::to_string(surface.dim()) +
                                               " coordinates (2 or 3 are supported)");
  }
  if (!(options.resolution > 0.0 && options.resolution < 1.0) || !(options.newtonWidth > 0.0)) {
    return invalidInput("search resolution must be in (0, 1) and the Newton width positive");
  }
  if (surface.degreeU() > kMaxSearchSurfaceDegree || surface.degreeV() > kMaxSearchSurfaceDegree) {
    return Status(ErrorCode::kUnsupported,
                  "the defect search takes degrees up to " + std::to_string(kMaxSearchSurfaceDegree) +
                      " per direction; this patch has degree " + std::to_string(surface.degreeU()) + " x " +
                      std::to_string(surface.degreeV()) + " (S_u x S_v would have degree " +
                      std::to_string(2 * surface.degreeU() - 1) + " x " + std::to_string(2 * surface.degreeV() - 1) +
                      "; split the patch, or lower its degree)");
  }
  SurfaceSearch search(surface, options);
  return search.run();
}

}  // namespace seam::regularity
