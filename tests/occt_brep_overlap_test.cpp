// Overlapping faces of a B-rep (src/occt/brep_overlap.cpp, issue 38 §11): faces built with OpenCASCADE whose
// overlap is known from their construction (a share of a parameter box, an offset, a crossing), and real files whose
// reported witness points are checked by OpenCASCADE alone (projection and its exact face classifier).
#include <gtest/gtest.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakePolygon.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepClass_FaceClassifier.hxx>
#include <BRepGProp.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <GProp_GProps.hxx>
#include <GeomAPI_ProjectPointOnSurf.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_Plane.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <gp_Ax3.hxx>
#include <gp_Pln.hxx>

#include <cmath>
#include <vector>

#include "occt/brep_check_internal.h"
#include "seam/occt/brep_check.h"
#include "real_cad_files.h"

namespace seam {
namespace {

using test::kData;

constexpr double kTol = 1e-3;  // the distance tolerance of these tests (mm)

/// The faces in the order given, as the search sees a shape's faces (TopExp::MapShapes of a compound).
TopTools_IndexedMapOfShape mapOf(const std::vector<TopoDS_Face>& faces) {
  TopoDS_Compound c;
  BRep_Builder b;
  b.MakeCompound(c);
  for (const TopoDS_Face& f : faces) b.Add(c, f);
  TopTools_IndexedMapOfShape m;
  TopExp::MapShapes(c, TopAbs_FACE, m);
  return m;
}

occt::detail::BRepOverlapSearch search(const std::vector<TopoDS_Face>& faces, int threads = 0) {
  OverlapOptions o;
  o.threads = threads;
  return occt::detail::findBRepOverlaps(mapOf(faces), kTol, o);
}

/// A rectangle [x0, x1] x [y0, y1] of the plane z = `z` (a plane face with natural bounds).
TopoDS_Face rectangle(double x0, double x1, double y0, double y1, double z = 0.0) {
  return BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0, 0, z), gp_Dir(0, 0, 1)), x0, x1, y0, y1).Face();
}

/// A curved bicubic Bezier patch over [0, 4] x [0, 2] as a B-spline surface (a dome, no plane).
Handle(Geom_BSplineSurface) dome() {
  TColgp_Array2OfPnt poles(1, 4, 1, 4);
  for (int i = 1; i <= 4; ++i)
    for (int j = 1; j <= 4; ++j) {
      const double x = 4.0 * (i - 1) / 3.0, y = 2.0 * (j - 1) / 3.0;
      poles(i, j) = gp_Pnt(x, y, 0.3 * std::sin(0.8 * x) + 0.2 * y * y);
    }
  TColStd_Array1OfReal knots(1, 2);
  knots(1) = 0.0;
  knots(2) = 1.0;
  TColStd_Array1OfInteger mults(1, 2);
  mults(1) = 4;
  mults(2) = 4;
  return new Geom_BSplineSurface(poles, knots, knots, mults, mults, 3, 3);
}

/// The part [u0, u1] x [0, 1] of a surface's parameter box as a face (a trimmed face of that surface).
TopoDS_Face band(const Handle(Geom_Surface)& s, double u0, double u1) {
  return BRepBuilderAPI_MakeFace(s, u0, u1, 0.0, 1.0, 1e-7).Face();
}

TEST(BRepOverlaps, HalfOfEachRectangleLiesOnTheOtherAndTheShareIsThatHalf) {
  // [0, 2] x [0, 1] and [1, 3] x [0, 1] in one plane: each lies half on the other (by construction: 1/2 of its width).
  const auto found = search({rectangle(0, 2, 0, 1), rectangle(1, 3, 0, 1)});
  ASSERT_EQ(found.overlaps.size(), 1u);
  const FaceOverlap& o = found.overlaps[0];
  EXPECT_EQ(o.a, 0);
  EXPECT_EQ(o.b, 1);
  EXPECT_NEAR(o.fraction, 0.5, 1.0 / 16.0);  // one column of the 16 x 16 sample grid either way
  EXPECT_LE(o.maxDistance, 1e-12);
  EXPECT_GE(o.point.x(), 1.0);  // a witness inside both
  EXPECT_LE(o.point.x(), 2.0);
  EXPECT_EQ(found.skippedFaces, 0);
}

