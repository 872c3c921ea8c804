// Tests of the network generator and the independent seam checker of network_support.h (the fixtures of the
// local G1 scheme's tests): counts and valences, exact G0, a clearly non-G1 network, regular patches,
// orientation, and the checker itself on hinges of known angle and on a fold.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "network_support.h"

namespace {

using namespace seam;
namespace nt = seam::testing;
using nt::VertexKind;

// ---------------------------------------------------------------------------------------------------------------------
// Meshes.
// ---------------------------------------------------------------------------------------------------------------------

struct MeshCounts {
  int v = 0, e = 0, f = 0;
  bool closed = false;
  bool consistent = true;  ///< every directed edge used once; interior edges once each way
};

MeshCounts countMesh(const nt::PolyMesh& m) {
  std::map<std::pair<int, int>, int> directed;
  for (const auto& f : m.faces)
    for (size_t i = 0; i < f.size(); ++i) ++directed[{f[i], f[(i + 1) % f.size()]}];
  std::set<std::pair<int, int>> undirected;
  MeshCounts c;
  c.closed = true;
  for (const auto& [key, n] : directed) {
    c.consistent = c.consistent && n == 1;
    undirected.insert({std::min(key.first, key.second), std::max(key.first, key.second)});
    if (!directed.count({key.second, key.first})) c.closed = false;
  }
  c.v = static_cast<int>(m.vertices.size());
  c.e = static_cast<int>(undirected.size());
  c.f = static_cast<int>(m.faces.size());
  return c;
}

TEST(NetworkMeshes, CountsOrientationAndEuler) {
  struct Expect {
    std::string name;
    nt::PolyMesh mesh;
    int v, e, f;
    bool closed;
  };
  std::vector<Expect> cases = {{"cube", nt::cubeMesh(), 8, 12, 6, true},
                               {"dodecahedron", nt::dodecahedronMesh(), 20, 30, 12, true},
                               {"icosahedron", nt::icosahedronMesh(), 12, 30, 20, true},
                               {"geodesic2", nt::geodesicIcosahedronMesh(2), 42, 120, 80, true},
                               {"geodesic3", nt::geodesicIcosahedronMesh(3), 92, 270, 180, true},
                               {"grid", nt::gridMesh(3, 2), 12, 17, 6, false}};
  for (int k = 3; k <= 8; ++k)
    cases.push_back({"fan" + std::to_string(k), nt::fanMesh(k), k + 1, 2 * k, k, false});
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const MeshCounts m = countMesh(c.mesh);
    EXPECT_EQ(m.v, c.v);
    EXPECT_EQ(m.e, c.e);
    EXPECT_EQ(m.f, c.f);
    EXPECT_EQ(m.closed, c.closed);
    EXPECT_TRUE(m.consistent);
    EXPECT_EQ(m.v - m.e + m.f, c.closed ? 2 : 1);
    // Outward (closed, centred at the origin) or upward (flat) orientation of every face.
    for (const auto& f : c.mesh.faces) {
      Vec3 n = Vec3::Zero(), centroid = Vec3::Zero();
      for (size_t i = 0; i < f.size(); ++i) {
        n += c.mesh.vertices[static_cast<size_t>(f[i])].cross(
            c.mesh.vertices[static_cast<size_t>(f[(i + 1) % f.size()])]);
        centroid += c.mesh.vertices[static_cast<size_t>(f[i])];
      }
      EXPECT_GT(c.closed ? n.dot(centroid) : n.z(), 0.0);
    }
  }
  // Geodesic degrees: 12 of degree 5, the rest 6.
  const auto g = nt::geodesicIcosahedronMesh(2);
  std::vector<int> degree(g.vertices.size(), 0);
  for (const auto& f : g.faces)
    for (int i : f) ++degree[static_cast<size_t>(i)];
  EXPECT_EQ(std::count(degree.begin(), degree.end(), 5), 12);
  EXPECT_EQ(std::count(degree.begin(), degree.end(), 6), 30);
}

// ---------------------------------------------------------------------------------------------------------------------
// Networks: topology.
// ---------------------------------------------------------------------------------------------------------------------

