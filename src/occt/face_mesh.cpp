#include "occt/face_mesh.h"

#include <fmt/format.h>

#include <BRepAdaptor_Surface.hxx>
#include <BRepMesh_IncrementalMesh.hxx>
#include <BRep_Tool.hxx>
#include <Poly_Triangulation.hxx>
#include <TopAbs_Orientation.hxx>
#include <TopLoc_Location.hxx>
#include <gp_Pnt.hxx>
#include <gp_Pnt2d.hxx>
#include <gp_Trsf.hxx>
#include <gp_Vec.hxx>

#include <cmath>
#include <utility>

#include "seam/core/tolerances.h"

namespace seam::occt::detail {

std::vector<BRepFaceMesh> meshFaces(const TopoDS_Shape& shape, const std::vector<TopoDS_Face>& faces,
                                    double deflection, const std::vector<bool>& wanted) {
  // Relative deflection off: `deflection` is an absolute length. In parallel: BRepMesh meshes faces on threads.
  BRepMesh_IncrementalMesh mesher(shape, deflection, /*isRelative=*/false, kFaceMeshAngle, /*isInParallel=*/true);
  (void)mesher;
  std::vector<BRepFaceMesh> out;
  for (size_t k = 0; k < faces.size(); ++k) {
    if (!wanted.empty() && (k >= wanted.size() || !wanted[k])) continue;
    const TopoDS_Face& face = faces[k];
    TopLoc_Location loc;
    const Handle(Poly_Triangulation) tri = BRep_Tool::Triangulation(face, loc);
    if (tri.IsNull() || tri->NbTriangles() == 0) continue;
    const gp_Trsf trsf = loc.Transformation();
    const bool reversed = face.Orientation() == TopAbs_REVERSED;
    BRepFaceMesh m;
    m.face = fmt::format("F{}", k + 1);
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
    // for a reversed face. Where the two derivatives are parallel up to round-off (a pole, a degenerate side) the
    // direction is noise: the triangles' mean normal is kept there.
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
        if (cross.Magnitude() > kRoundoff * du.Magnitude() * dv.Magnitude())
          normal = reversed ? Vec3(-cross.X(), -cross.Y(), -cross.Z()) : Vec3(cross.X(), cross.Y(), cross.Z());
      }
      const double len = normal.norm();
      m.normals.push_back(len > 0.0 ? Vec3(normal / len) : Vec3::UnitZ());
    }
    out.push_back(std::move(m));
  }
  return out;
}

}  // namespace seam::occt::detail