TEST(BRepOverlaps, AnOffsetBelowTheToleranceOverlapsAndAboveItDoesNot) {
  for (const double offset : {0.25 * kTol, 0.9 * kTol}) {
    const auto found = search({rectangle(0, 1, 0, 1), rectangle(0, 1, 0, 1, offset)});
    ASSERT_EQ(found.overlaps.size(), 1u) << offset;
    EXPECT_NEAR(found.overlaps[0].fraction, 1.0, 1e-12);
    EXPECT_NEAR(found.overlaps[0].maxDistance, offset, 1e-12);  // achieved, not the tolerance
  }
  for (const double offset : {1.5 * kTol, 4.0 * kTol})
    EXPECT_TRUE(search({rectangle(0, 1, 0, 1), rectangle(0, 1, 0, 1, offset)}).overlaps.empty()) << offset;
}

TEST(BRepOverlaps, NeighboursSharingAnEdgeAndCrossingFacesDoNotOverlap) {
  // Side by side (one shared side), and a face standing across the other (they meet along a line).
  EXPECT_TRUE(search({rectangle(0, 1, 0, 1), rectangle(1, 2, 0, 1)}).overlaps.empty());
  const TopoDS_Face across =
      BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0.5, 0, 0), gp_Dir(1, 0, 0)), -1.0, 1.0, 0.0, 1.0).Face();
  EXPECT_TRUE(search({rectangle(0, 1, 0, 1), across}).overlaps.empty());
  // A face tilted by 10 degrees about the line y = 0.5: only the samples next to that line are near the other face.
  gp_Ax3 tilted(gp_Pnt(0, 0.5, 0), gp_Dir(0, -std::sin(0.1745), std::cos(0.1745)), gp_Dir(1, 0, 0));
  const TopoDS_Face tiltedFace = BRepBuilderAPI_MakeFace(gp_Pln(tilted), 0.0, 1.0, -0.5, 0.5).Face();
  EXPECT_TRUE(search({rectangle(0, 1, 0, 1), tiltedFace}).overlaps.empty());
}

TEST(BRepOverlaps, FacesTrimmedFromOneCurvedSurfaceOverlapOnlyWhereTheirTrimsDo) {
  const Handle(Geom_BSplineSurface) s = dome();
  // Side by side on one surface object: no overlap (their samples lie on the other's surface, outside its trims).
  EXPECT_TRUE(search({band(s, 0.0, 0.5), band(s, 0.5, 1.0)}).overlaps.empty());
  // [0, 0.6] and [0.4, 1]: each lies on the other over 0.2 of its 0.6 of u, a third.
  const auto found = search({band(s, 0.0, 0.6), band(s, 0.4, 1.0)});
  ASSERT_EQ(found.overlaps.size(), 1u);
  EXPECT_NEAR(found.overlaps[0].fraction, 1.0 / 3.0, 1.0 / 16.0);
  // The same with a copy of the surface (another object, the same geometry): the same overlap.
  const Handle(Geom_Surface) copy = Handle(Geom_Surface)::DownCast(s->Copy());
  const auto copied = search({band(s, 0.0, 0.6), band(copy, 0.4, 1.0)});
  ASSERT_EQ(copied.overlaps.size(), 1u);
  EXPECT_NEAR(copied.overlaps[0].fraction, found.overlaps[0].fraction, 1e-12);
}

