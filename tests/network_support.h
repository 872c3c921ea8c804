#pragma once
// Test support for the local G1 scheme (issue 13): G0 networks of quad patches built from polygon meshes, and
// an INDEPENDENT checker of the seams between them.
//
// Construction: a polygon mesh (consistently oriented faces) is split once into quads, Catmull-Clark style
// without smoothing (each k-gon -> k quads through its centre and its edge midpoints). The network's vertices
// are placed on a surface (a sphere or a height field z = f(x, y)); each network edge becomes a cubic Bezier
// curve whose end tangents lie in the surface's tangent planes, shared exactly (the same doubles, possibly
// reversed) by the two quads at it; each quad becomes the bicubic Coons patch of its four edge curves. The
// network is exactly G0 and generally not G1; every corner normal equals the surface normal at its vertex.
//
// Independence rule: nothing here calls a seam analysis, pairing or repair routine. The checker uses only
// BSplineSurface::evaluate (finite differences for derivatives, Gauss-Newton for closest points); the
// generator uses only plain control-point arithmetic and the exact kernel operations degreeElevated,
// withKnotInsertedU/V, swappedUV and reversedU/V.
#include <algorithm>
#include <array>
#include <cassert>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "seam/continuity/corner.h"  // PatchCorner (plain data only)
#include "seam/core/types.h"
#include "seam/model/model.h"
#include "seam/spline/bspline_surface.h"

namespace seam::testing {

inline constexpr double kPi = std::numbers::pi;

// =====================================================================================================================
// Polygon meshes.
// =====================================================================================================================

/// Vertices and faces (index lists), every face counter-clockwise seen from outside (from +z for flat
/// meshes), so that every interior edge is used once in each direction.
struct PolyMesh {
  std::vector<Vec3> vertices;
  std::vector<std::vector<int>> faces;
};

namespace detail {

inline Vec3 newellNormal(const PolyMesh& m, const std::vector<int>& f) {
  Vec3 n = Vec3::Zero();
  for (size_t i = 0; i < f.size(); ++i) {
    const Vec3& a = m.vertices[static_cast<size_t>(f[i])];
    const Vec3& b = m.vertices[static_cast<size_t>(f[(i + 1) % f.size()])];
    n += a.cross(b);
  }
  return n;
}

/// Reverses every face whose normal points towards the origin (convex polyhedra centred at the origin).
inline void orientOutward(PolyMesh& m) {
  for (auto& f : m.faces) {
    Vec3 c = Vec3::Zero();
    for (int i : f) c += m.vertices[static_cast<size_t>(i)];
    if (newellNormal(m, f).dot(c) < 0.0) std::reverse(f.begin(), f.end());
  }
}

inline std::vector<Vec3> icosahedronVertices() {
  const double phi = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Vec3> v;
  for (double a : {-1.0, 1.0})
    for (double b : {-phi, phi}) {
      v.emplace_back(0.0, a, b);
      v.emplace_back(a, b, 0.0);
      v.emplace_back(b, 0.0, a);
    }
  return v;
}

}  // namespace detail

/// The cube [-1, 1]^3: 8 vertices (degree 3), 6 squares.
inline PolyMesh cubeMesh() {
  PolyMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back(i & 1 ? 1.0 : -1.0, i & 2 ? 1.0 : -1.0, i & 4 ? 1.0 : -1.0);
  m.faces = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  detail::orientOutward(m);
  return m;
}

/// The regular icosahedron (0, +-1, +-phi) and cyclic: 12 vertices (degree 5), 20 triangles (edge length 2).
inline PolyMesh icosahedronMesh() {
  PolyMesh m;
  m.vertices = detail::icosahedronVertices();
  const int n = static_cast<int>(m.vertices.size());
  auto adjacent = [&](int i, int j) {
    return std::abs((m.vertices[static_cast<size_t>(i)] - m.vertices[static_cast<size_t>(j)]).norm() - 2.0) <
           1e-9;
  };
  for (int i = 0; i < n; ++i)
    for (int j = i + 1; j < n; ++j)
      for (int k = j + 1; k < n; ++k)
        if (adjacent(i, j) && adjacent(j, k) && adjacent(i, k)) m.faces.push_back({i, j, k});
  detail::orientOutward(m);
  return m;
}

/// The regular dodecahedron as the dual of icosahedronMesh(): 20 vertices (degree 3), 12 pentagons.
inline PolyMesh dodecahedronMesh() {
  const PolyMesh ico = icosahedronMesh();
  PolyMesh m;
  for (const auto& f : ico.faces) {
    Vec3 c = Vec3::Zero();
    for (int i : f) c += ico.vertices[static_cast<size_t>(i)];
    m.vertices.push_back(c / 3.0);
  }
  for (size_t v = 0; v < ico.vertices.size(); ++v) {
    const Vec3 axis = ico.vertices[v].normalized();
    const Vec3 e1 = axis.unitOrthogonal();
    const Vec3 e2 = axis.cross(e1);
    std::vector<std::pair<double, int>> around;
    for (size_t f = 0; f < ico.faces.size(); ++f)
      if (std::find(ico.faces[f].begin(), ico.faces[f].end(), static_cast<int>(v)) != ico.faces[f].end()) {
        const Vec3& c = m.vertices[f];
        around.emplace_back(std::atan2(c.dot(e2), c.dot(e1)), static_cast<int>(f));
      }
    std::sort(around.begin(), around.end());
    std::vector<int> face;
    for (const auto& [angle, f] : around) face.push_back(f);
    m.faces.push_back(face);
  }
  detail::orientOutward(m);
  return m;
}

/// The frequency-m geodesic icosahedron: every icosahedron triangle cut into m^2 triangles, every vertex
/// projected to the unit sphere. 10 m^2 + 2 vertices: 12 of degree 5, the others of degree 6; 20 m^2
/// triangles.
inline PolyMesh geodesicIcosahedronMesh(int m) {
  assert(m >= 1);
  const PolyMesh ico = icosahedronMesh();
  PolyMesh out;
  auto vertexOf = [&](const Vec3& p) {
    const Vec3 q = p.normalized();
    for (size_t i = 0; i < out.vertices.size(); ++i)
      if ((out.vertices[i] - q).norm() < 1e-9) return static_cast<int>(i);
    out.vertices.push_back(q);
    return static_cast<int>(out.vertices.size()) - 1;
  };
  for (const auto& f : ico.faces) {
    const Vec3& a = ico.vertices[static_cast<size_t>(f[0])];
    const Vec3& b = ico.vertices[static_cast<size_t>(f[1])];
    const Vec3& c = ico.vertices[static_cast<size_t>(f[2])];
    auto at = [&](int i, int j) {
      return vertexOf(a + (static_cast<double>(i) / m) * (b - a) + (static_cast<double>(j) / m) * (c - a));
    };
    for (int i = 0; i < m; ++i)
      for (int j = 0; i + j < m; ++j) {
        out.faces.push_back({at(i, j), at(i + 1, j), at(i, j + 1)});
        if (i + j + 2 <= m) out.faces.push_back({at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)});
      }
  }
  detail::orientOutward(out);
  return out;
}

