// occt_probe: an OpenCASCADE-only measuring tool, independent of seam.
//
// It reads a STEP or IGES file with OpenCASCADE's own readers and measures the B-rep with OpenCASCADE's own
// algorithms only (no seam code), so that its numbers can be used as an independent check of seam's results.
//
//   occt_probe summary FILE                      topology counts, area, volume, validity, free edges, bbox
//   occt_probe seams FILE [--samples N] [--sew]  gap and normal angle along every edge shared by two faces
//
// Both print one JSON object on stdout. Exit codes: 0 done, 1 bad usage, 2 the file cannot be read.
// See README.md beside this file for what is measured and how.

#include <BRepAdaptor_Curve.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_Copy.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepCheck_Analyzer.hxx>
#include <BRepGProp.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <Extrema_GenLocateExtPS.hxx>
#include <Extrema_POnSurf.hxx>
#include <GProp_GProps.hxx>
#include <Geom2d_Curve.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <GeomLProp_SLProps.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_BezierSurface.hxx>
#include <Geom_OffsetSurface.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Geom_Surface.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Reader.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <OSD.hxx>
#include <STEPControl_Reader.hxx>
#include <ShapeAnalysis_Surface.hxx>
#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Vertex.hxx>
#include <gp_Pnt.hxx>
#include <gp_Pnt2d.hxx>
#include <gp_Vec.hxx>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <iostream>
#include <limits>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace {

using Json = nlohmann::ordered_json;

constexpr double kPi = 3.14159265358979323846;
constexpr double kSewingRelTol = 1e-4;     // sewing tolerance = this x bounding-box diagonal
constexpr double kUntrimmedRelTol = 1e-7;  // "on the UV box boundary" within this x box size
constexpr double kEndExclusion = 0.02;  // fraction of samples at each end left out of the interior max angle
constexpr int kPcurveChecks = 11;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kAngleWindow = 0.1;  // boundary normals are paired within this fraction of the edge
constexpr double kPoleSine = 1e-6;    // a surface point with |Su x Sv| below this x |Su| |Sv| is singular (a pole)
constexpr double kPoleStep = 1e-6;    // ... and its normal is taken this fraction of the edge further in
constexpr double kKnotNudgeRel = 1e-9;  // a normal on a knot line is taken this x knot range inside the face       // pcurve points tested when deciding whether a face is trimmed

// ---------------------------------------------------------------------------------------------------------------
// Reading

enum class Format { kStep, kIges };

std::optional<Format> formatOf(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".stp" || ext == ".step") return Format::kStep;
  if (ext == ".igs" || ext == ".iges") return Format::kIges;
  return std::nullopt;
}

// Reads the file with the plain OpenCASCADE reader (TransferRoots + OneShape). A null shape means failure.
TopoDS_Shape readShape(const std::string& path, Format format) {
  try {
    OCC_CATCH_SIGNALS
    if (format == Format::kStep) {
      STEPControl_Reader reader;
      if (reader.ReadFile(path.c_str()) != IFSelect_RetDone) return {};
      reader.TransferRoots();
      return reader.OneShape();
    }
    IGESControl_Reader reader;
    if (reader.ReadFile(path.c_str()) != IFSelect_RetDone) return {};
    reader.TransferRoots();
    return reader.OneShape();
  } catch (const Standard_Failure&) {
    return {};
  }
}

// ---------------------------------------------------------------------------------------------------------------
// Small shape queries

int countShapes(const TopoDS_Shape& shape, TopAbs_ShapeEnum type) {
  TopTools_IndexedMapOfShape map;
  TopExp::MapShapes(shape, type, map);
  return map.Extent();
}

// Bounding-box diagonal. BRepBndLib::Add over the whole shape (what most tools use, seam included; it can be
// a little loose for B-splines because it bounds control points and adds tolerances), or the tight box of the
// faces' geometry (BRepBndLib::AddOptimal face by face: edges outside faces may lack a 3-D curve and make it
// infinite).
double bboxDiagonal(const TopoDS_Shape& shape, bool optimal) {
  Bnd_Box box;
  if (optimal) {
    for (TopExp_Explorer f(shape, TopAbs_FACE); f.More(); f.Next())
      BRepBndLib::AddOptimal(f.Current(), box, /*useTriangulation=*/false, /*useShapeTolerance=*/false);
  } else {
    BRepBndLib::Add(shape, box);
  }
  return box.IsVoid() ? 0.0 : std::sqrt(box.SquareExtent());
}

// The basis surface of a face's surface, with trimming and offset wrappers removed.
Handle(Geom_Surface) basisSurface(Handle(Geom_Surface) surface) {
  for (;;) {
    if (auto t = Handle(Geom_RectangularTrimmedSurface)::DownCast(surface); !t.IsNull())
      surface = t->BasisSurface();
    else if (auto o = Handle(Geom_OffsetSurface)::DownCast(surface); !o.IsNull())
      surface = o->BasisSurface();
    else
      return surface;
  }
}