struct VertexCount {
  VertexKind kind;
  int valence;
  bool boundary;
  int count;
};

void expectTopology(const nt::Network& net, int quads, const std::vector<VertexCount>& counts, int euler) {
  EXPECT_EQ(net.numFaces(), quads);
  EXPECT_EQ(static_cast<int>(net.model.patches.size()), quads);
  int listed = 0;
  for (const auto& c : counts) {
    EXPECT_EQ(net.count(c.kind, c.valence, c.boundary), c.count)
        << "kind " << static_cast<int>(c.kind) << " valence " << c.valence << " boundary " << c.boundary;
    listed += c.count;
  }
  EXPECT_EQ(listed, static_cast<int>(net.vertices.size())) << "unexpected vertices";
  EXPECT_EQ(net.eulerCharacteristic(), euler);
  EXPECT_EQ(net.closed(), euler == 2);
  for (size_t p = 0; p < net.model.patches.size(); ++p)
    EXPECT_EQ(net.model.patches[p].name, "P" + std::to_string(p));
  // Every listed corner of a patch is at its vertex (in the final parametrisation), and the valence is its
  // count.
  for (const auto& v : net.vertices) {
    EXPECT_EQ(static_cast<int>(v.corners.size()), v.valence);
    for (const auto& c : v.corners) {
      const Vec3 q = nt::pointAt(net.model.patches[static_cast<size_t>(c.patch)].surface, c.uMax ? 1 : 0,
                                 c.vMax ? 1 : 0);
      EXPECT_LT((q - v.point).norm(), 1e-14 * net.size);
    }
  }
}

TEST(NetworkTopology, Cube) {
  const auto net = nt::buildNetwork(nt::cubeMesh(), nt::sphereShape());
  expectTopology(net, 24,
                 {{VertexKind::kOriginal, 3, false, 8},
                  {VertexKind::kEdgeMidpoint, 4, false, 12},
                  {VertexKind::kFaceCentre, 4, false, 6}},
                 2);
}

TEST(NetworkTopology, Icosahedron) {
  const auto net = nt::buildNetwork(nt::icosahedronMesh(), nt::sphereShape());
  expectTopology(net, 60,
                 {{VertexKind::kOriginal, 5, false, 12},
                  {VertexKind::kEdgeMidpoint, 4, false, 30},
                  {VertexKind::kFaceCentre, 3, false, 20}},
                 2);
}

TEST(NetworkTopology, Dodecahedron) {
  const auto net = nt::buildNetwork(nt::dodecahedronMesh(), nt::sphereShape());
  expectTopology(net, 60,
                 {{VertexKind::kOriginal, 3, false, 20},
                  {VertexKind::kEdgeMidpoint, 4, false, 30},
                  {VertexKind::kFaceCentre, 5, false, 12}},
                 2);
}

TEST(NetworkTopology, Geodesic) {
  const auto net = nt::buildNetwork(nt::geodesicIcosahedronMesh(2), nt::sphereShape());
  expectTopology(net, 240,
                 {{VertexKind::kOriginal, 5, false, 12},
                  {VertexKind::kOriginal, 6, false, 30},
                  {VertexKind::kEdgeMidpoint, 4, false, 120},
                  {VertexKind::kFaceCentre, 3, false, 80}},
                 2);
}

TEST(NetworkTopology, Fans) {
  for (int k = 3; k <= 8; ++k) {
    SCOPED_TRACE(k);
    const auto net = nt::buildNetwork(nt::fanMesh(k), nt::heightFieldShape());
    expectTopology(net, 3 * k,
                   {{VertexKind::kOriginal, k, false, 1},
                    {VertexKind::kOriginal, 2, true, k},
                    {VertexKind::kEdgeMidpoint, 4, false, k},
                    {VertexKind::kEdgeMidpoint, 2, true, k},
                    {VertexKind::kFaceCentre, 3, false, k}},
                   1);
    EXPECT_EQ(net.numFreeEdges(), 2 * k);
  }
}