/// An open fan (a disc) of k triangles around the centre vertex 0 at the origin of the xy-plane; rim vertices
/// 1..k at `radius`, angles 2 pi (i - 1) / k (+ `phase`). Counter-clockwise seen from +z.
inline PolyMesh fanMesh(int k, double radius = 1.0, double phase = 0.0) {
  assert(k >= 3);
  PolyMesh m;
  m.vertices.push_back(Vec3::Zero());
  for (int i = 0; i < k; ++i) {
    const double a = phase + 2.0 * kPi * i / k;
    m.vertices.emplace_back(radius * std::cos(a), radius * std::sin(a), 0.0);
  }
  for (int i = 1; i <= k; ++i) m.faces.push_back({0, i, i % k + 1});
  return m;
}

/// nx x ny unit quads of the xy-plane, centred at the origin, counter-clockwise seen from +z.
inline PolyMesh gridMesh(int nx, int ny, double cell = 1.0) {
  PolyMesh m;
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.vertices.emplace_back(cell * (i - 0.5 * nx), cell * (j - 0.5 * ny), 0.0);
  auto id = [&](int i, int j) { return j * (nx + 1) + i; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) m.faces.push_back({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)});
  return m;
}

/// The mesh with every vertex moved by `amount` x (mean edge length) in a fixed pseudo-random direction per
/// vertex index (deterministic): breaks the symmetry of the regular solids (whose networks on a sphere are
/// nearly G1, see network_support_test) without changing the topology. Meant for meshes that are then placed
/// on a surface.
inline PolyMesh jittered(const PolyMesh& mesh, double amount) {
  double total = 0.0;
  int count = 0;
  for (const auto& f : mesh.faces)
    for (size_t i = 0; i < f.size(); ++i, ++count)
      total += (mesh.vertices[static_cast<size_t>(f[i])] -
                mesh.vertices[static_cast<size_t>(f[(i + 1) % f.size()])])
                   .norm();
  const double len = count > 0 ? total / count : 1.0;
  PolyMesh out = mesh;
  for (size_t i = 0; i < out.vertices.size(); ++i) {
    const double x = static_cast<double>(i) + 1.0;
    out.vertices[i] +=
        amount * len * Vec3(std::sin(12.9898 * x), std::sin(78.233 * x + 1.0), std::sin(37.719 * x + 2.0));
  }
  return out;
}

// =====================================================================================================================
// The quad split (topology only).
// =====================================================================================================================

enum class VertexKind { kOriginal, kEdgeMidpoint, kFaceCentre };

/// The quads of the split, before placement: quad corners in the order (u0v0, u1v0, u1v1, u0v1),
/// counter-clockwise seen from outside; corner u0v0 is always the original vertex, u1v1 the face centre.
struct QuadSplit {
  std::vector<Vec3> points;  ///< unplaced: original vertices, edge midpoints, face centroids
  std::vector<VertexKind> kinds;
  /// For an edge midpoint: the two original vertices of its mesh edge (smaller index first); {-1, -1} otherwise.
  std::vector<std::pair<int, int>> midpointEnds;
  std::vector<std::array<int, 4>> quads;
};