bool isBSplineSurface(const Handle(Geom_Surface) & basis) {
  return !basis.IsNull() && (basis->IsKind(STANDARD_TYPE(Geom_BSplineSurface)) ||
                             basis->IsKind(STANDARD_TYPE(Geom_BezierSurface)));
}

// True when the edge's pcurve on the face lies on one side of the UV box (an iso-parameter line on its
// boundary).
bool pcurveOnBoxSide(const TopoDS_Edge& edge, const TopoDS_Face& face, const std::array<double, 4>& box) {
  const auto [u0, u1, v0, v1] = box;
  const double tu = kUntrimmedRelTol * (u1 - u0);
  const double tv = kUntrimmedRelTol * (v1 - v0);
  double f = 0, l = 0;
  const Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(edge, face, f, l);
  if (pc.IsNull()) return false;
  bool onU0 = true, onU1 = true, onV0 = true, onV1 = true;
  for (int i = 0; i < kPcurveChecks; ++i) {
    const gp_Pnt2d p = pc->Value(f + (l - f) * i / (kPcurveChecks - 1));
    onU0 = onU0 && std::abs(p.X() - u0) <= tu;
    onU1 = onU1 && std::abs(p.X() - u1) <= tu;
    onV0 = onV0 && std::abs(p.Y() - v0) <= tv;
    onV1 = onV1 && std::abs(p.Y() - v1) <= tv;
  }
  return onU0 || onU1 || onV0 || onV1;
}

// A face is untrimmed when it has exactly one wire and every edge's pcurve runs along the boundary of the
// face's parameter box (BRepTools::UVBounds). Everything else (holes, curved or inset boundaries) counts as
// trimmed.
bool isTrimmedFace(const TopoDS_Face& face) {
  if (countShapes(face, TopAbs_WIRE) != 1) return true;
  std::array<double, 4> box{};
  BRepTools::UVBounds(face, box[0], box[1], box[2], box[3]);
  for (TopExp_Explorer e(face, TopAbs_EDGE); e.More(); e.Next())
    if (!pcurveOnBoxSide(TopoDS::Edge(e.Current()), face, box)) return true;
  return false;
}

// Edges (not degenerate) that bound exactly one face. A seam edge of a closed surface lists its face twice
// and so is not free.
int countFreeEdges(const TopoDS_Shape& shape) {
  TopTools_IndexedDataMapOfShapeListOfShape edgeFaces;
  TopExp::MapShapesAndAncestors(shape, TopAbs_EDGE, TopAbs_FACE, edgeFaces);
  int n = 0;
  for (int i = 1; i <= edgeFaces.Extent(); ++i) {
    const TopoDS_Edge& e = TopoDS::Edge(edgeFaces.FindKey(i));
    if (!BRep_Tool::Degenerated(e) && edgeFaces(i).Extent() == 1) ++n;
  }
  return n;
}

// Sews a copy of the shape (returned in `copied`, for the sewing history) at kSewingRelTol x diagonal.
// Returns a null shape when sewing fails.
TopoDS_Shape sewCopy(const TopoDS_Shape& shape, double diagonal, BRepBuilderAPI_Sewing& sewing,
                     TopoDS_Shape& copied) {
  BRepBuilderAPI_Copy copy(shape);
  copied = copy.Shape();
  sewing.Init(kSewingRelTol * diagonal);
  sewing.Add(copied);
  sewing.Perform();
  return sewing.SewedShape();
}

// ---------------------------------------------------------------------------------------------------------------
// summary

Json summarize(const TopoDS_Shape& shape) {
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  int bspline = 0, trimmed = 0, faceErrors = 0;
  std::map<std::string, int> types;  // basis surface type name -> faces
  for (int i = 1; i <= faces.Extent(); ++i) {
    try {
      OCC_CATCH_SIGNALS
      const TopoDS_Face& f = TopoDS::Face(faces(i));
      const Handle(Geom_Surface) basis = basisSurface(BRep_Tool::Surface(f));
      ++types[basis.IsNull() ? "none" : basis->DynamicType()->Name()];
      bspline += isBSplineSurface(basis) ? 1 : 0;
      trimmed += isTrimmedFace(f) ? 1 : 0;
    } catch (const Standard_Failure&) {
      ++faceErrors;
    }
  }
  Json j;
  j["faces"] = faces.Extent();
  j["bspline_faces"] = bspline;
  j["trimmed_faces"] = trimmed;
  if (faceErrors) j["face_errors"] = faceErrors;
  j["surface_types"] = types;
  j["wires"] = countShapes(shape, TopAbs_WIRE);
  j["edges"] = countShapes(shape, TopAbs_EDGE);
  j["shells"] = countShapes(shape, TopAbs_SHELL);
  j["solids"] = countShapes(shape, TopAbs_SOLID);

  GProp_GProps area;
  BRepGProp::SurfaceProperties(shape, area);
  j["area"] = area.Mass();
  double volume = 0;
  TopTools_IndexedMapOfShape solids;
  TopExp::MapShapes(shape, TopAbs_SOLID, solids);
  for (int i = 1; i <= solids.Extent(); ++i) {
    GProp_GProps v;
    BRepGProp::VolumeProperties(solids(i), v);
    volume += v.Mass();
  }
  j["volume"] = volume;
  j["valid"] = faces.Extent() > 0 && BRepCheck_Analyzer(shape).IsValid();

  const double diag = bboxDiagonal(shape, false);
  j["free_edges"] = countFreeEdges(shape);
  BRepBuilderAPI_Sewing sewing;
  TopoDS_Shape copied;
  const TopoDS_Shape sewn = faces.Extent() > 0 ? sewCopy(shape, diag, sewing, copied) : TopoDS_Shape();
  j["free_edges_after_sewing"] = sewn.IsNull() ? Json(nullptr) : Json(countFreeEdges(sewn));
  j["sewing_tolerance"] = kSewingRelTol * diag;
  j["bbox_diagonal"] = diag;
  j["bbox_diagonal_optimal"] = bboxDiagonal(shape, true);
  return j;
}

