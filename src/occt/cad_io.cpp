#include "seam/occt/cad_io.h"

#include "occt/cad_internal.h"

#include <fmt/format.h>
#include <unistd.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <GeomConvert.hxx>
#include <GeomConvert_ApproxSurface.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Geom_Surface.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Reader.hxx>
#include <IGESControl_Writer.hxx>
#include <IGESData_IGESWriter.hxx>
#include <IGESSelect_WorkLibrary.hxx>
#include <StepAP214.hxx>
#include <StepAP214_Protocol.hxx>
#include <StepData_StepModel.hxx>
#include <StepData_StepWriter.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Precision.hxx>
#include <STEPControl_Reader.hxx>
#include <STEPControl_Writer.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopExp_Explorer.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Compound.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Wire.hxx>
#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <fstream>
#include <mutex>
#include <string>

namespace seam::occt {

namespace fs = std::filesystem;

namespace {

/// Largest degree and segment count of the approximation of faces OpenCASCADE cannot convert exactly.
constexpr int kApproxMaxDegree = 9;
constexpr int kApproxMaxSegments = 64;
/// A trimming edge lies on a side of the face's parameter box when its pcurve stays within this fraction of the
/// box size of that side (relative: parameter boxes of different surfaces have unrelated scales).
constexpr double kIsoEdgeRelTol = 1e-7;
/// Reals in written files: 17 significant digits (round-trip exact for doubles), exponent form.
constexpr const char* kRealFormat = "%.16E";
/// Sample points per trimming edge for the iso-line test.
constexpr int kIsoEdgeSamples = 5;

/// OpenCASCADE prints progress and warnings on stdout by default; seam's stdout carries tables and JSON.
void silenceOcct() {
  static std::once_flag once;
  std::call_once(once, [] {
    Message_SequenceOfPrinters printers = Message::DefaultMessenger()->Printers();
    for (Message_SequenceOfPrinters::Iterator it(printers); it.More(); it.Next())
      Message::DefaultMessenger()->RemovePrinter(it.Value());
  });
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

Status ioError(const fs::path& file, const std::string& what) {
  return {ErrorCode::kIoError, fmt::format("{}: {}", file.string(), what)};
}

/// Converts an OpenCASCADE B-spline surface (periodic ones are unrolled) into seam's representation.
Result<BSplineSurface> fromOcct(Handle(Geom_BSplineSurface) s) {
  if (s->IsUPeriodic() || s->IsVPeriodic()) {
    s = Handle(Geom_BSplineSurface)::DownCast(s->Copy());
    if (s->IsUPeriodic()) s->SetUNotPeriodic();
    if (s->IsVPeriodic()) s->SetVNotPeriodic();
  }
  const int nu = s->NbUPoles(), nv = s->NbVPoles();
  TColStd_Array1OfReal ku(1, s->NbUPoles() + s->UDegree() + 1), kv(1, s->NbVPoles() + s->VDegree() + 1);
  s->UKnotSequence(ku);
  s->VKnotSequence(kv);
  std::vector<double> knotsU(ku.begin(), ku.end()), knotsV(kv.begin(), kv.end());
  const bool rational = s->IsURational() || s->IsVRational();
  Matrix pts(nu * nv, 3);
  VecX w = rational ? VecX(nu * nv) : VecX();
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const gp_Pnt p = s->Pole(i + 1, j + 1);
      pts.row(i * nv + j) << p.X(), p.Y(), p.Z();
      if (rational) w[i * nv + j] = s->Weight(i + 1, j + 1);
    }
  return BSplineSurface::create(s->UDegree(), s->VDegree(), std::move(knotsU), std::move(knotsV), nu, nv,
                                std::move(pts), std::move(w));
}

/// Distinct knot values and multiplicities of a flat knot vector.
void distinctKnots(const std::vector<double>& flat, TColStd_Array1OfReal& knots, TColStd_Array1OfInteger& mults) {
  std::vector<double> k;
  std::vector<int> m;
  for (double x : flat) {
    if (!k.empty() && x == k.back())
      ++m.back();
    else {
      k.push_back(x);
      m.push_back(1);
    }
  }
  knots.Resize(1, static_cast<int>(k.size()), false);
  mults.Resize(1, static_cast<int>(m.size()), false);
  for (size_t i = 0; i < k.size(); ++i) {
    knots.SetValue(static_cast<int>(i) + 1, k[i]);
    mults.SetValue(static_cast<int>(i) + 1, m[i]);
  }
}

Handle(Geom_BSplineSurface) toOcct(const BSplineSurface& s) {
  const int nu = s.numU(), nv = s.numV();
  TColgp_Array2OfPnt poles(1, nu, 1, nv);
  TColStd_Array2OfReal weights(1, nu, 1, nv);
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      const auto p = s.point(i, j);
      poles.SetValue(i + 1, j + 1, gp_Pnt(p(0), p(1), p(2)));
      weights.SetValue(i + 1, j + 1, s.weight(i, j));
    }
  TColStd_Array1OfReal ku, kv;
  TColStd_Array1OfInteger mu, mv;
  distinctKnots(s.knotsU().values(), ku, mu);
  distinctKnots(s.knotsV().values(), kv, mv);
  if (s.isRational())
    return new Geom_BSplineSurface(poles, weights, ku, kv, mu, mv, s.degreeU(), s.degreeV());
  return new Geom_BSplineSurface(poles, ku, kv, mu, mv, s.degreeU(), s.degreeV());
}

/// True when every edge of the face's only wire runs along a side of its parameter box (a natural boundary).
bool naturallyBounded(const TopoDS_Face& face, const detail::ParamBox& box, int& wires, int& edges) {
  wires = 0;
  edges = 0;
  for (TopExp_Explorer w(face, TopAbs_WIRE); w.More(); w.Next()) ++wires;
  const TopoDS_Wire outer = BRepTools::OuterWire(face);
  bool natural = wires == 1 && !outer.IsNull();
  for (TopExp_Explorer e(outer, TopAbs_EDGE); e.More(); e.Next()) {
    ++edges;
    if (!detail::boxSideOf(TopoDS::Edge(e.Current()), face, box, false)) natural = false;
  }
  return natural;
}

}  // namespace