inline QuadSplit splitIntoQuads(const PolyMesh& mesh) {
  QuadSplit s;
  s.points = mesh.vertices;
  s.kinds.assign(mesh.vertices.size(), VertexKind::kOriginal);
  s.midpointEnds.assign(mesh.vertices.size(), {-1, -1});
  std::map<std::pair<int, int>, int> midpoint;
  auto mid = [&](int a, int b) {
    const std::pair<int, int> key(std::min(a, b), std::max(a, b));
    if (auto it = midpoint.find(key); it != midpoint.end()) return it->second;
    s.points.push_back(0.5 * (mesh.vertices[static_cast<size_t>(a)] + mesh.vertices[static_cast<size_t>(b)]));
    s.kinds.push_back(VertexKind::kEdgeMidpoint);
    s.midpointEnds.push_back(key);
    return midpoint[key] = static_cast<int>(s.points.size()) - 1;
  };
  for (const auto& f : mesh.faces) {
    const int k = static_cast<int>(f.size());
    Vec3 c = Vec3::Zero();
    for (int i : f) c += mesh.vertices[static_cast<size_t>(i)];
    s.points.push_back(c / k);
    s.kinds.push_back(VertexKind::kFaceCentre);
    s.midpointEnds.push_back({-1, -1});
    const int centre = static_cast<int>(s.points.size()) - 1;
    for (int i = 0; i < k; ++i) {
      const int v = f[static_cast<size_t>(i)];
      const int next = f[static_cast<size_t>((i + 1) % k)];
      const int prev = f[static_cast<size_t>((i + k - 1) % k)];
      s.quads.push_back({v, mid(v, next), centre, mid(prev, v)});
    }
  }
  return s;
}

// =====================================================================================================================
// Surfaces the network is placed on.
// =====================================================================================================================

/// place(p): a point of the surface for the unplaced point p; normal(q): the unit normal at a surface point
/// q, in the sense of the mesh's outside.
struct SurfaceShape {
  std::function<Vec3(const Vec3&)> place;
  std::function<Vec3(const Vec3&)> normal;
};

/// The sphere of `radius` about the origin (radial projection; outward normal).
inline SurfaceShape sphereShape(double radius = 1.0) {
  return {[radius](const Vec3& p) -> Vec3 { return radius * p.normalized(); },
          [](const Vec3& q) -> Vec3 { return q.normalized(); }};
}

/// z = amplitude sin(kx x) cos(ky y) + bilinear x y.
struct HeightField {
  double amplitude = 0.3, kx = 1.0, ky = 1.3, bilinear = 0.1;
  [[nodiscard]] double operator()(double x, double y) const {
    return amplitude * std::sin(kx * x) * std::cos(ky * y) + bilinear * x * y;
  }
  [[nodiscard]] Vec2 gradient(double x, double y) const {
    return {amplitude * kx * std::cos(kx * x) * std::cos(ky * y) + bilinear * y,
            -amplitude * ky * std::sin(kx * x) * std::sin(ky * y) + bilinear * x};
  }
};

/// The graph of f over the xy-plane (vertical projection; upward normal).
inline SurfaceShape heightFieldShape(HeightField f = {}) {
  return {[f](const Vec3& p) -> Vec3 {
            return {p.x(), p.y(), f(p.x(), p.y())};
          },
          [f](const Vec3& q) -> Vec3 {
            const Vec2 g = f.gradient(q.x(), q.y());
            return Vec3(-g.x(), -g.y(), 1.0).normalized();
          }};
}

// =====================================================================================================================
// The network of patches.
// =====================================================================================================================

enum class PatchForm {
  kBicubicBezier,     ///< 4 x 4 control points, PatchKind::kBezier
  kBiquarticBSpline,  ///< the same surface raised to degree 4 and knot 1/2 inserted once each way (6 x 6,
                      ///< kBSpline)
};

struct NetworkOptions {
  PatchForm form = PatchForm::kBicubicBezier;
  /// Reparametrise patch i by parametrisationFlip(i) (identity, swap u/v, reverse u, swap then reverse v,
  /// cyclically), so that neighbours see their shared edges in every combination of orientations.
  bool mixedParametrisations = false;
  /// Patch names are namePrefix + index.
  std::string namePrefix = "P";
  /// Each original mesh edge is one cubic (end tangents in the tangent planes of its end vertices) split at t = 1/2
  /// by de Casteljau, so its two halves join C1 at the edge midpoint (which then lies on that cubic, not exactly on
  /// the surface). false: the two halves are independent cubics through the projected midpoint (a corner in the
  /// edge there, in general).
  bool c1MeshEdges = true;
};

/// The reparametrisation applied to patch i under NetworkOptions::mixedParametrisations: i % 4, see above.
struct ParametrisationFlip {
  bool swapUV = false;
  bool reverseU = false;  ///< applied after the swap
  bool reverseV = false;
};
inline ParametrisationFlip parametrisationFlip(int patchIndex) {
  switch (patchIndex % 4) {
    case 1:
      return {true, false, false};
    case 2:
      return {false, true, false};
    case 3:
      return {true, false, true};
    default:
      return {};
  }
}
inline BSplineSurface applyFlip(const BSplineSurface& s, const ParametrisationFlip& f) {
  BSplineSurface r = f.swapUV ? s.swappedUV() : s;
  if (f.reverseU) r = r.reversedU();
  if (f.reverseV) r = r.reversedV();
  return r;
}
inline PatchCorner applyFlip(PatchCorner c, const ParametrisationFlip& f) {
  if (f.swapUV) std::swap(c.uMax, c.vMax);
  if (f.reverseU) c.uMax = !c.uMax;
  if (f.reverseV) c.vMax = !c.vMax;
  return c;
}
inline Edge applyFlip(Edge e, const ParametrisationFlip& f) {
  if (f.swapUV) e = e == Edge::U0 ? Edge::V0 : e == Edge::U1 ? Edge::V1 : e == Edge::V0 ? Edge::U0 : Edge::U1;
  if (f.reverseU && isUEdge(e)) e = e == Edge::U0 ? Edge::U1 : Edge::U0;
  if (f.reverseV && !isUEdge(e)) e = e == Edge::V0 ? Edge::V1 : Edge::V0;
  return e;
}

