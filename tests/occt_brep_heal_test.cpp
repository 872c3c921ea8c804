// The B-rep routes that keep trims (issue 34): occt::convertCadFile (STEP/IGES -> STEP/IGES) and occt::healBRepFile.
// Every expected value comes from OpenCASCADE alone, on the files read back (no seam code on that side): face and
// solid counts, areas (BRepGProp), validity (BRepCheck_Analyzer), trimmed faces (a face whose area is below that of
// its whole parameter box), the surfaces' control points, and a probe that samples the shared edge, projects onto
// both faces and measures the angle between their normals and the two-sided distance between their boundaries.
#include <gtest/gtest.h>
#include <unistd.h>

#include <BRepAdaptor_Curve.hxx>
#include <BRepBuilderAPI_MakeEdge.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_MakeWire.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepGProp.hxx>
#include <BRepLib.hxx>
#include <BRepPrimAPI_MakeBox.hxx>
#include <BRepTools.hxx>
#include <BRepTopAdaptor_FClass2d.hxx>
#include <Precision.hxx>
#include <BRep_Tool.hxx>
#include <BRep_Builder.hxx>
#include <TopoDS_Compound.hxx>
#include <Geom_Plane.hxx>
#include <gp_Pln.hxx>
#include <GCE2d_MakeSegment.hxx>
#include <GProp_GProps.hxx>
#include <GeomAPI_ProjectPointOnCurve.hxx>
#include <Extrema_GenLocateExtPS.hxx>
#include <Extrema_POnSurf.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <GeomLProp_SLProps.hxx>
#include <Geom_BSplineSurface.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Reader.hxx>
#include <Interface_Static.hxx>
#include <STEPControl_Reader.hxx>
#include <ShapeAnalysis_Surface.hxx>
#include <STEPControl_Writer.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "seam/io/json.h"
#include "seam/occt/brep_heal.h"
#include "seam/occt/cad_io.h"
#include "occt_counts.h"
#include "real_cad_files.h"

