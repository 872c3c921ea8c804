// How the points of two edges are matched (continuity/seam_correspondence.h): the overlap, the correspondence maps
// (affine, fitted polynomial) and the exact pieces along them.
#include "continuity/seam_correspondence.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <tuple>

#include "continuity/curve_projection.h"
#include "seam/core/tolerances.h"

namespace seam::detail {

namespace {

/// A correspondence whose certified distance bound is below this fraction of the edge size is exact.
constexpr double kExactCorrespondenceRel = 1e-9;
/// Samples per span used to fit a polynomial correspondence (over-determined least squares, then verified exactly).
constexpr int kFitSamplesFactor = 3;

/// An edge end point is matched to the other edge's end point when that end is within this factor of the distance
/// to the other curve (gaps), rather than to its closest point (T-junctions).
constexpr double kOverlapSnapFactor = 2.0;

// Finds sigma in [lo, hi] with m(sigma) = target, m monotone on it (bisection to round-off).
double solveMonotone(const BernsteinPoly& m, double target, double lo, double hi) {
  const bool increasing = m.scalar(hi) >= m.scalar(lo);
  for (int i = 0; i < 200 && hi - lo > 1e-16; ++i) {
    const double mid = 0.5 * (lo + hi);
    const double v = m.scalar(mid);
    if ((v < target) == increasing)
      lo = mid;
    else
      hi = mid;
  }
  return 0.5 * (lo + hi);
}

// An end point whose partner edge's end is about as close as the partner curve itself (a gap, not a
// T-junction) is snapped to that end, so that offset seams keep their exact end-to-end correspondence.
// `lo`, `hi`: the curve's points at the range ends (computed once); `diag`: its control box diagonal.
double projectEnd(const BSplineCurve& c, const Vec3& lo, const Vec3& hi, double diag, const Vec3& p, Interval range) {
  const double dLo = (lo - p).norm(), dHi = (hi - p).norm();
  const double roundoff = kRoundoff * diag;
  if (std::min(dLo, dHi) <= roundoff) return dLo <= dHi ? range.lo : range.hi;  // shared end point
  const detail::CurvePoint cp = detail::closestPoint(c, p, range);
  const double slack = kOverlapSnapFactor * cp.distance + roundoff;
  if (std::min(dLo, dHi) <= slack) return dLo <= dHi ? range.lo : range.hi;
  return cp.t;
}

/// The exact pieces along `maps` and the certified bound of their gap |a - b o phi|.
std::pair<std::vector<Piece>, double> certifiedMaps(const Side& master, const Side& slave, bool masterIsA,
                                                    const std::vector<MapSpan>& maps, const SeamOptions& opt,
                                                    double exactFloor) {
  std::vector<Piece> pcs = buildPieces(master, slave, masterIsA, maps, opt);
  double best = 0.0, bx = 0.0;
  int bp = 0;
  bool ok = true;
  for (size_t i = 0; i < pcs.size(); ++i)
    for (int k = 0; k <= 4; ++k) best = std::max(best, g0Value(pcs[i], k / 4.0));
  const double bound = certifyMax(pcs, g0Bound, g0Value, best, bx, bp, exactFloor, opt, ok, nullptr, nullptr,
                                  opt.tol.distance);
  return std::pair{std::move(pcs), bound};
}

/// A polynomial map of degree deg_B / deg_A from B's parameter to A's (or the other way) whose gap bound is exact:
/// then c holds its pieces and bound, and rep its degree. Homogeneous degrees: b = a o psi holds for (wP, w) as
/// well, up to a common factor that is not sought.
bool polynomialCorrespondence(const Side& A, const Side& B, const SeamOptions& opt, double exactFloor,
                              SeamReport& rep, SeamCorrespondence& c) {
  const int pA = A.degree, pB = B.degree;
  const bool bOverA = pB % pA == 0 && pB / pA > 1;
  if (!bOverA && !(pA % pB == 0 && pA / pB > 1)) return false;
  const int r = bOverA ? pB / pA : pA / pB;
  auto [pcs, bound] = bOverA ? certifiedMaps(B, A, false, fittedMaps(B, A, rep.overlapB, r), opt, exactFloor)
                             : certifiedMaps(A, B, true, fittedMaps(A, B, rep.overlapA, r), opt, exactFloor);
  if (!(bound <= exactFloor)) return false;
  c.pieces = std::move(pcs);
  rep.correspondenceDegree = r;
  c.corrBound = bound;
  return true;
}

/// A gap: the affine map (gap bound `bound`) is as good as closest-point matching (offset seams). The Hausdorff
/// distance only grows, so the loop stops as soon as it decides the test (the same decision as the whole loop).
bool affineAsGoodAsProjection(const Side& A, const Side& B, const SeamOptions& opt, double exactFloor,
                              const SeamReport& rep, double bound) {
  double haus = 0.0;
  const auto affineAsGood = [&] { return bound <= (1.0 + opt.boundRelGap) * haus + exactFloor; };
  const int n = std::max(opt.samplesPerSpan, 8) * static_cast<int>(A.spans.size());
  for (int i = 0; i <= n && !affineAsGood(); ++i) {
    const double t = rep.overlapA.lo + rep.overlapA.length() * i / n;
    haus = std::max(haus, detail::closestPoint(B.curve, A.curve.point3(t), rep.overlapB).distance);
  }
  return affineAsGood();
}

}  // namespace

std::optional<double> partnerThroughPieces(const std::vector<Piece>& pieces, double t) {
  for (const Piece& pc : pieces) {
    const Matrix& c = pc.tOf.coeffs();
    if (c.rows() == 0) continue;
    const double t0 = c(0, 0), t1 = c(c.rows() - 1, 0);
    if (!(std::min(t0, t1) <= t && t <= std::max(t0, t1))) continue;
    if (t0 == t1) return pc.sOf.scalar(0.0);
    const double x = pc.tOf.degree() <= 1 ? std::clamp((t - t0) / (t1 - t0), 0.0, 1.0)
                                          : solveMonotone(pc.tOf, t, 0.0, 1.0);
    return pc.sOf.scalar(x);
  }
  return std::nullopt;
}

std::vector<Piece> buildPieces(const Side& master, const Side& slave, bool masterIsA,
                               const std::vector<MapSpan>& maps, const SeamOptions& opt) {
  std::vector<Piece> out;
  for (const MapSpan& ms : maps) {
    const Interval msp = master.spans[static_cast<size_t>(ms.span)];
    // Split the local interval where the slave parameter crosses one of the slave's breakpoints.
    std::vector<double> cuts{ms.sig0};
    const double m0 = ms.m.scalar(ms.sig0), m1 = ms.m.scalar(ms.sig1);
    for (size_t k = 0; k + 1 < slave.spans.size(); ++k) {
      const double b = slave.spans[k].hi;
      if (b > std::min(m0, m1) && b < std::max(m0, m1)) cuts.push_back(solveMonotone(ms.m, b, ms.sig0, ms.sig1));
    }
    cuts.push_back(ms.sig1);
    std::sort(cuts.begin(), cuts.end());
    // Knots of the two edges that agree to round-off (the same knot value seen through an affine map) must not
    // leave a sliver piece: its polynomials vanish to round-off and no bound closes on it.
    const double sliver = kKnotRelTol * master.domain().length() / msp.length();
    std::vector<double> kept{cuts.front()};
    for (size_t c = 1; c + 1 < cuts.size(); ++c)
      if (cuts[c] - kept.back() > sliver && cuts.back() - cuts[c] > sliver) kept.push_back(cuts[c]);
    kept.push_back(cuts.back());
    cuts = std::move(kept);
    for (size_t c = 0; c + 1 < cuts.size(); ++c) {
      const double sa = cuts[c], sb = cuts[c + 1];
      if (!(sb - sa > sliver)) continue;
      // Master data restricted to [sa, sb] of its span.
      std::array<BernsteinPoly, 3> XM, XS;
      for (size_t k = 0; k < 3; ++k) XM[k] = master.poly(k, static_cast<size_t>(ms.span)).restricted(sa, sb);
      // Slave: the span containing the middle, and the map in its local coordinates.
      const BernsteinPoly mr = ms.m.restricted(sa, sb);
      const int sspan = spanIndex(slave, mr.scalar(0.5));
      const Interval ssp = slave.spans[static_cast<size_t>(sspan)];
      BernsteinPoly local = mr;
      local.coeffs().array() -= ssp.lo;
      local *= 1.0 / ssp.length();
      for (size_t k = 0; k < 3; ++k) {
        const BernsteinPoly hs = slave.poly(k, static_cast<size_t>(sspan));
        XS[k] = local.degree() <= 1 ? hs.restricted(local.coeffs()(0, 0), local.coeffs()(local.degree(), 0))
                                    : hs.composed(local);
      }
      const BernsteinPoly masterParam = BernsteinPoly::linear(msp.lo + msp.length() * sa, msp.lo + msp.length() * sb);
      // Without the G2 certificate (SeamOptions::certifyG2 = false) the Lemma 2 polynomials are not formed: nothing
      // reads them then (g2Available only gates the G2 subdivision), and on biquintic seams they are most of the
      // piece's products.
      const int g2Degree = opt.certifyG2 ? opt.maxCertifiedDegree : -1;
      if (masterIsA)
        out.push_back(buildPiece(XM, XS, master.rational, slave.rational, masterParam, mr, g2Degree));
      else
        out.push_back(buildPiece(XS, XM, slave.rational, master.rational, mr, masterParam, g2Degree));
    }
  }
  return out;
}

// Affine map from A's overlap onto B's overlap.
std::vector<MapSpan> affineMaps(const Side& A, Interval oa, Interval ob, bool reversed) {
  std::vector<MapSpan> maps;
  const double slope = (reversed ? -1.0 : 1.0) * ob.length() / oa.length();
  const double s0 = reversed ? ob.hi : ob.lo;
  for (size_t k = 0; k < A.spans.size(); ++k) {
    const Interval sp = A.spans[k];
    const double lo = std::max(sp.lo, oa.lo), hi = std::min(sp.hi, oa.hi);
    if (!(hi - lo > kKnotRelTol * A.domain().length())) continue;  // no sliver spans (see buildPieces)
    const auto sOf = [&](double t) { return s0 + slope * (t - oa.lo); };
    maps.push_back({static_cast<int>(k), (lo - sp.lo) / sp.length(), (hi - sp.lo) / sp.length(),
                    BernsteinPoly::linear(sOf(sp.lo), sOf(sp.hi))});
  }
  return maps;
}

// Polynomial map of degree r from the master's parameter to the slave's, fitted per master span by least squares
// on closest-point projections (it is verified afterwards by the exact distance bound).
std::vector<MapSpan> fittedMaps(const Side& master, const Side& slave, Interval om, int r) {
  std::vector<MapSpan> maps;
  const int n = kFitSamplesFactor * (r + 1);
  double guess = slave.domain().lo;
  bool first = true;
  for (size_t k = 0; k < master.spans.size(); ++k) {
    const Interval sp = master.spans[k];
    const double lo = std::max(sp.lo, om.lo), hi = std::min(sp.hi, om.hi);
    if (!(hi - lo > kKnotRelTol * master.domain().length())) continue;  // no sliver spans (see buildPieces)
    Eigen::MatrixXd V(n, r + 1);
    Eigen::VectorXd y(n);
    for (int i = 0; i < n; ++i) {
      const double sigma = (static_cast<double>(i) + 0.5) / n;
      const double tm = sp.lo + sp.length() * sigma;
      const Vec3 p = master.curve.point3(tm);
      const auto cp = first ? detail::closestPoint(slave.curve, p) : detail::closestPoint(slave.curve, p, {}, guess);
      first = false;
      guess = cp.t;
      y[i] = cp.t;
      for (int j = 0; j <= r; ++j) V(i, j) = binomial(r, j) * std::pow(sigma, j) * std::pow(1.0 - sigma, r - j);
    }
    const Eigen::VectorXd c = V.colPivHouseholderQr().solve(y);
    maps.push_back({static_cast<int>(k), (lo - sp.lo) / sp.length(), (hi - sp.lo) / sp.length(),
                    BernsteinPoly(Matrix(c))});
  }
  return maps;
}

bool findOverlap(const Side& A, const Side& B, std::optional<Interval> aRange, double diagA, double diagB,
                 SeamReport& rep, SeamOverlap& o) {
  o.da = A.domain();
  if (aRange) o.da = {std::max(o.da.lo, aRange->lo), std::min(o.da.hi, aRange->hi)};
  const Interval da = o.da, db = B.domain();
  o.a0 = A.curve.point3(da.lo);
  o.a1 = A.curve.point3(da.hi);
  const Vec3 &a0 = o.a0, &a1 = o.a1;
  const Vec3 b0 = B.curve.point3(db.lo), b1 = B.curve.point3(db.hi);
  const double tb0 = projectEnd(A.curve, a0, a1, diagA, b0, da), tb1 = projectEnd(A.curve, a0, a1, diagA, b1, da);
  const double sa0 = projectEnd(B.curve, b0, b1, diagB, a0, db), sa1 = projectEnd(B.curve, b0, b1, diagB, a1, db);
  rep.reversed = tb0 > tb1 || (tb0 == tb1 && sa0 > sa1);
  // End mismatch (issue 15 §4): an end point of A and an end point of B matched to each other both ways (each is
  // the other's partner end) are the same end of the seam, so the gap there is their distance, also where one edge
  // runs a little past the other (an overhang within the snap distance, which the pairing does not report as a free
  // part). An end matched only one way (T-junctions, edges that go on past the other) is not a seam end.
  o.endMismatch = 0.0;
  o.endMismatchT = da.lo;
  o.endMismatchPoint = a0;
  for (const auto& [aT, aP, sa] : {std::tuple{da.lo, a0, sa0}, std::tuple{da.hi, a1, sa1}}) {
    for (const auto& [bS, bP, tb] : {std::tuple{db.lo, b0, tb0}, std::tuple{db.hi, b1, tb1}}) {
      if (sa != bS || tb != aT) continue;
      const double d = (aP - bP).norm();
      if (d > o.endMismatch) o.endMismatch = d, o.endMismatchT = aT, o.endMismatchPoint = aP;
    }
  }
  rep.overlapA = {std::min(tb0, tb1), std::max(tb0, tb1)};
  rep.overlapB = {std::min(sa0, sa1), std::max(sa0, sa1)};
  const double minOverlap = kKnotRelTol * 1e3;
  return rep.overlapA.length() > minOverlap * da.length() && rep.overlapB.length() > minOverlap * db.length();
}

double exactCorrespondenceFloor(double edgeScale) { return kExactCorrespondenceRel * edgeScale; }

SeamCorrespondence findCorrespondence(const Side& A, const Side& B, const SeamOptions& opt, double exactFloor,
                                      SeamReport& rep) {
  SeamCorrespondence c;
  // Both whole edges, the same spans and rows equal up to rounding (C^k splits): bounds straight from the rows.
  if (opt.sharedRows && rep.overlapA.lo == A.dom.lo && rep.overlapA.hi == A.dom.hi && rep.overlapB.lo == B.dom.lo &&
      rep.overlapB.hi == B.dom.hi)
    c.shared = sharedRowBounds(A, B, rep.reversed);
  if (c.shared) {
    rep.correspondence = Correspondence::kAffine;
    rep.sharedRows = true;
    c.certified = true;
    c.corrBound = c.shared->g0;
    return c;
  }
  auto [pcs, bound] =
      certifiedMaps(A, B, true, affineMaps(A, rep.overlapA, rep.overlapB, rep.reversed), opt, exactFloor);
  if (bound <= exactFloor) {
    c.pieces = std::move(pcs);
    rep.correspondence = Correspondence::kAffine;
    c.certified = true;
    c.corrBound = bound;
  } else if (polynomialCorrespondence(A, B, opt, exactFloor, rep, c)) {
    rep.correspondence = Correspondence::kPolynomial;
    c.certified = true;
  } else if (affineAsGoodAsProjection(A, B, opt, exactFloor, rep, bound)) {
    c.pieces = std::move(pcs);
    rep.correspondence = Correspondence::kAffine;
    c.certified = true;
    c.corrBound = bound;
  } else {
    rep.correspondence = Correspondence::kProjection;
    rep.notes.push_back("no polynomial correspondence between the edges: measures are sampled");
  }
  for (const Piece& pc : c.pieces)
    if (pc.P.degree() > opt.maxCertifiedDegree) {
      c.certified = false;
      c.pieces.clear();
      rep.notes.push_back("seam polynomials exceed the certified degree limit: measures are sampled");
      break;
    }
  return c;
}

}  // namespace seam::detail