struct NetworkVertex {
  Vec3 point = Vec3::Zero();   ///< on the surface
  Vec3 normal = Vec3::Zero();  ///< the surface's unit normal there
  VertexKind kind = VertexKind::kOriginal;
  int valence = 0;        ///< quads at the vertex
  bool boundary = false;  ///< on a free edge
  std::vector<PatchCorner>
      corners;  ///< (patch, corner) of every patch at the vertex, in the final parametrisation
};

/// One edge of the network: its end vertices and the (patch, edge) sides that hold it (1 = free, 2 = seam).
struct NetworkEdge {
  int v0 = 0, v1 = 0;
  std::vector<std::pair<int, Edge>> sides;
  [[nodiscard]] bool free() const { return sides.size() == 1; }
};

struct Network {
  Model model;  ///< patches "P0", "P1", ... (namePrefix)
  std::vector<NetworkVertex> vertices;
  std::vector<NetworkEdge> edges;
  /// Network vertices at the corners (u0v0, u1v0, u1v1, u0v1) of each patch as built (before any flip).
  std::vector<std::array<int, 4>> quads;
  std::vector<ParametrisationFlip> flips;  ///< per patch
  double size = 0.0;                       ///< bounding-box diagonal of the control points

  [[nodiscard]] int numFaces() const { return static_cast<int>(quads.size()); }
  [[nodiscard]] int numFreeEdges() const {
    return static_cast<int>(
        std::count_if(edges.begin(), edges.end(), [](const NetworkEdge& e) { return e.free(); }));
  }
  [[nodiscard]] int numSeams() const { return static_cast<int>(edges.size()) - numFreeEdges(); }
  [[nodiscard]] bool closed() const { return numFreeEdges() == 0; }
  [[nodiscard]] int eulerCharacteristic() const {
    return static_cast<int>(vertices.size()) - static_cast<int>(edges.size()) + numFaces();
  }
  /// Number of vertices with this kind, valence and boundary flag.
  [[nodiscard]] int count(VertexKind kind, int valence, bool boundary = false) const {
    return static_cast<int>(std::count_if(vertices.begin(), vertices.end(), [&](const NetworkVertex& v) {
      return v.kind == kind && v.valence == valence && v.boundary == boundary;
    }));
  }
};

/// Cubic Bezier control points of the edge from a to b (points on the surface, unit normals na, nb): the
/// chord projected onto each end's tangent plane, length |chord| / 3.
inline std::array<Vec3, 4> edgeCurve(const Vec3& a, const Vec3& na, const Vec3& b, const Vec3& nb) {
  const Vec3 chord = b - a;
  const double len = chord.norm();
  const Vec3 ta = (chord - chord.dot(na) * na).normalized() * (len / 3.0);
  const Vec3 tb = (-chord + chord.dot(nb) * nb).normalized() * (len / 3.0);
  return {a, a + ta, b + tb, b};
}

/// The bicubic bilinearly blended Coons patch of four cubic boundaries, in Bezier form: the boundary rows are
/// given in `p` (p[i][j], i along u), the interior points are computed, exactly, as ruled-in-u + ruled-in-v -
/// bilinear, each raised to degree 3: P_ij = (1 - j/3) P_i0 + (j/3) P_i3 + (1 - i/3) P_0j + (i/3) P_3j
///                                 - [(1 - i/3)(1 - j/3) P_00 + (i/3)(1 - j/3) P_30 + (1 - i/3)(j/3) P_03 +
///                                 (i/3)(j/3) P_33],
/// e.g. P_11 = (2 P_10 + P_13 + 2 P_01 + P_31) / 3 - (4 P_00 + 2 P_30 + 2 P_03 + P_33) / 9.
inline void coonsInterior(std::array<std::array<Vec3, 4>, 4>& p) {
  for (int i = 1; i <= 2; ++i)
    for (int j = 1; j <= 2; ++j) {
      const double s = i / 3.0, t = j / 3.0;
      p[i][j] =
          (1 - t) * p[i][0] + t * p[i][3] + (1 - s) * p[0][j] + s * p[3][j] -
          ((1 - s) * (1 - t) * p[0][0] + s * (1 - t) * p[3][0] + (1 - s) * t * p[0][3] + s * t * p[3][3]);
    }
}

inline BSplineSurface bicubicBezier(const std::array<std::array<Vec3, 4>, 4>& p) {
  Matrix pts(16, 3);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) pts.row(i * 4 + j) = p[i][j].transpose();
  const std::vector<double> k = {0, 0, 0, 0, 1, 1, 1, 1};
  return {3, 3, KnotVector(k), KnotVector(k), 4, 4, pts};
}

/// The biquartic B-spline form of a bicubic Bezier patch: degree raised by one each way, knot 1/2 inserted
/// once each way (6 x 6 control points). The same surface.
inline BSplineSurface biquarticBSpline(const BSplineSurface& bicubic) {
  return bicubic.degreeElevated(1, 1).withKnotInsertedU(0.5).withKnotInsertedV(0.5);
}