namespace seam {
namespace {

namespace fs = std::filesystem;

using test::kData;
using test::kRealFiles;
constexpr double kRadToDeg = 180.0 / std::numbers::pi;

fs::path tempPath(const std::string& name) {
  return fs::temp_directory_path() / ("seam_brep_heal_test_" + std::to_string(::getpid()) + "_" + name);
}

// ---- OpenCASCADE-only side ----

TopoDS_Shape readWithOcct(const fs::path& file) { return test::occtRead(file); }
using Counts = test::OcctCounts;
/// Faces, trimmed faces (wires and pcurves against the parameter box), solids, area and validity; no sewing.
Counts countWithOcct(const TopoDS_Shape& shape) { return test::occtCounts(shape, false); }

/// The probe of one shared edge: n samples of A's boundary image and of B's; the angle between the oriented normals
/// at A's samples and B's surface projected from them; the two-sided distance between the two boundary images.
struct Probe {
  double maxAngleDeg = 0.0, gap = 0.0;
  /// The largest distance from a point of one face's boundary image to the other face's surface, both ways: the gap
  /// of the surfaces themselves, free of the other face's pcurve (a reader rebuilds pcurves within the edge
  /// tolerance).
  double surfaceGap = 0.0;
};

gp_Dir orientedNormal(const TopoDS_Face& f, double u, double v) {
  GeomLProp_SLProps props(BRep_Tool::Surface(f), u, v, 1, 1e-9);
  gp_Dir n = props.Normal();
  return f.Orientation() == TopAbs_REVERSED ? n.Reversed() : n;
}

std::vector<gp_Pnt> boundaryImage(const TopoDS_Edge& e, const TopoDS_Face& f, int n) {
  double a, b;
  const Handle(Geom2d_Curve) c = BRep_Tool::CurveOnSurface(e, f, a, b);
  const Handle(Geom_Surface) s = BRep_Tool::Surface(f);
  std::vector<gp_Pnt> out;
  for (int i = 0; i <= n; ++i) {
    const gp_Pnt2d uv = c->Value(a + (b - a) * i / n);
    out.push_back(s->Value(uv.X(), uv.Y()));
  }
  return out;
}

double distanceToPolyline(const gp_Pnt& p, const std::vector<gp_Pnt>& line) {
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i + 1 < line.size(); ++i) {
    const gp_Vec d(line[i], line[i + 1]), w(line[i], p);
    const double t = d.SquareMagnitude() > 0 ? std::clamp(w.Dot(d) / d.SquareMagnitude(), 0.0, 1.0) : 0.0;
    best = std::min(best, p.Distance(line[i].Translated(d * t)));
  }
  return best;
}

Probe probeEdge(const TopoDS_Edge& e, const TopoDS_Face& fa, const TopoDS_Face& fb, int n = 400) {
  Probe p;
  const std::vector<gp_Pnt> a = boundaryImage(e, fa, n), b = boundaryImage(e, fb, 4 * n);
  const std::vector<gp_Pnt> aDense = boundaryImage(e, fa, 4 * n), bCoarse = boundaryImage(e, fb, n);
  for (const gp_Pnt& x : a) p.gap = std::max(p.gap, distanceToPolyline(x, b));
  for (const gp_Pnt& x : bCoarse) p.gap = std::max(p.gap, distanceToPolyline(x, aDense));
  // Both ways (A's boundary onto B's surface, B's onto A's): one direction alone changes its value when a writer
  // swaps the faces' order, and a heal that narrows a gap from one side may lengthen the other side's distance.
  auto oneWay = [&p, n](const TopoDS_Edge& edge, const TopoDS_Face& from, const TopoDS_Face& to, bool angle,
                        const std::vector<gp_Pnt>& toBoundary) {
    double first, last, firstTo, lastTo;
    const Handle(Geom2d_Curve) ca = BRep_Tool::CurveOnSurface(edge, from, first, last);
    const Handle(Geom2d_Curve) cb = BRep_Tool::CurveOnSurface(edge, to, firstTo, lastTo);
    // The nearest point of `to`, searched from its own boundary point at the same fraction of the edge (not over
    // all of its surface: two faces on one closed surface meet where it closes, and a global projection would
    // find the other side of it).
    ShapeAnalysis_Surface sb(BRep_Tool::Surface(to));
    const GeomAdaptor_Surface adaptor(BRep_Tool::Surface(to));
    Extrema_GenLocateExtPS locate(adaptor);
    for (int i = 1; i < n; ++i) {  // ends excluded: corners of the trims
      const gp_Pnt2d uv = ca->Value(first + (last - first) * i / n);
      const gp_Pnt x = BRep_Tool::Surface(from)->Value(uv.X(), uv.Y());
      gp_Pnt2d uvb = sb.NextValueOfUV(cb->Value(firstTo + (lastTo - firstTo) * i / n), x, 1e-12);
      // NextValueOfUV can stop short of the nearest point: a local minimisation of the distance from there
      // finishes it.
      locate.Perform(x, uvb.X(), uvb.Y(), Standard_True);
      if (locate.IsDone() && locate.SquareDistance() < x.SquareDistance(BRep_Tool::Surface(to)->Value(uvb.X(), uvb.Y()))) {
        double u = 0.0, v = 0.0;
        locate.Point().Parameter(u, v);
        uvb.SetCoord(u, v);
      }
      // The distance to the face: to its surface within the surface's bounds, or to its boundary image, whichever
      // is nearer. The nearest point found on the surface can be farther than the boundary image, which is on the
      // face too (trj3's F2/F4 edge after the heal: 0.00356 to the point found, 0.00223 between the boundary
      // images; `occt_probe seams` measures that edge 0.00298 -> 0.00256 between the projections of the 3-D edge).
      p.surfaceGap = std::max(p.surfaceGap, std::min(x.Distance(BRep_Tool::Surface(to)->Value(uvb.X(), uvb.Y())),
                                                     distanceToPolyline(x, toBoundary)));
      if (angle)
        p.maxAngleDeg = std::max(
            p.maxAngleDeg, orientedNormal(from, uv.X(), uv.Y()).Angle(orientedNormal(to, uvb.X(), uvb.Y())) * kRadToDeg);
    }
  };
  oneWay(e, fa, fb, true, b);
  oneWay(e, fb, fa, false, aDense);
  return p;
}

/// The edges shared by two faces of a shape, with their faces.
struct Shared {
  TopoDS_Edge edge;
  TopoDS_Face a, b;
};
std::vector<Shared> sharedEdges(const TopoDS_Shape& shape) {
  TopTools_IndexedDataMapOfShapeListOfShape m;
  TopExp::MapShapesAndAncestors(shape, TopAbs_EDGE, TopAbs_FACE, m);
  std::vector<Shared> out;
  for (int i = 1; i <= m.Extent(); ++i) {
    const TopTools_ListOfShape& l = m.FindFromIndex(i);
    if (l.Extent() != 2 || BRep_Tool::Degenerated(TopoDS::Edge(m.FindKey(i)))) continue;
    const TopoDS_Face a = TopoDS::Face(l.First()), b = TopoDS::Face(l.Last());
    if (a.IsSame(b)) continue;
    out.push_back({TopoDS::Edge(m.FindKey(i)), a, b});
  }
  return out;
}

// ---- The synthetic trimmed B-rep: two bicubic B-spline faces over [0,1] and [1,2] (x 100 mm), trimmed by a
// slanted side each, sharing the side x = 100. B's second pole column is lifted by `kinkDeg` (a kink), its first
// by `gap` (mm). ----

Handle(Geom_BSplineSurface) bicubic(const TColgp_Array2OfPnt& poles) {
  TColStd_Array1OfReal knots(1, 2);
  knots(1) = 0.0;
  knots(2) = 1.0;
  TColStd_Array1OfInteger mults(1, 2);
  mults.Init(4);
  return new Geom_BSplineSurface(poles, knots, knots, mults, mults, 3, 3);
}

TopoDS_Face trimmedFace(const Handle(Geom_BSplineSurface)& s, const std::vector<gp_Pnt2d>& polygon) {
  BRepBuilderAPI_MakeWire wire;
  for (size_t i = 0; i < polygon.size(); ++i) {
    const Handle(Geom2d_TrimmedCurve) seg = GCE2d_MakeSegment(polygon[i], polygon[(i + 1) % polygon.size()]);
    wire.Add(BRepBuilderAPI_MakeEdge(seg, s).Edge());
  }
  BRepBuilderAPI_MakeFace face(s, wire.Wire(), true);
  TopoDS_Face f = face.Face();
  BRepLib::BuildCurves3d(f);
  return f;
}

TopoDS_Shape twoFaces(double kinkDeg, double gap) {
  const double L = 100.0, c = 0.3 * L;  // z = c x^2 / L^2 on A: curved across the seam
  TColgp_Array2OfPnt pa(1, 4, 1, 4), pb(1, 4, 1, 4);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const double x = L * i / 3.0, y = L * j / 3.0;
      const double wave = 2.0 * std::sin(j);
      pa(i + 1, j + 1) = gp_Pnt(x, y, c * (i / 3.0) * (i / 3.0) + wave);
    }
  // B continues A with the same derivative across x = L (G1 and C1), then straight.
  const double slope = c * (1.0 - 4.0 / 9.0);  // z(A3) - z(A2) per third
  const double lift = std::tan(kinkDeg * std::numbers::pi / 180.0) * L / 3.0;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const double y = L * j / 3.0, wave = 2.0 * std::sin(j);
      const double z = c + wave + slope * i + (i >= 1 ? lift * (1.0 + 0.5 * (i - 1)) : 0.0) + gap;
      pb(i + 1, j + 1) = gp_Pnt(L + L * i / 3.0, y, z);
    }
  const TopoDS_Face a = trimmedFace(bicubic(pa), {{0, 0}, {1, 0}, {1, 1}, {0.25, 1}});
  const TopoDS_Face b = trimmedFace(bicubic(pb), {{0, 0}, {1, 0}, {0.75, 1}, {0, 1}});
  BRepBuilderAPI_Sewing sewing(std::max(0.01, 10.0 * gap));
  sewing.Add(a);
  sewing.Add(b);
  sewing.Perform();
  return sewing.SewedShape();
}