// ---------------------------------------------------------------------------------------------------------------
// seams: sampling

// One face along a shared edge: its oriented surface and the edge's pcurve on it.
struct Side {
  TopoDS_Face face;
  Handle(Geom_Surface) surface;            // with the face's location applied (BRep_Tool::Surface)
  Handle(GeomAdaptor_Surface) adaptor;     // for the local projection (Extrema_GenLocateExtPS)
  Handle(ShapeAnalysis_Surface) analysis;  // fallback projection when the local one fails
  Handle(Geom2d_Curve) pcurve;
  double pf = 0, pl = 0;  // pcurve range
  bool reversed = false;  // face orientation is TopAbs_REVERSED: flip the normal
  double box[4] = {0, 0, 0, 0};  // the face's UV box (BRepTools::UVBounds): umin, umax, vmin, vmax
};

std::optional<Side> makeSide(const TopoDS_Edge& edge, const TopoDS_Face& face) {
  Side s;
  s.face = face;
  s.surface = BRep_Tool::Surface(face);
  s.pcurve = BRep_Tool::CurveOnSurface(edge, face, s.pf, s.pl);
  if (s.surface.IsNull() || s.pcurve.IsNull()) return std::nullopt;
  s.adaptor = new GeomAdaptor_Surface(s.surface);
  s.analysis = new ShapeAnalysis_Surface(s.surface);
  s.reversed = face.Orientation() == TopAbs_REVERSED;
  BRepTools::UVBounds(face, s.box[0], s.box[1], s.box[2], s.box[3]);
  return s;
}

// What one sample gives on one side.
struct SideSample {
  gp_Pnt boundary;  // surface at the pcurve point (the face's image of its boundary)
  gp_Pnt foot;      // projection of the edge point onto the surface
  gp_Vec normal;    // unit oriented normal there
  std::optional<gp_Vec> boundaryNormal;  // unit oriented normal at the pcurve point (none at a pole)
};

// Projects p onto the side's surface: a local search (Extrema_GenLocateExtPS, normal-projection criterion)
// from the pcurve point uv0, which is already close; when it fails, ShapeAnalysis_Surface's projection
// (Newton from uv0, then a global search).
gp_Pnt2d projectNear(const Side& s, const gp_Pnt2d& uv0, const gp_Pnt& p, double precision) {
  Extrema_GenLocateExtPS locate(*s.adaptor);
  locate.Perform(p, uv0.X(), uv0.Y(), /*isDistanceCriteria=*/Standard_False);
  if (locate.IsDone()) {
    double u = 0, v = 0;
    locate.Point().Parameter(u, v);
    return {u, v};
  }
  return s.analysis->NextValueOfUV(uv0, p, precision);
}

// On a B-spline surface a point on a knot line (or on the closing line of a periodic surface) has two one-sided
// derivatives, which differ where the surface is only C0 there: two faces cut from one surface along a C0 knot line,
// or the two sides of a periodic surface's seam. The face's own normal is the one from its side. This moves such a
// coordinate by kKnotNudgeRel of the knot range toward the middle of the face's UV box (the face lies on that
// side of a knot line through its boundary), so that OpenCASCADE evaluates the span inside the face.
gp_Pnt2d insideKnotLines(const Side& s, const gp_Pnt2d& uv) {
  const auto bs = Handle(Geom_BSplineSurface)::DownCast(s.surface);
  if (bs.IsNull()) return uv;
  double at[2] = {uv.X(), uv.Y()};
  const double mid[2] = {0.5 * (s.box[0] + s.box[1]), 0.5 * (s.box[2] + s.box[3])};
  for (int k = 0; k < 2; ++k) {
    const int n = k == 0 ? bs->NbUKnots() : bs->NbVKnots();
    const double k0 = k == 0 ? bs->UKnot(1) : bs->VKnot(1), k1 = k == 0 ? bs->UKnot(n) : bs->VKnot(n);
    const double step = kKnotNudgeRel * (k1 - k0);
    for (int i = 1; i <= n; ++i) {
      const double knot = k == 0 ? bs->UKnot(i) : bs->VKnot(i);
      if (std::abs(at[k] - knot) > step) continue;
      at[k] = knot + (mid[k] >= knot ? step : -step);
      break;
    }
  }
  return {at[0], at[1]};
}