/// Builds the network of `mesh` placed on `shape`.
inline Network buildNetwork(const PolyMesh& mesh, const SurfaceShape& shape,
                            const NetworkOptions& options = {}) {
  const QuadSplit split = splitIntoQuads(mesh);
  Network net;
  net.quads = split.quads;
  net.vertices.resize(split.points.size());
  for (size_t i = 0; i < split.points.size(); ++i) {
    net.vertices[i].point = shape.place(split.points[i]);
    net.vertices[i].normal = shape.normal(net.vertices[i].point);
    net.vertices[i].kind = split.kinds[i];
  }
  // Undirected edges: curve stored from the smaller vertex index to the larger one.
  std::map<std::pair<int, int>, int> edgeIndex;
  std::vector<std::array<Vec3, 4>> curves;
  // Halves of the original mesh edges (c1MeshEdges), keyed like edgeIndex.
  std::map<std::pair<int, int>, std::array<Vec3, 4>> halves;
  if (options.c1MeshEdges)
    for (size_t m = 0; m < split.midpointEnds.size(); ++m) {
      const auto [a, b] = split.midpointEnds[m];
      if (a < 0) continue;
      const auto& va = net.vertices[static_cast<size_t>(a)];
      const auto& vb = net.vertices[static_cast<size_t>(b)];
      const std::array<Vec3, 4> full = edgeCurve(va.point, va.normal, vb.point, vb.normal);
      // de Casteljau at 1/2.
      const Vec3 p01 = 0.5 * (full[0] + full[1]), p12 = 0.5 * (full[1] + full[2]), p23 = 0.5 * (full[2] + full[3]);
      const Vec3 p012 = 0.5 * (p01 + p12), p123 = 0.5 * (p12 + p23), mid = 0.5 * (p012 + p123);
      auto& vm = net.vertices[m];
      vm.point = mid;
      vm.normal = shape.normal(mid);
      const int mi = static_cast<int>(m);
      auto store = [&](int from, int to, std::array<Vec3, 4> c) {  // c runs from `from` to `to`
        if (from > to) std::reverse(c.begin(), c.end());
        halves[{std::min(from, to), std::max(from, to)}] = c;
      };
      store(a, mi, {full[0], p01, p012, mid});
      store(mi, b, {mid, p123, p23, full[3]});
    }
  auto curve = [&](int a, int b) {
    const std::pair<int, int> key(std::min(a, b), std::max(a, b));
    auto it = edgeIndex.find(key);
    if (it == edgeIndex.end()) {
      const auto& va = net.vertices[static_cast<size_t>(key.first)];
      const auto& vb = net.vertices[static_cast<size_t>(key.second)];
      auto h = halves.find(key);
      curves.push_back(h != halves.end() ? h->second : edgeCurve(va.point, va.normal, vb.point, vb.normal));
      net.edges.push_back({key.first, key.second, {}});
      it = edgeIndex.emplace(key, static_cast<int>(curves.size()) - 1).first;
    }
    std::array<Vec3, 4> c = curves[static_cast<size_t>(it->second)];
    if (a > b) std::reverse(c.begin(), c.end());
    return std::make_pair(it->second, c);
  };
  for (size_t q = 0; q < split.quads.size(); ++q) {
    const int patch = static_cast<int>(q);
    const auto [a, b, c, d] = split.quads[q];
    const ParametrisationFlip flip =
        options.mixedParametrisations ? parametrisationFlip(patch) : ParametrisationFlip{};
    std::array<std::array<Vec3, 4>, 4> p;
    const auto [eV0, cV0] = curve(a, b);  // v = 0: a -> b along u
    const auto [eU1, cU1] = curve(b, c);  // u = 1: b -> c along v
    const auto [eV1, cV1] = curve(d, c);  // v = 1: d -> c along u
    const auto [eU0, cU0] = curve(a, d);  // u = 0: a -> d along v
    for (int i = 0; i < 4; ++i) {
      p[i][0] = cV0[i];
      p[3][i] = cU1[i];
      p[i][3] = cV1[i];
      p[0][i] = cU0[i];
    }
    coonsInterior(p);
    BSplineSurface s = bicubicBezier(p);
    if (options.form == PatchForm::kBiquarticBSpline) s = biquarticBSpline(s);
    s = applyFlip(s, flip);
    net.model.patches.push_back(
        {options.namePrefix + std::to_string(patch),
         options.form == PatchForm::kBicubicBezier ? PatchKind::kBezier : PatchKind::kBSpline, std::move(s)});
    net.flips.push_back(flip);
    net.edges[static_cast<size_t>(eV0)].sides.emplace_back(patch, applyFlip(Edge::V0, flip));
    net.edges[static_cast<size_t>(eU1)].sides.emplace_back(patch, applyFlip(Edge::U1, flip));
    net.edges[static_cast<size_t>(eV1)].sides.emplace_back(patch, applyFlip(Edge::V1, flip));
    net.edges[static_cast<size_t>(eU0)].sides.emplace_back(patch, applyFlip(Edge::U0, flip));
    const std::array<PatchCorner, 4> corners = {
        PatchCorner{patch, false, false}, PatchCorner{patch, true, false}, PatchCorner{patch, true, true},
        PatchCorner{patch, false, true}};
    for (int k = 0; k < 4; ++k) {
      auto& v = net.vertices[static_cast<size_t>(split.quads[q][static_cast<size_t>(k)])];
      v.corners.push_back(applyFlip(corners[static_cast<size_t>(k)], flip));
      ++v.valence;
    }
  }
  for (const auto& e : net.edges)
    if (e.free())
      net.vertices[static_cast<size_t>(e.v0)].boundary = net.vertices[static_cast<size_t>(e.v1)].boundary =
          true;
  BoundingBox box;
  for (const auto& patch : net.model.patches)
    for (int r = 0; r < patch.surface.points().rows(); ++r)
      box.add(Vec3(patch.surface.points().row(r).transpose()));
  net.size = box.diagonal();
  return net;
}