fs::path writeStep(const TopoDS_Shape& shape, const std::string& name) {
  const fs::path p = tempPath(name);
  STEPControl_Writer w;
  Interface_Static::SetCVal("write.step.unit", "MM");
  EXPECT_EQ(w.Transfer(shape, STEPControl_AsIs), IFSelect_RetDone);
  EXPECT_EQ(w.Write(p.c_str()), IFSelect_RetDone);
  return p;
}

Probe probeOnly(const fs::path& file) {
  const TopoDS_Shape s = readWithOcct(file);
  const std::vector<Shared> e = sharedEdges(s);
  EXPECT_EQ(e.size(), 1u) << file;
  if (e.empty()) return {};
  return probeEdge(e[0].edge, e[0].a, e[0].b);
}

TEST(BRepHeal, AKinkBetweenTwoTrimmedFacesBecomesG1AndTheTrimsStay) {
  const fs::path in = writeStep(twoFaces(2.0, 0.0), "kink.step"), out = tempPath("kink_healed.step");
  const Probe before = probeOnly(in);
  ASSERT_GT(before.maxAngleDeg, 1.0);
  Result<occt::BRepHealReport> r = occt::healBRepFile(in, out);
  ASSERT_TRUE(r) << r.status().message();
  EXPECT_TRUE(r->achieved);
  EXPECT_EQ(r->seamsWorse, 0);
  ASSERT_EQ(r->facesChanged.size(), 1u);
  const Probe after = probeOnly(out);
  EXPECT_LE(after.maxAngleDeg, r->tolerances.angleDeg) << "before " << before.maxAngleDeg;
  EXPECT_LE(after.gap, r->tolerances.distance);
  const Counts cin = countWithOcct(readWithOcct(in)), cout = countWithOcct(readWithOcct(out));
  EXPECT_EQ(cin.faces, 2);
  EXPECT_EQ(cin.trimmed, 2);
  EXPECT_EQ(cout.faces, cin.faces);
  EXPECT_EQ(cout.trimmed, cin.trimmed);
  EXPECT_NEAR(cout.area, cin.area, occt::kHealFaceAreaRel * cin.area);
  EXPECT_TRUE(cin.valid);
  EXPECT_TRUE(cout.valid);
  // The reported displacement bounds what the surfaces did, sampled independently on both parameter grids.
  const TopoDS_Shape sin = readWithOcct(in), sout = readWithOcct(out);
  TopTools_IndexedMapOfShape fin, fout;
  TopExp::MapShapes(sin, TopAbs_FACE, fin);
  TopExp::MapShapes(sout, TopAbs_FACE, fout);
  double moved = 0.0;
  for (int k = 1; k <= 2; ++k) {
    const Handle(Geom_Surface) s0 = BRep_Tool::Surface(TopoDS::Face(fin(k)));
    const Handle(Geom_Surface) s1 = BRep_Tool::Surface(TopoDS::Face(fout(k)));
    for (int i = 0; i <= 20; ++i)
      for (int j = 0; j <= 20; ++j) moved = std::max(moved, s0->Value(i / 20.0, j / 20.0).Distance(s1->Value(i / 20.0, j / 20.0)));
  }
  EXPECT_GT(moved, 0.0);
  EXPECT_LE(moved, r->maxSurfaceDisplacement * (1.0 + 1e-9));
  fs::remove(in);
  fs::remove(out);
}

TEST(BRepHeal, AGapIsClosedAtG0AndTheAngleDoesNotGrow) {
  const fs::path in = writeStep(twoFaces(0.5, 0.004), "gap.step"), out = tempPath("gap_healed.step");
  const Probe before = probeOnly(in);
  ASSERT_GT(before.gap, 0.003);
  occt::BRepHealOptions o;
  o.continuity = GeometricClass::kG0;
  Result<occt::BRepHealReport> r = occt::healBRepFile(in, out, o);
  ASSERT_TRUE(r) << r.status().message();
  EXPECT_TRUE(r->achieved);
  const Probe after = probeOnly(out);
  EXPECT_LE(after.gap, r->tolerances.distance);
  EXPECT_LE(after.maxAngleDeg, before.maxAngleDeg + r->tolerances.angleDeg);
  fs::remove(in);
  fs::remove(out);
}

TEST(BRepHeal, ACreaseKeepsItsAngleWhileItsGapCloses) {
  const fs::path in = writeStep(twoFaces(45.0, 0.004), "crease.step"), out = tempPath("crease_healed.step");
  const Probe before = probeOnly(in);
  ASSERT_GT(before.maxAngleDeg, 25.0);
  Result<occt::BRepHealReport> r = occt::healBRepFile(in, out);
  ASSERT_TRUE(r) << r.status().message();
  const Probe after = probeOnly(out);
  EXPECT_LE(after.gap, r->tolerances.distance);
  EXPECT_NEAR(after.maxAngleDeg, before.maxAngleDeg, 0.5);
  fs::remove(in);
  fs::remove(out);
}

