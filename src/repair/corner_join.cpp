// Lai-Lian-Cassidy §4.1: the proportionality conditions at a corner and the successive joins. The derivation of the
// conditions (and of the corrected index ranges) is in docs/algorithms/lai-lian-cassidy.md §5.
#include "seam/repair/corner_join.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "repair/frame_internal.h"
#include "repair/join_internal.h"
#include "seam/continuity/model_check.h"
#include "seam/repair/bicubic.h"
#include "seam/repair/heal.h"

namespace seam {

std::string_view toString(CornerCondition c) {
  switch (c) {
    case CornerCondition::kUProportional: return "u-proportional";
    case CornerCondition::kUEqualSpans: return "u-equal-spans";
    case CornerCondition::kBreakpointsMatch: return "breakpoints-match";
    case CornerCondition::kHatTildeJunctions: return "hat-tilde-junctions";
    case CornerCondition::kHatSJunctions: return "hat-s-junctions";
    case CornerCondition::kRatioChain: return "ratio-chain";
    case CornerCondition::kPair12Proportional: return "pair12-proportional";
    case CornerCondition::kPair12EqualSpans: return "pair12-equal-spans";
    case CornerCondition::kPair34Proportional: return "pair34-proportional";
    case CornerCondition::kPair34EqualSpans: return "pair34-equal-spans";
    case CornerCondition::kCompoundChain: return "compound-chain";
  }
  return "?";
}

namespace {

/// Points of the edge of S^ sampled to find which end lies on S~'s side (only the order matters).
constexpr int kOrientationSamples = 400;

const ConditionCheck* findCheck(const std::vector<ConditionCheck>& v, CornerCondition c) {
  for (const ConditionCheck& k : v)
    if (k.condition == c) return &k;
  return nullptr;
}

// A patch seen from `edge` (frame edge V0, u along) with the along parameter starting at the corner where `other`
// (an edge perpendicular to `edge`) meets it; the across parameter then runs along `other` from that corner.
struct CornerFrame {
  BSplineSurface f;
  bool flip = false;
};
Result<CornerFrame> frameFromCorner(const BSplineSurface& s, Edge edge, Edge other, const std::string& name) {
  if (isUEdge(edge) == isUEdge(other))
    return invalidInput(fmt::format("patch \"{}\": edges {} and {} do not meet at a corner", name, edgeName(edge),
                                    edgeName(other)));
  CornerFrame cf;
  cf.flip = isUEdge(edge) ? other == Edge::V1 : other == Edge::U1;
  cf.f = detail::toEdgeFrame(s, edge, cf.flip);
  return cf;
}

Vec3 at(const BSplineSurface& f, double u, double v) { return f.evaluate(u, v).head<3>(); }
Vec3 cornerPoint(const BSplineSurface& f) { return at(f, f.domainU().lo, f.domainV().lo); }
Vec3 v3of(const VecX& v) { return v.head<3>(); }

std::vector<double> spans(const std::vector<double>& b) {
  std::vector<double> h;
  for (size_t i = 1; i < b.size(); ++i) h.push_back(b[i] - b[i - 1]);
  return h;
}

// xi at breakpoint k of b (interior): right span over the two spans around it (the alpha of (2.7)).
double xiAt(const std::vector<double>& b, int k) {
  const auto i = static_cast<size_t>(k);
  return (b[i + 1] - b[i]) / (b[i + 1] - b[i - 1]);
}

ConditionCheck proportionalCheck(CornerCondition c, const KnotVector& u, const KnotVector& uT, double tol,
                                 const char* statement) {
  ConditionCheck k;
  k.condition = c;
  k.statement = statement;
  k.tolerance = tol;
  auto pr = proportionalKnots(u, uT, tol);
  if (!pr) {
    k.residual = std::numeric_limits<double>::infinity();
    k.detail = pr.status().message();
    return k;
  }
  k.residual = pr->maxAlphaDeviation;
  k.holds = pr->proportional;
  double worst = -1.0;
  for (int i = 1; i <= pr->mHat - 1; ++i) {
    const double d = std::abs(pr->alpha[static_cast<size_t>(i)] - pr->alphaTilde[static_cast<size_t>(i)]);
    if (d > worst) {
      worst = d;
      k.detail = fmt::format("junction i = {}: alpha = {:.12g}, alpha~ = {:.12g}", i, pr->alpha[static_cast<size_t>(i)],
                             pr->alphaTilde[static_cast<size_t>(i)]);
    }
  }
  return k;
}

ConditionCheck equalSpansCheck(CornerCondition c, const KnotVector& u, const KnotVector& uT, double tol,
                               const char* statement) {
  ConditionCheck k;
  k.condition = c;
  k.statement = statement;
  k.tolerance = tol;
  const std::vector<double> h = spans(u.breakpoints()), hT = spans(uT.breakpoints());
  const size_t mh = std::min(h.size(), hT.size());
  double worst = -1.0;
  for (size_t i = 0; i < mh; ++i) {
    const double d = std::abs(h[i] - hT[i]) / std::max(h[i], hT[i]);
    if (d > worst) {
      worst = d;
      k.detail = fmt::format("span i = {}: {:.12g} against {:.12g}", i + 1, h[i], hT[i]);
    }
  }
  k.residual = std::max(worst, 0.0);
  k.holds = k.residual <= tol;
  return k;
}

ConditionCheck chainCheck(CornerCondition c, const std::vector<double>& ratios, double tol, const char* statement) {
  ConditionCheck k;
  k.condition = c;
  k.statement = statement;
  k.tolerance = tol;
  if (ratios.empty()) {
    k.holds = true;
    return k;
  }
  const auto [lo, hi] = std::minmax_element(ratios.begin(), ratios.end());
  k.residual = (*hi - *lo) / *hi;
  k.holds = k.residual <= tol;
  k.detail = fmt::format("ratios from {:.12g} (index {}) to {:.12g} (index {})", *lo, lo - ratios.begin(), *hi,
                         hi - ratios.begin());
  return k;
}

struct Setup {
  double diag = 1.0, maxGap = 0.0;
  Tolerances tol;
  SeamOptions so;
};
Setup setupFor(const Model& model, const CornerJoinOptions& opt) {
  Setup s;
  s.diag = model.boundingBox().diagonal();
  if (!(s.diag > 0.0)) s.diag = 1.0;
  s.tol = opt.tolerances ? *opt.tolerances : Tolerances::forModelSize(s.diag);
  s.maxGap = opt.maxGap ? *opt.maxGap : kDefaultMaxGapRel * s.diag;
  s.so = opt.seam;
  s.so.tol = s.tol;
  return s;
}

Result<int> indexOf(const Model& m, const std::string& name) {
  for (size_t i = 0; i < m.patches.size(); ++i)
    if (m.patches[i].name == name) return static_cast<int>(i);
  return Status(ErrorCode::kNotFound, fmt::format("no patch named \"{}\"", name));
}

// ---------------------------------------------------------------------------------------------------------------------
// Three surfaces: the frames and the numbers of the report.
// ---------------------------------------------------------------------------------------------------------------------

struct ThreeFrames {
  int is = 0, it = 0, ih = 0;
  CornerFrame fs, ft;  // S and S~ from the S/S~ seam, along from the corner
  BSplineSurface fh;   // S^ from its edge, along from S~'s side
  bool flipH = false;
};

Result<ThreeFrames> threeFrames(const Model& model, const ThreePatchCorner& c, const Setup& st) {
  ThreeFrames tf;
  auto is = indexOf(model, c.s), it = indexOf(model, c.sTilde), ih = indexOf(model, c.sHat);
  if (!is) return is.status();
  if (!it) return it.status();
  if (!ih) return ih.status();
  tf.is = *is;
  tf.it = *it;
  tf.ih = *ih;
  if (tf.is == tf.it || tf.is == tf.ih || tf.it == tf.ih) return invalidInput("S, S~ and S^ must be three patches");
  const Patch& S = model.patches[static_cast<size_t>(tf.is)];
  const Patch& T = model.patches[static_cast<size_t>(tf.it)];
  const Patch& H = model.patches[static_cast<size_t>(tf.ih)];
  for (const Patch* p : {&S, &T, &H})
    if (p->surface.dim() != 3) return invalidInput(fmt::format("patch \"{}\" is not 3-D", p->name));
  auto fs = frameFromCorner(S.surface, c.sToTilde, c.sToHat, S.name);
  if (!fs) return fs.status();
  auto ft = frameFromCorner(T.surface, c.tildeToS, c.tildeToHat, T.name);
  if (!ft) return ft.status();
  tf.fs = *fs;
  tf.ft = *ft;
  const double cornerGap = (cornerPoint(tf.fs.f) - cornerPoint(tf.ft.f)).norm();
  if (cornerGap > st.maxGap)
    return invalidInput(fmt::format("the corners of \"{}\" ({} / {}) and \"{}\" ({} / {}) are {:.6g} apart, above the gap "
                                    "limit {:.6g}: these edges do not meet at one corner",
                                    S.name, edgeName(c.sToTilde), edgeName(c.sToHat), T.name, edgeName(c.tildeToS),
                                    edgeName(c.tildeToHat), cornerGap, st.maxGap));
  // Which way S^'s edge runs: the middle of S~'s edge along S^ must come before the middle of S's.
  const BSplineSurface h0 = detail::toEdgeFrame(H.surface, c.hatEdge, false);
  const Interval dh = h0.domainU();
  auto closest = [&](const Vec3& p) {
    double best = std::numeric_limits<double>::infinity(), tb = dh.lo;
    for (int k = 0; k <= kOrientationSamples; ++k) {
      const double t = dh.lo + dh.length() * k / kOrientationSamples;
      const double d = (at(h0, t, h0.domainV().lo) - p).norm();
      if (d < best) best = d, tb = t;
    }
    return tb;
  };
  auto midAlongHat = [](const BSplineSurface& f) {
    return at(f, f.domainU().lo, 0.5 * (f.domainV().lo + f.domainV().hi));
  };
  tf.flipH = closest(midAlongHat(tf.ft.f)) > closest(midAlongHat(tf.fs.f));
  tf.fh = detail::toEdgeFrame(H.surface, c.hatEdge, tf.flipH);
  return tf;
}

Result<ThreePatchProportionality> proportionality3(const Model& model, const ThreePatchCorner& corner, const Setup& st,
                                                   const ThreeFrames& tf, double ptol) {
  for (int idx : {tf.is, tf.it, tf.ih}) {
    const Patch& p = model.patches[static_cast<size_t>(idx)];
    if (Status s = checkC1Bicubic(p.surface); !s)
      return Status(ErrorCode::kUnsupported,
                    fmt::format("the §4.1 conditions are defined for C1 bicubic B-splines; \"{}\" is not: {}", p.name,
                                s.message()));
  }
  ThreePatchProportionality r;
  const BSplineSurface &FS = tf.fs.f, &FT = tf.ft.f, &FH = tf.fh;
  const std::vector<double> bu = FS.knotsU().breakpoints(), bt = FT.knotsU().breakpoints();
  r.m = static_cast<int>(bu.size()) - 1;
  r.mTilde = static_cast<int>(bt.size()) - 1;
  r.checks.push_back(proportionalCheck(CornerCondition::kUProportional, FS.knotsU(), FT.knotsU(), ptol,
                                       "(a) Def. 3.1: alpha_i = alpha~_i, i = 1..m^-1"));
  r.checks.push_back(equalSpansCheck(CornerCondition::kUEqualSpans, FS.knotsU(), FT.knotsU(), ptol,
                                     "(c) u_{2i+2} - u_{2i} = u~_{2i+2} - u~_{2i}, i = 1..m^"));

  const std::vector<double> c = FS.knotsV().breakpoints(), ct = FT.knotsV().breakpoints(),
                            bh = FH.knotsU().breakpoints();
  r.n = static_cast<int>(c.size()) - 1;
  r.nTilde = static_cast<int>(ct.size()) - 1;
  r.q = static_cast<int>(bh.size()) - 1;
  const Vec3 P = cornerPoint(FS);
  const double vh = FH.domainV().lo;
  int K = 0;
  double best = std::numeric_limits<double>::infinity();
  for (int k = 0; k <= r.q; ++k) {
    const double d = (at(FH, bh[static_cast<size_t>(k)], vh) - P).norm();
    if (d < best) best = d, K = k;
  }
  if (K == 0 || K == r.q)
    return invalidInput(fmt::format("the corner lies at an end of \"{}\"'s edge {} (breakpoint {} of {}), not in its "
                                    "interior: S^ does not run along both S and S~",
                                    corner.sHat, edgeName(corner.hatEdge), K, r.q));
  r.cornerIndex = K;
  r.nHat1 = std::min(r.nTilde, K);
  r.nHat2 = std::min(r.n, r.q - K);
  const double uS = FS.domainU().lo, uT = FT.domainU().lo;
  {
    ConditionCheck k;
    k.condition = CornerCondition::kBreakpointsMatch;
    k.statement = "(4.1), (4.2): f^(b^_{K-j}) = f~(c~_j), j = 0..n^1; f^(b^_{K+j}) = f(c_j), j = 0..n^2";
    k.tolerance = st.maxGap;
    double worst = -1.0;
    for (int j = 0; j <= r.nHat1; ++j) {
      const double d = (at(FH, bh[static_cast<size_t>(K - j)], vh) - at(FT, uT, ct[static_cast<size_t>(j)])).norm();
      if (d > worst) worst = d, k.detail = fmt::format("S~ breakpoint j = {}: {:.6g} apart", j, d);
    }
    for (int j = 0; j <= r.nHat2; ++j) {
      const double d = (at(FH, bh[static_cast<size_t>(K + j)], vh) - at(FS, uS, c[static_cast<size_t>(j)])).norm();
      if (d > worst) worst = d, k.detail = fmt::format("S breakpoint j = {}: {:.6g} apart", j, d);
    }
    k.residual = worst;
    k.holds = worst <= st.maxGap;
    r.checks.push_back(k);
  }
  {
    ConditionCheck k;
    k.condition = CornerCondition::kHatTildeJunctions;
    k.statement = "(b) eta^_{K-i} = xi~_i, i = 1..n^1-1 (the paper's eta^_{J-j-2} = xi~_{j+1})";
    k.tolerance = ptol;
    double worst = 0.0;
    for (int i = 1; i <= r.nHat1 - 1; ++i) {
      const double eh = 1.0 - xiAt(bh, K - i), xt = xiAt(ct, i);
      if (std::abs(eh - xt) >= worst) {
        worst = std::abs(eh - xt);
        k.detail = fmt::format("i = {}: eta^ = {:.12g}, xi~ = {:.12g}", i, eh, xt);
      }
    }
    k.residual = worst;
    k.holds = worst <= ptol;
    r.checks.push_back(k);
  }
  {
    ConditionCheck k;
    k.condition = CornerCondition::kHatSJunctions;
    k.statement = "(b) xi^_{K+i} = xi_i, i = 1..n^2-1 (the paper's xi^_{J+j} = xi_{j+1})";
    k.tolerance = ptol;
    double worst = 0.0;
    for (int i = 1; i <= r.nHat2 - 1; ++i) {
      const double xh = xiAt(bh, K + i), x = xiAt(c, i);
      if (std::abs(xh - x) >= worst) {
        worst = std::abs(xh - x);
        k.detail = fmt::format("i = {}: xi^ = {:.12g}, xi = {:.12g}", i, xh, x);
      }
    }
    k.residual = worst;
    k.holds = worst <= ptol;
    r.checks.push_back(k);
  }
  for (int i = r.nHat1; i >= 1; --i)
    r.chainRatios.push_back((bh[static_cast<size_t>(K - i + 1)] - bh[static_cast<size_t>(K - i)]) /
                            (ct[static_cast<size_t>(i)] - ct[static_cast<size_t>(i - 1)]));
  for (int i = 1; i <= r.nHat2; ++i)
    r.chainRatios.push_back((bh[static_cast<size_t>(K + i)] - bh[static_cast<size_t>(K + i - 1)]) /
                            (c[static_cast<size_t>(i)] - c[static_cast<size_t>(i - 1)]));
  r.checks.push_back(chainCheck(CornerCondition::kRatioChain, r.chainRatios, ptol,
                                "(c) (b^_{K+i} - b^_{K+i-1}) / (c_i - c_{i-1}) = (b^_{K-i+1} - b^_{K-i}) / (c~_i - "
                                "c~_{i-1}) = const, i = 1..n^2 and 1..n^1"));
  r.allHold = std::all_of(r.checks.begin(), r.checks.end(), [](const ConditionCheck& k) { return k.holds; });
  const bool startsTogether = K == r.nTilde, endsTogether = r.q - K == r.n;
  r.theorem1ForHat = r.allHold && (startsTogether || endsTogether);
  if (r.allHold && !r.theorem1ForHat)
    r.notes.push_back("the conditions hold, but S^'s edge reaches past both S~'s and S's far corners: Theorem 1 pairs "
                      "span i with span i from a common corner, so S^ joins by least squares");
  return r;
}

// The compound S~ u S* seen from S^: rows 0..3 of the first across span of both (exact restriction), along from the
// start of S^'s edge. `first` runs towards the corner, `second` away from it; both are corner frames (along from
// the corner, across along S^) of the two patches.
BSplineSurface compoundTarget(const BSplineSurface& firstFromCorner, const BSplineSurface& second) {
  // firstFromCorner's along runs away from the corner: reverse it (exactly) so that it ends there.
  const BSplineSurface a = detail::toEdgeFrame(firstFromCorner, Edge::V0, true);
  auto firstSpanRows = [](const BSplineSurface& f, int row) -> Matrix {
    // Bezier row `row` (0..3) of the first across span, as de Boor points along.
    const int nb = f.numV();
    Matrix out(f.numU(), f.dim());
    const std::vector<double> xi = c1CubicAlphas(f.knotsV());
    for (int i = 0; i < f.numU(); ++i) {
      if (row < 3 || nb == 4) {
        out.row(i) = f.point(i, row);
      } else {
        out.row(i) = xi[1] * f.point(i, 2) + (1.0 - xi[1]) * f.point(i, 3);
      }
    }
    return out;
  };
  const std::vector<double>& ka = a.knotsU().values();
  const std::vector<double>& kb = second.knotsU().values();
  const double shift = ka.back() - kb.front();
  std::vector<double> k(ka.begin(), ka.end() - 2);  // the corner knot stays double
  for (size_t i = 4; i < kb.size(); ++i) k.push_back(kb[i] + shift);
  const int na = a.numU(), nbp = second.numU(), n = na + nbp - 2;
  const double h = second.knotsV().breakpoints()[1] - second.knotsV().breakpoints()[0];
  Matrix pts(n * 4, 3);
  for (int row = 0; row < 4; ++row) {
    const Matrix ra = firstSpanRows(a, row), rb = firstSpanRows(second, row);
    for (int i = 0; i < na - 1; ++i) pts.row(i * 4 + row) = ra.row(i);
    for (int i = 1; i < nbp; ++i) pts.row((na - 2 + i) * 4 + row) = rb.row(i);
  }
  return BSplineSurface(3, 3, KnotVector(std::move(k)), KnotVector({0, 0, 0, 0, h, h, h, h}), n, 4, std::move(pts));
}


CornerJoinStep stepFor(const Model& before, const Model& after, const std::vector<int>& movedIdx,
                       const std::vector<int>& ontoIdx, double threshold) {
  CornerJoinStep s;
  for (int i : movedIdx) {
    s.moved.push_back(after.patches[static_cast<size_t>(i)].name);
    const Displacement d = controlPointDisplacement(before.patches[static_cast<size_t>(i)].surface,
                                                    after.patches[static_cast<size_t>(i)].surface, threshold);
    s.maxDisplacement = std::max(s.maxDisplacement, d.max);
    s.movedPoints += d.moved;
  }
  for (int i : ontoIdx) s.onto.push_back(after.patches[static_cast<size_t>(i)].name);
  return s;
}

// The least-squares join of one patch onto one or two fixed neighbours at once (as healModel does it): the part of
// its edge against each neighbour is found by the seam analysis, with the ends snapped to corners within maxGap.
//  * kappa = 0 at the `corner` (the seam line stays straight through the vertex, so that a later patch can meet the
//    two patches there with one smooth edge: the T-junction of Fig. 1 needs S*_v and S~_v~ collinear there);
//  * with two neighbours along one edge (S^ against S~ and S* in Fig. 1), one correspondence for both: the split
//    point on the mover's edge is placed where the two targets' speeds agree (docs §5.1), so the composite target is
//    C1 in the mover's parameter and needs no C0 knot at the corner. Affine maps fixed by the breakpoints would give
//    a jump of speed at the corner whenever the ratio chain fails, which a C1 edge cannot follow.
Result<detail::LsJoinOutcome> lsOntoNeighbours(const Model& m, int mover, Edge moverEdge,
                                               const std::vector<std::pair<int, Edge>>& fixed, const Vec3& corner,
                                               const Setup& st, std::vector<std::string>& notes) {
  const Patch& S = m.patches[static_cast<size_t>(mover)];
  struct Part {
    detail::JoinOverlap ov;
    bool reversed = false;
    BSplineSurface xf;
  };
  std::vector<Part> parts;
  for (const auto& [ix, ex] : fixed) {
    const Patch& X = m.patches[static_cast<size_t>(ix)];
    auto cur = analyzeSeam(S, moverEdge, X, ex, st.so);
    if (!cur) return cur.status().withContext(fmt::format("seam {}/{}", S.name, X.name));
    Part p;
    p.ov = detail::cornerSnappedOverlap(S.surface, moverEdge, X.surface, ex, cur->overlapA, cur->overlapB,
                                        cur->reversed, st.maxGap);
    p.reversed = cur->reversed;
    p.xf = detail::toEdgeFrame(X.surface, ex, cur->reversed);
    parts.push_back(std::move(p));
  }
  // The frame's along parameter of the target at S's parameter s on part p: c0 + c1 (s - ov.s.lo).
  auto c0Of = [](const Part& p) { return p.reversed ? -p.ov.t.hi : p.ov.t.lo; };
  BSplineSurface work = S.surface;
  if (parts.size() == 2) {
    Part& a = parts[0].ov.s.lo <= parts[1].ov.s.lo ? parts[0] : parts[1];
    Part& b = &a == &parts[0] ? parts[1] : parts[0];
    // Speeds of the two targets at the corner (the end of a's target range and the start of b's), per unit of their
    // frame parameter.
    const double ta = c0Of(a) + a.ov.t.length(), tb = c0Of(b);
    const double sa = v3of(a.xf.derivatives(ta, a.xf.domainV().lo, 1)[1][0]).norm();
    const double sb = v3of(b.xf.derivatives(tb, b.xf.domainV().lo, 1)[1][0]).norm();
    const double la = a.ov.t.length() * sa, lb = b.ov.t.length() * sb;
    const Interval R{a.ov.s.lo, b.ov.s.hi};
    if (la > 0.0 && lb > 0.0 && R.hi > R.lo) {
      const bool alongV = isUEdge(moverEdge);
      const KnotVector& kn = alongV ? work.knotsV() : work.knotsU();
      const int p = alongV ? work.degreeV() : work.degreeU();
      const double split = detail::snapToKnot(kn, R.lo + R.length() * la / (la + lb));
      a.ov.s = Interval{R.lo, split};
      b.ov.s = Interval{split, R.hi};
      // The composite target is only C1 at the split (two different surfaces meet there): the mover's edge needs a
      // knot of multiplicity p - 1 there (the least-squares join inserts the ends of a partial seam only once).
      const int have = static_cast<int>(std::count(kn.values().begin(), kn.values().end(), split));
      if (have < p - 1) {
        const std::vector<double> ins(static_cast<size_t>(p - 1 - have), split);
        work = alongV ? work.refinedV(ins) : work.refinedU(ins);
        notes.push_back(fmt::format("knot {:.9g} inserted {} time(s) where the two neighbours meet (exact)", split,
                                    ins.size()));
      }
    }
  }
  std::vector<detail::EdgeConstraint> cons;
  for (const Part& p : parts) {
    detail::EdgeConstraint c;
    c.edge = moverEdge;
    c.target = detail::targetFromFrame(p.xf, p.ov.s, c0Of(p), p.ov.t.length() / p.ov.s.length(), 1);
    const Interval du = work.domainU(), dv = work.domainV();
    auto endPoint = [&](double t) -> Vec3 {
      switch (moverEdge) {
        case Edge::U0: return work.evaluate(du.lo, t).head<3>();
        case Edge::U1: return work.evaluate(du.hi, t).head<3>();
        case Edge::V0: return work.evaluate(t, dv.lo).head<3>();
        case Edge::V1: return work.evaluate(t, dv.hi).head<3>();
      }
      return Vec3::Zero();
    };
    c.kappaZeroAtStart = (endPoint(p.ov.s.lo) - corner).norm() <= st.maxGap;
    c.kappaZeroAtEnd = (endPoint(p.ov.s.hi) - corner).norm() <= st.maxGap;
    cons.push_back(std::move(c));
  }
  detail::LsJoinOptions lo;
  lo.continuity = GeometricClass::kG1;
  lo.scale = st.diag;
  Result<detail::LsJoinOutcome> best = Status(ErrorCode::kNoSolution, "not run");
  for (int elevate = 0; elevate <= 2; ++elevate) {
    lo.elevate = elevate;
    auto r = detail::leastSquaresJoin(work, cons, lo);
    if (!r) return r;
    if (!best || r->residual < best->residual) best = r;
    if (r->feasible) {
      if (elevate > 0) notes.push_back(fmt::format("degree raised by {} (exact) for enough freedom", elevate));
      break;
    }
  }
  if (best && !best->feasible)
    notes.push_back(fmt::format("constraints not met exactly (residual {:.3g})", best->residual));
  for (const std::string& n : best->notes) notes.push_back(n);
  return best;
}

bool isFold(const SeamReport& r) {
  const bool lambdaKnown = !(r.lambdaRange.lo == 0.0 && r.lambdaRange.hi == 0.0);
  return r.g1SampledDeg >= kFoldAngleDeg || (lambdaKnown && r.lambdaRange.lo <= 0.0);
}

// What the joins made worse on a seam, in plain words ("" when nothing): the certified values after against those
// of the input (the same rule as joinSeam and healModel).
std::string worseThan(const SeamReport& now, const SeamReport& ref, const Tolerances& tol) {
  std::vector<std::string> why;
  if (now.g0Max > ref.g0Max + tol.distance)
    why.push_back(fmt::format("the gap would grow from {:.6g} to {:.6g}", ref.g0Max, now.g0Max));
  if (now.g1MaxDeg > ref.g1MaxDeg + tol.angleDeg)
    why.push_back(fmt::format("the kink angle would grow from {:.6g} to {:.6g} degrees", ref.g1MaxDeg, now.g1MaxDeg));
  if (static_cast<int>(now.geometric) < static_cast<int>(ref.geometric))
    why.push_back(fmt::format("it would drop from {} to {}", toString(ref.geometric), toString(now.geometric)));
  if (isFold(now) && !isFold(ref))
    why.push_back(fmt::format("it would fold (the tangent planes turn over: {:.4g} degrees, lambda down to {:.4g})",
                              now.g1SampledDeg, now.lambdaRange.lo));
  if (ref.certified && !now.certified) why.push_back("its values would no longer be certified");
  std::string out;
  for (const std::string& w : why) out += (out.empty() ? "" : "; ") + w;
  return out;
}

bool samePatch(const Patch& a, const Patch& b) {
  return a.surface.degreeU() == b.surface.degreeU() && a.surface.degreeV() == b.surface.degreeV() &&
         a.surface.knotsU().values() == b.surface.knotsU().values() &&
         a.surface.knotsV().values() == b.surface.knotsV().values() && a.surface.points() == b.surface.points() &&
         a.surface.weights() == b.surface.weights();
}

std::string seamName(const CornerSeam& s) {
  return fmt::format("{}:{} / {}:{}", s.a, edgeName(s.aEdge), s.b, edgeName(s.bEdge));
}

// The verdict on the corner: every seam after against the input; any seam worse undoes every join (`out` becomes
// the input). Then the displacements of what stays.
void finishReport(const Model& input, Model& out, const std::vector<CornerSeam>& seams, const Setup& st,
                  CornerJoinReport& rep) {
  rep.seams = seams;
  std::string why;
  for (CornerSeam& s : rep.seams) {
    if (!s.before) continue;
    s.worseWhy = worseThan(s.after, *s.before, st.tol);
    s.worse = !s.worseWhy.empty();
    if (s.worse) {
      ++rep.seamsWorse;
      why += fmt::format("{}seam {}: {}", why.empty() ? "" : "; ", seamName(s), s.worseWhy);
    }
  }
  rep.reverted = rep.seamsWorse > 0;
  if (rep.reverted) {
    out = input;
    for (CornerSeam& s : rep.seams) {
      if (s.before) {
        s.after = *s.before;
        s.achieved = meets(s.after.geometric, GeometricClass::kG1);
      } else {
        s.achieved = false;  // the input's seam could not be analysed: nothing to claim for it
      }
    }
    rep.notes.push_back(fmt::format("the corner join is undone and the input returned unchanged, since it would make "
                                    "{} seam(s) worse: {}",
                                    rep.seamsWorse, why));
  }
  rep.achieved = !rep.reverted;
  for (const CornerSeam& s : rep.seams) {
    rep.achieved = rep.achieved && s.achieved;
    rep.worstG0 = std::max(rep.worstG0, s.after.g0Max);
    rep.worstG1Deg = std::max(rep.worstG1Deg, s.after.g1MaxDeg);
  }
  for (size_t i = 0; i < input.patches.size(); ++i) {
    const Patch& p0 = input.patches[i];
    const Patch& p1 = out.patches[i];
    if (samePatch(p0, p1)) continue;
    const Displacement d = controlPointDisplacement(p0.surface, p1.surface, kRoundoff * st.diag);
    rep.maxDisplacement = std::max(rep.maxDisplacement, d.max);
    const SurfaceDisplacement sd = surfaceDisplacement(p0.surface, p1.surface);
    rep.maxSurfaceDisplacement = std::max(rep.maxSurfaceDisplacement, sd.bound);
    rep.maxSurfaceDisplacementSampled = std::max(rep.maxSurfaceDisplacementSampled, sd.sampled);
    const double size = controlBox(p0.surface).diagonal();
    if (size > 0.0) rep.maxSurfaceDisplacementRel = std::max(rep.maxSurfaceDisplacementRel, sd.bound / size);
  }
}

// The seam between edge ea of patch a and eb of patch b (indices into both models): before in the input (plain
// analysis), after in `m` (span by span when `pieceBreaks` are given).
Result<CornerSeam> seamAfter(const Model& input, const Model& m, int a, Edge ea, int b, Edge eb, const Setup& st,
                             std::vector<std::string>& notes, const std::vector<double>& pieceBreaks = {}) {
  const Patch& A = m.patches[static_cast<size_t>(a)];
  const Patch& B = m.patches[static_cast<size_t>(b)];
  auto r = pieceBreaks.size() >= 3 ? analyzeSeamPiecewise(A, ea, B, eb, st.so, pieceBreaks)
                                   : analyzeSeam(A, ea, B, eb, st.so);
  if (!r) return r.status().withContext(fmt::format("seam {}:{} / {}:{} after the joins", A.name, edgeName(ea), B.name,
                                                    edgeName(eb)));
  CornerSeam s;
  s.a = A.name;
  s.b = B.name;
  s.aEdge = ea;
  s.bEdge = eb;
  s.after = *r;
  s.achieved = meets(r->geometric, GeometricClass::kG1);
  auto before = analyzeSeam(input.patches[static_cast<size_t>(a)], ea, input.patches[static_cast<size_t>(b)], eb, st.so);
  if (before) {
    s.before = *before;
  } else {
    notes.push_back(fmt::format("seam {}: no analysis of the input ({}), so it cannot be compared with the result",
                                seamName(s), before.status().message()));
  }
  return s;
}

}  // namespace

const ConditionCheck* ThreePatchProportionality::find(CornerCondition c) const { return findCheck(checks, c); }
const ConditionCheck* FourPatchProportionality::find(CornerCondition c) const { return findCheck(checks, c); }

namespace {
/// The corner joins take method auto or bspline, and a fallback of bezier-strip or least-squares.
Status validMethods(const CornerJoinOptions& opt) {
  if (opt.method != JoinMethod::kAuto && opt.method != JoinMethod::kBSpline)
    return invalidInput("the corner join takes method auto or bspline (the fallback is chosen by `fallback`)");
  if (opt.fallback != JoinMethod::kBezierStrip && opt.fallback != JoinMethod::kLeastSquares)
    return invalidInput("the fallback is bezier-strip or least-squares");
  return Status::ok();
}
}  // namespace

Result<ThreePatchProportionality> checkThreePatchCorner(const Model& model, const ThreePatchCorner& corner,
                                                        const CornerJoinOptions& opt) {
  const Setup st = setupFor(model, opt);
  auto tf = threeFrames(model, corner, st);
  if (!tf) return tf.status();
  return proportionality3(model, corner, st, *tf, opt.proportionalTol);
}

Result<ThreePatchJoinResult> joinThreePatchCorner(const Model& model, const ThreePatchCorner& c,
                                                  const CornerJoinOptions& opt) {
  if (Status st = validMethods(opt); !st) return st;
  const Setup st = setupFor(model, opt);
  auto tfr = threeFrames(model, c, st);
  if (!tfr) return tfr.status();
  const ThreeFrames& tf = *tfr;
  ThreePatchJoinResult res;
  res.model = model;
  res.model.brep.reset();  // the patches change: the trims would not follow (Model::brep)
  CornerJoinReport& rep = res.report;
  auto prop = proportionality3(model, c, st, tf, opt.proportionalTol);
  if (!prop) {
    if (prop.status().code() != ErrorCode::kUnsupported || opt.method == JoinMethod::kBSpline) return prop.status();
    rep.notes.push_back(prop.status().message() + "; both joins are least squares");
  } else {
    res.proportionality = *prop;
    if (opt.method == JoinMethod::kBSpline && !prop->theorem1ForHat) {
      std::string failing;
      for (const ConditionCheck& k : prop->checks)
        if (!k.holds) failing += fmt::format("{}{} (residual {:.3g}: {})", failing.empty() ? "" : "; ",
                                             toString(k.condition), k.residual, k.detail);
      if (failing.empty()) failing = prop->notes.empty() ? "S^'s edge has no common corner" : prop->notes.front();
      return Status(ErrorCode::kNoSolution, "Theorem 1 through the corner needs every §4.1 condition: " + failing);
    }
  }
  const bool c1 = prop.isOk();
  const double moveThreshold = kRoundoff * st.diag;

  // ---- join 1: S onto S~.
  {
    const Patch& S = model.patches[static_cast<size_t>(tf.is)];
    const Patch& T = model.patches[static_cast<size_t>(tf.it)];
    auto before = analyzeSeam(S, c.sToTilde, T, c.tildeToS, st.so);
    if (!before) return before.status();
    if (before->g0Max > st.maxGap)
      return invalidInput(fmt::format("the edges {}:{} and {}:{} are {:.6g} apart, above the gap limit {:.6g}", S.name,
                                      edgeName(c.sToTilde), T.name, edgeName(c.tildeToS), before->g0Max, st.maxGap));
    const bool useT1 = c1 && prop->find(CornerCondition::kUProportional)->holds;
    CornerJoinStep step;
    if (useT1) {
      auto r = theorem1Join(tf.fs.f, tf.ft.f);
      if (!r) return r.status();
      res.model.patches[static_cast<size_t>(tf.is)] =
          detail::replacedSurface(S, detail::fromEdgeFrame(r->surface, c.sToTilde, tf.fs.flip));
      step = stepFor(model, res.model, {tf.is}, {tf.it}, moveThreshold);
      step.method = JoinMethod::kBSpline;
      step.reason = fmt::format("condition (a) holds (u proportional to u~, Def. 3.1): Theorem 1, case {}",
                                toString(r->spanCase));
    } else {
      bool strip = false;
      if (c1 && opt.fallback == JoinMethod::kBezierStrip) {
        JoinOptions jo;
        jo.method = JoinMethod::kBezierStrip;
        jo.maxGap = st.maxGap;
        jo.tolerances = st.tol;
        jo.seam = opt.seam;
        auto r = joinSeam(model, S.name, c.sToTilde, T.name, c.tildeToS, jo);
        if (r) {
          res.model = r->model;
          step.notes = r->report.notes;
          strip = true;
        } else if (r.status().code() == ErrorCode::kUnsupported) {
          rep.notes.push_back("Algorithm 3.3 does not apply to S/S~ (" + r.status().message() + "): least squares");
        } else {
          return r.status();
        }
      }
      if (!strip) {
        // Least squares with kappa = 0 at the corner, so that S^ can later meet S* and S~ with one smooth edge.
        std::vector<std::string> notes;
        auto r = lsOntoNeighbours(model, tf.is, c.sToTilde, {{tf.it, c.tildeToS}}, cornerPoint(tf.fs.f), st, notes);
        if (!r) return r.status();
        res.model.patches[static_cast<size_t>(tf.is)] = detail::replacedSurface(S, r->surface);
        step.notes = notes;
      }
      const std::vector<std::string> keep = step.notes;
      step = stepFor(model, res.model, {tf.is}, {tf.it}, moveThreshold);
      step.notes = keep;
      step.method = strip ? JoinMethod::kBezierStrip : JoinMethod::kLeastSquares;
      step.reason = (c1 ? std::string("condition (a) fails (u not proportional to u~): ")
                        : std::string("not C1 bicubic: ")) +
                    (strip ? "Algorithm 3.3 (the paper's fallback)"
                           : "the general least-squares join (kappa = 0 at the corner)");
    }
    rep.steps.push_back(step);
  }

  // ---- join 2: S^ onto S* u S~.
  {
    const Model afterJoin1 = res.model;
    CornerJoinStep step;
    bool done = false;
    if (c1 && prop->theorem1ForHat && rep.steps.front().method == JoinMethod::kBSpline) {
      const BSplineSurface& Sstar = afterJoin1.patches[static_cast<size_t>(tf.is)].surface;
      const BSplineSurface& T = afterJoin1.patches[static_cast<size_t>(tf.it)].surface;
      auto gs = frameFromCorner(Sstar, c.sToHat, c.sToTilde, "S");
      auto gt = frameFromCorner(T, c.tildeToHat, c.tildeToS, "S~");
      if (!gs || !gt) return gs ? gt.status() : gs.status();
      const bool forward = prop->cornerIndex == prop->nTilde;
      const BSplineSurface comp = forward ? compoundTarget(gt->f, gs->f) : compoundTarget(gs->f, gt->f);
      const bool flipH = forward ? tf.flipH : !tf.flipH;
      const BSplineSurface fh = detail::toEdgeFrame(afterJoin1.patches[static_cast<size_t>(tf.ih)].surface, c.hatEdge,
                                                    flipH);
      auto r = theorem1Join(fh, comp);
      if (r) {
        res.model.patches[static_cast<size_t>(tf.ih)] = detail::replacedSurface(
            afterJoin1.patches[static_cast<size_t>(tf.ih)], detail::fromEdgeFrame(r->surface, c.hatEdge, flipH));
        step = stepFor(afterJoin1, res.model, {tf.ih}, {tf.is, tf.it}, moveThreshold);
        step.method = JoinMethod::kBSpline;
        step.reason = fmt::format("every §4.1 condition holds: Theorem 1 onto the compound S* u S~ (one C1 bicubic "
                                  "B-spline along S^), case {}",
                                  toString(r->spanCase));
        done = true;
      } else {
        rep.notes.push_back("Theorem 1 onto the compound failed (" + r.status().message() + "): least squares");
      }
    }
    if (!done) {
      std::vector<std::string> notes;
      auto r = lsOntoNeighbours(afterJoin1, tf.ih, c.hatEdge, {{tf.is, c.sToHat}, {tf.it, c.tildeToHat}},
                                cornerPoint(tf.fs.f), st, notes);
      if (!r) return r.status();
      res.model.patches[static_cast<size_t>(tf.ih)] =
          detail::replacedSurface(afterJoin1.patches[static_cast<size_t>(tf.ih)], r->surface);
      step = stepFor(afterJoin1, res.model, {tf.ih}, {tf.is, tf.it}, moveThreshold);
      step.method = JoinMethod::kLeastSquares;
      step.reason = !c1 ? "not C1 bicubic: least squares onto S and S~ at once"
                        : (rep.steps.front().method != JoinMethod::kBSpline
                               ? "S* u S~ is not one C1 bicubic B-spline (S joined by the fallback): the union is "
                                 "joined by least squares onto both at once, as the paper's fallback"
                               : "a §4.1 condition fails for S^ (see the report): least squares onto S* and S~ at once");
      step.notes = notes;
    }
    rep.steps.push_back(step);
  }

  // ---- the verdict on the three seams.
  std::vector<CornerSeam> seams;
  std::vector<double> pieceBreaks;
  if (rep.steps.front().method == JoinMethod::kBezierStrip) {
    const BSplineSurface fsOwn = detail::toEdgeFrame(model.patches[static_cast<size_t>(tf.is)].surface, c.sToTilde,
                                                     false);
    pieceBreaks = fsOwn.knotsU().breakpoints();
  }
  auto s1 = seamAfter(model, res.model, tf.is, c.sToTilde, tf.it, c.tildeToS, st, rep.notes, pieceBreaks);
  if (!s1) return s1.status();
  seams.push_back(*s1);
  for (const auto& [ix, ex] : std::vector<std::pair<int, Edge>>{{tf.is, c.sToHat}, {tf.it, c.tildeToHat}}) {
    auto s = seamAfter(model, res.model, ix, ex, tf.ih, c.hatEdge, st, rep.notes);
    if (!s) return s.status();
    seams.push_back(*s);
  }
  finishReport(model, res.model, seams, st, rep);
  return res;
}

// ---------------------------------------------------------------------------------------------------------------------
// Four surfaces.
// ---------------------------------------------------------------------------------------------------------------------

namespace {

struct FourFrames {
  std::array<int, 4> idx{};
  std::array<CornerFrame, 4> pairFrame;  // S1, S2 from the S1/S2 seam, S3, S4 from the S3/S4 seam, along from the corner
};

Result<FourFrames> fourFrames(const Model& model, const FourPatchCorner& c, const Setup& st) {
  FourFrames ff;
  for (int k = 0; k < 4; ++k) {
    auto i = indexOf(model, c.patches[static_cast<size_t>(k)]);
    if (!i) return i.status();
    ff.idx[static_cast<size_t>(k)] = *i;
  }
  for (int a = 0; a < 4; ++a)
    for (int b = a + 1; b < 4; ++b)
      if (ff.idx[static_cast<size_t>(a)] == ff.idx[static_cast<size_t>(b)])
        return invalidInput("the four corner patches must be different patches");
  // S1 and S3 are seen from their toNext edge, S2 and S4 from their toPrev edge.
  for (int k = 0; k < 4; ++k) {
    const Patch& p = model.patches[static_cast<size_t>(ff.idx[static_cast<size_t>(k)])];
    if (p.surface.dim() != 3) return invalidInput(fmt::format("patch \"{}\" is not 3-D", p.name));
    const Edge e = (k % 2 == 0) ? c.toNext[static_cast<size_t>(k)] : c.toPrev[static_cast<size_t>(k)];
    const Edge o = (k % 2 == 0) ? c.toPrev[static_cast<size_t>(k)] : c.toNext[static_cast<size_t>(k)];
    auto f = frameFromCorner(p.surface, e, o, p.name);
    if (!f) return f.status();
    ff.pairFrame[static_cast<size_t>(k)] = *f;
  }
  const Vec3 p0 = cornerPoint(ff.pairFrame[0].f);
  for (int k = 1; k < 4; ++k) {
    const double d = (cornerPoint(ff.pairFrame[static_cast<size_t>(k)].f) - p0).norm();
    if (d > st.maxGap)
      return invalidInput(fmt::format("the corners of \"{}\" and \"{}\" at the vertex are {:.6g} apart, above the gap "
                                      "limit {:.6g}: these edges do not meet at one vertex",
                                      c.patches[0], c.patches[static_cast<size_t>(k)], d, st.maxGap));
  }
  return ff;
}

Result<FourPatchProportionality> proportionality4(const Model& model, const FourFrames& ff, double ptol) {
  for (int i : ff.idx) {
    const Patch& p = model.patches[static_cast<size_t>(i)];
    if (Status s = checkC1Bicubic(p.surface); !s)
      return Status(ErrorCode::kUnsupported,
                    fmt::format("the §4.1 conditions are defined for C1 bicubic B-splines; \"{}\" is not: {}", p.name,
                                s.message()));
  }
  FourPatchProportionality r;
  const BSplineSurface &F1 = ff.pairFrame[0].f, &F2 = ff.pairFrame[1].f, &F3 = ff.pairFrame[2].f,
                       &F4 = ff.pairFrame[3].f;
  r.checks.push_back(proportionalCheck(CornerCondition::kPair12Proportional, F1.knotsU(), F2.knotsU(), ptol,
                                       "Def. 3.1 for S1, S2 along their shared edge from the vertex"));
  r.checks.push_back(equalSpansCheck(CornerCondition::kPair12EqualSpans, F1.knotsU(), F2.knotsU(), ptol,
                                     "equal spans of S1, S2 along their shared edge"));
  r.checks.push_back(proportionalCheck(CornerCondition::kPair34Proportional, F3.knotsU(), F4.knotsU(), ptol,
                                       "Def. 3.1 for S3, S4 along their shared edge from the vertex"));
  r.checks.push_back(equalSpansCheck(CornerCondition::kPair34EqualSpans, F3.knotsU(), F4.knotsU(), ptol,
                                     "equal spans of S3, S4 along their shared edge"));
  // The compound seam: across knots of the pair frames run along it from the vertex. S4 faces S1, S3 faces S2.
  auto addRatios = [&](const BSplineSurface& mover, const BSplineSurface& fixed) {
    const std::vector<double> hm = spans(mover.knotsV().breakpoints()), hf = spans(fixed.knotsV().breakpoints());
    for (size_t i = 0; i < std::min(hm.size(), hf.size()); ++i) r.chainRatios.push_back(hm[i] / hf[i]);
  };
  addRatios(F4, F1);
  addRatios(F3, F2);
  r.checks.push_back(chainCheck(CornerCondition::kCompoundChain, r.chainRatios, ptol,
                                "span_i(S4) / span_i(S1) = span_i(S3) / span_i(S2) = const along the compound seam"));
  r.allHold = std::all_of(r.checks.begin(), r.checks.end(), [](const ConditionCheck& k) { return k.holds; });
  return r;
}

}  // namespace

Result<FourPatchProportionality> checkFourPatchCorner(const Model& model, const FourPatchCorner& corner,
                                                      const CornerJoinOptions& opt) {
  const Setup st = setupFor(model, opt);
  auto ff = fourFrames(model, corner, st);
  if (!ff) return ff.status();
  return proportionality4(model, *ff, opt.proportionalTol);
}

Result<FourPatchJoinResult> joinFourPatchCorner(const Model& model, const FourPatchCorner& c,
                                                const CornerJoinOptions& opt) {
  if (Status st = validMethods(opt); !st) return st;
  const Setup st = setupFor(model, opt);
  auto ffr = fourFrames(model, c, st);
  if (!ffr) return ffr.status();
  const FourFrames& ff = *ffr;
  FourPatchJoinResult res;
  res.model = model;
  res.model.brep.reset();  // the patches change: the trims would not follow (Model::brep)
  CornerJoinReport& rep = res.report;
  auto prop = proportionality4(model, ff, opt.proportionalTol);
  if (!prop) {
    if (prop.status().code() != ErrorCode::kUnsupported || opt.method == JoinMethod::kBSpline) return prop.status();
    rep.notes.push_back(prop.status().message() + "; the joins are least squares");
  } else {
    res.proportionality = *prop;
    if (opt.method == JoinMethod::kBSpline && !prop->allHold) {
      std::string failing;
      for (const ConditionCheck& k : prop->checks)
        if (!k.holds) failing += fmt::format("{}{} (residual {:.3g}: {})", failing.empty() ? "" : "; ",
                                             toString(k.condition), k.residual, k.detail);
      return Status(ErrorCode::kNoSolution, "Theorem 1 at the vertex needs every condition: " + failing);
    }
  }
  const bool c1 = prop.isOk();
  const double moveThreshold = kRoundoff * st.diag;
  const auto I = [&](int k) { return ff.idx[static_cast<size_t>(k)]; };
  const auto P = [&](const Model& m, int k) -> const Patch& { return m.patches[static_cast<size_t>(I(k))]; };
  for (int k = 0; k < 4; ++k) {
    const int k1 = (k + 1) % 4;
    auto b = analyzeSeam(P(model, k), c.toNext[static_cast<size_t>(k)], P(model, k1), c.toPrev[static_cast<size_t>(k1)],
                         st.so);
    if (!b) return b.status();
    if (b->g0Max > st.maxGap)
      return invalidInput(fmt::format("the edges of \"{}\" and \"{}\" are {:.6g} apart, above the gap limit {:.6g}",
                                      P(model, k).name, P(model, k1).name, b->g0Max, st.maxGap));
  }

  // Theorem 1 of one patch onto a fixed one, both seen from the vertex (edges through it).
  auto t1 = [&](Model& m, int mover, Edge me, Edge mo, int fixed, Edge fe, Edge fo) -> Status {
    auto fm = frameFromCorner(P(m, mover).surface, me, mo, P(m, mover).name);
    auto fx = frameFromCorner(P(m, fixed).surface, fe, fo, P(m, fixed).name);
    if (!fm) return fm.status();
    if (!fx) return fx.status();
    auto r = theorem1Join(fm->f, fx->f);
    if (!r) return r.status();
    m.patches[static_cast<size_t>(I(mover))] =
        detail::replacedSurface(P(m, mover), detail::fromEdgeFrame(r->surface, me, fm->flip));
    return Status::ok();
  };
  const auto& N = c.toNext;
  const auto& Pv = c.toPrev;
  std::vector<std::pair<int, int>> pairs{{1, 0}, {3, 2}};  // (mover, fixed)
  for (const auto& [mv, fx] : pairs) {
    const CornerCondition pc = mv == 1 ? CornerCondition::kPair12Proportional : CornerCondition::kPair34Proportional;
    const Model before = res.model;
    CornerJoinStep step;
    // S2's edge against S1 is toPrev[1]; S4's against S3 is toPrev[3]; S1's and S3's are toNext.
    if (c1 && prop->find(pc)->holds) {
      if (Status s = t1(res.model, mv, Pv[static_cast<size_t>(mv)], N[static_cast<size_t>(mv)], fx,
                        N[static_cast<size_t>(fx)], Pv[static_cast<size_t>(fx)]);
          !s)
        return s;
      step = stepFor(before, res.model, {I(mv)}, {I(fx)}, moveThreshold);
      step.method = JoinMethod::kBSpline;
      step.reason = "the pair is proportional (Def. 3.1): Theorem 1";
    } else {
      JoinOptions jo;
      jo.method = (c1 && opt.fallback == JoinMethod::kBezierStrip) ? JoinMethod::kBezierStrip
                                                                     : JoinMethod::kLeastSquares;
      jo.maxGap = st.maxGap;
      jo.tolerances = st.tol;
      jo.seam = opt.seam;
      auto r = joinSeam(res.model, P(res.model, mv).name, Pv[static_cast<size_t>(mv)], P(res.model, fx).name,
                        N[static_cast<size_t>(fx)], jo);
      if (!r && jo.method == JoinMethod::kBezierStrip && r.status().code() == ErrorCode::kUnsupported) {
        jo.method = JoinMethod::kLeastSquares;
        r = joinSeam(res.model, P(res.model, mv).name, Pv[static_cast<size_t>(mv)], P(res.model, fx).name,
                     N[static_cast<size_t>(fx)], jo);
      }
      if (!r) return r.status();
      res.model = r->model;
      step = stepFor(before, res.model, {I(mv)}, {I(fx)}, moveThreshold);
      step.method = r->report.method;
      step.reason = std::string(c1 ? "the pair is not proportional: " : "not C1 bicubic: ") +
                    (step.method == JoinMethod::kBezierStrip ? "Algorithm 3.3" : "the general least-squares join");
      step.notes = r->report.notes;
    }
    rep.steps.push_back(step);
  }

  // The compounds: S3 u S4 onto S1 u S2.
  {
    const Model before = res.model;
    CornerJoinStep step;
    const bool theorem1 = c1 && prop->allHold && rep.steps[0].method == JoinMethod::kBSpline &&
                          rep.steps[1].method == JoinMethod::kBSpline;
    bool done = false;
    if (theorem1) {
      // S3 onto S2 (S3's toPrev, S2's toNext) and S4 onto S1 (S4's toNext, S1's toPrev): with the conditions this is
      // Theorem 1 on the compounds (docs §5), so S3 and S4 stay C1 to each other.
      Model m = res.model;
      Status s = t1(m, 2, Pv[2], N[2], 1, N[1], Pv[1]);
      if (s) s = t1(m, 3, N[3], Pv[3], 0, Pv[0], N[0]);
      if (s) {
        res.model = m;
        step = stepFor(before, res.model, {I(2), I(3)}, {I(0), I(1)}, moveThreshold);
        step.method = JoinMethod::kBSpline;
        step.reason = "every condition holds: Theorem 1 of the compound S3 u S4 onto S1 u S2";
        done = true;
      } else {
        rep.notes.push_back("Theorem 1 on the compounds failed (" + s.message() + "): healModel");
      }
    }
    if (!done) {
      Model sub;
      for (int k = 0; k < 4; ++k) sub.patches.push_back(P(res.model, k));
      HealOptions ho;
      ho.maxGap = st.maxGap;
      ho.tolerances = st.tol;
      ho.seam = opt.seam;
      auto h = healModel(sub, ho);
      if (!h) return h.status();
      for (int k = 0; k < 4; ++k) res.model.patches[static_cast<size_t>(I(k))] = h->model.patches[static_cast<size_t>(k)];
      std::vector<int> moved, fixed;
      for (int k = 0; k < 4; ++k) {
        const bool changed = std::find(h->report.patchesChanged.begin(), h->report.patchesChanged.end(),
                                       P(res.model, k).name) != h->report.patchesChanged.end();
        (changed ? moved : fixed).push_back(I(k));
      }
      step = stepFor(before, res.model, moved, fixed, moveThreshold);
      step.method = JoinMethod::kLeastSquares;
      step.reason = c1 ? "a condition fails (see the report): the compounds are joined by healModel (least squares, "
                         "each patch once onto its settled neighbours)"
                       : "not C1 bicubic: healModel";
      step.notes = h->report.notes;
    }
    rep.steps.push_back(step);
  }

  std::vector<CornerSeam> seams;
  for (int k = 0; k < 4; ++k) {
    const int k1 = (k + 1) % 4;
    // A pair joined by the Bezier strip corresponds span by span (piecewise affine): analysed span by span.
    std::vector<double> breaks;
    const bool pairSeam = k == 0 || k == 2;
    if (pairSeam && rep.steps[static_cast<size_t>(k / 2)].method == JoinMethod::kBezierStrip)
      breaks = detail::toEdgeFrame(P(res.model, k).surface, N[static_cast<size_t>(k)], false).knotsU().breakpoints();
    auto s = seamAfter(model, res.model, I(k), N[static_cast<size_t>(k)], I(k1), Pv[static_cast<size_t>(k1)], st,
                       rep.notes, breaks);
    if (!s) return s.status();
    seams.push_back(*s);
  }
  finishReport(model, res.model, seams, st, rep);
  return res;
}

}  // namespace seam