namespace detail {

std::optional<Edge> boxSideOf(const TopoDS_Edge& edge, const TopoDS_Face& face, const ParamBox& box, bool wholeSide) {
  double f = 0.0, l = 0.0;
  const Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(edge, face, f, l);
  if (pc.IsNull()) return std::nullopt;
  const double tu = kIsoEdgeRelTol * std::max(box.u1 - box.u0, Precision::PConfusion());
  const double tv = kIsoEdgeRelTol * std::max(box.v1 - box.v0, Precision::PConfusion());
  bool onSide[4] = {true, true, true, true};  // U0, U1, V0, V1
  for (int i = 0; i < kIsoEdgeSamples; ++i) {
    const gp_Pnt2d q = pc->Value(f + (l - f) * i / (kIsoEdgeSamples - 1));
    onSide[0] = onSide[0] && std::abs(q.X() - box.u0) <= tu;
    onSide[1] = onSide[1] && std::abs(q.X() - box.u1) <= tu;
    onSide[2] = onSide[2] && std::abs(q.Y() - box.v0) <= tv;
    onSide[3] = onSide[3] && std::abs(q.Y() - box.v1) <= tv;
  }
  const gp_Pnt2d a = pc->Value(f), b = pc->Value(l);
  // The side's running coordinate at the two ends covers [lo, hi] (either way round).
  auto covers = [](double x, double y, double lo, double hi, double t) {
    return (std::abs(x - lo) <= t && std::abs(y - hi) <= t) || (std::abs(x - hi) <= t && std::abs(y - lo) <= t);
  };
  for (int k = 0; k < 4; ++k) {
    if (!onSide[k]) continue;
    const bool full = k < 2 ? covers(a.Y(), b.Y(), box.v0, box.v1, tv) : covers(a.X(), b.X(), box.u0, box.u1, tu);
    if (!wholeSide || full) return std::array{Edge::U0, Edge::U1, Edge::V0, Edge::V1}[static_cast<size_t>(k)];
  }
  return std::nullopt;
}

/// Reads the file into one shape (STEP or IGES), with OpenCASCADE's errors turned into messages.
Result<TopoDS_Shape> readShape(const fs::path& file, CadFormat format) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) return ioError(file, "cannot read: no such file");
  silenceOcct();
  try {
    if (format == CadFormat::kStep) {
      STEPControl_Reader reader;
      const IFSelect_ReturnStatus st = reader.ReadFile(file.c_str());
      if (st != IFSelect_RetDone) return Status(ErrorCode::kInvalidInput, fmt::format("{}: not a readable STEP file", file.string()));
      if (reader.TransferRoots() == 0 || reader.NbShapes() == 0)
        return Status(ErrorCode::kInvalidInput,
                      fmt::format("{}: the STEP file holds no shape or surface that can be transferred", file.string()));
      return reader.OneShape();
    }
    IGESControl_Controller::Init();
    IGESControl_Reader reader;
    const IFSelect_ReturnStatus st = reader.ReadFile(file.c_str());
    if (st != IFSelect_RetDone) return Status(ErrorCode::kInvalidInput, fmt::format("{}: not a readable IGES file", file.string()));
    if (reader.TransferRoots() == 0 || reader.NbShapes() == 0)
      return Status(ErrorCode::kInvalidInput,
                    fmt::format("{}: the IGES file holds no shape or surface that can be transferred", file.string()));
    return reader.OneShape();
  } catch (const Standard_Failure& f) {
    return Status(ErrorCode::kInvalidInput,
                  fmt::format("{}: OpenCASCADE failed to read the file: {}", file.string(), f.GetMessageString()));
  }
}


}  // namespace detail

