#pragma once
// Triangle meshes of B-rep faces for the report's 3-D view (issue 17 §4): OpenCASCADE's BRepMesh_IncrementalMesh,
// which respects the trims (holes, outer loops), read back face by face with BRep_Tool::Triangulation, the face's
// location applied and its orientation kept (triangles counter-clockwise seen from the side the face's normal points
// to). Private to seam::occt; the public entry is BRepCheckOptions::meshFaces (brep_check.h).
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
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

}  // namespace seam::occt::detail