TEST(BRepOverlaps, ATrimmedLShapeOverlapsARectangleByTheShareOfItsAreaOnIt) {
  // The L = [0, 2] x [0, 2] without [1, 2] x [1, 2] (area 3), a wire on the plane z = 0; the rectangle
  // [0, 2] x [0, 1] covers 2 of its 3 units of area, and the L covers all of the rectangle.
  BRepBuilderAPI_MakePolygon wire;
  for (const auto& [x, y] : std::vector<std::pair<double, double>>{{0, 0}, {2, 0}, {2, 1}, {1, 1}, {1, 2}, {0, 2}})
    wire.Add(gp_Pnt(x, y, 0));
  wire.Close();
  const TopoDS_Face l = BRepBuilderAPI_MakeFace(gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), wire.Wire()).Face();
  ASSERT_TRUE(BRepCheck_Analyzer(l).IsValid());
  const auto found = search({l, rectangle(0, 2, 0, 1)});
  ASSERT_EQ(found.overlaps.size(), 1u);
  EXPECT_NEAR(found.overlaps[0].fraction, 1.0, 1e-12);  // the rectangle's share (the larger of the two)
  // The square that fills the L's notch: inside the L's box, outside its trims (it shares two edges with it).
  EXPECT_TRUE(search({l, rectangle(1, 2, 1, 2)}).overlaps.empty());
  const auto other = search({l, rectangle(0.0, 2.0, 1.2, 2.0)});  // lies on the L's upper arm only: [0, 1] of its 2
  ASSERT_EQ(other.overlaps.size(), 1u);
  EXPECT_NEAR(other.overlaps[0].fraction, 0.5, 1.0 / 16.0);
}

TEST(BRepOverlaps, TheResultDoesNotDependOnTheNumberOfThreads) {
  const Handle(Geom_BSplineSurface) s = dome();
  const std::vector<TopoDS_Face> faces = {band(s, 0.0, 0.6), band(s, 0.4, 1.0), rectangle(0, 2, 0, 1, 5.0),
                                          rectangle(1, 3, 0, 1, 5.0), rectangle(5, 6, 0, 1)};
  const auto one = search(faces, 1), two = search(faces, 2);
  ASSERT_EQ(one.overlaps.size(), 2u);
  ASSERT_EQ(two.overlaps.size(), one.overlaps.size());
  for (size_t k = 0; k < one.overlaps.size(); ++k) {
    EXPECT_EQ(one.overlaps[k].a, two.overlaps[k].a);
    EXPECT_EQ(one.overlaps[k].b, two.overlaps[k].b);
    EXPECT_EQ(one.overlaps[k].fraction, two.overlaps[k].fraction);
    EXPECT_EQ(one.overlaps[k].maxDistance, two.overlaps[k].maxDistance);
  }
}

// Many faces lying on one face with a hole, searched on more threads than cores: every thread classifies its
// face's samples on that one face at once. OpenCASCADE 7.6's face classifier is not safe to call from two threads at
// once (its polygons sit in a sequence whose reads move a cached cursor), and the search crashed here (SIGSEGV in
// BRepTopAdaptor_FClass2d::Perform) before it took each face's classifier for one thread at a time (issue 39). The
// expected pairs come from the construction: the 8 x 8 unit tiles of [0, 8] x [0, 8] in its plane, less the 4 that
// fill the hole [3, 5] x [3, 5], lie on the face; the tiles share only edges with each other.
TEST(BRepOverlaps, ManyFacesOnOneFaceWithAHoleAreClassifiedOnItFromEveryThreadAtOnce) {
  auto square = [](double x0, double x1) {
    BRepBuilderAPI_MakePolygon wire(gp_Pnt(x0, x0, 0), gp_Pnt(x1, x0, 0), gp_Pnt(x1, x1, 0), gp_Pnt(x0, x1, 0), true);
    return wire.Wire();
  };
  BRepBuilderAPI_MakeFace holed(gp_Pln(gp_Pnt(0, 0, 0), gp_Dir(0, 0, 1)), square(0, 8));
  holed.Add(TopoDS::Wire(square(3, 5).Reversed()));
  const TopoDS_Face plate = holed.Face();
  ASSERT_TRUE(BRepCheck_Analyzer(plate).IsValid());
  std::vector<TopoDS_Face> faces{plate};
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j) faces.push_back(rectangle(i, i + 1, j, j + 1));
  for (int round = 0; round < 10; ++round) {
    const auto found = search(faces, 8);
    ASSERT_EQ(found.overlaps.size(), 60u) << "round " << round;
    for (const FaceOverlap& o : found.overlaps) {
      EXPECT_EQ(o.a, 0);
      EXPECT_GE(o.fraction, 0.8);  // a tile's samples on the hole's edge are on the plate's trim, not inside it
      EXPECT_LE(o.maxDistance, 1e-12);
    }
  }
}

