#pragma once
// OpenCASCADE alone (no seam code): reading a STEP/IGES file and counting what a B-rep holds (faces, trimmed faces,
// solids, area, validity, free edges after sewing). The independent side of the tests that hold seam's conversions
// and heals to "nothing lost" (occt_brep_model_test, occt_brep_heal_test).
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepGProp.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <GProp_GProps.hxx>
#include <Geom2d_Curve.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Reader.hxx>
#include <Interface_Static.hxx>
#include <STEPControl_Reader.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <UnitsMethods.hxx>
#include <cmath>
#include <filesystem>
#include <memory>
#include <string>

namespace seam::test {

/// The shape of a STEP/IGES file as OpenCASCADE's readers give it (default settings), in millimetres: the session
/// unit is global state that an IGES read in inches leaves behind, so it is set again before every read.
inline TopoDS_Shape occtRead(const std::filesystem::path& file) {
  Interface_Static::SetCVal("xstep.cascade.unit", "MM");
  UnitsMethods::SetCasCadeLengthUnit(1.0, UnitsMethods_LengthUnit_Millimeter);
  const std::string ext = file.extension().string();
  std::unique_ptr<XSControl_Reader> r;
  if (ext == ".igs" || ext == ".iges") {
    IGESControl_Controller::Init();
    r = std::make_unique<IGESControl_Reader>();
  } else {
    r = std::make_unique<STEPControl_Reader>();
  }
  if (r->ReadFile(file.c_str()) != IFSelect_RetDone) return {};
  r->TransferRoots();
  return r->OneShape();
}

/// The area of a shape's faces (adaptive integration: the default rule is off by up to 1e-3 on some faces).
inline double occtArea(const TopoDS_Shape& s) {
  GProp_GProps props;
  BRepGProp::SurfaceProperties(s, props, 1e-9);
  return props.Mass();
}

/// A face is untrimmed when it has one wire and every edge's pcurve runs along a side of its UV box (5 samples,
/// 1e-7 of the box size).
inline bool occtTrimmedFace(const TopoDS_Face& f) {
  int wires = 0;
  for (TopExp_Explorer w(f, TopAbs_WIRE); w.More(); w.Next()) ++wires;
  if (wires != 1) return true;
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
  BRepTools::UVBounds(f, u0, u1, v0, v1);
  const double tu = 1e-7 * (u1 - u0), tv = 1e-7 * (v1 - v0);
  for (TopExp_Explorer e(f, TopAbs_EDGE); e.More(); e.Next()) {
    double a = 0, b = 0;
    const Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(TopoDS::Edge(e.Current()), f, a, b);
    if (pc.IsNull()) return true;
    bool side[4] = {true, true, true, true};
    for (int i = 0; i < 5; ++i) {
      const gp_Pnt2d q = pc->Value(a + (b - a) * i / 4);
      side[0] = side[0] && std::abs(q.X() - u0) <= tu;
      side[1] = side[1] && std::abs(q.X() - u1) <= tu;
      side[2] = side[2] && std::abs(q.Y() - v0) <= tv;
      side[3] = side[3] && std::abs(q.Y() - v1) <= tv;
    }
    if (!side[0] && !side[1] && !side[2] && !side[3]) return true;
  }
  return false;
}

struct OcctCounts {
  int faces = 0, trimmed = 0, solids = 0;
  int freeEdgesAfterSewing = -1;  ///< -1: not sewn (occtCounts(..., false))
  double area = 0.0;
  bool valid = false;
};

/// The counts of `s`; with `sew`, also the free edges after sewing at 1e-4 of the bounding-box diagonal.
inline OcctCounts occtCounts(const TopoDS_Shape& s, bool sew = true) {
  OcctCounts c;
  TopTools_IndexedMapOfShape faces, solids;
  TopExp::MapShapes(s, TopAbs_FACE, faces);
  TopExp::MapShapes(s, TopAbs_SOLID, solids);
  c.faces = faces.Extent();
  c.solids = solids.Extent();
  for (int i = 1; i <= faces.Extent(); ++i) c.trimmed += occtTrimmedFace(TopoDS::Face(faces(i))) ? 1 : 0;
  c.area = occtArea(s);
  c.valid = BRepCheck_Analyzer(s).IsValid();
  if (!sew) return c;
  c.freeEdgesAfterSewing = 0;
  Bnd_Box box;
  BRepBndLib::Add(s, box);
  BRepBuilderAPI_Sewing sewing(1e-4 * std::sqrt(box.SquareExtent()));
  sewing.Add(s);
  sewing.Perform();
  const TopoDS_Shape sewn = sewing.SewedShape().IsNull() ? s : sewing.SewedShape();
  TopTools_IndexedDataMapOfShapeListOfShape edgeFaces;
  TopExp::MapShapesAndAncestors(sewn, TopAbs_EDGE, TopAbs_FACE, edgeFaces);
  for (int i = 1; i <= edgeFaces.Extent(); ++i) {
    const TopoDS_Edge& e = TopoDS::Edge(edgeFaces.FindKey(i));
    const TopTools_ListOfShape& around = edgeFaces.FindFromIndex(i);
    if (around.Extent() == 1 && !BRep_Tool::Degenerated(e) && !BRep_Tool::IsClosed(e, TopoDS::Face(around.First())))
      ++c.freeEdgesAfterSewing;
  }
  return c;
}

}  // namespace seam::test
