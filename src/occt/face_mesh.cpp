#include "occt/face_mesh.h"

#include <fmt/format.h>

#include <BRepAdaptor_Surface.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <Message_ProgressRange.hxx>
#include <BRepTools_WireExplorer.hxx>
#include <BRep_Tool.hxx>
#include <GCPnts_TangentialDeflection.hxx>
#include <Geom2dAdaptor_Curve.hxx>
#include <Geom2d_Curve.hxx>
#include <OSD_Signal.hxx>
#include <Poly_Triangulation.hxx>
#include <Precision.hxx>
#include <Standard_Failure.hxx>
#include <TopAbs_Orientation.hxx>
#include <TopExp_Explorer.hxx>
#include <TopLoc_Location.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Wire.hxx>
#include <gp_Pnt.hxx>
#include <gp_Pnt2d.hxx>
#include <gp_Trsf.hxx>
#include <gp_Vec.hxx>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>
#include <utility>

#include "seam/core/tolerances.h"

namespace seam::occt::detail {

namespace {

/// Points per trim edge of the fallback's parameter-space polygons (pcurves sampled evenly in their parameter).
constexpr int kFallbackEdgePoints = 64;
/// Grid cells per parameter direction of the fallback: the deflection decides between these bounds.
constexpr int kFallbackMinCells = 32;
constexpr int kFallbackMaxCells = 128;
/// Nodes per side of the coarse grid that estimates the face's 3-D extent along u and v.
constexpr int kExtentSamples = 9;
/// A trim loop whose ends lie within this fraction of the parameter rectangle's size is closed.
constexpr double kLoopClosedRel = 1e-6;
/// gridInsideTrims' polygons: each pcurve sampled (GCPnts_TangentialDeflection) to within this fraction of the grid
/// box's size of the curve, and to at most this turn (radians) between segments. OpenCASCADE's classifier uses a
/// coarser polygon of its own (a few points per knot span).
constexpr double kTrimPolygonDeflectionRel = 1e-6;
constexpr double kTrimPolygonAngle = 0.05;
/// gridInsideTrims: a wire's polygon whose ends lie within this fraction of the box's size is closed by a segment
/// (pcurve ends a reader leaves that far apart on real files; far below the grid's spacing); further apart, the
/// polygon is open and the grid is not classified here.
constexpr double kTrimLoopClosedRel = 1e-4;
/// gridInsideTrims: a point within this fraction of the box's size of a polygon segment is on the trim (not OUT).
constexpr double kTrimOnRel = 1e-9;

using Loop = std::vector<gp_Pnt2d>;  // a closed polygon in the surface's (u, v); the last point joins the first

/// The parameter rectangle the fallback works in: the surface's own bounds where they are finite, else the box of
/// the face's trim polygons.
struct Rect {
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
  double width() const { return u1 - u0; }
  double height() const { return v1 - v0; }
};

/// The position of `p` (on the rectangle's border) along it, counter-clockwise from (u0, v0), each side of length 1.
double borderParameter(const Rect& r, const gp_Pnt2d& p) {
  const double du = (p.X() - r.u0) / r.width(), dv = (p.Y() - r.v0) / r.height();
  const std::array<double, 4> dist = {std::abs(dv), std::abs(1.0 - du), std::abs(1.0 - dv), std::abs(du)};
  switch (std::min_element(dist.begin(), dist.end()) - dist.begin()) {
    case 0: return std::clamp(du, 0.0, 1.0);              // bottom, u increasing
    case 1: return 1.0 + std::clamp(dv, 0.0, 1.0);        // right, v increasing
    case 2: return 2.0 + std::clamp(1.0 - du, 0.0, 1.0);  // top, u decreasing
    default: return 3.0 + std::clamp(1.0 - dv, 0.0, 1.0);  // left, v decreasing
  }
}

gp_Pnt2d borderPoint(const Rect& r, double t) {
  t = std::fmod(t, 4.0);
  const int side = std::min(static_cast<int>(t), 3);
  const double s = t - side;
  switch (side) {
    case 0: return {r.u0 + s * r.width(), r.v0};
    case 1: return {r.u1, r.v0 + s * r.height()};
    case 2: return {r.u1 - s * r.width(), r.v1};
    default: return {r.u0, r.v1 - s * r.height()};
  }
}

/// The point of the rectangle's border nearest to `p`, distances measured relative to the rectangle's sides.
gp_Pnt2d nearestBorderPoint(const Rect& r, const gp_Pnt2d& p) {
  const double du = (p.X() - r.u0) / r.width(), dv = (p.Y() - r.v0) / r.height();
  const std::array<double, 4> dist = {std::abs(dv), std::abs(1.0 - du), std::abs(1.0 - dv), std::abs(du)};
  const double u = std::clamp(p.X(), r.u0, r.u1), v = std::clamp(p.Y(), r.v0, r.v1);
  switch (std::min_element(dist.begin(), dist.end()) - dist.begin()) {
    case 0: return {u, r.v0};
    case 1: return {r.u1, v};
    case 2: return {u, r.v1};
    default: return {r.u0, v};
  }
}

/// Closes an open trim polygon (its end E does not come back to its start S) as an outer loop whose face lies on its
/// left: E and S are joined to the nearest points of the parameter rectangle's border, and the border is followed
/// counter-clockwise from E's point to S's, through the corners between. This is how a trim curve that ends on the
/// surface's boundary (or at a pole) bounds a region in the systems that write such files (e.g. trj3's half discs:
/// one semicircle per face, open in the file).
void closeAlongBorder(const Rect& r, Loop& loop) {
  const gp_Pnt2d e = nearestBorderPoint(r, loop.back()), s = nearestBorderPoint(r, loop.front());
  const double te = borderParameter(r, e);
  double ts = borderParameter(r, s);
  if (ts < te) ts += 4.0;
  loop.push_back(e);
  for (double corner = std::floor(te) + 1.0; corner < ts; corner += 1.0) loop.push_back(borderPoint(r, corner));
  loop.push_back(s);
}

/// The parameters at which an edge's pcurve on [f, l] is sampled, in the order the wire runs (from l to f when
/// `reversed`); empty when it cannot be sampled.
using EdgeSampler = std::function<std::vector<double>(const Handle(Geom2d_Curve)&, double f, double l, bool reversed)>;

/// The polygon of one wire of `face` (oriented FORWARD) in its surface's parameters, the wire's edges as
/// BRepTools_WireExplorer chains them, each pcurve at the parameters `sample` gives. `strict`: nothing when an edge
/// has no usable pcurve or cannot be chained; else such edges are left out.
std::optional<Loop> wirePolygon(const TopoDS_Wire& wire, const TopoDS_Face& face, const EdgeSampler& sample,
                                bool strict) {
  Loop loop;
  int visited = 0;
  for (BRepTools_WireExplorer e(wire, face); e.More(); e.Next(), ++visited) {
    const TopoDS_Edge& edge = e.Current();
    double f = 0.0, l = 0.0;
    const Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(edge, face, f, l);
    const std::vector<double> at = pc.IsNull() || !std::isfinite(f) || !std::isfinite(l)
                                       ? std::vector<double>()
                                       : sample(pc, f, l, edge.Orientation() == TopAbs_REVERSED);
    if (at.empty() && strict) return std::nullopt;
    for (const double t : at) loop.push_back(pc->Value(t));
  }
  if (strict) {  // the wire explorer leaves out edges it cannot chain
    int edges = 0;
    for (TopExp_Explorer e(wire, TopAbs_EDGE); e.More(); e.Next()) ++edges;
    if (visited != edges) return std::nullopt;
  }
  return loop;
}

/// The trim polygons of `face` (oriented FORWARD) in its surface's parameters, one per wire, as the wires run (the
/// face on their left), each pcurve at kFallbackEdgePoints + 1 even parameters; an open wire's polygon is left open.
std::vector<Loop> trimPolygons(const TopoDS_Face& face) {
  const EdgeSampler even = [](const Handle(Geom2d_Curve)&, double f, double l, bool reversed) {
    std::vector<double> at;
    for (int i = 0; i <= kFallbackEdgePoints; ++i) {
      const double t = static_cast<double>(i) / kFallbackEdgePoints;
      at.push_back(reversed ? l + (f - l) * t : f + (l - f) * t);
    }
    return at;
  };
  std::vector<Loop> loops;
  for (TopExp_Explorer w(face, TopAbs_WIRE); w.More(); w.Next())
    if (std::optional<Loop> loop = wirePolygon(TopoDS::Wire(w.Current()), face, even, false); loop->size() >= 2)
      loops.push_back(std::move(*loop));
  return loops;
}

/// The box of the polygons' points.
Rect boxOf(const std::vector<Loop>& loops) {
  Rect box{std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest(),
           std::numeric_limits<double>::max(), std::numeric_limits<double>::lowest()};
  for (const Loop& l : loops)
    for (const gp_Pnt2d& p : l) {
      box.u0 = std::min(box.u0, p.X()), box.u1 = std::max(box.u1, p.X());
      box.v0 = std::min(box.v0, p.Y()), box.v1 = std::max(box.v1, p.Y());
    }
  return box;
}

/// Even-odd rule over all loops: inside the face.
bool insideLoops(const std::vector<Loop>& loops, double u, double v) {
  bool inside = false;
  for (const Loop& loop : loops)
    for (size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++) {
      const gp_Pnt2d& a = loop[i];
      const gp_Pnt2d& b = loop[j];
      if ((a.Y() > v) != (b.Y() > v) && u < a.X() + (v - a.Y()) * (b.X() - a.X()) / (b.Y() - a.Y()))
        inside = !inside;
    }
  return inside;
}

/// The largest 3-D length of the rows (along u) and of the columns (along v) of a coarse grid over the box.
std::pair<double, double> extent3d(const BRepAdaptor_Surface& s, const Rect& box) {
  double lu = 0.0, lv = 0.0;
  for (int i = 0; i < kExtentSamples; ++i) {
    double rowU = 0.0, rowV = 0.0;
    const double a = static_cast<double>(i) / (kExtentSamples - 1);
    for (int j = 1; j < kExtentSamples; ++j) {
      const double b0 = static_cast<double>(j - 1) / (kExtentSamples - 1);
      const double b1 = static_cast<double>(j) / (kExtentSamples - 1);
      const double v = box.v0 + a * box.height(), u = box.u0 + a * box.width();
      rowU += s.Value(box.u0 + b0 * box.width(), v).Distance(s.Value(box.u0 + b1 * box.width(), v));
      rowV += s.Value(u, box.v0 + b0 * box.height()).Distance(s.Value(u, box.v0 + b1 * box.height()));
    }
    lu = std::max(lu, rowU);
    lv = std::max(lv, rowV);
  }
  return {lu, lv};
}

/// seam's own triangulation of a face BRepMesh leaves without triangles (issue 17 §4: trj3's eight half discs, each
/// trimmed by one open edge, which BRepMesh reports as an open wire and skips): the surface sampled on a grid over
/// the box of the face's trim polygons (open ones closed along the parameter rectangle, closeAlongBorder), keeping
/// the grid triangles whose parameter-space centroid lies inside them (even-odd rule). The trims are respected to
/// within one grid cell. Null when the face has no usable trim or nothing lies inside.
Handle(Poly_Triangulation) gridTriangulation(const TopoDS_Face& face, double deflection) {
  const TopoDS_Face forward = TopoDS::Face(face.Oriented(TopAbs_FORWARD));
  // Unrestricted: the surface's own bounds (a restricted adaptor has the face's box, which an open trim need not
  // reach).
  const BRepAdaptor_Surface surface(forward, /*restriction=*/false);
  Rect rect{surface.FirstUParameter(), surface.LastUParameter(), surface.FirstVParameter(),
            surface.LastVParameter()};
  const bool finite = !Precision::IsInfinite(rect.u0) && !Precision::IsInfinite(rect.u1) &&
                      !Precision::IsInfinite(rect.v0) && !Precision::IsInfinite(rect.v1) && rect.width() > 0.0 &&
                      rect.height() > 0.0;
  std::vector<Loop> loops = trimPolygons(forward);
  if (loops.empty()) return {};
  if (!finite) rect = boxOf(loops);  // an unbounded surface (a plane): the trims' own box
  if (!(rect.width() > 0.0 && rect.height() > 0.0)) return {};
  const double closedTol = kLoopClosedRel * std::hypot(rect.width(), rect.height());
  for (Loop& loop : loops)
    if (loop.front().Distance(loop.back()) > closedTol) closeAlongBorder(rect, loop);
  Rect box = boxOf(loops);
  box = {std::max(box.u0, rect.u0), std::min(box.u1, rect.u1), std::max(box.v0, rect.v0), std::min(box.v1, rect.v1)};
  if (!(box.width() > 0.0 && box.height() > 0.0)) return {};
  const auto [lu, lv] = extent3d(surface, box);
  auto cells = [&](double length) {
    const double n = deflection > 0.0 ? std::ceil(length / deflection) : kFallbackMaxCells;
    return static_cast<int>(
        std::clamp(n, static_cast<double>(kFallbackMinCells), static_cast<double>(kFallbackMaxCells)));
  };
  const int nu = cells(lu), nv = cells(lv);
  // Node (i, j) at (u0 + i du, v0 + j dv); only the nodes of kept triangles are numbered (1-based, as OpenCASCADE).
  const double du = box.width() / nu, dv = box.height() / nv;
  std::vector<int> index(static_cast<size_t>((nu + 1) * (nv + 1)), 0);
  std::vector<gp_Pnt> point(index.size());
  for (size_t g = 0; g < point.size(); ++g)  // the adaptor applies the face's location
    point[g] = surface.Value(box.u0 + static_cast<double>(g % static_cast<size_t>(nu + 1)) * du,
                             box.v0 + static_cast<double>(g / static_cast<size_t>(nu + 1)) * dv);
  // A triangle with two corners on a pole (a collapsed side of the grid) has no area and no normal: dropped.
  auto flat = [&](const std::array<int, 3>& t) {
    const gp_Pnt &a = point[static_cast<size_t>(t[0])], &b = point[static_cast<size_t>(t[1])],
                 &c = point[static_cast<size_t>(t[2])];
    const double side = std::max({a.Distance(b), b.Distance(c), c.Distance(a)});
    return gp_Vec(a, b).Crossed(gp_Vec(a, c)).Magnitude() <= kRoundoff * side * side;
  };
  std::vector<std::array<int, 3>> kept;  // grid node ids
  auto id = [&](int i, int j) { return j * (nu + 1) + i; };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      // Two triangles per cell, counter-clockwise in (u, v): (i,j) (i+1,j) (i+1,j+1) and (i,j) (i+1,j+1) (i,j+1).
      const std::array<std::array<int, 3>, 2> tris = {{{id(i, j), id(i + 1, j), id(i + 1, j + 1)},
                                                       {id(i, j), id(i + 1, j + 1), id(i, j + 1)}}};
      const std::array<std::pair<double, double>, 2> centroid = {
          std::pair{box.u0 + (i + 2.0 / 3.0) * du, box.v0 + (j + 1.0 / 3.0) * dv},
          std::pair{box.u0 + (i + 1.0 / 3.0) * du, box.v0 + (j + 2.0 / 3.0) * dv}};
      for (int k = 0; k < 2; ++k)
        if (insideLoops(loops, centroid[static_cast<size_t>(k)].first, centroid[static_cast<size_t>(k)].second) &&
            !flat(tris[static_cast<size_t>(k)]))
          kept.push_back(tris[static_cast<size_t>(k)]);
    }
  if (kept.empty()) return {};
  int nodes = 0;
  for (const auto& t : kept)
    for (int g : t)
      if (index[static_cast<size_t>(g)] == 0) index[static_cast<size_t>(g)] = ++nodes;
  Handle(Poly_Triangulation) tri = new Poly_Triangulation(nodes, static_cast<int>(kept.size()), /*hasUV=*/true);
  for (int g = 0; g < static_cast<int>(index.size()); ++g) {
    const int n = index[static_cast<size_t>(g)];
    if (n == 0) continue;
    tri->SetNode(n, point[static_cast<size_t>(g)]);
    tri->SetUVNode(n, gp_Pnt2d(box.u0 + (g % (nu + 1)) * du, box.v0 + (g / (nu + 1)) * dv));
  }
  for (int t = 0; t < static_cast<int>(kept.size()); ++t) {
    const auto& k = kept[static_cast<size_t>(t)];
    tri->SetTriangle(t + 1, Poly_Triangle(index[static_cast<size_t>(k[0])], index[static_cast<size_t>(k[1])],
                                          index[static_cast<size_t>(k[2])]));
  }
  return tri;
}

/// The view's mesh of one face from a triangulation of it (nodes moved by `trsf`).
BRepFaceMesh faceMesh(const TopoDS_Face& face, const Handle(Poly_Triangulation)& tri, const gp_Trsf& trsf) {
  const bool reversed = face.Orientation() == TopAbs_REVERSED;
  BRepFaceMesh m;
  const int n = tri->NbNodes();
  m.points.reserve(static_cast<size_t>(n));
  for (int i = 1; i <= n; ++i) {
    const gp_Pnt p = tri->Node(i).Transformed(trsf);
    m.points.emplace_back(p.X(), p.Y(), p.Z());
  }
  m.triangles.reserve(static_cast<size_t>(3 * tri->NbTriangles()));
  std::vector<Vec3> meanNormal(static_cast<size_t>(n), Vec3::Zero());
  for (int t = 1; t <= tri->NbTriangles(); ++t) {
    int a = 0, b = 0, c = 0;
    tri->Triangle(t).Get(a, b, c);
    if (reversed) std::swap(b, c);  // the face's side, not the surface's
    --a, --b, --c;
    m.triangles.insert(m.triangles.end(), {a, b, c});
    const Vec3 normal = (m.points[static_cast<size_t>(b)] - m.points[static_cast<size_t>(a)])
                            .cross(m.points[static_cast<size_t>(c)] - m.points[static_cast<size_t>(a)]);
    for (int v : {a, b, c}) meanNormal[static_cast<size_t>(v)] += normal;  // area-weighted
  }
  // The surface normal at each node's (u, v): D1U x D1V of the located surface (BRepAdaptor_Surface), reversed
  // for a reversed face. Where the two derivatives are parallel up to round-off, or one of them vanishes next to the
  // other (a pole, a degenerate side), the direction is noise: the triangles' mean normal is kept there, and also
  // where the surface's normal points against the node's own triangles (noise that passed the two tests: at
  // trj3's disc centres, a pole, a tenth of the nodes had it reversed).
  const bool uv = tri->HasUVNodes();
  const BRepAdaptor_Surface surface(face);
  m.normals.reserve(static_cast<size_t>(n));
  for (int i = 1; i <= n; ++i) {
    Vec3 normal = meanNormal[static_cast<size_t>(i - 1)];
    if (uv) {
      const gp_Pnt2d q = tri->UVNode(i);
      gp_Pnt p;
      gp_Vec du, dv;
      surface.D1(q.X(), q.Y(), p, du, dv);
      const gp_Vec cross = du.Crossed(dv);
      const double a = du.Magnitude(), b = dv.Magnitude();
      const Vec3 surfaceNormal =
          reversed ? Vec3(-cross.X(), -cross.Y(), -cross.Z()) : Vec3(cross.X(), cross.Y(), cross.Z());
      if (cross.Magnitude() > kRoundoff * a * b && std::min(a, b) > kRoundoff * std::max(a, b) &&
          surfaceNormal.dot(normal) > 0.0)
        normal = surfaceNormal;
    }
    const double len = normal.norm();
    m.normals.push_back(len > 0.0 ? Vec3(normal / len) : Vec3::UnitZ());
  }
  return m;
}

}  // namespace