// trj3_s1-al-214.stp (5 solids, sliver and zero-area faces): every pair reported lies on each other at its witness
// point by OpenCASCADE alone (the point projects onto both faces' surfaces within the tolerance, and the exact face
// classifier puts both feet inside the trims); a face of zero area is never in a pair. The single-part files, valid
// solids, have no overlapping faces.
TEST(BRepOverlaps, RealFilesWitnessPointsLieInsideBothFacesByOpenCascade) {
  const Result<TopoDS_Shape> shape =
      occt::detail::readShape(kData / "step/trj3_s1-al-214.stp", occt::CadFormat::kStep, nullptr);
  ASSERT_TRUE(shape.isOk()) << shape.status().message();
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(*shape, TopAbs_FACE, faces);
  const occt::detail::BRepOverlapSearch found = occt::detail::findBRepOverlaps(faces, kTol, OverlapOptions{});
  EXPECT_GE(found.overlaps.size(), 10u);
  EXPECT_GE(found.skippedFaces, 1);
  auto inside = [&](int face, const Vec3& x) {
    const TopoDS_Face f = TopoDS::Face(faces(face + 1));
    GeomAPI_ProjectPointOnSurf projection(gp_Pnt(x.x(), x.y(), x.z()), BRep_Tool::Surface(f));
    if (projection.NbPoints() == 0 || projection.LowerDistance() > kTol) return false;
    double u = 0, v = 0;
    projection.LowerDistanceParameters(u, v);
    return BRepClass_FaceClassifier(f, gp_Pnt2d(u, v), 1e-9).State() == TopAbs_IN;
  };
  for (const FaceOverlap& o : found.overlaps) {
    SCOPED_TRACE(testing::Message() << "F" << o.a + 1 << " / F" << o.b + 1);
    EXPECT_TRUE(inside(o.a, o.point));
    EXPECT_TRUE(inside(o.b, o.point));
    for (const int face : {o.a, o.b}) {
      GProp_GProps props;
      BRepGProp::SurfaceProperties(faces(face + 1), props);
      EXPECT_GT(std::abs(props.Mass()), 1e-9);  // no face of zero area
    }
  }
  // The check names the solids of each pair's faces, through the sewing that trj3 needs (the sewn shape has none):
  // trj3 has 5 solids (OpenCASCADE's count of the file as read), and its assembly's parts touch.
  occt::BRepCheckOptions co;
  co.findOverlaps = true;
  const Result<occt::BRepCheckReport> checked = occt::checkBRepFile(kData / "step/trj3_s1-al-214.stp", co);
  ASSERT_TRUE(checked.isOk()) << checked.status().message();
  ASSERT_TRUE(checked->sewn);
  ASSERT_EQ(checked->overlapSolids.size(), checked->overlaps.size());
  EXPECT_EQ(checked->overlaps.size(), found.overlaps.size());
  int contacts = 0;
  for (const auto& [sa, sb] : checked->overlapSolids) {
    EXPECT_LE(sa, 5);
    EXPECT_LE(sb, 5);
    contacts += sa > 0 && sb > 0 && sa != sb ? 1 : 0;
  }
  EXPECT_GE(contacts, 4);
  for (const char* rel : {"step/linkrods.step", "iges/bearing.iges"}) {
    SCOPED_TRACE(rel);
    const std::filesystem::path file = kData / rel;
    const Result<TopoDS_Shape> part = occt::detail::readShape(
        file, file.extension() == ".step" ? occt::CadFormat::kStep : occt::CadFormat::kIges, nullptr);
    ASSERT_TRUE(part.isOk()) << part.status().message();
    TopTools_IndexedMapOfShape partFaces;
    TopExp::MapShapes(*part, TopAbs_FACE, partFaces);
    EXPECT_TRUE(occt::detail::findBRepOverlaps(partFaces, kTol, OverlapOptions{}).overlaps.empty());
  }
}

}  // namespace
}  // namespace seam