TEST(BRepHeal, AnalyticFacesAreLeftAndTheModelIsWrittenWhole) {
  const fs::path in = writeStep(BRepPrimAPI_MakeBox(10.0, 20.0, 30.0).Shape(), "box.step");
  const fs::path out = tempPath("box_healed.step");
  Result<occt::BRepHealReport> r = occt::healBRepFile(in, out);
  ASSERT_TRUE(r) << r.status().message();
  EXPECT_TRUE(r->facesChanged.empty());
  EXPECT_EQ(r->creasesKept, 12);
  const Counts cin = countWithOcct(readWithOcct(in)), cout = countWithOcct(readWithOcct(out));
  EXPECT_EQ(cout.faces, 6);
  EXPECT_EQ(cout.solids, 1);
  EXPECT_NEAR(cout.area, cin.area, 1e-9 * cin.area);
  fs::remove(in);
  fs::remove(out);
}

TEST(BRepHeal, G2AndStatedUnitsAreRefusedAndNothingIsWritten) {
  const fs::path in = writeStep(twoFaces(2.0, 0.0), "refuse.step"), out = tempPath("refuse_out.step");
  occt::BRepHealOptions o;
  o.continuity = GeometricClass::kG2;
  EXPECT_FALSE(occt::healBRepFile(in, out, o));
  o.continuity = GeometricClass::kG1;
  o.tolerances.units = LengthUnit::kInch;
  EXPECT_FALSE(occt::healBRepFile(in, out, o));
  EXPECT_FALSE(fs::exists(out));
  fs::remove(in);
}

// ---- Hostile B-reps (issue 34 §3) ----

TEST(BRepHeal, AKinkBetweenAPlaneAndABSplineFaceMovesTheBSplineFace) {
  // A: the plane z = 0 over [0, 100]^2 (an analytic face that must not move); B: a bicubic over x in [100, 200]
  // leaving it at 2 degrees (z = tan(2 deg) (x - 100)), trimmed by a slanted side.
  const double L = 100.0, t = std::tan(2.0 * std::numbers::pi / 180.0);
  const TopoDS_Face a = BRepBuilderAPI_MakeFace(gp_Pln(gp::Origin(), gp::DZ()), 0.0, L, 0.0, L).Face();
  TColgp_Array2OfPnt pb(1, 4, 1, 4);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) pb(i + 1, j + 1) = gp_Pnt(L + L * i / 3.0, L * j / 3.0, t * L * i / 3.0);
  const TopoDS_Face b = trimmedFace(bicubic(pb), {{0, 0}, {1, 0}, {0.75, 1}, {0, 1}});
  BRepBuilderAPI_Sewing sewing(0.01);
  sewing.Add(a);
  sewing.Add(b);
  sewing.Perform();
  const fs::path in = writeStep(sewing.SewedShape(), "plane_bspline.step"), out = tempPath("plane_bspline_h.step");
  const Probe before = probeOnly(in);
  ASSERT_NEAR(before.maxAngleDeg, 2.0, 0.01);
  Result<occt::BRepHealReport> r = occt::healBRepFile(in, out);
  ASSERT_TRUE(r) << r.status().message();
  EXPECT_EQ(r->seamsWorse, 0);
  ASSERT_EQ(r->facesChanged.size(), 1u);
  const Probe after = probeOnly(out);
  EXPECT_LE(after.maxAngleDeg, r->tolerances.angleDeg) << "before " << before.maxAngleDeg;
  EXPECT_LE(after.gap, r->tolerances.distance);
  // The plane is still the plane: its face's surface kept its type.
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(readWithOcct(out), TopAbs_FACE, faces);
  int planes = 0;
  for (int i = 1; i <= faces.Extent(); ++i)
    planes += BRep_Tool::Surface(TopoDS::Face(faces(i)))->IsKind(STANDARD_TYPE(Geom_Plane)) ? 1 : 0;
  EXPECT_EQ(planes, 1);
  fs::remove(in);
  fs::remove(out);
}

TEST(BRepHeal, AFaceWhoseTrimLoopRunsBackwardsIsNeverMadeWorse) {
  // The kinked pair, with A's outer wire reversed (clockwise in its parameters: a loop that, read literally,
  // bounds the outside). Whatever the heal does with it, no seam gets worse, nothing crashes, the counts stay.
  TopoDS_Shape pair = twoFaces(2.0, 0.0);
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(pair, TopAbs_FACE, faces);
  ASSERT_EQ(faces.Extent(), 2);
  TopoDS_Face a = TopoDS::Face(faces(1));
  BRep_Builder builder;
  TopoDS_Face reversed;
  builder.MakeFace(reversed, BRep_Tool::Surface(a), BRep_Tool::Tolerance(a));
  for (TopExp_Explorer ex(a, TopAbs_WIRE); ex.More(); ex.Next()) builder.Add(reversed, ex.Current().Reversed());
  TopoDS_Compound both;
  builder.MakeCompound(both);
  builder.Add(both, reversed);
  builder.Add(both, faces(2));
  const fs::path in = writeStep(both, "reversed_loop.step"), out = tempPath("reversed_loop_h.step");
  Result<occt::BRepHealReport> r = occt::healBRepFile(in, out);
  if (!r) {  // refused with a message naming the file: acceptable, nothing written
    EXPECT_NE(r.status().message().find("reversed_loop"), std::string::npos) << r.status().message();
    EXPECT_FALSE(fs::exists(out));
  } else {
    EXPECT_EQ(r->seamsWorse, 0);
    const Counts cin = countWithOcct(readWithOcct(in)), cout = countWithOcct(readWithOcct(out));
    EXPECT_EQ(cout.faces, cin.faces);
    EXPECT_EQ(cout.trimmed, cin.trimmed);
    for (const occt::BRepHealSeam& seam : r->seams)
      if (seam.after) {
        EXPECT_LE(seam.after->g1MaxDeg, std::max(seam.before.g1MaxDeg, r->tolerances.angleDeg) + 0.1 * r->tolerances.angleDeg)
            << "edge " << seam.edge;
      }
  }
  fs::remove(in);
  fs::remove(out);
}

