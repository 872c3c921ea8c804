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
#include <BRepBndLib.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <STEPControl_Reader.hxx>
#include <STEPControl_Writer.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Vertex.hxx>
#include <TopoDS_Wire.hxx>
#include <BRepAdaptor_Curve.hxx>
#include <BRepTools.hxx>
#include <BRepTopAdaptor_FClass2d.hxx>
#include <Geom2dAPI_ProjectPointOnCurve.hxx>
#include <Geom2d_Curve.hxx>
#include <Precision.hxx>
#include <gp_Ax1.hxx>
#include <gp_Ax2.hxx>
#include <gp_Circ.hxx>
#include <gp_Pln.hxx>
#include <gp_Trsf.hxx>
#include <algorithm>
#include <cmath>
#include <iostream>
#include <limits>
#include <optional>
#include <filesystem>
#include <numbers>
#include <string>

#include "occt/face_mesh.h"
#include "seam/core/tolerances.h"
#include "seam/occt/brep_check.h"
#include "occt_counts.h"
#include "real_cad_files.h"

namespace seam {
namespace {

namespace fs = std::filesystem;
const fs::path kData = SEAM_SHARED_DATA_DIR;
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

Vec3 toVec(const gp_Pnt& p) { return {p.X(), p.Y(), p.Z()}; }

/// The longest triangle side of a mesh (the grid fallback's resolution).
double longestSide(const occt::BRepFaceMesh& m) {
  double h = 0.0;
  for (size_t t = 0; t + 2 < m.triangles.size(); t += 3)
    for (int k = 0; k < 3; ++k)
      h = std::max(h, (m.points[static_cast<size_t>(m.triangles[t + k])] -
                       m.points[static_cast<size_t>(m.triangles[t + (k + 1) % 3])])
                          .norm());
  return h;
}

// trj3 (issue 17 §4): eight of its 94 faces are half discs, each trimmed by one edge only, a semicircle whose ends
// are the ends of the missing diameter (the file's EDGE_LOOP is open); BRepMesh reports an open wire and gives them
// no triangles. Every face gets triangles now, those eight from the grid fallback, and the fallback keeps the trim:
// the expected half disc comes from the edge alone (centre = the midpoint of its two vertices, radius = half their
// distance, the disc's side = where the edge's midpoint lies), not from the mesher. With h the longest triangle side,
// the mesh's area is pi r^2 / 2 within the half disc's perimeter (pi + 2) r times h (every kept triangle has its
// centroid inside; the surface is a plane), its points lie within r + h of the centre and on the edge's side of the
// diameter within h. The whole disc (pi r^2) or the sliver OpenCASCADE's own closure makes (area ~1 % of it) fail.
TEST(OcctFaceMesh, EveryFaceOfTrj3GetsTrianglesAndTheOpenlyTrimmedHalfDiscsKeepTheirTrim) {
  const fs::path file = kData / "step" / "trj3_s1-al-214.stp";
  if (!fs::exists(file)) GTEST_SKIP() << file << " missing";
  STEPControl_Reader reader;
  ASSERT_EQ(reader.ReadFile(file.string().c_str()), IFSelect_RetDone);
  ASSERT_GT(reader.TransferRoots(), 0);
  const TopoDS_Shape shape = reader.OneShape();
  TopTools_IndexedMapOfShape map;
  TopExp::MapShapes(shape, TopAbs_FACE, map);
  std::vector<TopoDS_Face> faces;
  for (int i = 1; i <= map.Extent(); ++i) faces.push_back(TopoDS::Face(map(i)));
  ASSERT_EQ(faces.size(), 94u);
  Bnd_Box box;
  BRepBndLib::Add(shape, box);
  const double deflection = occt::kFaceMeshDeflectionRel * std::sqrt(box.SquareExtent());
  const std::vector<occt::BRepFaceMesh> meshes = occt::detail::meshFaces(shape, faces, deflection);
  ASSERT_EQ(meshes.size(), faces.size()) << "every face has a mesh";
  int halfDiscs = 0;
  for (size_t k = 0; k < faces.size(); ++k) {
    const occt::BRepFaceMesh& m = meshes[k];
    EXPECT_EQ(m.face, "F" + std::to_string(k + 1));
    EXPECT_FALSE(m.triangles.empty()) << m.face;
    EXPECT_EQ(m.normals.size(), m.points.size()) << m.face;
    // A face trimmed by one edge whose two vertices differ: an open trim.
    std::vector<TopoDS_Edge> edges;
    for (TopExp_Explorer e(faces[k], TopAbs_EDGE); e.More(); e.Next()) edges.push_back(TopoDS::Edge(e.Current()));
    TopoDS_Vertex va, vb;
    if (edges.size() == 1) TopExp::Vertices(edges[0], va, vb);
    const bool openTrim = edges.size() == 1 && !va.IsSame(vb) &&
                          BRep_Tool::Pnt(va).Distance(BRep_Tool::Pnt(vb)) >
                                              10.0 * std::max(BRep_Tool::Tolerance(va), BRep_Tool::Tolerance(vb));
    EXPECT_EQ(m.gridFallback, openTrim) << m.face << ": BRepMesh meshes every face with a closed trim";
    if (!openTrim) continue;
    ++halfDiscs;
    const Vec3 a = toVec(BRep_Tool::Pnt(va)), b = toVec(BRep_Tool::Pnt(vb));
    const Vec3 centre = 0.5 * (a + b);
    const double r = 0.5 * (a - b).norm();
    const BRepAdaptor_Curve curve(edges[0]);
    const Vec3 middle = toVec(curve.Value(0.5 * (curve.FirstParameter() + curve.LastParameter())));
    const Vec3 side = (middle - centre).normalized();
    const double h = longestSide(m);
    EXPECT_LT(h, 0.2 * r) << m.face << ": the grid resolves the disc";
    EXPECT_NEAR(meshArea(m), 0.5 * kPi * r * r, (kPi + 2.0) * r * h) << m.face << " r " << r << " h " << h;
    for (const Vec3& p : m.points) {
      EXPECT_LE((p - centre).norm(), r + h) << m.face;
      EXPECT_GE((p - centre).dot(side), -h) << m.face;
    }
    // A flat disc: every point normal is the triangles' common normal (the pole's too, where the surface's vanishes).
    Vec3 areaVector;
    meshArea(m, &areaVector);
    for (const Vec3& n : m.normals) EXPECT_NEAR(n.dot(areaVector.normalized()), 1.0, 1e-6) << m.face;
  }
  EXPECT_EQ(halfDiscs, 8);
}

// The route of `seam report`: checkBRepFile with meshFaces on every face (sewn, as the check does) gives each of
// trj3's 94 faces triangles.
TEST(OcctFaceMesh, CheckBRepFileMeshesEveryFaceOfTrj3) {
  const fs::path file = kData / "step" / "trj3_s1-al-214.stp";
  if (!fs::exists(file)) GTEST_SKIP() << file << " missing";
  occt::BRepCheckOptions o;
  o.meshFaces = true;
  const Result<occt::BRepCheckReport> r = occt::checkBRepFile(file, o);
  ASSERT_TRUE(r.isOk()) << r.status().message();
  ASSERT_EQ(r->import.faces.size(), 94u);
  ASSERT_EQ(r->faceMeshes.size(), 94u);
  for (const occt::BRepFaceMesh& m : r->faceMeshes) EXPECT_FALSE(m.triangles.empty()) << m.face;
  EXPECT_EQ(std::count_if(r->faceMeshes.begin(), r->faceMeshes.end(),
                          [](const occt::BRepFaceMesh& m) { return m.gridFallback; }),
            8);
}

// Issue 35 §4: the view's meshing has a budget. With a budget of 1 ns OpenCASCADE's mesher is told to stop at its
// first progress poll; the report still gets a mesh of every face (seam's grid over the trims, counted against the
// 94 faces the file has, OpenCASCADE's own count), says that the mesher was stopped, and takes about as long as
// the check.
TEST(OcctFaceMesh, AMesherPastItsBudgetLeavesEveryFaceToTheGrid) {
  const fs::path file = kData / "step" / "trj3_s1-al-214.stp";
  if (!fs::exists(file)) GTEST_SKIP() << file << " missing";
  occt::BRepCheckOptions o;
  o.meshFaces = true;
  o.meshBudgetFactor = 1e-12;
  o.meshBudgetMinSeconds = 1e-9;
  const Result<occt::BRepCheckReport> r = occt::checkBRepFile(file, o);
  ASSERT_TRUE(r.isOk()) << r.status().message();
  EXPECT_GT(r->meshStoppedAfterSeconds, 0.0);
  EXPECT_LE(r->meshStoppedAfterSeconds, 1e-6);
  ASSERT_EQ(r->faceMeshes.size(), 94u);
  const auto grid = std::count_if(r->faceMeshes.begin(), r->faceMeshes.end(),
                                  [](const occt::BRepFaceMesh& m) { return m.gridFallback; });
  EXPECT_GT(grid, 8) << "more faces than the 8 OpenCASCADE cannot mesh at all come from the grid";
  for (const occt::BRepFaceMesh& m : r->faceMeshes) EXPECT_FALSE(m.triangles.empty()) << m.face;
  // Without a budget (factor 0) the mesher runs to the end, as before.
  o.meshBudgetFactor = 0.0;
  const Result<occt::BRepCheckReport> full = occt::checkBRepFile(file, o);
  ASSERT_TRUE(full.isOk()) << full.status().message();
  EXPECT_EQ(full->meshStoppedAfterSeconds, 0.0);
}

}  // namespace
}  // namespace seam