// Evaluates one side at the given fraction of the edge (mapped linearly onto the pcurve range; the identity
// for same-parameter edges). The normal is taken at the projection of the edge point, or at the pcurve point
// when that is nearer (a projection that went astray). Throws Standard_Failure, or returns nullopt when the
// normal is undefined (pole), so that the caller skips the sample.
std::optional<SideSample> sampleSide(const Side& s, double fraction, const gp_Pnt& p, double precision) {
  const gp_Pnt2d uv0 = s.pcurve->Value(s.pf + (s.pl - s.pf) * fraction);
  const gp_Pnt boundary = s.surface->Value(uv0.X(), uv0.Y());
  gp_Pnt2d uv = projectNear(s, uv0, p, precision);
  if (p.Distance(s.surface->Value(uv.X(), uv.Y())) > p.Distance(boundary)) uv = uv0;
  uv = insideKnotLines(s, uv);
  GeomLProp_SLProps props(s.surface, uv.X(), uv.Y(), 1, precision);
  if (!props.IsNormalDefined()) return std::nullopt;
  gp_Vec n(props.Normal());
  if (s.reversed) n.Reverse();
  SideSample out{boundary, props.Value(), n, std::nullopt};
  // The normal at the pcurve point; where the surface is singular there (a pole: a collapsed row, a cone's apex,
  // |S_u x S_v| below kPoleSine |S_u| |S_v|) its limit along the edge from inside, taken kPoleStep of the edge
  // further in (OpenCASCADE's normal at the singular point itself can be any direction: 24.6 deg at the
  // fuselage's nose).
  for (const double step : {0.0, kPoleStep}) {
    const double f = fraction < 0.5 ? fraction + step : fraction - step;
    const gp_Pnt2d uvb = insideKnotLines(s, s.pcurve->Value(s.pf + (s.pl - s.pf) * f));
    GeomLProp_SLProps atBoundary(s.surface, uvb.X(), uvb.Y(), 1, precision);
    const gp_Vec su = atBoundary.D1U(), sv = atBoundary.D1V();
    if (!(su.Crossed(sv).Magnitude() > kPoleSine * su.Magnitude() * sv.Magnitude())) continue;
    if (!atBoundary.IsNormalDefined()) continue;
    out.boundaryNormal = gp_Vec(atBoundary.Normal());
    if (s.reversed) out.boundaryNormal->Reverse();
    break;
  }
  return out;
}

// Both sides sampled at N points of the edge (ends included); skipped samples leave no entry.
struct SeamSamples {
  std::vector<gp_Pnt> boundaryA, boundaryB;
  std::vector<double> angle, param, position;  // angle (deg), edge parameter, index / (N-1)
  // Unit normals at each side's pcurve points (aligned with boundaryA / boundaryB; NaN vector at a pole).
  std::vector<gp_Vec> boundaryNormalA, boundaryNormalB;
  double maxDistance = 0;                      // largest distance from the edge to either surface
  double maxFootGap = 0;  // largest distance between the two projections of an edge point
  int skipped = 0;
};

SeamSamples sampleSeam(const TopoDS_Edge& edge, const Side& a, const Side& b, int n, double precision) {
  SeamSamples out;
  BRepAdaptor_Curve curve(edge);
  const double f = curve.FirstParameter(), l = curve.LastParameter();
  for (int k = 0; k < n; ++k) {
    const double fraction = n > 1 ? double(k) / (n - 1) : 0.0;
    const double t = f + (l - f) * fraction;
    try {
      OCC_CATCH_SIGNALS
      const gp_Pnt p = curve.Value(t);
      const auto sa = sampleSide(a, fraction, p, precision);
      const auto sb = sampleSide(b, fraction, p, precision);
      if (!sa || !sb) {
        ++out.skipped;
        continue;
      }
      const double c = std::clamp(sa->normal.Dot(sb->normal), -1.0, 1.0);
      out.boundaryA.push_back(sa->boundary);
      out.boundaryB.push_back(sb->boundary);
      out.angle.push_back(std::acos(c) * 180.0 / kPi);
      const gp_Vec none(kNaN, kNaN, kNaN);
      out.boundaryNormalA.push_back(sa->boundaryNormal.value_or(none));
      out.boundaryNormalB.push_back(sb->boundaryNormal.value_or(none));
      out.param.push_back(t);
      out.position.push_back(fraction);
      out.maxDistance = std::max({out.maxDistance, p.Distance(sa->foot), p.Distance(sb->foot)});
      out.maxFootGap = std::max(out.maxFootGap, sa->foot.Distance(sb->foot));
    } catch (const Standard_Failure&) {
      ++out.skipped;
    }
  }
  return out;
}

// ---------------------------------------------------------------------------------------------------------------
// seams: one-sided distance from points to a sampled curve, with no parameter correspondence