// =====================================================================================================================
// The independent checker (BSplineSurface::evaluate only).
// =====================================================================================================================

/// Point of s at normalised parameters (a, b) in [0, 1]^2 of its domain (clamped).
inline Vec3 pointAt(const BSplineSurface& s, double a, double b) {
  const Interval du = s.domainU(), dv = s.domainV();
  a = std::clamp(a, 0.0, 1.0);
  b = std::clamp(b, 0.0, 1.0);
  const VecX p = s.evaluate(du.lo + a * du.length(), dv.lo + b * dv.length());
  return {p[0], p[1], p[2]};
}

/// Normalised (a, b) of the point of edge e at normalised edge parameter t (increasing surface parameter) and
/// at normalised distance w inside the patch.
inline Vec2 edgeParameters(Edge e, double t, double w = 0.0) {
  switch (e) {
    case Edge::U0:
      return {w, t};
    case Edge::U1:
      return {1.0 - w, t};
    case Edge::V0:
      return {t, w};
    case Edge::V1:
      return {t, 1.0 - w};
  }
  return {0.0, 0.0};
}
inline Vec3 edgePoint(const BSplineSurface& s, Edge e, double t, double w = 0.0) {
  const Vec2 ab = edgeParameters(e, t, w);
  return pointAt(s, ab.x(), ab.y());
}

/// Finite-difference step, as a fraction of the domain.
inline constexpr double kFdStep = 1e-5;

/// d f / dx at x in [0, 1] by finite differences of step h: central when x +- h is inside [0, 1], else
/// one-sided of second order (-3 f0 + 4 f1 - f2) / 2h into the interval.
template <class F>
Vec3 derivative01(const F& f, double x, double h = kFdStep) {
  if (x - h >= 0.0 && x + h <= 1.0) return (f(x + h) - f(x - h)) / (2.0 * h);
  if (x - h < 0.0) return (-3.0 * f(x) + 4.0 * f(x + h) - f(x + 2.0 * h)) / (2.0 * h);
  return (3.0 * f(x) - 4.0 * f(x - h) + f(x - 2.0 * h)) / (2.0 * h);
}

/// The partial derivatives (per unit of normalised parameter) of s at normalised (a, b), by finite
/// differences.
inline std::pair<Vec3, Vec3> partials(const BSplineSurface& s, double a, double b) {
  return {derivative01([&](double x) { return pointAt(s, x, b); }, a),
          derivative01([&](double y) { return pointAt(s, a, y); }, b)};
}

/// Along-edge tangent and inward cross derivative at the edge point t (both per unit normalised parameter).
struct EdgeFrame {
  Vec3 point, along, inward;
  [[nodiscard]] Vec3 normal() const { return along.cross(inward).normalized(); }
  /// Sine of the angle between along and inward (0: the normal is undefined).
  [[nodiscard]] double regularity() const {
    return along.cross(inward).norm() / (along.norm() * inward.norm());
  }
};
inline EdgeFrame edgeFrame(const BSplineSurface& s, Edge e, double t) {
  return {edgePoint(s, e, t), derivative01([&](double x) { return edgePoint(s, e, x); }, t),
          derivative01([&](double w) { return edgePoint(s, e, t, w); }, 0.0)};
}

/// The normalised edge parameter of the point of edge e of s closest to p: Gauss-Newton steps on |S(t) - p|^2
/// with finite-difference tangents, clamped to [0, 1], started from `guess` or, without one (guess < 0), from
/// the best of `coarse` + 1 samples.
inline double closestOnEdge(const BSplineSurface& s, Edge e, const Vec3& p, double guess = -1.0,
                            int coarse = 32) {
  double t = guess;
  if (t < 0.0) {
    double bestD = std::numeric_limits<double>::infinity();
    for (int k = 0; k <= coarse; ++k) {
      const double x = static_cast<double>(k) / coarse;
      const double d = (edgePoint(s, e, x) - p).squaredNorm();
      if (d < bestD) {
        bestD = d;
        t = x;
      }
    }
  }
  for (int it = 0; it < 20; ++it) {
    const Vec3 q = edgePoint(s, e, t);
    const Vec3 d = derivative01([&](double x) { return edgePoint(s, e, x); }, t);
    const double next = std::clamp(t + (p - q).dot(d) / d.squaredNorm(), 0.0, 1.0);
    const bool done = std::abs(next - t) < 1e-15;
    t = next;
    if (done) break;
  }
  return t;
}

/// Angle in degrees (0..90) between the lines spanned by two vectors.
inline double lineAngleDeg(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b))) * 180.0 / kPi;
}