namespace seam {
namespace {

/// The distance in (u, v) from `p` to the nearest of `face`'s pcurves (each projected onto on its own range, ends
/// included): OpenCASCADE's projection on the curves themselves, no polygon.
double distanceToTrims(const TopoDS_Face& face, const gp_Pnt2d& p) {
  double best = std::numeric_limits<double>::infinity();
  for (TopExp_Explorer e(face, TopAbs_EDGE); e.More(); e.Next()) {
    double f = 0.0, l = 0.0;
    const Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(TopoDS::Edge(e.Current()), face, f, l);
    if (pc.IsNull()) continue;
    best = std::min({best, p.Distance(pc->Value(f)), p.Distance(pc->Value(l))});
    Geom2dAPI_ProjectPointOnCurve proj(p, pc, f, l);
    if (proj.NbPoints() > 0) best = std::min(best, proj.LowerDistance());
  }
  return best;
}

// The plate's inside is known exactly: the grid's points of [-L, L]^2 (its (u, v) is (x, y)) at or outside the circle.
// With L = 10, R = 4 and a 40 x 40 grid (spacing 1/2), r^2 is a multiple of 1/4: on the circle at 4 points, else at
// least 0.03 from it, far beyond the polygon's deflection. Runs under the sanitizers (the real-file test does not).
TEST(OcctGridInsideTrims, APlateWithAHoleIsClassifiedByItsGeometry) {
  const TopoDS_Face face = plateWithHole();
  constexpr int kGrid = 40;
  const std::optional<std::vector<gp_Pnt2d>> got =
      occt::detail::gridInsideTrims(face, kGrid, -kHalfSide, kHalfSide, -kHalfSide, kHalfSide);
  ASSERT_TRUE(got.has_value()) << "closed trims are scanned";
  std::vector<gp_Pnt2d> want;
  for (int a = 0; a <= kGrid; ++a)
    for (int b = 0; b <= kGrid; ++b) {
      const double x = -kHalfSide + 2.0 * kHalfSide * a / kGrid, y = -kHalfSide + 2.0 * kHalfSide * b / kGrid;
      if (x * x + y * y >= kRadius * kRadius) want.emplace_back(x, y);
    }
  ASSERT_EQ(got->size(), want.size());
  for (size_t k = 0; k < want.size(); ++k) {
    EXPECT_EQ((*got)[k].X(), want[k].X()) << k;
    EXPECT_EQ((*got)[k].Y(), want[k].Y()) << k;
  }
  // An open trim (one edge, not closed): not scanned, the caller classifies point by point.
  const TopoDS_Edge arc = BRepBuilderAPI_MakeEdge(gp_Circ(gp_Ax2(), kRadius), 0.0, kPi);
  const TopoDS_Wire open = BRepBuilderAPI_MakeWire(arc);
  const TopoDS_Face halfDisc = BRepBuilderAPI_MakeFace(gp_Pln(), open, /*OnlyPlane=*/true);
  ASSERT_FALSE(halfDisc.IsNull());
  ASSERT_TRUE(TopExp_Explorer(halfDisc, TopAbs_EDGE).More());
  EXPECT_FALSE(occt::detail::gridInsideTrims(halfDisc, kGrid, -kRadius, kRadius, 0.0, kRadius).has_value());
}

// gridInsideTrims (the heal's fold and area grid) against OpenCASCADE's own classifier point by point, on every face
// of the real files: the two agree on every grid point but those near a trim (where OpenCASCADE's coarser polygon
// and the scan's finer one may fall either side), and the scan classifies the faces with closed trims, not only the
// easy ones.
TEST(OcctGridInsideTrims, AgreesWithOpenCascadesClassifierAwayFromTheTrimsOnEveryRealFace) {
  constexpr int kGrid = 40;
  // Of the face's (u, v) box: measured, every point classified otherwise lies within 1e-5 of a trim (202 of 303
  // within 1e-9: points on the trim, which OpenCASCADE's tolerance puts either side).
  constexpr double kNearTrimRel = 1e-5;
  int faces = 0, scanned = 0, points = 0, nearDifferences = 0;
  for (const char* name : test::kRealFiles) {
    const fs::path file = test::kData / name;
    if (!fs::exists(file)) continue;
    const TopoDS_Shape shape = test::occtRead(file);
    ASSERT_FALSE(shape.IsNull()) << name;
    TopTools_IndexedMapOfShape map;
    TopExp::MapShapes(shape, TopAbs_FACE, map);
    for (int i = 1; i <= map.Extent(); ++i) {
      const TopoDS_Face face = TopoDS::Face(map(i));
      ++faces;
      double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
      BRepTools::UVBounds(face, u0, u1, v0, v1);
      const std::optional<std::vector<gp_Pnt2d>> got = occt::detail::gridInsideTrims(face, kGrid, u0, u1, v0, v1);
      if (!got) continue;
      ++scanned;
      const BRepTopAdaptor_FClass2d classifier(face, Precision::PConfusion());
      const double size = std::max(u1 - u0, v1 - v0);
      size_t at = 0;
      for (int a = 0; a <= kGrid; ++a)
        for (int b = 0; b <= kGrid; ++b) {
          const gp_Pnt2d uv(u0 + (u1 - u0) * a / kGrid, v0 + (v1 - v0) * b / kGrid);
          const bool scanInside = at < got->size() && (*got)[at].X() == uv.X() && (*got)[at].Y() == uv.Y();
          if (scanInside) ++at;
          ++points;
          if (scanInside == (classifier.Perform(uv) != TopAbs_OUT)) continue;
          ++nearDifferences;
          EXPECT_LE(distanceToTrims(face, uv), kNearTrimRel * size)
              << name << " face " << i << " (" << uv.X() << ", " << uv.Y() << "): scan says "
              << (scanInside ? "inside" : "outside") << ", OpenCASCADE the other, away from every trim";
        }
      EXPECT_EQ(at, got->size()) << name << " face " << i << ": the grid's points in order";
    }
  }
  if (faces == 0) GTEST_SKIP() << "no real file";
  std::cout << faces << " faces, " << scanned << " scanned, " << points << " points, " << nearDifferences
            << " classified otherwise next to a trim\n";
  EXPECT_GE(scanned, faces * 9 / 10) << "the scan takes most real faces";
  EXPECT_LE(nearDifferences, points / 1000);
}

}  // namespace
}  // namespace seam
