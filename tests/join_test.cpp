// Tests of joinSeam (include/seam/repair/join.h) and of `seam join`: the general least-squares join (any
// degree, knots, rational, G0/G1/G2, --average, --max-gap), the paper's methods through arbitrary edge
// orientations, and the command line.
//
// Every join is verified twice: by the certified referee (analyzeSeam: certified and G1 or better) and by the
// dense reference of seam_test_support.h (closest-point correspondence, kernel derivatives only). Patches
// that were not asked to move must be bit-identical; the part of a moved patch beyond the moved rows must be
// geometrically unchanged (evaluated). Expected values never come from the code under test.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "seam/continuity/seam.h"
#include "seam/io/json.h"
#include "seam/repair/bicubic.h"
#include "seam/repair/join.h"
#include "seam_test_support.h"
#include "test_helpers.h"

namespace seam {
namespace {

using seamtest::Rng;
using seamtest::c1Graph;
using seamtest::urand;

/// Joins exact to round-off: 1e-6 degrees (analyzeSeam's own default tolerance is 0.01 degrees).
constexpr double kExactAngleDeg = 1e-6;
/// Gap after a join relative to the patch size.
constexpr double kExactGapRel = 1e-9;
/// G2 joins: the curvature jump relative to the curvature scale (second derivatives lose ~2 digits).
constexpr double kExactCurvatureRel = 1e-6;
/// Unmodified region: same surface up to round-off of knot insertion / elevation (relative to the patch
/// size).
constexpr double kUnchangedRel = 1e-10;
/// Dense reference samples per seam.
constexpr int kDenseSamples = 1500;

/// Join options with the referee subdividing only until its bounds are within 25 % of the sampled worst values (the
/// curvature bounds of G1 seams are the expensive part of the analysis and are not what these tests check).
JoinOptions opts() {
  JoinOptions o;
  o.seam.boundRelGap = 0.25;
  o.seam.maxSubdivisionDepth = 12;
  return o;
}

bool atLeast(GeometricClass c, GeometricClass want) { return static_cast<int>(c) >= static_cast<int>(want); }

double sizeOf(const BSplineSurface& s) { return std::max(seamtest::patchScale(s), 1e-300); }

Patch patch(const std::string& name, BSplineSurface s) {
  return Patch{name, PatchKind::kBSpline, std::move(s)};
}

/// Re-orients a surface so that its edge V0 (at v_min, along u) becomes edge `e`, u running forwards or
/// backwards.
BSplineSurface orientEdge(const BSplineSurface& s, Edge e, bool reverseAlong) {
  BSplineSurface r = reverseAlong ? s.reversedU() : s;
  switch (e) {
    case Edge::V0:
      return r;
    case Edge::V1:
      return r.reversedV();
    case Edge::U0:
      return r.swappedUV();
    case Edge::U1:
      return r.swappedUV().reversedU();
  }
  return r;
}

/// Random gap and kink: rows 0 and 1 of edge `e` moved by up to `amp` (and row 2 for G2 cases).
BSplineSurface perturbNearEdge(Rng& rng, const BSplineSurface& s, Edge e, int rows, double amp) {
  Matrix p = s.points();
  for (int i = 0; i < s.numU(); ++i)
    for (int j = 0; j < s.numV(); ++j) {
      int depth = 0;
      switch (e) {
        case Edge::U0:
          depth = i;
          break;
        case Edge::U1:
          depth = s.numU() - 1 - i;
          break;
        case Edge::V0:
          depth = j;
          break;
        case Edge::V1:
          depth = s.numV() - 1 - j;
          break;
      }
      if (depth < rows)
        for (int c = 0; c < 3; ++c) p(i * s.numV() + j, c) += urand(rng, -amp, amp);
    }
  return BSplineSurface(s.degreeU(), s.degreeV(), s.knotsU(), s.knotsV(), s.numU(), s.numV(), std::move(p),
                        s.weights());
}

/// The box of parameters that rows 0..K of edge e cannot reach.
std::pair<Interval, Interval> unchangedBox(const BSplineSurface& s, Edge e, int K) {
  Interval u = s.domainU(), v = s.domainV();
  const auto& ku = s.knotsU().values();
  const auto& kv = s.knotsV().values();
  switch (e) {
    case Edge::U0:
      u.lo = ku[static_cast<size_t>(s.degreeU() + K + 1)];
      break;
    case Edge::U1:
      u.hi = ku[static_cast<size_t>(s.numU() - 1 - K)];
      break;
    case Edge::V0:
      v.lo = kv[static_cast<size_t>(s.degreeV() + K + 1)];
      break;
    case Edge::V1:
      v.hi = kv[static_cast<size_t>(s.numV() - 1 - K)];
      break;
  }
  return {u, v};
}

double maxDistanceOn(const BSplineSurface& a, const BSplineSurface& b, Interval u, Interval v, int n = 20) {
  double worst = 0.0;
  if (!(u.hi > u.lo) || !(v.hi > v.lo)) return 0.0;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) {
      const double x = u.lo + u.length() * i / n, y = v.lo + v.length() * j / n;
      worst = std::max(worst, (test::refSurfacePoint(a, x, y) - test::refSurfacePoint(b, x, y)).norm());
    }
  return worst;
}

struct Case {
  Model model;
  Edge moveEdge = Edge::V0, toEdge = Edge::V0;
};

/// Two halves of one random graph surface F (split at v = k): "T" below, "S" above; S is then re-degreed /
/// refined as asked, both are re-oriented so that the seam edges are random edges, and S's rows near the seam
/// are perturbed (a gap and a kink of size ~amp). A third patch "X" far away checks bit-identity.
Case makeCase(Rng& rng, int pu, int pv, bool rational, int elevateS, int elevateT, int extraKnotsS, int rows,
              double ampRel) {
  const int nu = pu + 1 + seamtest::irand(rng, 1, 3), nv = pv + 1 + seamtest::irand(rng, 2, 4);
  const BSplineSurface F = seamtest::randomGraphSurface(rng, pu, pv, nu, nv, rational);
  const std::vector<double> iv = seamtest::interiorKnots(F.knotsV(), pv);
  const double k = iv.empty() ? 0.5 : iv[iv.size() / 2];
  auto [lower, upper] = seamtest::splitV(F, k);
  BSplineSurface T = lower.reversedV();  // seam at v_min of both
  BSplineSurface S = upper;
  if (elevateS > 0) S = S.degreeElevated(elevateS, elevateS);
  if (elevateT > 0) T = T.degreeElevated(elevateT, elevateT);
  for (int x = 0; x < extraKnotsS; ++x)
    S = S.withKnotInsertedU(urand(rng, S.domainU().lo + 0.05, S.domainU().hi - 0.05));
  Case c;
  c.moveEdge = kAllEdges[static_cast<size_t>(seamtest::irand(rng, 0, 3))];
  c.toEdge = kAllEdges[static_cast<size_t>(seamtest::irand(rng, 0, 3))];
  const bool revS = seamtest::irand(rng, 0, 1) == 1, revT = seamtest::irand(rng, 0, 1) == 1;
  S = orientEdge(S, c.moveEdge, revS);
  T = orientEdge(T, c.toEdge, revT);
  S = perturbNearEdge(rng, S, c.moveEdge, rows, ampRel * sizeOf(S));
  c.model.patches.push_back(patch("T", T));
  c.model.patches.push_back(patch("S", S));
  c.model.patches.push_back(patch("X", seamtest::translated(F, Vec3(100.0, 0.0, 0.0))));
  return c;
}

/// The referee and the dense reference on the result; the bit-identity and unchanged-region checks.
/// `lastMovedRow`: the deepest row of the moved patch that the method may change (default: K = 0, 1, 2 for G0, G1,
/// G2; the Bezier strip of Algorithm 3.3 also irons rows 2 and 3, so only v >= v_6 is unchanged there).
void checkJoin(const Case& c, const JoinResult& r, GeometricClass want, bool tMayMove = false,
               int lastMovedRow = -1) {
  const Patch& S0 = c.model.patches[1];
  const Patch& S1 = r.model.patches[1];
  const Patch& T1 = r.model.patches[0];
  const double size = sizeOf(S0.surface);
  // Referee.
  EXPECT_TRUE(r.report.after.certified) << "after-analysis not certified";
  EXPECT_TRUE(atLeast(r.report.after.geometric, want)) << toString(r.report.after.geometric);
  EXPECT_TRUE(r.report.achieved);
  EXPECT_LE(r.report.after.g0Max, kExactGapRel * size);
  if (want != GeometricClass::kG0) {
    EXPECT_LE(r.report.after.g1MaxDeg, kExactAngleDeg);
  }
  // Independent dense evaluation (closest-point correspondence).
  seamtest::RefOptions ro;
  ro.samples = kDenseSamples;
  ro.g2 = want == GeometricClass::kG2;
  const seamtest::RefMeasures ref =
      seamtest::denseReference(S1.surface, c.moveEdge, T1.surface, c.toEdge, ro);
  EXPECT_LE(ref.g0, kExactGapRel * size);
  if (want != GeometricClass::kG0) {
    EXPECT_LE(ref.g1Deg, kExactAngleDeg);
    EXPECT_GT(ref.lambdaMin, 0.0) << "fold";
  }
  if (want == GeometricClass::kG2) {
    EXPECT_LE(ref.g2, kExactCurvatureRel * std::max(ref.curvScale, 1.0));
  }
  // Untouched patches bit-identical.
  EXPECT_TRUE(r.model.patches[2].surface.points() == c.model.patches[2].surface.points());
  EXPECT_EQ(r.model.patches[2].surface.knotsU().values(), c.model.patches[2].surface.knotsU().values());
  if (!tMayMove) {
    EXPECT_TRUE(T1.surface.points() == c.model.patches[0].surface.points()) << "T was not asked to move";
    EXPECT_EQ(T1.surface.knotsU().values(), c.model.patches[0].surface.knotsU().values());
  }
  // The moved patch is unchanged beyond the moved rows.
  const int K = lastMovedRow >= 0 ? lastMovedRow
                                  : (want == GeometricClass::kG2 ? 2 : (want == GeometricClass::kG1 ? 1 : 0));
  const auto [bu, bv] = unchangedBox(S1.surface, c.moveEdge, K);
  EXPECT_LE(maxDistanceOn(S0.surface, S1.surface, bu, bv), kUnchangedRel * size);
  EXPECT_GT(r.report.movedPoints, 0);
  EXPECT_GT(r.report.maxDisplacement, 0.0);
}

Result<JoinResult> join(const Case& c, const JoinOptions& o) {
  return joinSeam(c.model, "S", c.moveEdge, "T", c.toEdge, o);
}

// =====================================================================================================================

TEST(LeastSquaresJoin, RandomGapsAndKinksAnyOrientation) {
  Rng rng(1001);
  for (int trial = 0; trial < 10; ++trial) {
    const Case c = makeCase(rng, 3, 3, false, 0, 0, 0, 2, 0.01);
    JoinOptions o = opts();
    o.method = JoinMethod::kLeastSquares;
    auto r = join(c, o);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    EXPECT_EQ(r->report.method, JoinMethod::kLeastSquares);
    EXPECT_FALSE(atLeast(r->report.before.geometric, GeometricClass::kG1)) << "the case must start broken";
    checkJoin(c, *r, GeometricClass::kG1);
  }
}

/// Moves the middle control point of edge e (an interior point of the boundary row) by `offset`.
BSplineSurface withEdgeMidpointMoved(const BSplineSurface& s, Edge e, const Vec3& offset) {
  int i = s.numU() / 2, j = s.numV() / 2;
  switch (e) {
    case Edge::U0: i = 0; break;
    case Edge::U1: i = s.numU() - 1; break;
    case Edge::V0: j = 0; break;
    case Edge::V1: j = s.numV() - 1; break;
  }
  Matrix p = s.points();
  p.row(i * s.numV() + j) += offset.transpose();
  return BSplineSurface(s.degreeU(), s.degreeV(), s.knotsU(), s.knotsV(), s.numU(), s.numV(), std::move(p),
                        s.weights());
}

TEST(LeastSquaresJoin, DifferentDegreesAndKnots) {
  Rng rng(2002);
  for (int trial = 0; trial < 8; ++trial) {
    const int eS = trial % 2, eT = (trial / 2) % 2;  // S above or below T in degree
    Case c = makeCase(rng, seamtest::irand(rng, 2, 3), seamtest::irand(rng, 2, 3), false, eS, eT,
                      seamtest::irand(rng, 0, 2), 2, 0.01);
    if (eT > eS) {
      // T was degree-elevated from F, so its edge is still a curve of S's degree (elevation is exact) and S can
      // meet it without being raised. Moving one interior point of T's boundary row makes T's edge a genuine curve
      // of the higher degree, which S can only match after degree elevation.
      BSplineSurface& T = c.model.patches[0].surface;
      T = withEdgeMidpointMoved(T, c.toEdge, Vec3(0.0, 0.0, 0.005 * sizeOf(T)));
    }
    JoinOptions o = opts();
    auto r = join(c, o);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    checkJoin(c, *r, GeometricClass::kG1);
    if (eT > eS) {
      EXPECT_GT(r->report.elevatedU + r->report.elevatedV, 0) << "S must be raised to T's degree";
    }
  }
}

TEST(LeastSquaresJoin, RationalPatches) {
  Rng rng(3003);
  for (int trial = 0; trial < 6; ++trial) {
    const Case c = makeCase(rng, 2, seamtest::irand(rng, 2, 3), true, 0, 0, 0, 2, 0.01);
    JoinOptions o = opts();
    auto r = join(c, o);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    EXPECT_TRUE(r->model.patches[1].surface.isRational());
    checkJoin(c, *r, GeometricClass::kG1);
    const VecX& w = r->model.patches[1].surface.weights();
    EXPECT_GT(w.minCoeff(), 0.0);
  }
}

TEST(LeastSquaresJoin, G0AndG2) {
  Rng rng(4004);
  for (int trial = 0; trial < 6; ++trial) {
    const bool g2 = trial % 2 == 1;
    const Case c = makeCase(rng, seamtest::irand(rng, 3, 4), seamtest::irand(rng, 3, 5), false, 0, 0, 0,
                            g2 ? 3 : 1, 0.01);
    JoinOptions o = opts();
    o.continuity = g2 ? GeometricClass::kG2 : GeometricClass::kG0;
    auto r = join(c, o);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    checkJoin(c, *r, o.continuity);
    if (g2) {
      EXPECT_EQ(r->report.after.geometric, GeometricClass::kG2);
    }
  }
}

TEST(LeastSquaresJoin, AverageMovesBothToTheMiddle) {
  Rng rng(5005);
  for (int trial = 0; trial < 5; ++trial) {
    Case c = makeCase(rng, 3, 3, trial % 2 == 1, 0, 0, 0, 2, 0.01);
    JoinOptions o = opts();
    o.average = true;
    auto r = join(c, o);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    checkJoin(c, *r, GeometricClass::kG1, /*tMayMove=*/true);
    EXPECT_EQ(r->report.patchesChanged.size(), 2u);
    // Each side moves about half as far as it would if it alone did the whole join (S onto T, or T onto S).
    // (Not "less than the one-sided join of S": the middle tangent plane is each side turned by half the kink, so a
    // side's displacement scales with its own control legs across the seam, and T's may be several times S's.)
    JoinOptions one = opts();
    auto rS = joinSeam(c.model, "S", c.moveEdge, "T", c.toEdge, one);
    auto rT = joinSeam(c.model, "T", c.toEdge, "S", c.moveEdge, one);
    ASSERT_TRUE(rS.isOk());
    ASSERT_TRUE(rT.isOk());
    auto moved = [](const Patch& before, const Patch& after) {
      return controlPointDisplacement(before.surface, after.surface, 0.0).max;
    };
    const double avgS = moved(c.model.patches[1], r->model.patches[1]);
    const double avgT = moved(c.model.patches[0], r->model.patches[0]);
    const double oneS = moved(c.model.patches[1], rS->model.patches[1]);
    const double oneT = moved(c.model.patches[0], rT->model.patches[0]);
    EXPECT_GT(avgS, 0.0);
    EXPECT_GT(avgT, 0.0);
    EXPECT_LT(avgS, 0.75 * oneS) << "S: average " << avgS << ", alone " << oneS;
    EXPECT_LT(avgT, 0.75 * oneT) << "T: average " << avgT << ", alone " << oneT;
  }
}

TEST(LeastSquaresJoin, RefusesGapsAboveMaxGapAndBadOptions) {
  Rng rng(6006);
  Case c = makeCase(rng, 3, 3, false, 0, 0, 0, 2, 0.01);
  JoinOptions o = opts();
  o.maxGap = 1e-9;
  auto r = join(c, o);
  EXPECT_TRUE(test::failsMentioning(r.status(), {"max-gap", "gap limit"}));
  EXPECT_EQ(joinSeam(c.model, "nope", Edge::U0, "T", Edge::U0, opts()).status().code(), ErrorCode::kNotFound);
  JoinOptions e = opts();
  e.ell = 1.0;  // only for the strip
  EXPECT_EQ(join(c, e).status().code(), ErrorCode::kInvalidInput);
  JoinOptions b = opts();
  b.method = JoinMethod::kBSpline;  // random graph surfaces are not C1 bicubic
  EXPECT_EQ(join(c, b).status().code(), ErrorCode::kUnsupported);
}

// ---------------------------------------------------------------------------------------------------------------------
// The paper's methods through joinSeam (arbitrary edges and orientations).
// ---------------------------------------------------------------------------------------------------------------------

std::vector<double> randomBreaks(Rng& rng, int spans, double lo, double hi) {
  std::vector<double> b{lo};
  double acc = 0.0;
  std::vector<double> len(static_cast<size_t>(spans));
  double tot = 0.0;
  for (double& l : len) tot += (l = urand(rng, 0.4, 1.0));
  for (int k = 0; k + 1 < spans; ++k)
    b.push_back(lo + (hi - lo) * (acc += len[static_cast<size_t>(k)]) / tot);
  b.push_back(hi);
  return b;
}

/// Two halves of a C1 bicubic graph surface; S's net is put on new u-knots (proportional or not) and its rows
/// 0,1 perturbed. The seam starts at a common corner as the paper requires.
Case bicubicCase(Rng& rng, bool proportional) {
  const int m = seamtest::irand(rng, 2, 4);
  const std::vector<double> bu = randomBreaks(rng, m, 0.0, 1.0);
  std::vector<double> bv = randomBreaks(rng, 2, -1.0, 0.0);
  const std::vector<double> up = randomBreaks(rng, 2, 0.0, 1.0);
  bv.insert(bv.end(), up.begin() + 1, up.end());
  const BSplineSurface F = c1Graph(rng, bu, bv, 0.3);
  auto [lower, upper] = seamtest::splitV(F, 0.0);
  BSplineSurface T = lower.reversedV();
  std::vector<double> bs = bu;
  if (proportional) {
    for (double& x : bs) x = 3.0 * x - 1.0;  // an affine image of T's knots
  } else {
    bs = randomBreaks(rng, m, 0.0, 1.0);
  }
  BSplineSurface S(3, 3, c1CubicKnots(bs), upper.knotsV(), upper.numU(), upper.numV(), upper.points());
  Case c;
  c.moveEdge = kAllEdges[static_cast<size_t>(seamtest::irand(rng, 0, 3))];
  c.toEdge = kAllEdges[static_cast<size_t>(seamtest::irand(rng, 0, 3))];
  const bool rev = seamtest::irand(rng, 0, 1) == 1;
  S = perturbNearEdge(rng, S, Edge::V0, 2, 0.003 * sizeOf(S));
  S = orientEdge(S, c.moveEdge, rev);
  T = orientEdge(T, c.toEdge, rev);
  c.model.patches.push_back(patch("T", T));
  c.model.patches.push_back(patch("S", S));
  c.model.patches.push_back(patch("X", seamtest::translated(F, Vec3(50.0, 0.0, 0.0))));
  return c;
}

TEST(PaperJoin, AutoPicksTheorem1ForProportionalKnots) {
  Rng rng(7007);
  for (int trial = 0; trial < 6; ++trial) {
    const Case c = bicubicCase(rng, true);
    auto r = join(c, opts());
    ASSERT_TRUE(r.isOk()) << r.status().message();
    EXPECT_EQ(r->report.method, JoinMethod::kBSpline) << r->report.reason;
    ASSERT_TRUE(r->report.proportionalKnots.has_value());
    EXPECT_TRUE(*r->report.proportionalKnots);
    EXPECT_EQ(r->model.patches[1].surface.knotsU().values(), c.model.patches[1].surface.knotsU().values());
    EXPECT_EQ(r->model.patches[1].surface.knotsV().values(), c.model.patches[1].surface.knotsV().values());
    checkJoin(c, *r, GeometricClass::kG1);
  }
}

TEST(PaperJoin, BezierStripForNonProportionalKnots) {
  Rng rng(8008);
  for (int trial = 0; trial < 6; ++trial) {
    const Case c = bicubicCase(rng, false);
    JoinOptions o = opts();
    o.method = JoinMethod::kBezierStrip;
    o.maxGap = 0.5 * sizeOf(c.model.patches[1].surface);  // span i of S is paired with span i of S~
    auto r = join(c, o);
    ASSERT_TRUE(r.isOk()) << r.status().message();
    EXPECT_EQ(r->report.method, JoinMethod::kBezierStrip);
    ASSERT_TRUE(r->report.stripInternalG1MaxDeg.has_value());
    EXPECT_LE(*r->report.stripInternalG1MaxDeg, kExactAngleDeg);
    checkJoin(c, *r, GeometricClass::kG1, /*tMayMove=*/false, /*lastMovedRow=*/3);
    // auto prefers the least-squares join here (it keeps S a C1 B-spline).
    JoinOptions a = opts();
    a.maxGap = o.maxGap;
    auto ra = join(c, a);
    ASSERT_TRUE(ra.isOk()) << ra.status().message();
    EXPECT_EQ(ra->report.method, JoinMethod::kLeastSquares);
    checkJoin(c, *ra, GeometricClass::kG1);
  }
}

// ---------------------------------------------------------------------------------------------------------------------
// The command line.
// ---------------------------------------------------------------------------------------------------------------------

#ifdef SEAM_CLI_PATH
/// A per-process scratch path: ctest runs the tests of this file in parallel processes.
std::filesystem::path scratch(const std::string& name) {
  return std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()));
}