std::optional<CadFormat> cadFormatOf(const fs::path& file) {
  const std::string ext = lower(file.extension().string());
  if (ext == ".step" || ext == ".stp") return CadFormat::kStep;
  if (ext == ".iges" || ext == ".igs") return CadFormat::kIges;
  return std::nullopt;
}

Result<CadImport> readCadFile(const fs::path& file, const CadReadOptions& options) {
  const std::optional<CadFormat> format = cadFormatOf(file);
  if (!format)
    return invalidInput(fmt::format("{}: not a STEP (.step/.stp) or IGES (.iges/.igs) file name", file.string()));
  Result<TopoDS_Shape> shape = detail::readShape(file, *format);
  if (!shape) return shape.status();
  std::vector<TopoDS_Face> faces;
  for (TopExp_Explorer ex(*shape, TopAbs_FACE); ex.More(); ex.Next()) faces.push_back(TopoDS::Face(ex.Current()));
  return detail::convertFaces(file, faces, options);
}

namespace detail {

Result<CadImport> convertFaces(const fs::path& file, const std::vector<TopoDS_Face>& faces,
                               const CadReadOptions& options) {
  CadImport out;
  if (faces.empty())
    return Status(ErrorCode::kInvalidInput, fmt::format("{}: the file contains no faces or surfaces", file.string()));
  // Model size for the approximation tolerance: the parameter-box corners of every face, evaluated.
  BoundingBox box;
  for (const TopoDS_Face& f : faces) {
    try {
      double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
      BRepTools::UVBounds(f, u0, u1, v0, v1);
      const Handle(Geom_Surface) s = BRep_Tool::Surface(f);
      if (s.IsNull()) continue;
      for (double u : {u0, 0.5 * (u0 + u1), u1})
        for (double v : {v0, 0.5 * (v0 + v1), v1}) {
          const gp_Pnt p = s->Value(u, v);
          box.add(Vec3(p.X(), p.Y(), p.Z()));
        }
    } catch (const Standard_Failure&) {
    }
  }
  const double approxTol = options.approximationRelTol * std::max(box.empty() ? 1.0 : box.diagonal(), 1e-300);

  int index = 0;
  for (const TopoDS_Face& face : faces) {
    ++index;
    const std::string name = fmt::format("F{}", index);
    CadFace info;
    info.patch = name;
    info.faceIndex = index;
    info.reversed = face.Orientation() == TopAbs_REVERSED;
    try {
      const Handle(Geom_Surface) surf = BRep_Tool::Surface(face);
      if (surf.IsNull()) {
        out.warnings.push_back(fmt::format("{}: face {} has no surface; skipped", file.string(), index));
        continue;
      }
      info.surfaceType = surf->DynamicType()->Name();
      double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
      BRepTools::UVBounds(face, u0, u1, v0, v1);
      if (!(u1 > u0) || !(v1 > v0))
        return Status(ErrorCode::kInvalidInput,
                      fmt::format("{}: face {} ({}): empty parameter box [{}, {}] x [{}, {}]", file.string(), index,
                                  info.surfaceType, u0, u1, v0, v1));
      info.trimmed = !naturallyBounded(face, {u0, u1, v0, v1}, info.wires, info.edges);
      {  // pcurves may overshoot a bounded surface's domain by their tolerance: clamp the box into it
        double su0 = 0, su1 = 0, sv0 = 0, sv1 = 0;
        surf->Bounds(su0, su1, sv0, sv1);
        if (!surf->IsUPeriodic() && !Precision::IsInfinite(su0)) u0 = std::max(u0, su0);
        if (!surf->IsUPeriodic() && !Precision::IsInfinite(su1)) u1 = std::min(u1, su1);
        if (!surf->IsVPeriodic() && !Precision::IsInfinite(sv0)) v0 = std::max(v0, sv0);
        if (!surf->IsVPeriodic() && !Precision::IsInfinite(sv1)) v1 = std::min(v1, sv1);
      }
      Handle(Geom_BSplineSurface) bs = Handle(Geom_BSplineSurface)::DownCast(surf);
      double su0 = 0, su1 = 0, sv0 = 0, sv1 = 0;
      if (!bs.IsNull()) bs->Bounds(su0, su1, sv0, sv1);
      const bool wholeBSpline = !bs.IsNull() && std::abs(su0 - u0) <= Precision::PConfusion() &&
                                std::abs(su1 - u1) <= Precision::PConfusion() &&
                                std::abs(sv0 - v0) <= Precision::PConfusion() &&
                                std::abs(sv1 - v1) <= Precision::PConfusion();
      if (!wholeBSpline) {
        // Restrict to the face's parameter box, then convert (exact for B-spline, Bezier and analytic surfaces
        // with a rational form); approximate what cannot be converted.
        const Handle(Geom_RectangularTrimmedSurface) trimmedSurf = new Geom_RectangularTrimmedSurface(surf, u0, u1, v0, v1);
        std::string why = "no exact B-spline form";
        try {
          bs = GeomConvert::SurfaceToBSplineSurface(trimmedSurf);
        } catch (const Standard_Failure& f) {
          bs.Nullify();
          why = f.GetMessageString();
        }
        if (bs.IsNull()) {
          GeomConvert_ApproxSurface approx(trimmedSurf, approxTol, GeomAbs_C2, GeomAbs_C2, kApproxMaxDegree,
                                           kApproxMaxDegree, kApproxMaxSegments, 0);
          if (!approx.HasResult())
            return Status(ErrorCode::kUnsupported,
                          fmt::format("{}: face {} ({}): OpenCASCADE can neither convert nor approximate the surface",
                                      file.string(), index, info.surfaceType));
          bs = approx.Surface();
          info.exact = false;
          info.approximationError = approx.MaxError();
          out.warnings.push_back(fmt::format("{}: face {} ({}) approximated within {:.3g} ({})", file.string(), index,
                                             info.surfaceType, info.approximationError, why));
        }
      }
      Result<BSplineSurface> s = fromOcct(bs);
      if (!s)
        return Status(s.status().code(),
                      fmt::format("{}: face {} ({}): {}", file.string(), index, info.surfaceType, s.status().message()));
      out.model.patches.push_back({name, PatchKind::kBSpline, std::move(s).value()});
      out.faces.push_back(info);
    } catch (const Standard_Failure& f) {
      // One unreadable face does not lose the model: it is skipped, and said so.
      out.warnings.push_back(fmt::format("{}: face {} ({}) skipped: OpenCASCADE failed: {}", file.string(), index,
                                         info.surfaceType, f.GetMessageString()));
    }
  }
  if (out.model.patches.empty())
    return Status(ErrorCode::kInvalidInput, fmt::format("{}: no face could be read", file.string()));
  return out;
}

}  // namespace detail

