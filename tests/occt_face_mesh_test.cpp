// The report's 3-D view of trimmed B-rep faces (issue 17 §4): OpenCASCADE's triangulation of a face keeps its trims.
// Expected values come from plane geometry, not from the mesher: a square of side 2L with a circular hole of radius
// R has the area 4L^2 - pi R^2 exactly; the mesh's boundary nodes lie on the circle, so its hole is a polygon
// inscribed in it, and each chord cuts off a circular segment of area at most (its arc length) x (its sagitta), the
// sagitta being bounded by the linear deflection d. Hence 0 <= area(mesh) - (4L^2 - pi R^2) <= 2 pi R d.
#include <gtest/gtest.h>
#include <unistd.h>

#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <STEPControl_Writer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Wire.hxx>
#include <gp_Ax1.hxx>
#include <gp_Ax2.hxx>
#include <gp_Circ.hxx>
#include <gp_Pln.hxx>
#include <gp_Trsf.hxx>
#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include "occt/face_mesh.h"
#include "seam/core/tolerances.h"
#include "seam/occt/brep_check.h"

namespace seam {
namespace {

namespace fs = std::filesystem;
constexpr double kPi = std::numbers::pi;
constexpr double kHalfSide = 10.0, kRadius = 4.0;  // the square [-L, L]^2 and the hole's radius
/// Round-off of summing a few thousand triangle areas of size ~1 in a model of size ~10.
constexpr double kAreaRoundoff = 1e-9;

/// The plane z = 0 over [-L, L]^2 with a circular hole of radius R around the origin.
TopoDS_Face plateWithHole() {
  const gp_Pln plane;  // z = 0, normal +z
  BRepBuilderAPI_MakeFace plate(plane, -kHalfSide, kHalfSide, -kHalfSide, kHalfSide);
  const TopoDS_Edge circle = BRepBuilderAPI_MakeEdge(gp_Circ(gp_Ax2(), kRadius));
  const TopoDS_Wire hole = BRepBuilderAPI_MakeWire(circle);
  plate.Add(TopoDS::Wire(hole.Reversed()));  // an inner loop runs clockwise
  EXPECT_TRUE(plate.IsDone());
  return plate.Face();
}

double exactArea() { return 4.0 * kHalfSide * kHalfSide - kPi * kRadius * kRadius; }

/// The mesh's area, and (through `areaVector`) the sum of its triangles' area vectors.
double meshArea(const occt::BRepFaceMesh& m, Vec3* areaVector = nullptr) {
  double area = 0.0;
  Vec3 sum = Vec3::Zero();
  for (size_t t = 0; t + 2 < m.triangles.size(); t += 3) {
    const Vec3& a = m.points[static_cast<size_t>(m.triangles[t])];
    const Vec3& b = m.points[static_cast<size_t>(m.triangles[t + 1])];
    const Vec3& c = m.points[static_cast<size_t>(m.triangles[t + 2])];
    const Vec3 n = 0.5 * (b - a).cross(c - a);
    area += n.norm();
    sum += n;
  }
  if (areaVector != nullptr) *areaVector = sum;
  return area;
}

void expectAreaWithinDeflectionBound(const occt::BRepFaceMesh& m, double deflection) {
  const double excess = meshArea(m) - exactArea();
  EXPECT_GE(excess, -kAreaRoundoff) << "the hole's polygon is inscribed in the circle";
  EXPECT_LE(excess, 2.0 * kPi * kRadius * deflection + kAreaRoundoff) << "deflection " << deflection;
}

TEST(OcctFaceMesh, PlateWithAHoleHasTheExactAreaWithinTheDeflectionBound) {
  for (const double deflection : {0.1, 0.01, 0.001}) {
    const TopoDS_Face face = plateWithHole();
    const auto meshes = occt::detail::meshFaces(face, {face}, deflection);
    ASSERT_EQ(meshes.size(), 1u);
    const occt::BRepFaceMesh& m = meshes[0];
    EXPECT_EQ(m.face, "F1");
    ASSERT_EQ(m.normals.size(), m.points.size());
    expectAreaWithinDeflectionBound(m, deflection);
    // No triangle covers the hole: every triangle's centroid lies outside the circle (and inside the square).
    for (size_t t = 0; t + 2 < m.triangles.size(); t += 3) {
      const Vec3 c = (m.points[static_cast<size_t>(m.triangles[t])] + m.points[static_cast<size_t>(m.triangles[t + 1])] +
                      m.points[static_cast<size_t>(m.triangles[t + 2])]) /
                     3.0;
      EXPECT_GT(std::hypot(c.x(), c.y()), kRadius - deflection) << "triangle " << t / 3;
      EXPECT_LE(std::max(std::abs(c.x()), std::abs(c.y())), kHalfSide);
    }
    Vec3 areaVector;
    meshArea(m, &areaVector);
    EXPECT_GT(areaVector.z(), 0.0) << "counter-clockwise seen from +z, the face's normal";
    for (const Vec3& n : m.normals) EXPECT_NEAR(n.z(), 1.0, kRoundoff);
  }
}

// A reversed face (its normal -z): the triangles turn the other way and the normals point down; a located face (a
// rotation and a translation as a TopLoc_Location, not baked into the geometry) is meshed where it stands.
TEST(OcctFaceMesh, OrientationAndLocationAreRespected) {
  constexpr double kDeflection = 0.01;
  const TopoDS_Face reversed = TopoDS::Face(plateWithHole().Reversed());
  const auto r = occt::detail::meshFaces(reversed, {reversed}, kDeflection);
  ASSERT_EQ(r.size(), 1u);
  Vec3 areaVector;
  meshArea(r[0], &areaVector);
  EXPECT_LT(areaVector.z(), 0.0);
  for (const Vec3& n : r[0].normals) EXPECT_NEAR(n.z(), -1.0, kRoundoff);

  gp_Trsf move;
  move.SetRotation(gp_Ax1(gp_Pnt(0, 0, 0), gp_Dir(1, 0, 0)), kPi / 2.0);  // (x, y, z) -> (x, -z, y): normal -y
  gp_Trsf shift;
  shift.SetTranslation(gp_Vec(100.0, 200.0, 300.0));
  const TopoDS_Face located = TopoDS::Face(BRepBuilderAPI_Transform(plateWithHole(), shift * move, false).Shape());
  const auto l = occt::detail::meshFaces(located, {located}, kDeflection);
  ASSERT_EQ(l.size(), 1u);
  expectAreaWithinDeflectionBound(l[0], kDeflection);
  const gp_Dir normal = gp_Dir(0, 0, 1).Transformed(move);
  for (size_t i = 0; i < l[0].points.size(); ++i) {
    const Vec3& p = l[0].points[i];
    EXPECT_NEAR(p.y(), 200.0, kAreaRoundoff) << "in the moved plane y = 200";
    EXPECT_NEAR(l[0].normals[i].dot(Vec3(normal.X(), normal.Y(), normal.Z())), 1.0, kRoundoff);
  }
  meshArea(l[0], &areaVector);
  EXPECT_GT(areaVector.dot(Vec3(normal.X(), normal.Y(), normal.Z())), 0.0);
}

// The public route of `seam report`: the face written as STEP, read back by checkBRepFile with meshFaces; the face
// is trimmed (a hole), its mesh has the plate's area within the bound of the deflection the check reports, which is
// kFaceMeshDeflectionRel x the model's diagonal.
TEST(OcctFaceMesh, CheckBRepFileMeshesTrimmedFaces) {
  const fs::path file =
      fs::temp_directory_path() / ("seam_face_mesh_test_" + std::to_string(::getpid()) + "_plate.step");
  STEPControl_Writer w;
  ASSERT_EQ(w.Transfer(plateWithHole(), STEPControl_AsIs), IFSelect_RetDone);
  ASSERT_EQ(w.Write(file.string().c_str()), IFSelect_RetDone);
  occt::BRepCheckOptions o;
  o.meshFaces = true;
  o.meshTrimmedOnly = true;
  const Result<occt::BRepCheckReport> r = occt::checkBRepFile(file, o);
  const Result<occt::BRepCheckReport> plain = occt::checkBRepFile(file);  // without meshFaces: no meshes
  fs::remove(file);
  ASSERT_TRUE(plain.isOk()) << plain.status().message();
  EXPECT_TRUE(plain->faceMeshes.empty());
  EXPECT_EQ(plain->meshDeflection, 0.0);
  ASSERT_TRUE(r.isOk()) << r.status().message();
  ASSERT_EQ(r->import.faces.size(), 1u);
  EXPECT_TRUE(r->import.faces[0].trimmed);
  ASSERT_EQ(r->faceMeshes.size(), 1u);
  const double diagonal = std::sqrt(2.0) * 2.0 * kHalfSide;  // the plate's bounding box (its thickness is 0)
  EXPECT_GE(r->meshDeflection, occt::kFaceMeshDeflectionRel * diagonal);
  EXPECT_LE(r->meshDeflection, occt::kFaceMeshDeflectionRel * diagonal * 1.01);  // Bnd_Box adds a small gap
  expectAreaWithinDeflectionBound(r->faceMeshes[0], r->meshDeflection);
}

}  // namespace
}  // namespace seam