std::optional<std::vector<gp_Pnt2d>> gridInsideTrims(const TopoDS_Face& face, int n, double u0, double u1, double v0,
                                                     double v1) {
  const double size = std::max(u1 - u0, v1 - v0);
  if (n < 1 || !(size > 0.0) || !std::isfinite(size)) return std::nullopt;
  const TopoDS_Face forward = TopoDS::Face(face.Oriented(TopAbs_FORWARD));
  const double deflection = kTrimPolygonDeflectionRel * size, on = kTrimOnRel * size;
  if (!(deflection >= Precision::Confusion())) return std::nullopt;  // below what GCPnts can sample to
  struct Segment {
    gp_Pnt2d a, b;
  };
  const EdgeSampler fine = [&](const Handle(Geom2d_Curve)& pc, double f, double l, bool reversed) {
    std::vector<double> at;
    if (!(l > f)) return at;
    const GCPnts_TangentialDeflection points(Geom2dAdaptor_Curve(pc, f, l), kTrimPolygonAngle, deflection, 2);
    const int m = points.NbPoints();
    for (int k = 1; m >= 2 && k <= m; ++k) at.push_back(points.Parameter(reversed ? m + 1 - k : k));
    return at;
  };
  std::vector<Segment> segments;
  for (TopExp_Explorer w(forward, TopAbs_WIRE); w.More(); w.Next()) {
    const std::optional<Loop> loop = wirePolygon(TopoDS::Wire(w.Current()), forward, fine, true);
    // Every edge in it, and back to its start (a band of a periodic surface bounded by wires that each run once
    // around it is not).
    if (!loop || loop->size() < 2 || loop->front().Distance(loop->back()) > kTrimLoopClosedRel * size)
      return std::nullopt;
    for (size_t k = 0; k < loop->size(); ++k) segments.push_back({(*loop)[k], (*loop)[(k + 1) % loop->size()]});
  }
  if (segments.empty()) return std::nullopt;
  std::vector<gp_Pnt2d> out;
  std::vector<double> crossings;
  std::vector<std::pair<double, double>> onSpans;  // the v ranges of the segments within `on` of the column
  for (int i = 0; i <= n; ++i) {
    const double u = u0 + (u1 - u0) * i / n;
    crossings.clear();
    onSpans.clear();
    for (const Segment& s : segments) {
      const double lo = std::min(s.a.X(), s.b.X()), hi = std::max(s.a.X(), s.b.X());
      if (u < lo - on || u > hi + on) continue;
      double vlo = std::min(s.a.Y(), s.b.Y()), vhi = std::max(s.a.Y(), s.b.Y());
      if (hi - lo > 2.0 * on) {  // the segment's part within the strip |u' - u| <= on
        const auto vAt = [&](double x) {
          const double t = std::clamp((x - s.a.X()) / (s.b.X() - s.a.X()), 0.0, 1.0);
          return s.a.Y() + t * (s.b.Y() - s.a.Y());
        };
        vlo = std::min(vAt(u - on), vAt(u + on));
        vhi = std::max(vAt(u - on), vAt(u + on));
      }
      onSpans.emplace_back(vlo - on, vhi + on);
      // Half-open in u: a column through a polygon vertex counts the two segments there once.
      if ((s.a.X() > u) != (s.b.X() > u))
        crossings.push_back(s.a.Y() + (u - s.a.X()) * (s.b.Y() - s.a.Y()) / (s.b.X() - s.a.X()));
    }
    std::sort(crossings.begin(), crossings.end());
    for (int j = 0; j <= n; ++j) {
      const double v = v0 + (v1 - v0) * j / n;
      bool inside = (std::lower_bound(crossings.begin(), crossings.end(), v) - crossings.begin()) % 2 == 1;
      if (!inside)
        inside = std::any_of(onSpans.begin(), onSpans.end(),
                             [&](const std::pair<double, double>& r) { return v >= r.first && v <= r.second; });
      if (inside) out.emplace_back(u, v);
    }
  }
  return out;
}