struct EdgeCheck {
  double maxGap = 0.0;        ///< largest distance from a sample of A's edge to B's edge
  double maxAngleDeg = 0.0;   ///< largest angle between the normal lines (0..90)
  double worstT = 0.0;        ///< A's normalised edge parameter of the largest angle
  int foldSamples = 0;        ///< samples where both inward cross derivatives point to the same side
  int degenerateSamples = 0;  ///< samples where a normal is undefined (regularity < 1e-8)
  [[nodiscard]] bool fold() const { return foldSamples > 0; }
};

/// Compares A's edge ea with B's edge eb at `samples` points of A's edge (t = k / (samples - 1)); the
/// corresponding point of B is found by closest point (a coarse search for the first sample, then
/// continuation from the previous one), never assumed.
inline EdgeCheck checkSharedEdge(const BSplineSurface& a, Edge ea, const BSplineSurface& b, Edge eb,
                                 int samples = 100) {
  EdgeCheck r;
  double tb = -1.0;
  for (int k = 0; k < samples; ++k) {
    const double t = static_cast<double>(k) / (samples - 1);
    const EdgeFrame fa = edgeFrame(a, ea, t);
    tb = closestOnEdge(b, eb, fa.point, tb);
    const EdgeFrame fb = edgeFrame(b, eb, tb);
    r.maxGap = std::max(r.maxGap, (fa.point - fb.point).norm());
    if (fa.regularity() < 1e-8 || fb.regularity() < 1e-8) {
      ++r.degenerateSamples;
      continue;
    }
    const Vec3 na = fa.normal(), nb = fb.normal();
    const double angle = lineAngleDeg(na, nb);
    if (angle > r.maxAngleDeg) {
      r.maxAngleDeg = angle;
      r.worstT = t;
    }
    // The cross-boundary directions in A's tangent plane, across A's edge tangent: opposite sides unless
    // folded.
    const Vec3 tan = fa.along.normalized();
    auto across = [&](const Vec3& d) { return Vec3(d - d.dot(tan) * tan - d.dot(na) * na); };
    if (across(fa.inward).dot(across(fb.inward)) > 0.0) ++r.foldSamples;
  }
  return r;
}

/// Two patch edges that coincide (found by geometry).
struct SharedEdge {
  int a = 0;
  Edge ea = Edge::U0;
  int b = 0;
  Edge eb = Edge::U0;
  bool reversed = false;  ///< B's edge runs the other way
};

/// Every pair of coinciding patch edges of the model, by geometry alone: the end points agree (in the same or
/// the reversed order) within `tol` and the points at 1/4, 1/2, 3/4 of A's edge lie within `tol` of B's edge.
/// Default tol: 1e-9 x the bounding-box diagonal of the control points.
inline std::vector<SharedEdge> findSharedEdges(const Model& model, double tol = -1.0) {
  if (tol < 0.0) {
    BoundingBox box;
    for (const auto& p : model.patches)
      for (int r = 0; r < p.surface.points().rows(); ++r)
        box.add(Vec3(p.surface.points().row(r).transpose()));
    tol = 1e-9 * box.diagonal();
  }
  struct Ends {
    Vec3 p0, p1;
  };
  const int n = static_cast<int>(model.patches.size());
  std::vector<Ends> ends(static_cast<size_t>(4 * n));
  for (int p = 0; p < n; ++p)
    for (int e = 0; e < 4; ++e)
      ends[static_cast<size_t>(4 * p + e)] = {
          edgePoint(model.patches[static_cast<size_t>(p)].surface, kAllEdges[e], 0.0),
          edgePoint(model.patches[static_cast<size_t>(p)].surface, kAllEdges[e], 1.0)};
  std::vector<SharedEdge> out;
  for (int i = 0; i < 4 * n; ++i)
    for (int j = i + 1; j < 4 * n; ++j) {
      const Ends& x = ends[static_cast<size_t>(i)];
      const Ends& y = ends[static_cast<size_t>(j)];
      const bool same = (x.p0 - y.p0).norm() <= tol && (x.p1 - y.p1).norm() <= tol;
      const bool rev = (x.p0 - y.p1).norm() <= tol && (x.p1 - y.p0).norm() <= tol;
      if (!same && !rev) continue;
      if ((x.p0 - x.p1).norm() <= tol) continue;  // a collapsed edge
      const auto& sa = model.patches[static_cast<size_t>(i / 4)].surface;
      const auto& sb = model.patches[static_cast<size_t>(j / 4)].surface;
      const Edge ea = kAllEdges[static_cast<size_t>(i % 4)], eb = kAllEdges[static_cast<size_t>(j % 4)];
      bool on = true;
      for (double t : {0.25, 0.5, 0.75}) {
        const Vec3 q = edgePoint(sa, ea, t);
        on = on && (edgePoint(sb, eb, closestOnEdge(sb, eb, q)) - q).norm() <= tol;
      }
      if (on) out.push_back({i / 4, ea, j / 4, eb, !same});
    }
  return out;
}

/// The patch edges that findSharedEdges did not pair.
inline std::vector<std::pair<int, Edge>> unsharedEdges(const Model& model,
                                                       const std::vector<SharedEdge>& shared) {
  std::vector<std::pair<int, Edge>> out;
  for (int p = 0; p < static_cast<int>(model.patches.size()); ++p)
    for (Edge e : kAllEdges) {
      const bool used = std::any_of(shared.begin(), shared.end(), [&](const SharedEdge& s) {
        return (s.a == p && s.ea == e) || (s.b == p && s.eb == e);
      });
      if (!used) out.emplace_back(p, e);
    }
  return out;
}