TEST(NetworkTopology, Grid) {
  const auto net = nt::buildNetwork(nt::gridMesh(3, 2), nt::heightFieldShape());
  // 12 grid vertices: 2 inner (valence 4), 6 on the sides (2 quads each), 4 corners (1 quad); 7 interior
  // edges.
  expectTopology(net, 24,
                 {{VertexKind::kOriginal, 4, false, 2},
                  {VertexKind::kOriginal, 2, true, 6},
                  {VertexKind::kOriginal, 1, true, 4},
                  {VertexKind::kEdgeMidpoint, 4, false, 7},
                  {VertexKind::kEdgeMidpoint, 2, true, 10},
                  {VertexKind::kFaceCentre, 4, false, 6}},
                 1);
}

// ---------------------------------------------------------------------------------------------------------------------
// Networks: geometry (exact G0, not G1, regular, oriented, the two forms agree).
// ---------------------------------------------------------------------------------------------------------------------

struct GeometryCase {
  std::string name;
  nt::PolyMesh mesh;
  nt::SurfaceShape shape;
  /// Smallest worst normal-line angle of the network (degrees): 0.5 ("clearly not G1"), except the
  /// icosahedron and the dodecahedron on a sphere, which give the SAME network (the split of a regular solid
  /// and of its dual, projected radially) and are nearly G1 by symmetry (worst 0.208 degrees); jittered, they
  /// are far from it.
  double notG1Deg = 0.5;
};

std::vector<GeometryCase> geometryCases() {
  std::vector<GeometryCase> c = {
      {"cube", nt::cubeMesh(), nt::sphereShape()},
      {"dodecahedron", nt::dodecahedronMesh(), nt::sphereShape(2.0), 0.2},
      {"icosahedron", nt::icosahedronMesh(), nt::sphereShape(), 0.2},
      {"icosahedron jittered", nt::jittered(nt::icosahedronMesh(), 0.1), nt::sphereShape()},
      {"dodecahedron jittered", nt::jittered(nt::dodecahedronMesh(), 0.1), nt::sphereShape()},
      {"geodesic2", nt::geodesicIcosahedronMesh(2), nt::sphereShape()},
      {"grid", nt::gridMesh(3, 2), nt::heightFieldShape()}};
  for (int k = 3; k <= 8; ++k)
    c.push_back({"fan" + std::to_string(k), nt::fanMesh(k), nt::heightFieldShape()});
  return c;
}

TEST(NetworkGeometry, ExactlyG0NotG1RegularAndPairedAsBuilt) {
  for (const auto& gc : geometryCases())
    for (auto form : {nt::PatchForm::kBicubicBezier, nt::PatchForm::kBiquarticBSpline})
      for (bool mixed : {false, true}) {
        const std::string label = gc.name +
                                  (form == nt::PatchForm::kBicubicBezier ? " bicubic" : " biquartic") +
                                  (mixed ? " mixed" : "");
        SCOPED_TRACE(label);
        const auto net = nt::buildNetwork(gc.mesh, gc.shape, {form, mixed});
        const bool reference =
            form == nt::PatchForm::kBicubicBezier && !mixed;  // printed; 100 samples per seam
        const auto check = nt::checkAllSharedEdges(net.model, reference ? 100 : 30);
        EXPECT_EQ(check.sharedEdges, net.numSeams());
        EXPECT_EQ(check.freeEdges, net.numFreeEdges());
        EXPECT_LT(check.worstGap, 1e-12);
        EXPECT_GT(check.worstAngleDeg, gc.notG1Deg);
        EXPECT_EQ(check.folds, 0);
        EXPECT_EQ(check.degenerateSamples, 0);
        // The geometric pairing is the generator's.
        std::set<std::pair<std::pair<int, int>, std::pair<int, int>>> built, found;
        for (const auto& e : net.edges)
          if (!e.free())
            built.insert(std::minmax(std::make_pair(e.sides[0].first, static_cast<int>(e.sides[0].second)),
                                     std::make_pair(e.sides[1].first, static_cast<int>(e.sides[1].second))));
        for (const auto& s : check.edges)
          found.insert(std::minmax(std::make_pair(s.a, static_cast<int>(s.ea)),
                                   std::make_pair(s.b, static_cast<int>(s.eb))));
        EXPECT_EQ(built, found);
        double minReg = 1.0;
        for (const auto& p : net.model.patches) minReg = std::min(minReg, nt::minRegularity(p.surface));
        EXPECT_GT(minReg, 0.1);
        if (reference)
          std::cout << "[network] " << label << ": " << net.model.patches.size() << " patches, "
                    << check.sharedEdges << " seams, " << check.freeEdges << " free edges, worst gap "
                    << check.worstGap << ", normal-line angle max " << check.worstAngleDeg
                    << " deg (smallest per-seam max " << check.minAngleDeg << "), min regularity " << minReg
                    << "\n";
      }
}