std::vector<BRepFaceMesh> meshFaces(const TopoDS_Shape& shape, const std::vector<TopoDS_Face>& faces,
                                    double deflection, const std::vector<bool>& wanted,
                                    const Handle(DeadlineIndicator)& deadline) {
  // Relative deflection off: `deflection` is an absolute length. In parallel: BRepMesh meshes faces on threads.
  // The budget: BRepMesh polls its progress range's UserBreak between faces (and inside long steps).
  {
    IMeshTools_Parameters parameters;  // as the (deflection, relative, angle, parallel) constructor sets them
    parameters.Deflection = deflection;
    parameters.Angle = kFaceMeshAngle;
    parameters.Relative = false;
    parameters.InParallel = true;
    BRepMesh_IncrementalMesh mesher(shape, parameters,
                                    deadline.IsNull() ? Message_ProgressRange() : deadline->Start());
    (void)mesher;
  }
  std::vector<BRepFaceMesh> out;
  for (size_t k = 0; k < faces.size(); ++k) {
    if (!wanted.empty() && (k >= wanted.size() || !wanted[k])) continue;
    const TopoDS_Face& face = faces[k];
    TopLoc_Location loc;
    Handle(Poly_Triangulation) tri = BRep_Tool::Triangulation(face, loc);
    gp_Trsf trsf = loc.Transformation();
    bool fallback = false;
    if (tri.IsNull() || tri->NbTriangles() == 0) {
      try {
        tri = gridTriangulation(face, deflection);
      } catch (const Standard_Failure& f) {
        if (f.IsKind(STANDARD_TYPE(OSD_Signal))) throw;  // a crash ends the check (brep_check.cpp)
        tri.Nullify();
      }
      if (tri.IsNull()) continue;
      trsf = gp_Trsf();  // its nodes are already located
      fallback = true;
    }
    BRepFaceMesh m = faceMesh(face, tri, trsf);
    m.face = fmt::format("F{}", k + 1);
    m.gridFallback = fallback;
    out.push_back(std::move(m));
  }
  return out;
}

}  // namespace seam::occt::detail