// Nearest point of segment ab to q, as the segment parameter in [0, 1].
double segmentParameter(const gp_Pnt& q, const gp_Pnt& a, const gp_Pnt& b) {
  const gp_Vec ab(a, b), aq(a, q);
  const double len2 = ab.SquareMagnitude();
  return len2 > 0 ? std::clamp(aq.Dot(ab) / len2, 0.0, 1.0) : 0.0;
}

// The samples of a curve, cut into chunks of consecutive segments with their axis-aligned boxes, so that a
// nearest-point query can skip chunks that cannot beat the best distance found so far (the nearest segment
// found is the exact one; chunking only saves time). The distance is then refined on the quadratic through
// the three samples around that segment: a chord alone is off by its sag, about h^2 k / 8 for spacing h and
// curvature k (6e-5 for a 100 mm circle in 2000 samples), the quadratic by O(h^3).
class SampledCurve {
 public:
  explicit SampledCurve(const std::vector<gp_Pnt>& pts) : pts_(pts) {
    for (size_t s = 0; s + 1 < pts.size(); s += kChunk) {
      Chunk c{s, std::min(s + kChunk, pts.size() - 1), pts[s], pts[s]};
      for (size_t i = s; i <= c.end; ++i) {
        c.lo.SetCoord(std::min(c.lo.X(), pts[i].X()), std::min(c.lo.Y(), pts[i].Y()),
                      std::min(c.lo.Z(), pts[i].Z()));
        c.hi.SetCoord(std::max(c.hi.X(), pts[i].X()), std::max(c.hi.Y(), pts[i].Y()),
                      std::max(c.hi.Z(), pts[i].Z()));
      }
      chunks_.push_back(c);
    }
  }

  double distance(const gp_Pnt& q) const {
    if (pts_.size() == 1) return q.Distance(pts_[0]);
    double best = std::numeric_limits<double>::infinity(), bestT = 0;
    size_t bestSeg = 0;
    for (const Chunk& c : chunks_) {
      if (boxDistance(q, c) >= best) continue;
      for (size_t i = c.begin; i < c.end; ++i) {
        const double t = segmentParameter(q, pts_[i], pts_[i + 1]);
        const double d = q.Distance(pts_[i].Translated(gp_Vec(pts_[i], pts_[i + 1]) * t));
        if (d < best) best = d, bestSeg = i, bestT = t;
      }
    }
    return pts_.size() < 3 ? best : refined(q, bestSeg, bestT);
  }

 private:
  static constexpr size_t kChunk = 32;
  struct Chunk {
    size_t begin, end;  // segments begin..end-1 (points begin..end)
    gp_Pnt lo, hi;
  };

  static double boxDistance(const gp_Pnt& q, const Chunk& c) {
    const double dx = std::max({c.lo.X() - q.X(), 0.0, q.X() - c.hi.X()});
    const double dy = std::max({c.lo.Y() - q.Y(), 0.0, q.Y() - c.hi.Y()});
    const double dz = std::max({c.lo.Z() - q.Z(), 0.0, q.Z() - c.hi.Z()});
    return std::sqrt(dx * dx + dy * dy + dz * dz);
  }

  // Distance from q to C(t) = Q1 + t b + t^2 c, t in [-1, 1], the quadratic through samples j-1, j, j+1 (the
  // segment's nearer end, kept off the ends of the curve); Newton on (C - q).C' = 0 from the segment's foot.
  double refined(const gp_Pnt& q, size_t seg, double segT) const {
    const size_t j = std::clamp<size_t>(segT < 0.5 ? seg : seg + 1, 1, pts_.size() - 2);
    const gp_XYZ q0 = pts_[j - 1].XYZ(), q1 = pts_[j].XYZ(), q2 = pts_[j + 1].XYZ();
    const gp_XYZ b = (q2 - q0) / 2, c = (q2 - 2 * q1 + q0) / 2, r = q1 - q.XYZ();
    double t = std::clamp(double(seg) + segT - double(j), -1.0, 1.0);
    for (int it = 0; it < 8; ++it) {
      const gp_XYZ d = r + t * b + t * t * c, d1 = b + 2 * t * c;
      const double f = d.Dot(d1), df = d1.Dot(d1) + 2 * d.Dot(c);
      if (df <= 0) break;
      t = std::clamp(t - f / df, -1.0, 1.0);
    }
    return (r + t * b + t * t * c).Modulus();
  }

  const std::vector<gp_Pnt>& pts_;
  std::vector<Chunk> chunks_;
};

// max over the points of `from` of the distance to the curve sampled by `to`.
double oneSidedGap(const std::vector<gp_Pnt>& from, const std::vector<gp_Pnt>& to) {
  if (from.empty() || to.empty()) return std::numeric_limits<double>::quiet_NaN();
  const SampledCurve curve(to);
  double gap = 0;
  for (const gp_Pnt& q : from) gap = std::max(gap, curve.distance(q));
  return gap;
}

// ---------------------------------------------------------------------------------------------------------------
// seams: per-edge record