Status writeCadFile(const Model& model, const fs::path& file, CadFormat format, const CadWriteOptions& options) {
  if (model.patches.empty()) return invalidInput(fmt::format("{}: the model has no patches to write", file.string()));
  silenceOcct();
  const double tol = options.sewingTolerance.value_or(1e-6 * model.boundingBox().diagonal());
  const fs::path temp = file.parent_path() / fmt::format(".{}.seam-tmp-{}{}", file.stem().string(), ::getpid(),
                                                          file.extension().string());
  try {
    std::vector<TopoDS_Face> faces;
    for (const Patch& p : model.patches) {
      if (p.surface.dim() != 3)
        return invalidInput(fmt::format("{}: patch \"{}\" is not 3-D", file.string(), p.name));
      const Handle(Geom_BSplineSurface) s = toOcct(p.surface);
      BRepBuilderAPI_MakeFace mf(s, Precision::Confusion());
      if (!mf.IsDone())
        return invalidInput(fmt::format("{}: patch \"{}\": OpenCASCADE cannot make a face of it", file.string(), p.name));
      faces.push_back(mf.Face());
    }
    TopoDS_Shape shape;
    if (faces.size() == 1) {
      shape = faces.front();
    } else {
      BRepBuilderAPI_Sewing sewing(tol);
      for (const TopoDS_Face& f : faces) sewing.Add(f);
      sewing.Perform();
      shape = sewing.SewedShape();
      if (shape.IsNull()) {
        TopoDS_Compound c;
        BRep_Builder b;
        b.MakeCompound(c);
        for (const TopoDS_Face& f : faces) b.Add(c, f);
        shape = c;
      }
    }
    // The writers' default real format keeps 12 significant digits (STEP) or 9 (IGES); seam writes 17 so that
    // every control point, weight and knot survives a round trip (issue 8: STEP -> JSON -> STEP is exact).
    bool ok = false;
    std::ofstream os(temp, std::ios::binary | std::ios::trunc);
    if (!os) return ioError(file, "cannot create temporary file " + temp.string());
    if (format == CadFormat::kStep) {
      STEPControl_Writer w;
      Interface_Static::SetCVal("write.step.schema", "AP214IS");
      if (w.Transfer(shape, STEPControl_AsIs) == IFSelect_RetDone) {
        StepData_StepWriter sw(w.Model());
        sw.FloatWriter().SetFormat(kRealFormat);
        sw.SendModel(StepAP214::Protocol());
        ok = sw.Print(os);
      }
    } else {
      IGESControl_Controller::Init();
      IGESControl_Writer w("MM", 1);  // B-rep mode
      if (w.AddShape(shape)) {
        w.ComputeModel();
        IGESData_IGESWriter iw(w.Model());
        iw.FloatWriter().SetFormat(kRealFormat);
        iw.SendModel(IGESSelect_WorkLibrary::DefineProtocol());
        ok = iw.Print(os);
      }
    }
    os.close();
    ok = ok && !os.fail();
    if (!ok) {
      std::error_code ec;
      fs::remove(temp, ec);
      return ioError(file, "OpenCASCADE could not write the file");
    }
  } catch (const Standard_Failure& f) {
    std::error_code ec;
    fs::remove(temp, ec);
    return ioError(file, std::string("OpenCASCADE failed: ") + f.GetMessageString());
  }
  std::error_code ec;
  fs::rename(temp, file, ec);
  if (ec) {
    fs::remove(temp, ec);
    return ioError(file, "cannot replace file: " + ec.message());
  }
  return Status::ok();
}

}  // namespace seam::occt
