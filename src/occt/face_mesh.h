#pragma once
// Triangle meshes of B-rep faces for the report's 3-D view (issue 17 §4): OpenCASCADE's BRepMesh_IncrementalMesh,
// which respects the trims (holes, outer loops), read back face by face with BRep_Tool::Triangulation, the face's
// location applied and its orientation kept (triangles counter-clockwise seen from the side the face's normal points
// to). Also the faces' trim polygons in parameter space for their other users: the mesher's grid fallback and the
// heal's fold grid (gridInsideTrims). Private to seam::occt; the public entry is BRepCheckOptions::meshFaces
// (brep_check.h).
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <gp_Pnt2d.hxx>
#include <optional>
#include <vector>

#include "occt/cad_internal.h"
#include "seam/occt/brep_check.h"

namespace seam::occt::detail {

/// Meshes `shape` with the linear deflection `deflection` (model units) and kFaceMeshAngle, then returns the mesh
/// of each of `faces` (named "F<k>", k the 1-based position in `faces`) where `wanted[k-1]` is true (all when
/// `wanted` is empty). A face OpenCASCADE leaves without triangles (trj3's half discs, each trimmed by one open edge:
/// BRepMesh reports an open wire and skips them) is triangulated by seam's grid fallback instead
/// (BRepFaceMesh::gridFallback): its surface sampled on a grid over the box of its trim polygons, an open polygon
/// closed as an outer loop along the surface's parameter rectangle (its ends joined to the nearest border points, the
/// border followed counter-clockwise), the triangles whose parameter-space centroid is inside kept; with no usable
/// trim, or nothing inside, the face gets no mesh. Point normals are the face's
/// surface normals (reversed for a reversed face); where the surface normal vanishes (a pole) or points against the
/// node's triangles, the mean of the adjacent triangles' normals. Throws Standard_Failure as OpenCASCADE does (the caller guards it).
///
///
/// `deadline` (when not null) bounds OpenCASCADE's meshing: once it has expired BRepMesh is told to stop (UserBreak),
/// and the faces it has not triangulated by then take the grid fallback (`deadline->expired()` says so).
std::vector<BRepFaceMesh> meshFaces(const TopoDS_Shape& shape, const std::vector<TopoDS_Face>& faces,
                                    double deflection, const std::vector<bool>& wanted = {},
                                    const Handle(DeadlineIndicator)& deadline = nullptr);

/// The points of the (n + 1) x (n + 1) grid over the box [u0, u1] x [v0, v1] that lie inside `face`'s trims or on them
/// (in the sense of OpenCASCADE's BRepTopAdaptor_FClass2d: not OUT), row by row in u then v as `u0 + (u1 - u0) i / n`,
/// `v0 + (v1 - v0) j / n`. One scan per grid column over the trims' parameter-space polygons (pcurves sampled to
/// kTrimPolygonDeflectionRel of the box), even-odd rule, a point within kTrimOnRel of the box of a polygon segment
/// counted as on it: linear in the polygons' segments per column where the classifier is per point. Nothing when
/// the trims do not make closed polygons in (u, v) (an open wire, a pcurve missing, a band of a periodic surface
/// bounded by two wires that each run once around it): the caller then asks OpenCASCADE point by point.
/// Throws Standard_Failure as OpenCASCADE does (the caller guards it).
std::optional<std::vector<gp_Pnt2d>> gridInsideTrims(const TopoDS_Face& face, int n, double u0, double u1, double v0,
                                                     double v1);

}  // namespace seam::occt::detail