// True when the face has a degenerate edge (a pole) through either vertex of the edge.
bool poleAtEdgeEnd(const TopoDS_Face& face, const TopoDS_Edge& edge) {
  TopoDS_Vertex v1, v2;
  TopExp::Vertices(edge, v1, v2);
  for (TopExp_Explorer e(face, TopAbs_EDGE); e.More(); e.Next()) {
    const TopoDS_Edge& d = TopoDS::Edge(e.Current());
    if (!BRep_Tool::Degenerated(d)) continue;
    TopoDS_Vertex d1, d2;
    TopExp::Vertices(d, d1, d2);
    for (const TopoDS_Vertex& v : {d1, d2})
      if (!v.IsNull() && ((!v1.IsNull() && v.IsSame(v1)) || (!v2.IsNull() && v.IsSame(v2)))) return true;
  }
  return false;
}

// Points of the 3-D edge at 0, 1/32, ..., 1 of its range: where the edge is, for matching it with another tool's
// report of the same seam without relying on edge numbers.
Json edgePoints(const TopoDS_Edge& edge) {
  constexpr int kPoints = 33;
  const BRepAdaptor_Curve c(edge);
  Json pts = Json::array();
  for (int i = 0; i < kPoints; ++i) {
    const gp_Pnt p = c.Value(c.FirstParameter() + (c.LastParameter() - c.FirstParameter()) * i / (kPoints - 1));
    pts.push_back({p.X(), p.Y(), p.Z()});
  }
  return pts;
}

// The largest angle (deg) between the normal at a boundary sample of one face and the normal at the other face's
// boundary sample nearest to it in space, among the samples within kAngleWindow of the same fraction of the edge
// (the window keeps a boundary that passes through one point twice, e.g. a closed one, from pairing its two ends;
// inside it no parameter correspondence is assumed); -1 when no pair has both normals.
double boundaryAngle(const std::vector<gp_Pnt>& from, const std::vector<gp_Vec>& fromNormal,
                     const std::vector<double>& position, const std::vector<gp_Pnt>& to,
                     const std::vector<gp_Vec>& toNormal, double* where = nullptr, bool interiorOnly = false) {
  double worst = -1;
  size_t lo = 0;
  for (size_t i = 0; i < from.size(); ++i) {
    if (interiorOnly && (position[i] < kEndExclusion || position[i] > 1.0 - kEndExclusion)) continue;
    while (lo < to.size() && position[lo] < position[i] - kAngleWindow) ++lo;
    // The nearest point of the other boundary's sample polyline within the window, and the normal there
    // interpolated between the segment's two samples (a sample alone would be off by half a spacing: 0.3 deg on a
    // 0.3 mm sphere in 300 samples).
    double best = std::numeric_limits<double>::infinity();
    gp_Vec normal(kNaN, kNaN, kNaN);
    for (size_t j = lo; j < to.size() && position[j] <= position[i] + kAngleWindow; ++j) {
      const size_t k = j + 1 < to.size() ? j + 1 : j;
      const double t = k == j ? 0.0 : segmentParameter(from[i], to[j], to[k]);
      const double d = from[i].Distance(to[j].Translated(gp_Vec(to[j], to[k]) * t));
      if (d < best) {
        best = d;
        normal = toNormal[j] * (1 - t) + toNormal[k] * t;
      }
    }
    const double len = normal.Magnitude();
    const double c = len > 0 ? fromNormal[i].Dot(normal) / len : kNaN;
    if (std::isnan(c)) continue;
    const double angle = std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / kPi;
    if (angle > worst && where) *where = position[i];
    worst = std::max(worst, angle);
  }
  return worst;
}

// JSON number or null for NaN (no valid sample).
Json number(double x) { return std::isnan(x) ? Json(nullptr) : Json(x); }

Json seamRecord(const SeamSamples& s, int samples) {
  Json j;
  const double gab = oneSidedGap(s.boundaryA, s.boundaryB);
  const double gba = oneSidedGap(s.boundaryB, s.boundaryA);
  j["gap_ab"] = number(gab);
  j["gap_ba"] = number(gba);
  j["gap"] = number(std::isnan(gab) || std::isnan(gba) ? std::numeric_limits<double>::quiet_NaN()
                                                       : std::max(gab, gba));
  double maxAngle = -1, maxParam = 0, interior = -1, unsignedMax = -1;
  for (size_t i = 0; i < s.angle.size(); ++i) {
    if (s.angle[i] > maxAngle) maxAngle = s.angle[i], maxParam = s.param[i];
    unsignedMax = std::max(unsignedMax, std::min(s.angle[i], 180.0 - s.angle[i]));
    if (s.position[i] >= kEndExclusion && s.position[i] <= 1.0 - kEndExclusion)
      interior = std::max(interior, s.angle[i]);
  }
  const bool any = !s.angle.empty();
  double whereAB = 0, whereBA = 0;
  const double ab = boundaryAngle(s.boundaryA, s.boundaryNormalA, s.position, s.boundaryB, s.boundaryNormalB, &whereAB);
  const double ba = boundaryAngle(s.boundaryB, s.boundaryNormalB, s.position, s.boundaryA, s.boundaryNormalA, &whereBA);
  const double boundaryMax = std::max(ab, ba);
  j["max_angle_boundary_at"] = boundaryMax < 0 ? Json(nullptr) : Json(ab >= ba ? whereAB : whereBA);
  const double interiorMax =
      std::max(boundaryAngle(s.boundaryA, s.boundaryNormalA, s.position, s.boundaryB, s.boundaryNormalB, nullptr, true),
               boundaryAngle(s.boundaryB, s.boundaryNormalB, s.position, s.boundaryA, s.boundaryNormalA, nullptr, true));
  j["max_angle_boundary_interior_deg"] = interiorMax >= 0 ? Json(interiorMax) : Json(nullptr);
  j["max_angle_boundary_deg"] = boundaryMax >= 0 ? Json(boundaryMax) : Json(nullptr);
  j["max_angle_deg"] = any ? Json(maxAngle) : Json(nullptr);
  j["max_angle_param"] = any ? Json(maxParam) : Json(nullptr);
  j["max_angle_interior_deg"] = interior >= 0 ? Json(interior) : Json(nullptr);
  j["max_angle_unsigned_deg"] = any ? Json(unsignedMax) : Json(nullptr);
  j["gap_surfaces"] = any ? Json(s.maxFootGap) : Json(nullptr);
  j["max_edge_to_surface"] = any ? Json(s.maxDistance) : Json(nullptr);
  j["samples"] = samples;
  j["skipped"] = s.skipped;
  return j;
}