struct NetworkCheck {
  int sharedEdges = 0;
  int freeEdges = 0;
  double worstGap = 0.0;
  double worstAngleDeg = 0.0;
  int worstAngleEdge = -1;                                       ///< index into `edges`
  double minAngleDeg = std::numeric_limits<double>::infinity();  ///< smallest per-edge maximum angle
  int folds = 0;                                                 ///< shared edges with a fold
  int degenerateSamples = 0;
  std::vector<SharedEdge> edges;
  std::vector<EdgeCheck> checks;  ///< per shared edge
};

/// Uneven interior knots (issue 36 goal 4): 1 or 2 knots inserted exactly at random parameters in (0.15, 0.85) into
/// each direction of every patch (fixed seed), so that no two patches share their knots; the geometry is unchanged.
inline void insertUnevenKnots(Model& model, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> at(0.15, 0.85);
  for (Patch& p : model.patches) {
    for (int dir = 0; dir < 2; ++dir) {
      const int n = 1 + static_cast<int>(rng() % 2);
      for (int k = 0; k < n; ++k) {
        const Interval d = dir == 0 ? p.surface.domainU() : p.surface.domainV();
        const double t = d.lo + at(rng) * d.length();
        p.surface = dir == 0 ? p.surface.withKnotInsertedU(t) : p.surface.withKnotInsertedV(t);
      }
    }
    p.kind = PatchKind::kBSpline;
  }
}

/// findSharedEdges + checkSharedEdge on every shared edge.
inline NetworkCheck checkAllSharedEdges(const Model& model, int samples = 100, double tol = -1.0) {
  NetworkCheck r;
  r.edges = findSharedEdges(model, tol);
  r.sharedEdges = static_cast<int>(r.edges.size());
  r.freeEdges = static_cast<int>(unsharedEdges(model, r.edges).size());
  for (size_t i = 0; i < r.edges.size(); ++i) {
    const SharedEdge& s = r.edges[i];
    const EdgeCheck c = checkSharedEdge(model.patches[static_cast<size_t>(s.a)].surface, s.ea,
                                        model.patches[static_cast<size_t>(s.b)].surface, s.eb, samples);
    r.worstGap = std::max(r.worstGap, c.maxGap);
    if (r.worstAngleEdge < 0 || c.maxAngleDeg > r.worstAngleDeg) {
      r.worstAngleDeg = c.maxAngleDeg;
      r.worstAngleEdge = static_cast<int>(i);
    }
    r.minAngleDeg = std::min(r.minAngleDeg, c.maxAngleDeg);
    r.folds += c.fold() ? 1 : 0;
    r.degenerateSamples += c.degenerateSamples;
    r.checks.push_back(c);
  }
  return r;
}

// =====================================================================================================================
// Surface comparisons.
// =====================================================================================================================

/// Bounding-box diagonal of the control points.
inline double patchSize(const BSplineSurface& s) {
  BoundingBox box;
  for (int r = 0; r < s.points().rows(); ++r) box.add(Vec3(s.points().row(r).transpose()));
  return box.diagonal();
}

/// Largest distance between a and b sampled at the same normalised parameters on an n x n grid.
inline double maxGridDistance(const BSplineSurface& a, const BSplineSurface& b, int n = 21) {
  double d = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double x = static_cast<double>(i) / (n - 1), y = static_cast<double>(j) / (n - 1);
      d = std::max(d, (pointAt(a, x, y) - pointAt(b, x, y)).norm());
    }
  return d;
}

/// Symmetric sampled distance between edge ea of a and edge eb of b (closest points, both ways, n samples
/// each).
inline double edgeDistance(const BSplineSurface& a, Edge ea, const BSplineSurface& b, Edge eb, int n = 50) {
  double d = 0.0, tb = -1.0, ta = -1.0;
  for (int k = 0; k < n; ++k) {
    const double t = static_cast<double>(k) / (n - 1);
    const Vec3 p = edgePoint(a, ea, t), q = edgePoint(b, eb, t);
    tb = closestOnEdge(b, eb, p, tb);
    ta = closestOnEdge(a, ea, q, ta);
    d = std::max(d, (edgePoint(b, eb, tb) - p).norm());
    d = std::max(d, (edgePoint(a, ea, ta) - q).norm());
  }
  return d;
}

/// Smallest sine of the angle between the partial derivatives over an n x n grid (boundary included,
/// one-sided differences there): > 0 means the normal is defined at every sample.
inline double minRegularity(const BSplineSurface& s, int n = 11) {
  double m = 1.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const auto [su, sv] = partials(s, static_cast<double>(i) / (n - 1), static_cast<double>(j) / (n - 1));
      const double den = su.norm() * sv.norm();
      m = std::min(m, den > 0.0 ? su.cross(sv).norm() / den : 0.0);
    }
  return m;
}

/// The unit normal (S_u x S_v, finite differences) at normalised (a, b).
inline Vec3 normalAt(const BSplineSurface& s, double a, double b) {
  const auto [su, sv] = partials(s, a, b);
  return su.cross(sv).normalized();
}

}  // namespace seam::testing
