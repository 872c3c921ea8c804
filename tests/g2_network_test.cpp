// Tests of the G2 network solve (seam/repair/g2_network.h).
//
// Every network is made in the test (tests/network_support.h): a polygon mesh split into quads, vertices on a sphere
// or a height field, cubic edge curves with end tangents in the surface's tangent plane, Coons interiors: G0 and
// nearly G1, with curvature jumps of 1-100 % across the seams. After the solve every seam is checked
//  (a) by an independent test-side comparison of normal curvatures: at 50 points per seam, in three tangent
//      directions, the normal curvature of each side from finite differences of the evaluator (second order, one
//      sided across the edge), the two sides matched by closest point;
//  (b) by seam::checkModel (certified G2);
// and the free edges, the surface displacement and the patches outside the chosen set are checked against the input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <iostream>
#include <tuple>
#include <string>
#include <vector>

#include "network_support.h"
#include "seam/continuity/model_check.h"
#include "seam/repair/g2_network.h"

namespace {

using namespace seam;
namespace nt = seam::testing;

/// Normal-curvature difference allowed after the solve, relative to max(1 / model size, the curvatures): 0.1 %, ten
/// times below the check's default G2 tolerance (1 %); the inputs' jumps are 55-200 %. The solve stops when its
/// last digits converge linearly (identity residual ~1e-8 of the model size), which leaves jumps of ~3e-4 at most.
constexpr double kMaxCurvatureJumpRel = 1e-3;
/// The solve minimises the change of the control points, not a fairness energy: curvature may grow (by up to 5x on
/// the fan of 3, thesis-abstract.md "Not done"). This bound catches sharp bends bought for G2 (a trial that allowed
/// C0 knots inside patches produced |k| = 90 on a model of size 2.3 whose input has |k| <= 1.8).
constexpr double kMaxCurvatureGrowth = 6.0;
/// Largest curvature jump of the input that makes a case meaningful (the test must be able to fail).
constexpr double kMinInputJumpRel = 0.01;
/// Finite-difference step for the curvatures (normalised parameters).
constexpr double kStep = 1e-4;
/// Samples per seam for the curvature comparison.
constexpr int kSamples = 50;
/// How far the surface may move: largest control-point displacement relative to the patch's control-box diagonal.
constexpr double kMaxDisplacementRel = 0.1;
/// Free edges keep their geometry (exact raise and refinement only): sampled distance relative to the model size.
constexpr double kFreeEdgeTolRel = 1e-12;

/// f' and f'' at x in [0, 1] by finite differences of step h: central inside, second-order one-sided at the ends.
template <class F>
std::pair<Vec3, Vec3> derivatives01(const F& f, double x, double h = kStep) {
  if (x - h >= 0.0 && x + h <= 1.0) {
    const Vec3 fm = f(x - h), f0 = f(x), fp = f(x + h);
    return {(fp - fm) / (2.0 * h), (fp - 2.0 * f0 + fm) / (h * h)};
  }
  const double s = x - h < 0.0 ? 1.0 : -1.0;  // into the interval
  const Vec3 f0 = f(x), f1 = f(x + s * h), f2 = f(x + 2 * s * h), f3 = f(x + 3 * s * h);
  return {s * (-3.0 * f0 + 4.0 * f1 - f2) / (2.0 * h), (2.0 * f0 - 5.0 * f1 + 4.0 * f2 - f3) / (h * h)};
}

struct Jet2 {
  Vec3 su, sv, suu, suv, svv;
};

/// First and second partial derivatives at normalised (a, b), by finite differences of the evaluator only.
Jet2 fdJet(const BSplineSurface& s, double a, double b) {
  Jet2 j;
  std::tie(j.su, j.suu) = derivatives01([&](double x) { return nt::pointAt(s, x, b); }, a);
  std::tie(j.sv, j.svv) = derivatives01([&](double y) { return nt::pointAt(s, a, y); }, b);
  j.suv = derivatives01([&](double x) { return derivatives01([&](double y) { return nt::pointAt(s, x, y); }, b).first; },
                        a)
              .first;
  return j;
}

/// Normal curvature of the patch in the tangent direction d with respect to the unit normal n.
double normalCurvature(const Jet2& j, const Vec3& d, const Vec3& n) {
  Eigen::Matrix<double, 3, 2> m;
  m << j.su, j.sv;
  const Eigen::Vector2d c = (m.transpose() * m).ldlt().solve(m.transpose() * d);
  return n.dot(c[0] * c[0] * j.suu + 2.0 * c[0] * c[1] * j.suv + c[1] * c[1] * j.svv) / d.squaredNorm();
}

struct CurvatureCheck {
  double maxJumpRel = 0.0;  ///< largest |kappa_A - kappa_B| / max(1 / size, |kappa_A|, |kappa_B|)
  double maxAbsCurvature = 0.0;  ///< largest |kappa| over both sides (a G2 result must not buy G2 with sharp bends)
  double maxGap = 0.0;
};

/// Compares the normal curvatures of the two sides of every seam of the network at kSamples points, in three
/// directions (along the edge, across it in the tangent plane, and at 45 degrees).
CurvatureCheck compareCurvatures(const Model& m, const nt::Network& net, const std::vector<int>& skipEdges = {}) {
  CurvatureCheck out;
  for (size_t ei = 0; ei < net.edges.size(); ++ei) {
    const nt::NetworkEdge& e = net.edges[ei];
    if (e.free() || std::find(skipEdges.begin(), skipEdges.end(), static_cast<int>(ei)) != skipEdges.end()) continue;
    const auto [pa, ea] = e.sides[0];
    const auto [pb, eb] = e.sides[1];
    const BSplineSurface& A = m.patches[static_cast<size_t>(pa)].surface;
    const BSplineSurface& B = m.patches[static_cast<size_t>(pb)].surface;
    double guess = -1.0;
    for (int k = 0; k < kSamples; ++k) {
      const double t = (k + 0.5) / kSamples;
      const Vec3 p = nt::edgePoint(A, ea, t);
      const double tb = nt::closestOnEdge(B, eb, p, guess);
      guess = tb;
      out.maxGap = std::max(out.maxGap, (nt::edgePoint(B, eb, tb) - p).norm());
      const Vec2 abA = nt::edgeParameters(ea, t), abB = nt::edgeParameters(eb, tb);
      const Jet2 ja = fdJet(A, abA.x(), abA.y()), jb = fdJet(B, abB.x(), abB.y());
      const Vec3 n = ja.su.cross(ja.sv).normalized();
      const Vec3 along = (isUEdge(ea) ? ja.sv : ja.su).normalized();
      const Vec3 across = n.cross(along);
      for (const Vec3& d : {along, across, Vec3((along + across).normalized())}) {
        const double ka = normalCurvature(ja, d, n), kb = normalCurvature(jb, d, n);
        const double scale = std::max({1.0 / net.size, std::abs(ka), std::abs(kb)});
        out.maxJumpRel = std::max(out.maxJumpRel, std::abs(ka - kb) / scale);
        out.maxAbsCurvature = std::max({out.maxAbsCurvature, std::abs(ka), std::abs(kb)});
      }
    }
  }
  return out;
}

struct CertifiedCounts {
  int seams = 0, g2 = 0, g1 = 0, certified = 0;
  double g2RelMax = 0.0;  ///< largest certified relative curvature jump over the G2 seams
};

CertifiedCounts certify(const Model& m) {
  auto rep = checkModel(m);
  EXPECT_TRUE(static_cast<bool>(rep)) << rep.status().message();
  CertifiedCounts c;
  if (!rep) return c;
  for (const ModelSeam& s : rep->seams) {
    ++c.seams;
    if (!s.report) continue;
    c.certified += s.report->certified;
    c.g2 += s.report->geometric == GeometricClass::kG2;
    if (s.report->geometric == GeometricClass::kG2) c.g2RelMax = std::max(c.g2RelMax, s.report->g2RelMax);
    c.g1 += s.report->geometric == GeometricClass::kG1;
  }
  return c;
}

/// Largest distance between the free edges of the input and of the output (sampled).
double freeEdgeMove(const nt::Network& net, const Model& out) {
  double worst = 0.0;
  for (const nt::NetworkEdge& e : net.edges) {
    if (!e.free()) continue;
    const auto [p, ed] = e.sides[0];
    for (int k = 0; k <= 20; ++k) {
      const double t = k / 20.0;
      worst = std::max(worst, (nt::edgePoint(net.model.patches[static_cast<size_t>(p)].surface, ed, t) -
                               nt::edgePoint(out.patches[static_cast<size_t>(p)].surface, ed, t))
                                  .norm());
    }
  }
  return worst;
}

struct NetworkCase {
  std::string name;
  std::function<nt::Network()> build;
  int expectG1Only = 0;  ///< seams the solve must leave G1 only (straight free boundary with a curvature jump)
};

void PrintTo(const NetworkCase& c, std::ostream* os) { *os << c.name; }

class G2NetworkCase : public ::testing::TestWithParam<NetworkCase> {};

TEST_P(G2NetworkCase, EverySeamComesOutG2AndTheIndependentCurvatureComparisonAgrees) {
  const nt::Network net = GetParam().build();
  const CurvatureCheck before = compareCurvatures(net.model, net);
  ASSERT_GT(before.maxJumpRel, kMinInputJumpRel) << "the input must have curvature jumps for the test to mean anything";

  auto res = g2NetworkScheme(net.model);
  ASSERT_TRUE(static_cast<bool>(res)) << res.status().message();
  const G2NetworkReport& rep = res->report;
  EXPECT_EQ(rep.interiorSeams, net.numSeams());
  EXPECT_EQ(rep.g1OnlySeams, GetParam().expectG1Only);
  EXPECT_GT(rep.minLambda, 0.0);
  EXPECT_LE(rep.maxDisplacementRel, kMaxDisplacementRel);
  EXPECT_EQ(static_cast<int>(rep.patchesChanged.size()), net.numFaces());

  // (a) independent: normal curvatures agree on both sides of every seam (all of them when none is G1 only).
  if (GetParam().expectG1Only == 0) {
    const CurvatureCheck after = compareCurvatures(res->model, net);
    EXPECT_LE(after.maxJumpRel, kMaxCurvatureJumpRel) << "before: " << before.maxJumpRel;
    EXPECT_LE(after.maxGap, 1e-9 * net.size);
    EXPECT_LE(after.maxAbsCurvature, kMaxCurvatureGrowth * before.maxAbsCurvature);
    std::cout << GetParam().name << ": largest |normal curvature| on the seams " << before.maxAbsCurvature << " before, "
              << after.maxAbsCurvature << " after\n";
  }
  // (b) certified.
  const CertifiedCounts c = certify(res->model);
  EXPECT_EQ(c.seams, net.numSeams());
  EXPECT_EQ(c.certified, c.seams);
  EXPECT_EQ(c.g2, c.seams - GetParam().expectG1Only);
  EXPECT_EQ(c.g1, GetParam().expectG1Only);
  // Free edges stay where they are.
  EXPECT_LE(freeEdgeMove(net, res->model), kFreeEdgeTolRel * net.size);
  // Every interior vertex: one second fundamental form afterwards (the curvature-point systems are met), and the
  // input did not have one; valence 4: Johansson's Theorem 2 relations hold; valence >= 5: a note with the mismatch.
  if (GetParam().expectG1Only == 0) {
    ASSERT_FALSE(rep.vertices.empty());
    double spreadBefore = 0.0;
    int notesAt5 = 0, at5 = 0;
    for (const G2NetworkVertex& v : rep.vertices) {
      ASSERT_TRUE(v.spreadAfter && v.spreadBefore) << "valence " << v.valence;
      EXPECT_LE(*v.spreadAfter, kMaxCurvatureJumpRel) << "valence " << v.valence;
      spreadBefore = std::max(spreadBefore, *v.spreadBefore);
      if (v.valence == 4) {
        ASSERT_TRUE(v.theorem2After.has_value());
        EXPECT_LE(*v.theorem2After, kMaxCurvatureJumpRel);
      }
      at5 += v.valence >= 5;
    }
    for (const std::string& n : rep.notes) notesAt5 += n.find("patches meet: curvature mismatch") != std::string::npos;
    EXPECT_EQ(notesAt5, at5);
    EXPECT_GT(spreadBefore, kMinInputJumpRel);
    std::cout << GetParam().name << ": vertex curvature spread before " << spreadBefore << "\n";
  }
  std::cout << GetParam().name << ": " << rep.iterations << " steps, residual " << rep.residualRel
            << ", curvature jump before " << before.maxJumpRel << ", certified after " << c.g2RelMax
            << ", displacement " << rep.maxDisplacementRel
            << ", min lambda " << rep.minLambda << ", vertex curvature spread after " << rep.maxSpreadAfter.value_or(-1.0)
            << "\n";
}

std::vector<NetworkCase> networkCases() {
  return {
      {"CubeSphereBicubic", [] { return nt::buildNetwork(nt::cubeMesh(), nt::sphereShape()); }},
      {"CubeSphereBiquarticMixedParametrisations",
       [] { return nt::buildNetwork(nt::cubeMesh(), nt::sphereShape(), {nt::PatchForm::kBiquarticBSpline, true}); }},
      {"FanOf3", [] { return nt::buildNetwork(nt::fanMesh(3), nt::heightFieldShape()); }},
      {"FanOf4Mixed",
       [] { return nt::buildNetwork(nt::fanMesh(4), nt::heightFieldShape(), {nt::PatchForm::kBicubicBezier, true}); }},
      {"FanOf5", [] { return nt::buildNetwork(nt::fanMesh(5), nt::heightFieldShape()); }},
      {"FanOf6BiquarticMixed",
       [] { return nt::buildNetwork(nt::fanMesh(6), nt::heightFieldShape(), {nt::PatchForm::kBiquarticBSpline, true}); }},
  };
}

INSTANTIATE_TEST_SUITE_P(Networks, G2NetworkCase, ::testing::ValuesIn(networkCases()),
                         [](const ::testing::TestParamInfo<NetworkCase>& p) { return p.param.name; });

/// The derivatives at a patch corner in directions pointing into the patch (x along the corner's v = const edge, y
/// along its u = const edge), by second-order one-sided finite differences of the evaluator.
struct CornerJet {
  Vec3 x, y, xx, xy, yy;
};
CornerJet cornerJetFd(const BSplineSurface& s, const PatchCorner& c) {
  constexpr double h = 1e-3;
  auto g = [&](double x, double y) -> Vec3 {
    return nt::pointAt(s, c.uMax ? 1.0 - x : x, c.vMax ? 1.0 - y : y);
  };
  // Explicit Vec3 results: an Eigen expression returned by a lambda would refer to its dead temporaries.
  auto d1 = [&](auto f) -> Vec3 { return (-3.0 * f(0.0) + 4.0 * f(h) - f(2 * h)) / (2.0 * h); };
  auto d2 = [&](auto f) -> Vec3 { return (2.0 * f(0.0) - 5.0 * f(h) + 4.0 * f(2 * h) - f(3 * h)) / (h * h); };
  CornerJet j;
  j.x = d1([&](double x) { return g(x, 0.0); });
  j.y = d1([&](double y) { return g(0.0, y); });
  j.xx = d2([&](double x) { return g(x, 0.0); });
  j.yy = d2([&](double y) { return g(0.0, y); });
  j.xy = d1([&](double y) { return d1([&](double x) { return g(x, y); }); });
  return j;
}

/// At every interior vertex of valence 3: the common second fundamental form II fitted to the three edges' normal
/// second derivatives alone (3 x 3 system, regular when no two edges are collinear: its determinant is a product of
/// the pairwise sines, docs/algorithms/thesis-abstract.md "The vertex systems") predicts every patch's twist normal
/// component N . S_xy = II(S_x, S_y). Returns the largest relative misprediction over the vertices.
double valenceThreeTwistMisprediction(const Model& m, const nt::Network& net) {
  double worst = 0.0;
  for (const nt::NetworkVertex& v : net.vertices) {
    if (v.boundary || v.valence != 3) continue;
    std::vector<CornerJet> jets;
    for (const PatchCorner& c : v.corners) jets.push_back(cornerJetFd(m.patches[static_cast<size_t>(c.patch)].surface, c));
    Vec3 n = Vec3::Zero();
    for (const CornerJet& j : jets) {
      const Vec3 ni = j.x.cross(j.y).normalized();
      n += ni.dot(v.normal) > 0.0 ? ni : -ni;
    }
    n.normalize();
    const Vec3 e1 = n.unitOrthogonal(), e2 = n.cross(e1);
    // The three edges: every corner's two edge ends, the same edge seen from two corners merged by direction.
    std::vector<std::pair<Vec3, Vec3>> edges;  // (first derivative, second derivative) away from V
    for (const CornerJet& j : jets)
      for (const auto& [d, dd] : {std::make_pair(j.x, j.xx), std::make_pair(j.y, j.yy)}) {
        const bool seen = std::any_of(edges.begin(), edges.end(), [&](const auto& e) {
          return e.first.normalized().dot(d.normalized()) > 0.99;
        });
        if (!seen) edges.emplace_back(d, dd);
      }
    EXPECT_EQ(edges.size(), 3u);
    if (edges.size() != 3) continue;
    Eigen::Matrix3d A;
    Eigen::Vector3d b;
    double scale = 0.0;
    for (int k = 0; k < 3; ++k) {
      const auto& [d, dd] = edges[static_cast<size_t>(k)];
      const double a1 = e1.dot(d), a2 = e2.dot(d);
      A.row(k) << a1 * a1, 2.0 * a1 * a2, a2 * a2;
      b[k] = n.dot(dd);
      scale = std::max(scale, std::abs(b[k]) / d.squaredNorm());
    }
    const Eigen::Vector3d ii = A.fullPivLu().solve(b);
    Eigen::Matrix2d II;
    II << ii[0], ii[1], ii[1], ii[2];
    for (const CornerJet& j : jets) {
      const Eigen::Vector2d x(e1.dot(j.x), e2.dot(j.x)), y(e1.dot(j.y), e2.dot(j.y));
      const Vec3 ni = j.x.cross(j.y).normalized();
      const double predicted = x.dot(II * y), actual = (ni.dot(n) > 0.0 ? ni : -ni).dot(j.xy);
      worst = std::max(worst, std::abs(predicted - actual) /
                                  (std::max(scale, 1.0 / net.size) * j.x.norm() * j.y.norm()));
    }
  }
  return worst;
}

// The first of the thesis' intertwining systems at a vertex where three patches meet, in closed form: the three
// edges' curvatures fix the vertex's second fundamental form (no restriction on them), which fixes the twists. The
// input breaks it (its twists come from Coons blending), the output meets it.
TEST(G2Network, AtValenceThreeTheEdgesFixTheCurvatureAndTheTwists) {
  for (const nt::Network& net : {nt::buildNetwork(nt::fanMesh(3), nt::heightFieldShape()),
                                 nt::buildNetwork(nt::cubeMesh(), nt::sphereShape())}) {
    ASSERT_GT(net.count(nt::VertexKind::kOriginal, 3) + net.count(nt::VertexKind::kFaceCentre, 3), 0);
    const double before = valenceThreeTwistMisprediction(net.model, net);
    EXPECT_GT(before, kMinInputJumpRel);
    auto res = g2NetworkScheme(net.model);
    ASSERT_TRUE(static_cast<bool>(res)) << res.status().message();
    const double after = valenceThreeTwistMisprediction(res->model, net);
    EXPECT_LT(after, kMaxCurvatureJumpRel);
    std::cout << "valence-3 twist predicted from the three edges: misprediction " << before << " before, " << after
              << " after\n";
  }
}

// A regular 4-valent grid, perturbed: every interior vertex has valence 4 (Johansson's Theorem 2 compatibility
// there is met by the solve). The free boundary runs straight through the boundary vertices in the middle of each
// side of the original 2 x 2 grid, with different normal curvatures on the two sides: G2 is impossible there with
// the free edges kept, and the 4 seams ending there are left G1 (named in the notes); every other seam is G2.
TEST(G2Network, PerturbedGridIsG2ExceptWhereAStraightFreeBoundaryHasACurvatureJump) {
  nt::PolyMesh mesh = nt::gridMesh(2, 2);
  // Jitter the interior vertex only (index 4 of the 3 x 3 vertices), so that the sides stay straight.
  mesh.vertices[4] += Vec3(0.13, -0.08, 0.0);
  const nt::Network net = nt::buildNetwork(mesh, nt::heightFieldShape());
  auto res = g2NetworkScheme(net.model);
  ASSERT_TRUE(static_cast<bool>(res)) << res.status().message();
  EXPECT_EQ(res->report.g1OnlySeams, 4);
  EXPECT_EQ(res->report.valences, std::vector<int>{4});
  int notes = 0;
  for (const std::string& n : res->report.notes) notes += n.find("free boundary runs straight") != std::string::npos;
  EXPECT_EQ(notes, 4);
  const CertifiedCounts c = certify(res->model);
  EXPECT_EQ(c.certified, c.seams);
  EXPECT_EQ(c.g2, c.seams - 4);
  EXPECT_EQ(c.g1, 4);
  EXPECT_LE(freeEdgeMove(net, res->model), kFreeEdgeTolRel * net.size);
}

// A regular 4-valent grid with random perturbations (every vertex of a 3 x 3 grid moved, the boundary too): G2 on
// every seam except those ending where the free boundary runs straight with a curvature jump (counted by the solve),
// which are G1; the independent curvature comparison on every seam that does not touch the boundary.
TEST(G2Network, RandomlyPerturbedGridIsG2AwayFromStraightBoundaryVertices) {
  const nt::Network net = nt::buildNetwork(nt::jittered(nt::gridMesh(3, 3), 0.12), nt::heightFieldShape());
  const CurvatureCheck before = compareCurvatures(net.model, net);
  ASSERT_GT(before.maxJumpRel, kMinInputJumpRel);
  auto res = g2NetworkScheme(net.model);
  ASSERT_TRUE(static_cast<bool>(res)) << res.status().message();
  EXPECT_EQ(res->report.valences, std::vector<int>{4});
  EXPECT_GT(res->report.minLambda, 0.0);
  EXPECT_LE(res->report.maxDisplacementRel, kMaxDisplacementRel);
  const CertifiedCounts c = certify(res->model);
  EXPECT_EQ(c.certified, c.seams);
  EXPECT_EQ(c.g2, c.seams - res->report.g1OnlySeams);
  EXPECT_EQ(c.g1, res->report.g1OnlySeams);
  std::vector<int> boundaryEdges;
  for (size_t e = 0; e < net.edges.size(); ++e)
    if (net.vertices[static_cast<size_t>(net.edges[e].v0)].boundary ||
        net.vertices[static_cast<size_t>(net.edges[e].v1)].boundary)
      boundaryEdges.push_back(static_cast<int>(e));
  const CurvatureCheck after = compareCurvatures(res->model, net, boundaryEdges);
  EXPECT_LE(after.maxJumpRel, kMaxCurvatureJumpRel) << "before: " << before.maxJumpRel;
  EXPECT_LE(freeEdgeMove(net, res->model), kFreeEdgeTolRel * net.size);
  std::cout << "jittered 3 x 3 grid: " << c.seams << " seams, " << c.g2 << " G2, " << res->report.g1OnlySeams
            << " G1 only; jump before " << before.maxJumpRel << ", after (interior) " << after.maxJumpRel
            << ", certified after " << c.g2RelMax << ", displacement " << res->report.maxDisplacementRel << ", "
            << res->report.iterations << " steps\n";
}

// Double interior knots (the thesis' Theorems 9-10: the patches only C1 there) and knots other than the middle are
// handled, not refused: every patch gets the union of the region's knots (mirrored, at least triple at degree 5), the
// blending functions are independent per span, and every seam comes out G2.
TEST(G2Network, DoubleKnotsAndKnotsOffTheMiddleAreHandled) {
  nt::Network net = nt::buildNetwork(nt::fanMesh(4), nt::heightFieldShape());
  const CurvatureCheck before = compareCurvatures(net.model, net);
  for (size_t i = 0; i < net.model.patches.size(); ++i) {
    BSplineSurface& s = net.model.patches[i].surface;
    if (i % 3 == 0) {
      // A genuine double knot (C1 only): insert 1/2 twice in u, then move a point of the knot's row.
      s = s.withKnotInsertedU(0.5, 2);
      Matrix pts = s.points();
      for (int j = 0; j < s.numV(); ++j) pts.row(2 * s.numV() + j) += Vec3(0.0, 0.0, 0.01).transpose();
      s = BSplineSurface(s.degreeU(), s.degreeV(), s.knotsU(), s.knotsV(), s.numU(), s.numV(), pts);
    } else if (i % 3 == 1) {
      s = s.withKnotInsertedV(1.0 / 3.0);  // exact refinement off the middle
    }
  }
  auto res = g2NetworkScheme(net.model);
  ASSERT_TRUE(static_cast<bool>(res)) << res.status().message();
  const BSplineSurface& out = res->model.patches[0].surface;
  EXPECT_EQ(out.knotsU().multiplicity(0.5), 4);  // the double knot stays C1 (degree 5)
  EXPECT_EQ(out.knotsU().multiplicity(1.0 / 3.0), 3);
  EXPECT_EQ(out.knotsU().multiplicity(2.0 / 3.0), 3);  // mirrored for the reversed neighbours
  const CertifiedCounts c = certify(res->model);
  EXPECT_EQ(c.certified, c.seams);
  EXPECT_EQ(c.g2, c.seams);
  const CurvatureCheck after = compareCurvatures(res->model, net);
  EXPECT_LE(after.maxJumpRel, kMaxCurvatureJumpRel) << "before: " << before.maxJumpRel;
  EXPECT_LE(freeEdgeMove(net, res->model), kFreeEdgeTolRel * net.size);
}

/// Largest jump of the d-th u-derivative (d = 1, 2) across u = knot, over v, from one-sided finite differences of the
/// evaluator, relative to the derivative's size.
double derivativeJumpU(const BSplineSurface& s, double knot, int d) {
  double worst = 0.0;
  for (int k = 1; k < 10; ++k) {
    const double v = k / 10.0;
    auto f = [&](double u) { return nt::pointAt(s, u, v); };
    auto side = [&](double sgn) {  // one-sided derivatives of order d at the knot, second order
      constexpr double h = 1e-3;
      const Vec3 f0 = f(knot), f1 = f(knot + sgn * h), f2 = f(knot + 2 * sgn * h), f3 = f(knot + 3 * sgn * h);
      return d == 1 ? Vec3(sgn * (-3.0 * f0 + 4.0 * f1 - f2) / (2.0 * h))
                    : Vec3((2.0 * f0 - 5.0 * f1 + 4.0 * f2 - f3) / (h * h));
    };
    const Vec3 a = side(-1.0), b = side(1.0);
    worst = std::max(worst, (a - b).norm() / std::max({a.norm(), b.norm(), 1e-300}));
  }
  return worst;
}

// A triple knot of a cubic (C0) inside one patch with a real crease along it (the thesis' Theorem 10 case for the
// input's degree): handled, not refused. The patch keeps its crease line as a C0 knot; every other patch gets the
// knot in the common form but keeps its C2 smoothness there (smoothness rows); every seam comes out G2.
TEST(G2Network, ATripleKnotWithACreaseInsideAPatchIsKeptAndTheOthersStaySmooth) {
  const nt::Network net = nt::buildNetwork(nt::fanMesh(3), nt::heightFieldShape());
  Model knots = net.model;
  BSplineSurface s = knots.patches[1].surface.withKnotInsertedU(0.3, 3);
  ASSERT_EQ(s.degreeU(), 3);
  Matrix pts = s.points();
  int row = -1;  // the control-point row at the knot (interpolated by the surface)
  for (int i = 0; i < s.numU(); ++i)
    if (std::abs(s.knotsU()[i + 1] - 0.3 * s.domainU().length() - s.domainU().lo) < 1e-12 &&
        std::abs(s.knotsU()[i + 3] - s.knotsU()[i + 1]) < 1e-12)
      row = i;
  ASSERT_GE(row, 0);
  for (int j = 1; j + 1 < s.numV(); ++j) pts(row * s.numV() + j, 2) += 0.005 * net.size;  // interior points only
  s = BSplineSurface(s.degreeU(), s.degreeV(), s.knotsU(), s.knotsV(), s.numU(), s.numV(), pts);
  knots.patches[1].surface = s;
  ASSERT_GT(derivativeJumpU(s, 0.3, 1), 0.05) << "the input must have a crease along the knot";
  const CurvatureCheck before = compareCurvatures(knots, net);
  auto res = g2NetworkScheme(knots);
  ASSERT_TRUE(static_cast<bool>(res)) << res.status().message();
  const CertifiedCounts c = certify(res->model);
  EXPECT_EQ(c.certified, c.seams);
  EXPECT_EQ(c.g2, c.seams);
  const CurvatureCheck after = compareCurvatures(res->model, net);
  EXPECT_LE(after.maxJumpRel, kMaxCurvatureJumpRel);
  EXPECT_LE(after.maxAbsCurvature, kMaxCurvatureGrowth * before.maxAbsCurvature);
  std::cout << "triple knot: " << res->report.iterations << " steps, largest |normal curvature| on the seams "
            << before.maxAbsCurvature << " before, " << after.maxAbsCurvature << " after, displacement "
            << res->report.maxDisplacementRel << "\n";
  EXPECT_LE(freeEdgeMove(net, res->model), kFreeEdgeTolRel * net.size);
  const BSplineSurface& p1 = res->model.patches[1].surface;
  EXPECT_EQ(p1.knotsU().multiplicity(0.3 * p1.domainU().length() + p1.domainU().lo), 5);  // C0 at degree 5
  EXPECT_GT(derivativeJumpU(p1, 0.3, 1), 0.01) << "the crease inside the patch is the patch's design";
  // The other patches: C2 across every knot of the common form, also where it has multiplicity 5.
  for (int i : {0, 2, 3, 4}) {
    const BSplineSurface& o = res->model.patches[static_cast<size_t>(i)].surface;
    for (double t : {0.3, 0.7}) {
      const double knot = o.domainU().lo + t * o.domainU().length();
      EXPECT_EQ(o.knotsU().multiplicity(knot), 5) << "patch " << i;
      EXPECT_LT(derivativeJumpU(o, t, 1), 1e-5) << "patch " << i << " at " << t;
      EXPECT_LT(derivativeJumpU(o, t, 2), 1e-2) << "patch " << i << " at " << t;
    }
  }
}

TEST(G2Network, PatchesOutsideTheSubsetAreBitIdentical) {
  const nt::Network net = nt::buildNetwork(nt::fanMesh(4), nt::heightFieldShape());
  G2NetworkOptions o;
  for (int i = 0; i < net.numFaces(); ++i)
    if (i % 4 != 3) o.patches.push_back(i);
  auto res = g2NetworkScheme(net.model, o);
  ASSERT_TRUE(static_cast<bool>(res)) << res.status().message();
  for (int i = 0; i < net.numFaces(); ++i) {
    const BSplineSurface& a = net.model.patches[static_cast<size_t>(i)].surface;
    const BSplineSurface& b = res->model.patches[static_cast<size_t>(i)].surface;
    if (i % 4 == 3) {
      EXPECT_EQ(a.points(), b.points()) << i;
      EXPECT_EQ(a.knotsU().values(), b.knotsU().values()) << i;
    } else {
      EXPECT_EQ(b.degreeU(), 5);
      EXPECT_EQ(b.degreeV(), 5);
    }
  }
  // The seams between chosen patches are G2; those to the unchosen ones stay as they were (G0 or better).
  const CertifiedCounts c = certify(res->model);
  EXPECT_EQ(c.certified, c.seams);
  EXPECT_GE(c.g2, res->report.interiorSeams);
}

TEST(G2Network, RefusesRationalPatchesAndBadIndices) {
  nt::Network net = nt::buildNetwork(nt::fanMesh(3), nt::heightFieldShape());
  Model rational = net.model;
  const BSplineSurface& s = rational.patches[0].surface;
  VecX w = VecX::Ones(s.numU() * s.numV());
  w[5] = 1.5;
  rational.patches[0].surface =
      BSplineSurface(s.degreeU(), s.degreeV(), s.knotsU(), s.knotsV(), s.numU(), s.numV(), s.points(), w);
  auto r = g2NetworkScheme(rational);
  ASSERT_FALSE(static_cast<bool>(r));
  EXPECT_EQ(r.status().code(), ErrorCode::kUnsupported);
  EXPECT_NE(r.status().message().find("rational"), std::string::npos);

  G2NetworkOptions bad;
  bad.patches = {99};
  r = g2NetworkScheme(net.model, bad);
  ASSERT_FALSE(static_cast<bool>(r));
  EXPECT_EQ(r.status().code(), ErrorCode::kInvalidInput);
}

}  // namespace