// ---------------------------------------------------------------------------------------------------------------
// seams: driver

struct SeamOptions {
  int samples = 2000;
  bool sew = false;
};

// Maps each face of `shape` (1-based, MapShapes order) to the 1-based index of the file's face it came from.
// Without sewing this is the identity; after sewing, faces are traced through the sewing history.
std::vector<int> originalFaceIndex(const TopTools_IndexedMapOfShape& faces,
                                   const TopTools_IndexedMapOfShape& original,
                                   const BRepBuilderAPI_Sewing* sewing, const TopoDS_Shape& copied) {
  std::vector<int> out(faces.Extent() + 1, 0);
  if (!sewing) {
    for (int i = 1; i <= faces.Extent(); ++i) out[i] = i;
    return out;
  }
  TopTools_IndexedMapOfShape copiedFaces;  // same order as `original`: the copy preserves the structure
  TopExp::MapShapes(copied, TopAbs_FACE, copiedFaces);
  for (int i = 1; i <= copiedFaces.Extent() && i <= original.Extent(); ++i) {
    const TopoDS_Shape& f = copiedFaces(i);
    const TopoDS_Shape now = sewing->IsModifiedSubShape(f) ? sewing->ModifiedSubShape(f) : f;
    if (const int k = faces.FindIndex(now); k > 0) out[k] = i;
  }
  return out;
}

// Two (possibly equal) faces of an edge, each with the edge oriented as that face uses it.
struct EdgeUse {
  TopoDS_Edge edgeA, edgeB;
  TopoDS_Face faceA, faceB;
};

std::optional<EdgeUse> twoFaceUse(const TopoDS_Edge& edge, const TopTools_ListOfShape& faces) {
  if (faces.Extent() != 2) return std::nullopt;
  EdgeUse u;
  u.faceA = TopoDS::Face(faces.First());
  u.faceB = TopoDS::Face(faces.Last());
  if (u.faceA.IsSame(u.faceB)) {  // seam edge of a closed surface: its two pcurves
    u.edgeA = TopoDS::Edge(edge.Oriented(TopAbs_FORWARD));
    u.edgeB = TopoDS::Edge(edge.Oriented(TopAbs_REVERSED));
  } else {
    u.edgeA = u.edgeB = edge;
  }
  return u;
}

Json seamsOf(const TopoDS_Shape& shape, const std::vector<int>& faceIndex, const SeamOptions& opt,
             double diag) {
  TopTools_IndexedMapOfShape faces, edges;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  TopExp::MapShapes(shape, TopAbs_EDGE, edges);
  TopTools_IndexedDataMapOfShapeListOfShape edgeFaces;
  TopExp::MapShapesAndAncestors(shape, TopAbs_EDGE, TopAbs_FACE, edgeFaces);
  const double precision = std::max(1e-7 * diag, 1e-12);
  Json list = Json::array();
  int nonManifold = 0, failed = 0;
  for (int i = 1; i <= edges.Extent(); ++i) {
    const TopoDS_Edge& edge = TopoDS::Edge(edges(i));
    if (BRep_Tool::Degenerated(edge)) continue;
    const TopTools_ListOfShape& owners = edgeFaces.FindFromKey(edge);
    if (owners.Extent() > 2) ++nonManifold;
    const auto use = twoFaceUse(edge, owners);
    if (!use) continue;
    try {
      OCC_CATCH_SIGNALS
      const auto a = makeSide(use->edgeA, use->faceA);
      const auto b = makeSide(use->edgeB, use->faceB);
      if (!a || !b) throw Standard_Failure("no pcurve");
      Json j;
      j["edge"] = i;
      j["face_a"] = faceIndex[faces.FindIndex(use->faceA)];
      j["face_b"] = faceIndex[faces.FindIndex(use->faceB)];
      j["closed_seam"] = use->faceA.IsSame(use->faceB);
      j.update(seamRecord(sampleSeam(edge, *a, *b, opt.samples, precision), opt.samples));
      j["edge_tolerance"] = BRep_Tool::Tolerance(edge);
      j["pole"] = poleAtEdgeEnd(use->faceA, edge) || poleAtEdgeEnd(use->faceB, edge);
      j["points"] = edgePoints(edge);
      list.push_back(std::move(j));
    } catch (const Standard_Failure&) {
      ++failed;
    }
  }
  Json out;
  out["nonmanifold_edges"] = nonManifold;
  out["failed_edges"] = failed;
  out["seams"] = std::move(list);
  return out;
}