TEST(BRepHeal, APeriodicFaceMeetingItselfIsLeftWithItsReason) {
  // A closed tube: a bicubic whose first and last pole rows coincide (closed in u, not periodic) and whose
  // tangents there differ by 5 degrees (P3 is the G1 position P1 - (P2 - P1) turned by 5 degrees about P1). Its
  // face has one seam edge shared with itself; the heal must leave it, say why, and write the model whole.
  TColgp_Array2OfPnt p(1, 4, 1, 4);
  const double turn = 5.0 * std::numbers::pi / 180.0;
  const gp_Vec d(-10, 20, 0);
  const gp_Vec back = -d.Rotated(gp_Ax1(gp::Origin(), gp::DZ()), turn);
  const gp_Pnt p1(10, 0, 0);
  const std::array<gp_Pnt, 4> ring = {p1, p1.Translated(d), p1.Translated(back), p1};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) p(i + 1, j + 1) = gp_Pnt(ring[i].X(), ring[i].Y(), 10.0 * j);
  const Handle(Geom_BSplineSurface) s = bicubic(p);
  ASSERT_TRUE(s->IsUClosed());
  const TopoDS_Face f = BRepBuilderAPI_MakeFace(s, 1e-7).Face();
  const fs::path in = writeStep(f, "tube.step"), out = tempPath("tube_h.step");
  Result<occt::BRepHealReport> r = occt::healBRepFile(in, out);
  ASSERT_TRUE(r) << r.status().message();
  EXPECT_EQ(r->seamsWorse, 0);
  EXPECT_TRUE(r->facesChanged.empty());
  bool saidWhy = false;
  for (const occt::BRepHealSeam& seam : r->seams)
    saidWhy |= seam.a == seam.b && seam.action.find("closed face with itself") != std::string::npos;
  const bool kinked = std::any_of(r->seams.begin(), r->seams.end(), [&](const occt::BRepHealSeam& seam) {
    return seam.a == seam.b && seam.before.g1MaxDeg > r->tolerances.angleDeg && seam.before.g1MaxDeg < 20.0;
  });
  EXPECT_TRUE(kinked) << "the closing seam of the tube was not found as a kink";
  EXPECT_TRUE(saidWhy);
  EXPECT_TRUE(fs::exists(out));
  fs::remove(in);
  fs::remove(out);
}

// ---- Real files: convert keeps the B-rep, bit for bit; heal keeps faces and trims, and no seam gets worse ----

std::vector<Handle(Geom_BSplineSurface)> bsplineSurfaces(const TopoDS_Shape& s) {
  std::vector<Handle(Geom_BSplineSurface)> out;
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(s, TopAbs_FACE, faces);
  for (int i = 1; i <= faces.Extent(); ++i)
    out.push_back(Handle(Geom_BSplineSurface)::DownCast(BRep_Tool::Surface(TopoDS::Face(faces(i)))));
  return out;
}

/// Degrees, pole counts, then every pole's coordinates and weight: equal vectors are equal surfaces' nets.
std::vector<double> poleCoordinates(const Handle(Geom_BSplineSurface)& s) {
  std::vector<double> v{double(s->UDegree()), double(s->VDegree()), double(s->NbUPoles()), double(s->NbVPoles())};
  for (int i = 1; i <= s->NbUPoles(); ++i)
    for (int j = 1; j <= s->NbVPoles(); ++j) {
      const gp_Pnt p = s->Pole(i, j);
      v.insert(v.end(), {p.X(), p.Y(), p.Z(), s->Weight(i, j)});
    }
  return v;
}