struct CliRun {
  int exit = -1;
  std::string out;
};
CliRun runCli(const std::string& args) {
  const std::filesystem::path tmp = scratch("seam_join_test_stdout.txt");
  const std::string cmd = std::string(SEAM_CLI_PATH) + " " + args + " > " + tmp.string() + " 2>&1";
  const int rc = std::system(cmd.c_str());
  CliRun r;
  r.exit = WIFEXITED(rc) ? WEXITSTATUS(rc) : -1;
  std::ifstream in(tmp);
  std::stringstream ss;
  ss << in.rdbuf();
  r.out = ss.str();
  return r;
}

TEST(JoinCli, WritesTheJoinedModelAndReportsBeforeAndAfter) {
  const std::filesystem::path dir = scratch("seam_join_cli_test");
  std::filesystem::create_directories(dir);
  Rng rng(9009);
  const Case c = makeCase(rng, 3, 3, false, 0, 0, 0, 2, 0.01);
  const std::filesystem::path in = dir / "in.json", out = dir / "out.json";
  ASSERT_TRUE(io::writeModelJson(c.model, in).isOk());
  const std::string inText = [&] {
    std::ifstream f(in);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  }();
  const std::string edges = std::string("--move S:") + std::string(edgeName(c.moveEdge)) +
                            " --to T:" + std::string(edgeName(c.toEdge));
  CliRun r = runCli("join " + in.string() + " " + edges + " -o " + out.string() + " --json");
  ASSERT_EQ(r.exit, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["method"], "least-squares");
  EXPECT_EQ(j["after"]["geometric"].get<std::string>().substr(0, 1), "G");
  EXPECT_TRUE(j["after"]["certified"].get<bool>());
  EXPECT_LE(j["after"]["g1_max_deg"].get<double>(), kExactAngleDeg);
  EXPECT_GT(j["before"]["g0_max"].get<double>(), 0.0);
  for (const char* key :
       {"a", "a_edge", "b", "b_edge", "overlap", "g0_max", "g1_max_deg", "g2_max", "g2_rel_max",
        "lambda_range", "kappa_range", "geometric", "parametric", "certified", "worst"})
    EXPECT_TRUE(j["after"].contains(key)) << key;
  EXPECT_GT(j["moved_points"].get<int>(), 0);
  EXPECT_EQ(j["patches_changed"], nlohmann::json::array({"S"}));
  // The output model reads back; the input file is untouched.
  auto back = io::readModelJson(out);
  ASSERT_TRUE(back.isOk()) << back.status().message();
  EXPECT_TRUE(back->patches[0].surface.points() == c.model.patches[0].surface.points());
  std::ifstream f(in);
  std::stringstream s;
  s << f.rdbuf();
  EXPECT_EQ(s.str(), inText);
  // Text output, bad input, and a missed continuity (G2 of a pair that only has G1 freedom is still reached,
  // so force a miss with a gap limit instead: exit 2).
  r = runCli("join " + in.string() + " " + edges + " -o " + out.string());
  EXPECT_EQ(r.exit, 0) << r.out;
  EXPECT_NE(r.out.find("method: least-squares"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("G1 achieved"), std::string::npos) << r.out;
  r = runCli("join " + in.string() + " --move S:q0 --to T:v0 -o " + out.string());
  EXPECT_EQ(r.exit, 2) << r.out;
  r = runCli("join " + in.string() + " " + edges + " --max-gap 1e-12 -o " + out.string());
  EXPECT_EQ(r.exit, 2) << r.out;
  r = runCli("join " + (dir / "missing.json").string() + " " + edges + " -o " + out.string());
  EXPECT_EQ(r.exit, 2) << r.out;
}

TEST(JoinCli, ExampleModels) {
  const std::filesystem::path dir = scratch("seam_join_cli_examples");
  std::filesystem::create_directories(dir);
  struct Ex {
    const char* file;
    const char* args;
    const char* method;
  };
  for (const Ex& e :
       {Ex{"join_bicubic_proportional.json", "--move S:v0 --to T:v1", "bspline"},
        Ex{"join_bicubic_strip.json", "--move S:v0 --to T:v1 --method bezier-strip", "bezier-strip"},
        Ex{"join_bicubic_strip.json", "--move S:v0 --to T:v1", "least-squares"},
        Ex{"join_rational_degrees.json", "--move S:u0 --to T:u1", "least-squares"}}) {
    const std::string in = std::string(SEAM_EXAMPLES_DIR) + "/models/" + e.file;
    const std::filesystem::path out = dir / "out.json";
    CliRun r = runCli("join " + in + " " + e.args + " -o " + out.string() + " --json");
    ASSERT_EQ(r.exit, 0) << e.file << ": " << r.out;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["method"], e.method) << e.file;
    EXPECT_TRUE(j["after"]["certified"].get<bool>()) << e.file;
    EXPECT_LE(j["after"]["g1_max_deg"].get<double>(), kExactAngleDeg) << e.file;
  }
}
#endif

}  // namespace
}  // namespace seam