// Totals over the per-seam records (NaN-free maxima).
void addTotals(Json& out) {
  double gap = 0, footGap = 0, angle = 0, interior = 0, unsignedMax = 0;
  long skipped = 0;
  for (const Json& s : out["seams"]) {
    if (s["gap"].is_number()) gap = std::max(gap, s["gap"].get<double>());
    if (s["gap_surfaces"].is_number()) footGap = std::max(footGap, s["gap_surfaces"].get<double>());
    if (s["max_angle_deg"].is_number()) angle = std::max(angle, s["max_angle_deg"].get<double>());
    if (s["max_angle_interior_deg"].is_number())
      interior = std::max(interior, s["max_angle_interior_deg"].get<double>());
    if (s["max_angle_unsigned_deg"].is_number())
      unsignedMax = std::max(unsignedMax, s["max_angle_unsigned_deg"].get<double>());
    skipped += s["skipped"].get<long>();
  }
  out["seam_count"] = out["seams"].size();
  out["max_gap"] = gap;
  out["max_gap_surfaces"] = footGap;
  out["max_angle_deg"] = angle;
  out["max_angle_interior_deg"] = interior;
  out["max_angle_unsigned_deg"] = unsignedMax;
  out["skipped_samples"] = skipped;
}

Json seams(const TopoDS_Shape& read, const SeamOptions& opt) {
  const double diag = bboxDiagonal(read, false);
  TopTools_IndexedMapOfShape original;
  TopExp::MapShapes(read, TopAbs_FACE, original);
  Json head;
  head["samples"] = opt.samples;
  head["bbox_diagonal"] = diag;
  head["sewn"] = false;
  TopoDS_Shape shape = read;
  std::vector<int> faceIndex;
  BRepBuilderAPI_Sewing sewing;
  if (opt.sew && original.Extent() > 1) {
    TopoDS_Shape copied;
    if (const TopoDS_Shape sewn = sewCopy(read, diag, sewing, copied); !sewn.IsNull()) {
      shape = sewn;
      head["sewn"] = true;
      head["sewing_tolerance"] = kSewingRelTol * diag;
      TopTools_IndexedMapOfShape faces;
      TopExp::MapShapes(shape, TopAbs_FACE, faces);
      faceIndex = originalFaceIndex(faces, original, &sewing, copied);
    }
  }
  if (faceIndex.empty()) faceIndex = originalFaceIndex(original, original, nullptr, read);
  Json body = seamsOf(shape, faceIndex, opt, diag);
  head.update(body);
  addTotals(head);
  return head;
}

// ---------------------------------------------------------------------------------------------------------------
// main

int usage() {
  std::cerr << "usage: occt_probe summary FILE\n"
               "       occt_probe seams FILE [--samples N] [--sew]\n";
  return 1;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) return usage();
  const std::string command = argv[1], path = argv[2];
  SeamOptions opt;
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--samples" && i + 1 < argc)
      opt.samples = std::max(2, std::atoi(argv[++i]));
    else if (a == "--sew")
      opt.sew = true;
    else
      return usage();
  }
  if (command != "summary" && command != "seams") return usage();
  const auto format = formatOf(path);
  if (!format || !std::filesystem::is_regular_file(path)) {
    std::cerr << "occt_probe: " << path << ": not a readable .stp/.step/.igs/.iges file\n";
    return 2;
  }
  // OpenCASCADE's readers print progress on stdout; the JSON must be the only thing there.
  Message::DefaultMessenger()->ChangePrinters().Clear();
  OSD::SetSignal(
      Standard_False);  // turn crashes inside OpenCASCADE into Standard_Failure (OCC_CATCH_SIGNALS)
  const TopoDS_Shape shape = readShape(path, *format);
  if (shape.IsNull()) {
    std::cerr << "occt_probe: " << path << ": OpenCASCADE could not read a shape\n";
    return 2;
  }
  Json out;
  out["file"] = std::filesystem::path(path).filename().string();
  out["format"] = *format == Format::kStep ? "STEP" : "IGES";
  try {
    OCC_CATCH_SIGNALS
    out.update(command == "summary" ? summarize(shape) : seams(shape, opt));
  } catch (const Standard_Failure& e) {
    std::cerr << "occt_probe: " << path << ": OpenCASCADE failed: " << e.GetMessageString() << "\n";
    return 2;
  }
  std::cout << out.dump(1) << "\n";
  return 0;
}
