// B's side of a B-rep edge re-expressed in A's parameter through a monotone piecewise-cubic correspondence
// (pcurve_correspondence.h).
#include "occt/pcurve_correspondence.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "continuity/sampling.h"
#include "seam/core/bernstein.h"
#include "seam/spline/bezier.h"

namespace seam::occt::detail {

EdgeJet edgeJet(const PCurveSide& s, double t) {
  Vec2 c, d;
  s.pcurve.derivatives1(t, c, d);
  const Interval du = s.surface->domainU(), dv = s.surface->domainV();
  Vec3 p, su, sv;
  s.surface->pointAndFirstDerivatives(std::clamp(c[0], du.lo, du.hi), std::clamp(c[1], dv.lo, dv.hi), p, su, sv);
  return {p, su * d[0] + sv * d[1]};
}

EdgeJet EdgeJetMemo::at(double t) {
  const auto key = std::bit_cast<std::uint64_t>(t);
  for (size_t i = 0; i < count_; ++i)
    if (keys_[i] == key) return jets_[i];
  const size_t i = next_;
  next_ = (next_ + 1) % kEdgeJetMemoSize;
  count_ = std::max(count_, i + 1);
  keys_[i] = key;
  jets_[i] = edgeJet(side_, t);
  return jets_[i];
}

namespace {

/// An edge is closed when its end points lie within this fraction of the distance from its start to its middle point
/// (a full circle or ellipse: the same vertex at both ends, apart by round-off).
constexpr double kClosedEdgeRel = 1e-6;

/// Gauss-Newton steps of a closest-point search along an edge, and the step (relative to the range) that ends it.
constexpr int kClosestIterations = 40;
constexpr double kClosestStepRel = 1e-15;

/// The parameter t of side `s`'s edge where (x - E(t)) . d = 0, from `t` (Newton's steps, clamped to the range):
/// with d = E'(t) the point closest to x (Gauss-Newton), with a fixed direction d the point in the plane through x
/// normal to d.
double footOnEdge(EdgeJetMemo& memo, const Vec3& x, const std::optional<Vec3>& direction, double t) {
  const Interval r = memo.side().range;
  t = std::clamp(t, r.lo, r.hi);
  for (int it = 0; it < kClosestIterations; ++it) {
    const EdgeJet j = memo.at(t);
    const Vec3 d = direction ? *direction : j.tangent;
    const double slope = j.tangent.dot(d);
    if (!(slope != 0.0)) break;  // a vanishing tangent (a pole of the edge) or one in the plane: keep the point
    const double next = std::clamp(t + (x - j.point).dot(d) / slope, r.lo, r.hi);
    if (!std::isfinite(next)) break;
    const bool done = std::abs(next - t) <= kClosestStepRel * r.length();
    t = next;
    if (done) break;
  }
  return t;
}

/// The parameter of the point of side `s`'s edge closest to x, from `t`.
double closest(EdgeJetMemo& memo, const Vec3& x, double t) { return footOnEdge(memo, x, std::nullopt, t); }

/// The parameter of the point of side `s`'s edge in the normal plane of the other edge at jet b, from `t`: the r whose
/// closest point on the other edge is b's point, found from b's side of the closest-point equation. Projecting b's
/// point onto A instead solves A's side of it; between two edges a gap apart the two differ (by 5e-10 of the
/// parameter on trj3_s1-al-214.stp F2/F4, whose pcurves share 44 knots), enough to put a knot's preimage on the wrong
/// side of the other edge's matching knot.
double inNormalPlane(EdgeJetMemo& memo, const EdgeJet& b, double t) { return footOnEdge(memo, b.point, b.tangent, t); }

/// Where a piece of phi is compared with the closest points (its local parameter; phi interpolates them at 0, 1/3,
/// 2/3 and 1).
constexpr std::array<double, 9> kPairingChecks = {1.0 / 12, 1.0 / 6, 1.0 / 4, 5.0 / 12, 1.0 / 2,
                                                  7.0 / 12, 3.0 / 4, 5.0 / 6, 11.0 / 12};

/// A piece of the correspondence at an end of the edge, once no longer than kEndPieceRel of the range, pairs within
/// kEndOverhangFactor times the end's overhang (when that is above the pairing tolerance): the rest keeps the pairing
/// tolerance.
constexpr double kEndOverhangFactor = 2.0;
constexpr double kEndPieceRel = 1.0 / 64.0;

/// The Bernstein cubic on [0, 1] through (0, q0), (1/3, q1), (2/3, q2), (1, q3).
BernsteinPoly cubicThrough(double q0, double q1, double q2, double q3) {
  // Bernstein coefficients from the values at 0, 1/3, 2/3, 1 (inverse of the collocation matrix).
  const double b1 = (-5.0 * q0 + 18.0 * q1 - 9.0 * q2 + 2.0 * q3) / 6.0;
  const double b2 = (2.0 * q0 - 9.0 * q1 + 18.0 * q2 - 5.0 * q3) / 6.0;
  Matrix c(4, 1);
  c << q0, b1, b2, q3;
  return BernsteinPoly(std::move(c));
}

struct Piece {
  double r0, r1;       // A's parameter
  BernsteinPoly phi;   // B's parameter as a cubic in s = (r - r0) / (r1 - r0)
};

}  // namespace

Result<Correspondence> correspondInParameterOf(const PCurveSide& a, const PCurveSide& b, double distanceTol,
                                               double pairFraction) {
  auto unsupported = [](std::string why) { return Status(ErrorCode::kUnsupported, std::move(why)); };
  if (!(distanceTol > 0.0) || !(pairFraction > 0.0) || !a.surface || !b.surface)
    return invalidInput("correspondence: bad sides");
  const Interval ra = a.range, rb = b.range;
  // Orientation: B's range runs along A's or against it, from the end points. On two closed edges (a full ellipse)
  // the end points tie and round-off chose (4.90998e-13 against 4.91064e-13 at radius 0.05 in
  // OcctTruth.AnEllipseOnACylinderIsCertifiedThroughTheCylindersAngleParameter: reversed, and no correspondence):
  // there the points a third and two thirds along each range decide.
  EdgeJetMemo jetA(a), jetB(b);
  const Vec3 a0 = jetA.at(ra.lo).point, a1 = jetA.at(ra.hi).point;
  const Vec3 b0 = jetB.at(rb.lo).point, b1 = jetB.at(rb.hi).point;
  const auto along = [](const Interval& r, double f) { return r.lo + f * r.length(); };
  const auto closed = [&](EdgeJetMemo& jet, const Interval& r, const Vec3& p0, const Vec3& p1) {
    return (p1 - p0).norm() <= kClosedEdgeRel * (jet.at(along(r, 0.5)).point - p0).norm();
  };
  bool reversed = (a0 - b1).norm() + (a1 - b0).norm() < (a0 - b0).norm() + (a1 - b1).norm();
  if (closed(jetA, ra, a0, a1) && closed(jetB, rb, b0, b1)) {
    const Vec3 a3 = jetA.at(along(ra, 1.0 / 3)).point, a6 = jetA.at(along(ra, 2.0 / 3)).point;
    const Vec3 b3 = jetB.at(along(rb, 1.0 / 3)).point, b6 = jetB.at(along(rb, 2.0 / 3)).point;
    reversed = (a3 - b6).norm() + (a6 - b3).norm() < (a3 - b3).norm() + (a6 - b6).norm();
  }
  const double qStart = reversed ? rb.hi : rb.lo, qEnd = reversed ? rb.lo : rb.hi;
  auto linearGuess = [&](double r) { return qStart + (r - ra.lo) / ra.length() * (qEnd - qStart); };
  auto phiStar = [&](double r, double guess) { return closest(jetB, jetA.at(r).point, guess); };

  // Breakpoints in r: A's pcurve breakpoints and the preimages of B's (so that every piece of phi stays inside one
  // Bezier piece of B's pcurve), with B's parameter there: B's own knot values exactly.
  struct Break {
    double r, q;
  };
  std::vector<Break> breaks{{ra.lo, qStart}, {ra.hi, qEnd}};
  const double minGap = seam::detail::kSameBreakpointRel;  // of each range
  for (const BezierCurvePiece& p : a.pcurve.bezierPieces()) {
    const double r = p.interval.lo;
    if (r > ra.lo + minGap * ra.length() && r < ra.hi - minGap * ra.length())
      breaks.push_back({r, phiStar(r, linearGuess(r))});
  }
  for (const BezierCurvePiece& p : b.pcurve.bezierPieces()) {
    const double q = p.interval.lo;
    if (!(q > rb.lo + minGap * rb.length() && q < rb.hi - minGap * rb.length())) continue;
    const double guess = ra.lo + (q - qStart) / (qEnd - qStart) * ra.length();
    breaks.push_back({inNormalPlane(jetA, jetB.at(q), guess), q});
  }
  std::sort(breaks.begin(), breaks.end(), [](const Break& x, const Break& y) { return x.r < y.r; });
  {
    std::vector<Break> kept{breaks.front()};
    for (size_t i = 1; i < breaks.size(); ++i) {
      if (breaks[i].r - kept.back().r <= minGap * ra.length()) {
        if (i + 1 == breaks.size()) kept.back() = breaks[i];  // keep the range end itself
        continue;
      }
      kept.push_back(breaks[i]);
    }
    breaks = std::move(kept);
  }
  for (size_t i = 0; i + 1 < breaks.size(); ++i)
    if ((breaks[i + 1].q - breaks[i].q) * (qEnd - qStart) <= 0.0)
      return unsupported("the two edges' breakpoints do not correspond in order");

  const double pairTol = pairFraction * distanceTol;
  // Where one edge overhangs the other at an end, the closest-point correspondence is clamped there (or starts inside
  // B's range) while phi maps end to end: a piece at an end pairs within the overhang (the distance between B's end
  // and the closest point of A's end on B) and no closer, however short. A finer pairing (pairFraction below
  // kCorrespondenceTolFraction, tried where a bound lies below a sample) holds such a piece to kEndOverhangFactor
  // times that instead of pairTol when larger; the interior keeps pairTol. The default pairing stays as it was: the
  // heal's checks go through it, and a looser end there changed the heal of a 45-degree crease
  // (BRepHeal.ACreaseKeepsItsAngleWhileItsGapCloses) into a model OpenCASCADE's STEP writer could not keep.
  const bool finer = pairFraction < kCorrespondenceTolFraction;
  const auto overhang = [&](double r, double q) {  // B past A's end r, or A past B's end q
    return std::max((jetB.at(q).point - jetB.at(phiStar(r, q)).point).norm(),
                    (jetA.at(r).point - jetA.at(inNormalPlane(jetA, jetB.at(q), r)).point).norm());
  };
  const double overhangLo = finer ? overhang(ra.lo, qStart) : 0.0, overhangHi = finer ? overhang(ra.hi, qEnd) : 0.0;
  std::vector<Piece> pieces;
  double pairingError = 0.0;
  std::function<bool(double, double, double, double, int)> build = [&](double r0, double q0, double r1, double q3,
                                                                       int depth) -> bool {
    const double h = r1 - r0;
    const double q1 = phiStar(r0 + h / 3.0, q0 + (q3 - q0) / 3.0);
    const double q2 = phiStar(r0 + 2.0 * h / 3.0, q0 + 2.0 * (q3 - q0) / 3.0);
    BernsteinPoly phi = cubicThrough(q0, q1, q2, q3);
    // Strictly monotone in the sense of the whole correspondence (the derivative's Bernstein coefficients).
    const BernsteinPoly d = phi.derivative();
    const double sense = qEnd > qStart ? 1.0 : -1.0;
    bool ok = (d.coeffs().array() * sense).minCoeff() > 0.0;
    double err = 0.0;
    if (ok) {
      for (const double s : kPairingChecks) {
        const double r = r0 + s * h, q = phi.scalar(s);
        const double qs = phiStar(r, q);
        err = std::max(err, (jetB.at(q).point - jetB.at(qs).point).norm());
      }
      double tol = pairTol;
      if (finer && h <= kEndPieceRel * ra.length()) {
        if (r0 == ra.lo) tol = std::max(tol, kEndOverhangFactor * overhangLo);
        if (r1 == ra.hi) tol = std::max(tol, kEndOverhangFactor * overhangHi);
      }
      ok = err <= tol;
    }
    if (ok) {
      pairingError = std::max(pairingError, err);
      pieces.push_back({r0, r1, std::move(phi)});
      return true;
    }
    if (depth >= kCorrespondenceMaxDepth) return false;
    const double rm = 0.5 * (r0 + r1);
    const double qm = phiStar(rm, 0.5 * (q0 + q3));
    if (!((qm - q0) * sense > 0.0 && (q3 - qm) * sense > 0.0)) return false;
    return build(r0, q0, rm, qm, depth + 1) && build(rm, qm, r1, q3, depth + 1);
  };
  for (size_t i = 0; i + 1 < breaks.size(); ++i)
    if (!build(breaks[i].r, breaks[i].q, breaks[i + 1].r, breaks[i + 1].q, 0))
      return unsupported(fmt::format("no monotone correspondence between the edges within {:.3g} near r = {:.9g}",
                                     pairTol, breaks[i].r));

  // Composition: on each piece, B's Bezier piece (in homogeneous form when rational) of the local parameter
  // (phi - k0) / (k1 - k0), composed with the cubic exactly.
  const std::vector<BezierCurvePiece> bp = b.pcurve.bezierPieces();
  const bool rational = b.pcurve.isRational();
  const int degree = 3 * b.pcurve.degree();
  const int cols = rational ? 3 : 2;
  Matrix rows(static_cast<Eigen::Index>(pieces.size()) * degree + 1, cols);
  std::vector<double> knots(static_cast<size_t>(degree + 1), ra.lo);
  Eigen::Index row = 0;
  for (size_t i = 0; i < pieces.size(); ++i) {
    const Piece& p = pieces[i];
    const double qMid = p.phi.scalar(0.5);
    const auto it = std::find_if(bp.begin(), bp.end(), [&](const BezierCurvePiece& x) {
      return qMid >= x.interval.lo && qMid <= x.interval.hi;
    });
    if (it == bp.end()) return unsupported("the correspondence leaves B's pcurve");
    const double k0 = it->interval.lo, k1 = it->interval.hi;
    BernsteinPoly local = p.phi;
    local.coeffs().array() = (local.coeffs().array() - k0) / (k1 - k0);
    const BernsteinPoly h = it->curve.homogeneous().composed(local);
    const Matrix& c = h.coeffs();
    if (i == 0) {
      rows.row(row++) = c.row(0);
    } else {
      rows.row(row - 1) = 0.5 * (rows.row(row - 1) + c.row(0));  // the shared end, equal up to round-off
    }
    for (int k = 1; k <= degree; ++k) rows.row(row++) = c.row(k);
    if (i + 1 < pieces.size())
      for (int k = 0; k < degree; ++k) knots.push_back(p.r1);
  }
  for (int k = 0; k <= degree; ++k) knots.push_back(ra.hi);
  Matrix pts(rows.rows(), 2);
  VecX weights;
  if (rational) {
    weights = rows.col(2);
    if (!(weights.minCoeff() > 0.0)) return unsupported("the composed pcurve has a weight that is not positive");
    pts.col(0) = rows.col(0).cwiseQuotient(weights);
    pts.col(1) = rows.col(1).cwiseQuotient(weights);
  } else {
    pts = rows;
  }
  Result<BSplineCurve> curve = BSplineCurve::create(degree, std::move(knots), std::move(pts), std::move(weights));
  if (!curve) return unsupported("the composed pcurve is not a valid B-spline: " + curve.status().message());

  Correspondence out;
  out.b = b;
  out.b.pcurve = std::move(curve).value();
  out.b.range = ra;
  out.pieces = static_cast<int>(pieces.size());
  out.pairingError = pairingError;
  return out;
}

}  // namespace seam::occt::detail