TEST(CadConvert, RealFilesKeepEveryFaceTrimAndSolidAndStepToStepIsBitForBit) {
  int refused = 0;
  for (const char* rel : kRealFiles) {
    const fs::path in = kData / rel;
    if (!fs::exists(in)) {
      GTEST_SKIP() << in << " missing";
    }
    const TopoDS_Shape original = readWithOcct(in);
    const Counts c0 = countWithOcct(original);
    for (const char* ext : {".step", ".igs"}) {
      const fs::path out = tempPath(std::string("convert") + ext);
      occt::CadConvertOptions keepOnly;
      keepOnly.compareSeams = false;  // the seams' comparison has its own test (below)
      Result<occt::CadConvertReport> r = occt::convertCadFile(in, out, {}, keepOnly);
      if (!r) {
        // A refusal is allowed only as the verification's: what OpenCASCADE wrote lost part of the model when read
        // back, and then nothing is written (measured: boxed_sphere.step -> STEP, a trim: 47 trimmed faces instead
        // of 46 and 0.18 of 824 mm²; bearing.iges -> STEP, trims rebuilt from the 3-D curves: 1.1e-5 of the area).
        EXPECT_NE(r.status().message().find("would lose part of the model"), std::string::npos)
            << rel << " -> " << ext << ": " << r.status().message();
        EXPECT_FALSE(fs::exists(out)) << rel << ext;
        ++refused;
        continue;
      }
      const TopoDS_Shape back = readWithOcct(out);
      const Counts c1 = countWithOcct(back);
      EXPECT_EQ(c1.faces, c0.faces) << rel << ext;
      EXPECT_EQ(c1.trimmed, c0.trimmed) << rel << ext;
      // IGES keeps solids where OpenCASCADE's B-rep mode keeps every trim; else the solids are written as their
      // faces, and a warning says so.
      if (std::string(ext) == ".step" || c1.solids != 0 || c0.solids == 0)
        EXPECT_EQ(c1.solids, c0.solids) << rel << ext;
      else
        EXPECT_FALSE(r->warnings.empty()) << rel << ext;
      EXPECT_NEAR(c1.area, c0.area, (std::string(ext) == ".step" ? 1e-6 : 1e-4) * c0.area) << rel << ext;
      if (c0.valid) {
        EXPECT_TRUE(c1.valid) << rel << ext;
      }
      if (std::string(ext) == ".step" && std::string(rel).rfind("step/", 0) == 0) {
        // Every B-spline surface of the input is in the output with the same control points, bit for bit (the
        // faces may come in another order: XDE writes a model's parts in its own order).
        std::vector<std::vector<double>> written;
        for (const Handle(Geom_BSplineSurface)& s : bsplineSurfaces(back))
          if (!s.IsNull()) written.push_back(poleCoordinates(s));
        std::sort(written.begin(), written.end());
        int matched = 0, rewritten = 0;
        for (const Handle(Geom_BSplineSurface)& s : bsplineSurfaces(original)) {
          if (s.IsNull()) continue;
          const std::vector<double> mine = poleCoordinates(s);
          double nearest = std::numeric_limits<double>::infinity();
          for (const std::vector<double>& w : written)
            if (w.size() == mine.size()) {
              double d = 0.0;
              for (size_t q = 0; q < w.size(); ++q) d = std::max(d, std::abs(w[q] - mine[q]));
              nearest = std::min(nearest, d);
            }
          if (!std::binary_search(written.begin(), written.end(), mine)) {
            // OpenCASCADE rewrites a few nets (periodic ones as their non-periodic net; trj3: 2 of 88 surfaces):
            // the same surface with other poles, checked on a grid against every written surface.
            bool same = false;
            double u0, u1, v0, v1;
            s->Bounds(u0, u1, v0, v1);
            for (const Handle(Geom_BSplineSurface)& w : bsplineSurfaces(back)) {
              if (w.IsNull() || same) continue;
              double d = 0.0;
              for (int i = 0; i <= 6 && d <= 1e-9; ++i)
                for (int j = 0; j <= 6; ++j) {
                  const double u = u0 + (u1 - u0) * i / 6, v = v0 + (v1 - v0) * j / 6;
                  d = std::max(d, s->Value(u, v).Distance(w->Value(u, v)));
                }
              same = d <= 1e-9 * std::max(1.0, s->Pole(1, 1).XYZ().Modulus());
            }
            EXPECT_TRUE(same) << rel << " a surface of the input is not in the output (nearest net " << nearest << ")";
            ++rewritten;
          }
          ++matched;
        }
        EXPECT_EQ(matched, static_cast<int>(written.size())) << rel;
        EXPECT_LE(rewritten, 2) << rel;
      }
      fs::remove(out);
    }
  }
  EXPECT_LE(refused, 2);  // measured: boxed_sphere.step and bearing.iges -> .step
}

/// The middle of an edge's 3-D curve.
gp_Pnt edgeMiddle(const TopoDS_Edge& e) {
  BRepAdaptor_Curve c(e);
  return c.Value(0.5 * (c.FirstParameter() + c.LastParameter()));
}

// A STEP round trip through OpenCASCADE keeps the surfaces and 3-D edges bit for bit, but its reader builds the
// trims again, and on trj3 two seams come back with larger gaps. convert names them in warnings instead of writing
// them silently. Expected by the OpenCASCADE-only probe (pcurve images of both faces, both ways; no seam code): the
// seams whose gap grows by more than 3 tolerances from the input to the file read back are all named by convert, and
// it names no more seams than the probe finds worse by a tenth of a tolerance (gap or angle).
TEST(CadConvert, SeamsTheRoundTripMakesWorseAreNamed) {
  const fs::path in = kData / "step" / "trj3_s1-al-214.stp";
  if (!fs::exists(in)) GTEST_SKIP() << in << " missing";
  const fs::path out = tempPath("convert_compare.step");
  Result<occt::CadConvertReport> r = occt::convertCadFile(in, out);
  ASSERT_TRUE(r) << r.status().message();
  EXPECT_GT(r->seamsCompared, 150);
  const double tol = 1e-3;           // mm: the default gap tolerance of `seam check` for a file with a unit
  const double angleTolDeg = 0.01;   // its default angle tolerance
  const std::vector<Shared> before = sharedEdges(readWithOcct(in)), after = sharedEdges(readWithOcct(out));
  std::vector<Probe> probed(before.size());
  for (size_t i = 0; i < before.size(); ++i) probed[i] = probeEdge(before[i].edge, before[i].a, before[i].b, 100);
  int clearlyWorse = 0, worseAtAll = 0;
  for (const Shared& s : after) {
    const gp_Pnt mid = edgeMiddle(s.edge);
    size_t nearest = 0;
    for (size_t i = 1; i < before.size(); ++i)
      if (edgeMiddle(before[i].edge).Distance(mid) < edgeMiddle(before[nearest].edge).Distance(mid)) nearest = i;
    const Probe p = probeEdge(s.edge, s.a, s.b, 100);
    const double grew = p.gap - std::max(probed[nearest].gap, tol);
    if (grew > 3.0 * tol) ++clearlyWorse;
    if (grew > 0.1 * tol || p.maxAngleDeg > std::max(probed[nearest].maxAngleDeg, angleTolDeg) + 0.1 * angleTolDeg)
      ++worseAtAll;
  }
  EXPECT_GE(clearlyWorse, 1) << "the probe finds no seam the round trip makes worse: the test lost its case";
  EXPECT_GE(static_cast<int>(r->seamsWorse.size()), clearlyWorse);
  EXPECT_LE(static_cast<int>(r->seamsWorse.size()), worseAtAll);
  for (const std::string& w : r->seamsWorse) EXPECT_NE(w.find("(edge "), std::string::npos) << w;
  fs::remove(out);
}