TEST(NetworkGeometry, BiquarticAndMixedFormsAreTheSameSurfaces) {
  for (const auto& gc : geometryCases()) {
    SCOPED_TRACE(gc.name);
    const auto cubic = nt::buildNetwork(gc.mesh, gc.shape);
    const auto quartic = nt::buildNetwork(gc.mesh, gc.shape, {nt::PatchForm::kBiquarticBSpline, false});
    const auto mixed = nt::buildNetwork(gc.mesh, gc.shape, {nt::PatchForm::kBicubicBezier, true});
    double d = 0.0;
    for (size_t p = 0; p < cubic.model.patches.size(); ++p) {
      const auto& s = cubic.model.patches[p].surface;
      EXPECT_EQ(quartic.model.patches[p].surface.degreeU(), 4);
      EXPECT_EQ(quartic.model.patches[p].surface.numU(), 6);
      EXPECT_EQ(quartic.model.patches[p].kind, PatchKind::kBSpline);
      EXPECT_EQ(cubic.model.patches[p].kind, PatchKind::kBezier);
      d = std::max(d, nt::maxGridDistance(s, quartic.model.patches[p].surface) / cubic.size);
      // The mixed patch is the same surface under its flip: compare at mapped parameters.
      const nt::ParametrisationFlip f = nt::parametrisationFlip(static_cast<int>(p));
      for (double a : {0.0, 0.3, 1.0})
        for (double b : {0.0, 0.7, 1.0}) {
          double x = f.swapUV ? b : a, y = f.swapUV ? a : b;
          if (f.reverseU) x = 1.0 - x;
          if (f.reverseV) y = 1.0 - y;
          EXPECT_LT((nt::pointAt(s, a, b) - nt::pointAt(mixed.model.patches[p].surface, x, y)).norm(),
                    1e-14 * cubic.size);
        }
    }
    EXPECT_LT(d, 1e-13);
  }
}

TEST(NetworkGeometry, CornerNormalsAreTheSurfaceNormalsAndPatchesFaceOutward) {
  for (const auto& gc : geometryCases()) {
    SCOPED_TRACE(gc.name);
    const auto net = nt::buildNetwork(gc.mesh, gc.shape);
    for (const auto& v : net.vertices)
      for (const auto& c : v.corners) {
        const Vec3 n = nt::normalAt(net.model.patches[static_cast<size_t>(c.patch)].surface, c.uMax, c.vMax);
        // Same sense: the quads keep the mesh's orientation. Edge midpoints lie on their mesh edge's cubic (the two
        // halves join C1 there), not exactly on the surface, so their corner normals only roughly agree.
        EXPECT_GT(n.dot(v.normal), v.kind == nt::VertexKind::kEdgeMidpoint ? 0.9 : 1.0 - 1e-8);
      }
  }
}

TEST(NetworkGeometry, CoonsInteriorReproducesABilinearPatch) {
  // A bilinear patch written as a bicubic: the Coons rule must give back its interior points exactly.
  const Vec3 a(0, 0, 0), b(3, 0.5, 1), c(2.5, 3, -1), d(-0.5, 2, 0.5);
  std::array<std::array<Vec3, 4>, 4> p, q;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const double s = i / 3.0, t = j / 3.0;
      p[i][j] = (1 - s) * (1 - t) * a + s * (1 - t) * b + s * t * c + (1 - s) * t * d;
    }
  q = p;
  for (int i = 1; i <= 2; ++i)
    for (int j = 1; j <= 2; ++j) q[i][j] = Vec3::Constant(99.0);
  nt::coonsInterior(q);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) EXPECT_LT((p[i][j] - q[i][j]).norm(), 1e-14);
  // And the Coons patch interpolates its boundary (checked by evaluation on the four edges).
  const BSplineSurface s = nt::bicubicBezier(q);
  EXPECT_LT((nt::pointAt(s, 1, 1) - c).norm(), 1e-14);
}