TEST(CadConvert, ATrimmedModelIsNeverWrittenAsPatches) {
  const fs::path in = kData / "step/trj3_s1-al-214.stp";
  if (!fs::exists(in)) GTEST_SKIP() << in << " missing";
  Result<occt::CadImport> m = occt::readCadFile(in);
  ASSERT_TRUE(m) << m.status().message();
  EXPECT_GT(m->model.trimmedFaces, 0);
  // Its trims are kept as plain data (the JSON's "brep"); without them, only patches are left, and those the
  // writers refuse.
  ASSERT_TRUE(m->model.brep);
  m->model.brep.reset();
  const fs::path json = tempPath("trimmed.json"), step = tempPath("trimmed_patches.step");
  const Status js = io::writeModelJson(m->model, json);
  EXPECT_FALSE(js);
  EXPECT_NE(js.message().find("trimmed"), std::string::npos) << js.message();
  EXPECT_FALSE(occt::writeCadFile(m->model, step, occt::CadFormat::kStep));
  EXPECT_FALSE(fs::exists(json));
  EXPECT_FALSE(fs::exists(step));
}

TEST(BRepHeal, RealFilesKeepTheirFacesAndTrimsAndNoSeamGetsWorse) {
  for (const char* rel : {"step/trj3_s1-al-214.stp", "step/linkrods.step", "iges/occ22470.igs"}) {
#ifdef SEAM_SANITIZED
    // linkrods' heal (24 kinks, every face put back) runs the same code as trj3's and takes about a minute under
    // AddressSanitizer: left to the Release run, to keep CI under its hour.
    if (std::string(rel) == "step/linkrods.step") continue;
#endif
    const fs::path in = kData / rel;
    if (!fs::exists(in)) {
      GTEST_SKIP() << in << " missing";
    }
    const fs::path out = tempPath(std::string("healed") + fs::path(rel).extension().string());
    Result<occt::BRepHealReport> r = occt::healBRepFile(in, out);
    ASSERT_TRUE(r) << rel << ": " << r.status().message();
    EXPECT_EQ(r->seamsWorse, 0) << rel;
    const Counts c0 = countWithOcct(readWithOcct(in)), c1 = countWithOcct(readWithOcct(out));
    EXPECT_EQ(c1.faces, c0.faces) << rel;
    EXPECT_EQ(c1.trimmed, c0.trimmed) << rel;
    EXPECT_EQ(c1.solids, c0.solids) << rel;
    EXPECT_NEAR(c1.area, c0.area, occt::kHealFaceAreaRel * c0.area) << rel;
    if (c0.valid) {
      EXPECT_TRUE(c1.valid) << rel;
    }
    // The probe on every shared edge whose faces changed (each written edge paired with the input's edges that pass
    // nearest to its midpoint: the writer may order them otherwise, and a rebuilt 3-D curve may be parameterised
    // otherwise): no angle or gap of the surfaces grows beyond the tolerance. (The pcurve images' gap is not
    // compared: the STEP reader rebuilds pcurves within the edge tolerances, trj3 edge 49: 0.0028 -> 0.0082 mm after
    // a plain STEP -> STEP conversion whose surfaces, 3-D curves and vertices are bit for bit the input's.)
    const TopoDS_Shape s0 = readWithOcct(in), s1 = readWithOcct(out);
    const std::vector<Shared> e0 = sharedEdges(s0), e1 = sharedEdges(s1);
    ASSERT_EQ(e0.size(), e1.size()) << rel;
    auto midpoint = [](const TopoDS_Edge& e) {
      BRepAdaptor_Curve c(e);
      return c.Value(0.5 * (c.FirstParameter() + c.LastParameter()));
    };
    auto distanceTo = [](const gp_Pnt& p, const TopoDS_Edge& e) {
      BRepAdaptor_Curve c(e);
      double d = std::min(p.Distance(c.Value(c.FirstParameter())), p.Distance(c.Value(c.LastParameter())));
      double f = 0.0, l = 0.0;
      const Handle(Geom_Curve) g = BRep_Tool::Curve(e, f, l);
      if (!g.IsNull()) {
        GeomAPI_ProjectPointOnCurve proj(p, g, f, l);
        if (proj.NbPoints() > 0) d = std::min(d, proj.LowerDistance());
      }
      return d;
    };
    int probed = 0;
    for (size_t k = 0; k < e1.size() && probed < 30; ++k) {
      // The input's edges nearest to the written edge's midpoint (coincident edges of touching solids pass through
      // it both): the written seam must be no worse than one of them.
      const gp_Pnt m = midpoint(e1[k].edge);
      std::vector<double> dist(e0.size());
      double nearest = std::numeric_limits<double>::infinity();
      for (size_t q = 0; q < e0.size(); ++q) nearest = std::min(nearest, dist[q] = distanceTo(m, e0[q].edge));
      const Probe p1 = probeEdge(e1[k].edge, e1[k].a, e1[k].b, 60);
      bool noWorse = false, unchanged = false;
      double gap0 = 0.0, angle0 = 0.0;
      for (size_t q = 0; q < e0.size(); ++q) {
        if (dist[q] > nearest + r->tolerances.distance) continue;
        const Probe p0 = probeEdge(e0[q].edge, e0[q].a, e0[q].b, 60);
        unchanged |=
            std::abs(p0.maxAngleDeg - p1.maxAngleDeg) < 1e-9 && std::abs(p0.surfaceGap - p1.surfaceGap) < 1e-12;
        gap0 = p0.surfaceGap;
        angle0 = p0.maxAngleDeg;
        noWorse |= p1.maxAngleDeg <= std::max(p0.maxAngleDeg, r->tolerances.angleDeg) + 0.05 &&
                   p1.surfaceGap <= std::max(p0.surfaceGap, r->tolerances.distance) * 1.05 + 1e-6;
      }
      if (unchanged) continue;
      ++probed;
      EXPECT_TRUE(noWorse) << rel << " edge " << k + 1 << " (midpoint " << m.X() << " " << m.Y() << " " << m.Z()
                           << "): surface gap " << gap0 << " -> " << p1.surfaceGap << ", angle "
                           << angle0 << " -> " << p1.maxAngleDeg;
    }
    // Gaps by the probe (two-sided, between the boundary images) over every shared edge, before and after: never
    // more; on trj3 (12 gaps of the trims alone, faces moved for others) fewer.
    auto gaps = [&](const std::vector<Shared>& edges) {
      int n = 0;
      for (const Shared& e : edges) n += probeEdge(e.edge, e.a, e.b, 60).gap > r->tolerances.distance ? 1 : 0;
      return n;
    };
    const int gaps0 = gaps(e0), gaps1 = gaps(e1);
    std::cout << rel << ": gaps by the probe " << gaps0 << " -> " << gaps1 << ", seams healed " << r->seamsHealed
              << " of " << r->seamsToHeal << "\n";
    // The plain STEP round trip of trj3 already turns 2 seams into gaps by the probe (OpenCASCADE's reader rebuilds
    // their pcurves): the heal is held to what `seam convert` writes.
    EXPECT_LE(gaps1, gaps0 + 2) << rel;
    if (std::string(rel) == "step/linkrods.step") {
      // A kink whose larger face cannot move is healed by moving the other face (edge 100, F31/F34: F34 goes back,
      // F31 moves): by the probe, some seam of 0.45 deg or more comes out below 0.2 deg.
      EXPECT_GT(r->seamsHealed, 0) << rel;
      bool healedByProbe = false;
      for (const Shared& a : e1) {
        const gp_Pnt m = midpoint(a.edge);
        size_t nearest = 0;
        for (size_t q = 1; q < e0.size(); ++q)
          if (distanceTo(m, e0[q].edge) < distanceTo(m, e0[nearest].edge)) nearest = q;
        const double was = probeEdge(e0[nearest].edge, e0[nearest].a, e0[nearest].b, 100).maxAngleDeg;
        const double now = probeEdge(a.edge, a.a, a.b, 100).maxAngleDeg;
        healedByProbe |= was >= 0.45 && now < 0.2;
      }
      EXPECT_TRUE(healedByProbe) << rel;
    }
    if (std::string(rel) == "step/trj3_s1-al-214.stp") {
      EXPECT_LT(gaps1, gaps0) << rel;
      EXPECT_GT(r->seamsHealed, 0) << rel;
      // A heal that would fold a face is refused for that face and reported (trj3: faces next to the 2.8 deg kinks).
      EXPECT_TRUE(std::any_of(r->notes.begin(), r->notes.end(),
                              [](const std::string& n) { return n.find("would fold") != std::string::npos; }))
          << rel;
      // How far each moved face moved (issue 38 goal 6), measured again by OpenCASCADE alone on the two files: the
      // input face and the written face nearest to its centre of mass, both surfaces sampled on a 40 x 40 grid of
      // the input face's (u, v) box inside its trims. Within the bound (the largest control-point move: the
      // surface's move is a convex combination of its poles' moves), and the seams say the same for their face.
      ASSERT_FALSE(r->faceMoves.empty()) << rel;
      TopTools_IndexedMapOfShape facesIn, facesOut;
      TopExp::MapShapes(s0, TopAbs_FACE, facesIn);
      TopExp::MapShapes(s1, TopAbs_FACE, facesOut);
      for (const occt::BRepFaceMove& m : r->faceMoves) {
        const TopoDS_Face fin = TopoDS::Face(facesIn(std::stoi(m.face.substr(1))));
        GProp_GProps pin;
        BRepGProp::SurfaceProperties(fin, pin);
        TopoDS_Face fout;
        double nearest = std::numeric_limits<double>::infinity();
        for (int i = 1; i <= facesOut.Extent(); ++i) {
          GProp_GProps p;
          BRepGProp::SurfaceProperties(facesOut(i), p);
          const double d = p.CentreOfMass().Distance(pin.CentreOfMass()) + std::abs(p.Mass() - pin.Mass());
          if (d < nearest) nearest = d, fout = TopoDS::Face(facesOut(i));
        }
        double u0, u1, v0, v1;
        BRepTools::UVBounds(fin, u0, u1, v0, v1);
        BRepTopAdaptor_FClass2d inside(fin, Precision::PConfusion());
        const Handle(Geom_Surface) a = BRep_Tool::Surface(fin), b = BRep_Tool::Surface(fout);
        double far = 0.0;
        for (int i = 0; i <= occt::kHealFoldGrid; ++i)
          for (int j = 0; j <= occt::kHealFoldGrid; ++j) {
            const gp_Pnt2d uv(u0 + (u1 - u0) * i / occt::kHealFoldGrid, v0 + (v1 - v0) * j / occt::kHealFoldGrid);
            if (inside.Perform(uv) != TopAbs_OUT)
              far = std::max(far, a->Value(uv.X(), uv.Y()).Distance(b->Value(uv.X(), uv.Y())));
          }
        EXPECT_GT(m.sampled, 0.0) << m.face;
        EXPECT_NEAR(m.sampled, far, 1e-9 + 1e-6 * far) << m.face;
        EXPECT_LE(m.sampled, m.bound * (1.0 + 1e-12)) << m.face;
        for (const occt::BRepHealSeam& hs : r->seams) {
          if (hs.moved == m.face) {
            EXPECT_EQ(hs.movedBy, m.sampled) << hs.edge;
          }
        }
      }
    }
    fs::remove(out);
  }
}

}  // namespace
}  // namespace seam