// ---------------------------------------------------------------------------------------------------------------------
// The checker on seams of known answer.
// ---------------------------------------------------------------------------------------------------------------------

/// A flat bicubic on [0, 1]^2 of the xy-plane and a second flat patch hinged on its U1 edge (x = 1) at
/// `angleDeg` (0: coplanar continuation; 180: folded back over A).
std::pair<BSplineSurface, BSplineSurface> hinge(double angleDeg) {
  const double th = angleDeg * nt::kPi / 180.0;
  std::array<std::array<Vec3, 4>, 4> pa, pb;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      pa[i][j] = Vec3(i / 3.0, j / 3.0, 0.0);
      const double r = 0.7 * i / 3.0;  // a narrower neighbour; its own parameter scale
      pb[i][j] = Vec3(1.0 + r * std::cos(th), j / 3.0, r * std::sin(th));
    }
  return {nt::bicubicBezier(pa), nt::bicubicBezier(pb)};
}

TEST(NetworkChecker, HingeAnglesAndFolds) {
  for (double angle : {0.0, 1.0, 30.0, 60.0, 120.0, 179.0}) {
    SCOPED_TRACE(angle);
    const auto [a, b] = hinge(angle);
    // B's U0 edge is A's U1 edge; try B with its edge parameter reversed as well.
    for (bool rev : {false, true}) {
      const BSplineSurface bb = rev ? b.reversedV() : b;
      const auto c = nt::checkSharedEdge(a, Edge::U1, bb, Edge::U0, 50);
      EXPECT_LT(c.maxGap, 1e-14);
      EXPECT_NEAR(c.maxAngleDeg, angle <= 90.0 ? angle : 180.0 - angle, 1e-6);
      EXPECT_EQ(c.fold(), angle > 90.0);
      EXPECT_EQ(c.degenerateSamples, 0);
    }
  }
  // A fold at a small angle (B turned back over A by 178 degrees) is reported as a fold with a 2-degree line
  // angle.
  const auto [a, b] = hinge(178.0);
  const auto c = nt::checkSharedEdge(a, Edge::U1, b.swappedUV(), Edge::V0, 50);
  EXPECT_TRUE(c.fold());
  EXPECT_EQ(c.foldSamples, 50);
  EXPECT_NEAR(c.maxAngleDeg, 2.0, 1e-6);
}

TEST(NetworkChecker, FindsShiftedGapsAndOnlyTrueSeams) {
  const auto [a, b] = hinge(20.0);
  Model m;
  m.patches.push_back({"A", PatchKind::kBezier, a});
  m.patches.push_back({"B", PatchKind::kBezier, b.reversedV()});
  auto shared = nt::findSharedEdges(m);
  ASSERT_EQ(shared.size(), 1u);
  EXPECT_EQ(shared[0].a, 0);
  EXPECT_EQ(shared[0].ea, Edge::U1);
  EXPECT_EQ(shared[0].eb, Edge::U0);
  EXPECT_TRUE(shared[0].reversed);
  EXPECT_EQ(nt::unsharedEdges(m, shared).size(), 6u);
  // Move B by 1e-4: no longer paired at the default tolerance, paired (with the gap measured) at 1e-3.
  Matrix pts = b.points();
  for (int r = 0; r < pts.rows(); ++r) pts(r, 2) += 1e-4;
  m.patches[1].surface = BSplineSurface(3, 3, b.knotsU(), b.knotsV(), 4, 4, pts);
  EXPECT_TRUE(nt::findSharedEdges(m).empty());
  shared = nt::findSharedEdges(m, 1e-3);
  ASSERT_EQ(shared.size(), 1u);
  const auto c = nt::checkSharedEdge(a, shared[0].ea, m.patches[1].surface, shared[0].eb);
  EXPECT_NEAR(c.maxGap, 1e-4, 1e-12);
}

}  // namespace
