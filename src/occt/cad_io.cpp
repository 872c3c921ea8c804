// OCC_CATCH_SIGNALS converts a signal raised inside OpenCASCADE into a Standard_Failure only when this macro is set
// (Debian's OpenCASCADE is built with it; see docs/reliability.md, "OpenCASCADE guards").
#ifndef OCC_CONVERT_SIGNALS
#define OCC_CONVERT_SIGNALS
#endif
#include "seam/occt/cad_io.h"

#include "occt/brep_model.h"
#include "occt/cad_internal.h"
#include "seam/io/file.h"
#include "seam/model/brep.h"
#include "seam/occt/brep_model.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <unistd.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepGProp.hxx>
#include <GProp_GProps.hxx>
#include <IGESCAFControl_Reader.hxx>
#include <IGESCAFControl_Writer.hxx>
#include <STEPCAFControl_Controller.hxx>
#include <STEPCAFControl_Reader.hxx>
#include <STEPCAFControl_Writer.hxx>
#include <TDF_LabelSequence.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopExp.hxx>
#include <XCAFApp_Application.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <BRepBuilderAPI_Transform.hxx>
#include <IGESData_BasicEditor.hxx>
#include <IGESData_GlobalSection.hxx>
#include <STEPConstruct_UnitContext.hxx>
#include <StepGeom_GeomRepContextAndGlobUnitAssCtxAndGlobUncertaintyAssCtx.hxx>
#include <StepRepr_GlobalUncertaintyAssignedContext.hxx>
#include <StepRepr_GlobalUnitAssignedContext.hxx>
#include <StepBasic_NamedUnit.hxx>
#include <StepBasic_UncertaintyMeasureWithUnit.hxx>
#include <StepBasic_Unit.hxx>
#include <TColStd_SequenceOfAsciiString.hxx>
#include <UnitsMethods.hxx>
#include <gp_Trsf.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepTools.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <GeomConvert.hxx>
#include <GeomConvert_ApproxSurface.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom_BSplineSurface.hxx>
#include <gp.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Geom_Surface.hxx>
#include <IFSelect_ReturnStatus.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Reader.hxx>
#include <IGESControl_Writer.hxx>
#include <IGESData_IGESWriter.hxx>
#include <IGESSelect_WorkLibrary.hxx>
#include <igesread.h>  // OpenCASCADE's IGES parser (C): what IGESFile_Read runs before it reads any entity
#include <StepAP214.hxx>
#include <StepAP214_Protocol.hxx>
#include <StepData_StepModel.hxx>
#include <StepRepr_RepresentationItem.hxx>
#include <IGESData_IGESEntity.hxx>
#include <IGESData_IGESModel.hxx>
#include <XSControl_TransferReader.hxx>
#include <Transfer_TransientProcess.hxx>
#include <TransferBRep.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <XSControl_WorkSession.hxx>
#include <TCollection_HAsciiString.hxx>
#include <StepData_StepWriter.hxx>
#include <Interface_Static.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_ProgressIndicator.hxx>
#include <Message_ProgressRange.hxx>
#include <OSD.hxx>
#include <OSD_Signal.hxx>
#include <Interface_Check.hxx>
#include <Interface_InterfaceModel.hxx>
#include <Precision.hxx>
#include <STEPControl_Reader.hxx>
#include <XSControl_Reader.hxx>
#include <STEPControl_Writer.hxx>
#include <Standard_ErrorHandler.hxx>
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
#include <cfenv>
#include <chrono>
#include <cstdint>
#include <cmath>
#include <exception>
#include <limits>
#include <csignal>
#include <fstream>
#include <functional>
#include <optional>
#include <tuple>
#include <iterator>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

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

/// OpenCASCADE's session length unit (the unit its readers convert into and its writers convert from) is global
/// state of the process: seam's readers and writers take it to be millimetres, so a host program (or an earlier
/// reader) that set another unit would get every model it reads or writes scaled. Every read and write starts from
/// millimetres.
void pinSessionUnitToMillimetres() {
  Interface_Static::SetCVal("xstep.cascade.unit", "MM");
  UnitsMethods::SetCasCadeLengthUnit(1.0, UnitsMethods_LengthUnit_Millimeter);
}

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

/// Temporary names tried (each unique in this process) before writing gives up on an existing one.
constexpr int kTemporaryAttempts = 100;

/// Signals converted into Standard_Failure by detail::OcctSignalGuard (SIGFPE is caught too, with traps off it
/// should not be raised).
constexpr std::array<int, 4> kGuardedSignals{SIGSEGV, SIGBUS, SIGILL, SIGFPE};
/// Nesting depth of OcctSignalGuard in this thread (only the outermost installs handlers).
thread_local int guardDepth = 0;

/// Warnings of the last readShape on this thread that was given no `warnings` list (the B-rep check reads the shape
/// and then converts its faces): convertFaces of the same file puts them first in CadImport::warnings.
thread_local std::pair<fs::path, std::vector<std::string>> pendingReadWarnings;

/// True when the failure is a signal caught inside OpenCASCADE (a crash, converted by OcctSignalGuard).
bool isSignal(const Standard_Failure& f) { return f.IsKind(STANDARD_TYPE(OSD_Signal)); }

/// OpenCASCADE treats magnitudes beyond Precision::Infinite() (2e100) as infinite and its shape healing can run for
/// minutes on them (issue 15): a STEP or IGES file holding a real of magnitude 1e100 or more (or one that overflows,
/// like 1E+999) is refused before OpenCASCADE sees it. No CAD coordinate, weight or knot comes near.
constexpr double kMaxCadReal = 1e100;
/// Exponents below this cannot reach kMaxCadReal with any sensible mantissa: they are not parsed at all.
constexpr int kMinSuspectExponent = 80;
/// IGES: fixed 80-column records; the data of the parameter section ('P' in column 73) is in columns 1 to 64.
constexpr size_t kIgesSectionColumn = 72;
constexpr size_t kIgesDataColumns = 64;

/// The first real in `text` (parameter data of a STEP or IGES file) whose magnitude is at least kMaxCadReal or not
/// finite; its text is returned.
std::optional<std::string> hugeReal(std::string_view text) {
  for (size_t i = 1; i + 1 < text.size(); ++i) {
    const char c = text[i];
    if (c != 'E' && c != 'e' && c != 'D' && c != 'd') continue;
    const char before = text[i - 1];
    if (!std::isdigit(static_cast<unsigned char>(before)) && before != '.') continue;
    size_t j = i + 1;
    if (text[j] == '+') ++j;
    int exponent = 0;
    size_t digits = 0;
    for (; j < text.size() && std::isdigit(static_cast<unsigned char>(text[j])); ++j, ++digits)
      exponent = std::min(exponent * 10 + (text[j] - '0'), 100000);
    if (digits == 0 || exponent < kMinSuspectExponent) continue;
    size_t start = i;
    while (start > 0 && (std::isdigit(static_cast<unsigned char>(text[start - 1])) || text[start - 1] == '.' ||
                         text[start - 1] == '-' || text[start - 1] == '+'))
      --start;
    std::string token(text.substr(start, j - start));
    std::replace_if(token.begin(), token.end(), [](char x) { return x == 'D' || x == 'd'; }, 'E');
    const double v = std::strtod(token.c_str(), nullptr);
    if (!(std::abs(v) < kMaxCadReal)) return std::string(text.substr(start, j - start));
  }
  return std::nullopt;
}

/// Refuses a STEP or IGES file holding a real beyond kMaxCadReal (STEP: outside quoted strings; IGES: the
/// parameter data section).
/// The entity instances of a STEP file's DATA section ("#123 =" outside quoted strings), in text already blanked.
int countStepInstances(std::string_view data) {
  size_t pos = data.find("DATA;");
  int n = 0;
  while (pos != std::string_view::npos && (pos = data.find('#', pos)) != std::string_view::npos) {
    size_t k = pos + 1;
    while (k < data.size() && std::isdigit(static_cast<unsigned char>(data[k]))) ++k;
    const bool digits = k > pos + 1;
    while (k < data.size() && std::isspace(static_cast<unsigned char>(data[k]))) ++k;
    if (digits && k < data.size() && data[k] == '=') ++n;
    pos = k;
  }
  return n;
}

/// IGES entities whose sizes come from counts in their own parameters: OpenCASCADE's readers allocate the arrays from
/// those counts before reading a value (IGESGeom_ToolBSplineSurface allocates (K1 + 1)(K2 + 1) poles and weights), so
/// a corrupt count of a few bytes asks for gigabytes (a fuzzed 128 entity: 655 MB in one allocation, 2.4 GB in all,
/// CI of 2026-12-03). A count that asks for more values than the entity holds is refused before OpenCASCADE reads the
/// file when it asks for more than this many: below it the arrays stay small (a few MB) and OpenCASCADE's own check
/// reports the shortfall as a failed entity (a truncated file, said as a warning).
constexpr std::int64_t kIgesMaxUnbackedValues = 100000;
/// Counts are clamped here while the declared size is computed (no overflow; any larger count is refused anyway).
constexpr std::int64_t kIgesCountClamp = std::int64_t{1} << 30;
/// The parameters of an entity that hold its counts: the type number and up to four counts after it.
constexpr size_t kIgesCountParams = 5;

/// One entity of an IGES file as OpenCASCADE's parser (igesread) splits it: its type (directory entry), the
/// sequence number of its directory entry, its first parameters (the type number, then the counts) and how many
/// parameters follow the type number.
struct IgesEntity {
  int type = 0;
  int directoryLine = 0;
  std::vector<std::string> params;
  std::int64_t held = 0;
};

/// The declared number of parameter values of an entity of the types whose arrays OpenCASCADE sizes from counts
/// (IGES 5.3 parameter layouts; a lower bound: optional trailing values are not counted), or nullopt for other types
/// and for counts that are not integers.
std::optional<std::int64_t> igesDeclaredValues(const IgesEntity& r) {
  const auto integer = [&r](size_t k) -> std::optional<std::int64_t> {
    if (k >= r.params.size()) return std::nullopt;
    std::string_view t = r.params[k];  // igesread drops the blanks around a parameter
    bool negative = false;
    if (!t.empty() && (t.front() == '+' || t.front() == '-')) {
      negative = t.front() == '-';
      t.remove_prefix(1);
    }
    if (t.empty()) return std::nullopt;
    std::int64_t v = 0;
    for (char c : t) {
      if (!std::isdigit(static_cast<unsigned char>(c))) return std::nullopt;
      v = std::min(v * 10 + (c - '0'), kIgesCountClamp);
    }
    return negative ? -v : v;
  };
  // OpenCASCADE reads an entity only when its first parameter is its directory entry's type number.
  if (integer(0) != std::optional<std::int64_t>(r.type)) return std::nullopt;
  // c(k): the count at parameter k, never below 0 (a negative count allocates nothing).
  const auto c = [&integer](size_t k) { return std::max<std::int64_t>(integer(k).value_or(0), 0); };
  switch (r.type) {
    case 102: return 1 + c(1);                                          // composite curve: N curves
    case 106: return 2 + 2 * c(2);                                      // copious data: N points (2 to 6 values each)
    case 112: return 4 + (c(3) + 1) + 12 * c(3);                        // parametric spline curve: N segments
    case 114: return 4 + (c(3) + 1) + (c(4) + 1) + 48 * c(3) * c(4);    // parametric spline surface: M x N patches
    case 126: return 6 + (c(1) + c(2) + 2) + 4 * (c(1) + 1) + 2;        // B-spline curve: K + 1 poles, degree M
    case 128:                                                           // B-spline surface: (K1 + 1)(K2 + 1) poles
      return 9 + (c(1) + c(3) + 2) + (c(2) + c(4) + 2) + 4 * (c(1) + 1) * (c(2) + 1) + 4;
    case 141: return 4 + 3 * c(4);                                      // boundary: N curves
    case 143: return 3 + c(3);                                          // bounded surface: N boundaries
    case 144: return 4 + c(3);                                          // trimmed surface: N2 inner boundaries
    case 186: return 3 + 2 * c(3);                                      // manifold solid: N voids
    case 308: return 3 + c(3);                                          // subfigure: N entities
    case 502: return 1 + 3 * c(1);                                      // vertex list: N vertices
    case 504: return 1 + 5 * c(1);                                      // edge list: N edges
    case 508: return 1 + 5 * c(1);                                      // loop: N edges
    case 510: return 3 + c(2);                                          // face: N loops
    case 514: return 2 + 2 * c(2);                                      // shell: N faces
    default: return std::nullopt;
  }
}

/// OpenCASCADE's IGES parser keeps its state in globals (structiges.c): one parse at a time in this process.
std::mutex& igesParserMutex() {
  static std::mutex m;
  return m;
}

/// The entities of an IGES file as OpenCASCADE's own parser splits them (igesread, which IGESFile_Read runs before it
/// reads any entity; its line reader and the assignment of parameter lines to entities have quirks that a separate
/// reading would miss: a fuzzed line one byte too long, for one). Empty where igesread cannot open the file.
/// The caller holds igesParserMutex.
std::vector<IgesEntity> igesEntities(const fs::path& file) {
  std::vector<IgesEntity> out;
  // igesread only opens the file (a name of one character would be stdin: seam's names end in .igs or .iges). No
  // memory of seam's is allocated before it returns: a signal inside it skips the destructors (see readShape).
  int sections[6] = {};
  if (igesread(const_cast<char*>(file.c_str()), sections, 0) != 0) return out;
  int parts = 0, params = 0;
  iges_stats(&parts, &params);
  if (parts > 0) {  // (IGESFile_Read reads no part either without one: the first page is then uninitialised)
    int* directory = nullptr;
    char *res1 = nullptr, *res2 = nullptr, *label = nullptr, *subscript = nullptr;
    int count = 0, line = 0;
    while ((line = iges_lirpart(&directory, &res1, &res2, &label, &subscript, &count)) != 0) {
      IgesEntity e;
      e.type = directory[0];
      e.directoryLine = line;
      e.held = std::max(count - 1, 0);
      int kind = 0;
      char* value = nullptr;
      while (e.params.size() < kIgesCountParams && iges_lirparam(&kind, &value) != 0) e.params.emplace_back(value);
      out.push_back(std::move(e));
      iges_nextpart();
    }
  }
  iges_finfile(0);
  return out;
}

/// Refuses an IGES file with an entity whose counts ask for more than kIgesMaxUnbackedValues values that it does not
/// hold (see kIgesMaxUnbackedValues). The caller holds igesParserMutex.
Status checkIgesCounts(const fs::path& file) {
  for (const IgesEntity& e : igesEntities(file)) {
    const std::optional<std::int64_t> declared = igesDeclaredValues(e);
    if (!declared || *declared <= e.held || *declared <= kIgesMaxUnbackedValues) continue;
    return invalidInput(fmt::format("{}: the IGES entity of type {} (directory entry {}) declares {} values (from its "
                                    "counts) but holds {}; the file is corrupt (refused before OpenCASCADE allocates "
                                    "for it)",
                                    file.string(), e.type, e.directoryLine, *declared, e.held));
  }
  return Status::ok();
}

/// With `stepInstances`, a STEP file's entity instances are counted too (countStepInstances).
Status checkReals(const fs::path& file, CadFormat format, int* stepInstances = nullptr) {
  std::ifstream is(file, std::ios::binary);
  if (!is) return {ErrorCode::kIoError, fmt::format("{}: cannot read the file", file.string())};
  std::string all;
  constexpr size_t kChunkBytes = size_t{1} << 20;
  while (is) {  // bulk reads (a character iterator costs ~20 instructions a byte)
    const size_t have = all.size();
    all.resize(have + kChunkBytes);
    is.read(all.data() + have, static_cast<std::streamsize>(kChunkBytes));
    all.resize(have + static_cast<size_t>(is.gcount()));
  }
  std::string data;
  if (format == CadFormat::kStep) {
    // Quoted strings become blanks (the closing quote stays).
    data = std::move(all);
    bool quoted = false;
    for (char& c : data) {
      if (c == '\'') quoted = !quoted;
      if (quoted) c = ' ';
    }
  } else {
    data.reserve(all.size());
    size_t pos = 0;
    while (pos < all.size()) {
      size_t end = all.find('\n', pos);
      if (end == std::string::npos) end = all.size();
      std::string_view line(all.data() + pos, end - pos);
      if (line.size() > kIgesSectionColumn && line[kIgesSectionColumn] == 'P') {
        data.append(line.substr(0, kIgesDataColumns));
        data.push_back(' ');
      }
      pos = end + 1;
    }
  }
  if (stepInstances != nullptr) *stepInstances = format == CadFormat::kStep ? countStepInstances(data) : -1;
  if (const std::optional<std::string> r = hugeReal(data))
    return invalidInput(fmt::format("{}: the real {} is beyond +-{:g}, which OpenCASCADE treats as infinite; the file "
                                    "is corrupt (refused before shape healing)",
                                    file.string(), *r, kMaxCadReal));
  return Status::ok();
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

namespace {

/// Reads the written temporary file `temp` back and checks that it holds `faces` faces (errors name `file`).
Status verifyWritten(const fs::path& temp, const fs::path& file, CadFormat format, int faces) {
  std::vector<std::string> warnings;
  Result<TopoDS_Shape> back = detail::readShape(temp, format, &warnings, detail::kTransferTimeLimit);
  if (!back) {
    // The reader's message names the temporary file, which the user never sees: name the output instead.
    std::string why = back.status().message();
    for (size_t at = why.find(temp.string()); at != std::string::npos; at = why.find(temp.string(), at))
      why.replace(at, temp.string().size(), file.string());
    return invalidInput(fmt::format("{}: OpenCASCADE cannot read back what it wrote ({}); nothing written",
                                    file.string(), why));
  }
  int n = 0;
  for (TopExp_Explorer ex(*back, TopAbs_FACE); ex.More(); ex.Next()) ++n;
  if (n != faces)
    return invalidInput(fmt::format("{}: OpenCASCADE wrote {} faces for {} patches (it drops surfaces it cannot "
                                    "represent: huge or tiny coordinates or knots, all control points equal); "
                                    "nothing written",
                                    file.string(), n, faces));
  return Status::ok();
}

}  // namespace

namespace detail {

namespace {

/// A stated unit that differs from the header's by less than this (relative) is the header's: no rescaling.
constexpr double kSameUnitRelTol = 1e-12;

/// The STEP file's length unit and uncertainty: from the first representation context that assigns a length unit
/// (OpenCASCADE's STEPConstruct_UnitContext computes the factor to millimetres and converts the uncertainty).
void readStepUnits(STEPControl_Reader& reader, CadUnits& units) {
  const Handle(Interface_InterfaceModel) model = reader.Model();
  bool haveUnit = false;
  for (int k = 1; k <= model->NbEntities() && !haveUnit; ++k) {
    const Handle(Standard_Transient) e = model->Value(k);
    Handle(StepRepr_GlobalUnitAssignedContext) unitCtx;
    Handle(StepRepr_GlobalUncertaintyAssignedContext) uncertaintyCtx;
    if (const auto complex = Handle(StepGeom_GeomRepContextAndGlobUnitAssCtxAndGlobUncertaintyAssCtx)::DownCast(e);
        !complex.IsNull()) {
      unitCtx = complex->GlobalUnitAssignedContext();
      uncertaintyCtx = complex->GlobalUncertaintyAssignedContext();
    } else {
      unitCtx = Handle(StepRepr_GlobalUnitAssignedContext)::DownCast(e);
    }
    if (unitCtx.IsNull()) continue;
    STEPConstruct_UnitContext ctx;
    if (ctx.ComputeFactors(unitCtx) != 0 || !ctx.LengthDone()) continue;
    haveUnit = true;
    units.millimetresPerFileUnit = ctx.LengthFactor();
    // The uncertainty in its own unit (STEPConstruct_UnitContext::Uncertainty is not converted in OpenCASCADE 7.6).
    for (int i = 1; !uncertaintyCtx.IsNull() && i <= uncertaintyCtx->NbUncertainty(); ++i) {
      const Handle(StepBasic_UncertaintyMeasureWithUnit) u = uncertaintyCtx->UncertaintyValue(i);
      if (u.IsNull()) continue;
      const Handle(StepBasic_NamedUnit) unit = u->UnitComponent().NamedUnit();
      STEPConstruct_UnitContext unitOfValue;
      if (unit.IsNull() || unitOfValue.ComputeFactors(unit) != 0 || !unitOfValue.LengthDone()) continue;
      const double mm = u->ValueComponent() * unitOfValue.LengthFactor();
      if (std::isfinite(mm) && mm > 0.0) {
        units.declaredResolutionMm = mm;
        break;
      }
    }
  }
  TColStd_SequenceOfAsciiString lengths, angles, solidAngles;
  reader.FileUnits(lengths, angles, solidAngles);
  if (!lengths.IsEmpty()) units.fileUnit = lengths.First().ToCString();
  else if (haveUnit) units.fileUnit = UnitsMethods::DumpLengthUnit(units.millimetresPerFileUnit);
}

/// The IGES file's global section: unit name (parameter 15), unit value and resolution (parameter 19).
void readIgesUnits(const Handle(IGESData_IGESModel)& model, CadUnits& units) {
  if (model.IsNull()) return;
  const IGESData_GlobalSection& g = model->GlobalSection();
  if (!g.UnitName().IsNull()) units.fileUnit = g.UnitName()->ToCString();
  // UnitValue() is documented "in meters" but is in OpenCASCADE's length unit (mm): 25.4 for an inch file.
  const double mm = g.UnitValue();
  if (std::isfinite(mm) && mm > 0.0) units.millimetresPerFileUnit = mm;
  if (std::isfinite(g.Resolution()) && g.Resolution() > 0.0)
    units.declaredResolutionMm = g.Resolution() * units.millimetresPerFileUnit;
}

/// The entity OpenCASCADE's transfer made each face of `shape` from, as
/// XSControl_TransferReader::EntityFromShapeResult(face, 1) finds it: the first mapped entity whose shape result
/// equals the face (same TShape, location and orientation), else the last one whose result is the same face in
/// another orientation. EntityFromShapeResult scans every mapped entity for each face (faces x entities: 126 M
/// instructions on boxed_sphere.step, 192 faces); this is one scan for all faces.
std::vector<Handle(Standard_Transient)> faceEntities(const Handle(XSControl_TransferReader)& transfer,
                                                     const TopTools_IndexedMapOfShape& faces) {
  std::vector<Handle(Standard_Transient)> entity(static_cast<size_t>(faces.Extent()));
  const Handle(Transfer_TransientProcess) tp = transfer.IsNull() ? nullptr : transfer->TransientProcess();
  if (tp.IsNull()) return entity;
  // Per face: the first entity whose result equals it in each orientation, and the last whose result is the same.
  constexpr size_t kOrientations = 4;  // TopAbs_FORWARD, REVERSED, INTERNAL, EXTERNAL
  std::vector<std::array<Handle(Standard_Transient), kOrientations>> equal(entity.size());
  std::vector<Handle(Standard_Transient)> same(entity.size());
  for (int j = 1; j <= tp->NbMapped(); ++j) {
    const Handle(Standard_Transient) ent = tp->Mapped(j);
    const TopoDS_Shape sh = TransferBRep::ShapeResult(tp, ent);
    if (sh.IsNull() || sh.ShapeType() != TopAbs_FACE) continue;
    const int k = faces.FindIndex(sh);  // keyed by TShape and location: IsSame
    if (k == 0) continue;
    Handle(Standard_Transient)& first = equal[static_cast<size_t>(k - 1)][static_cast<size_t>(sh.Orientation())];
    if (first.IsNull()) first = ent;
    same[static_cast<size_t>(k - 1)] = ent;
  }
  for (int k = 1; k <= faces.Extent(); ++k) {
    const Handle(Standard_Transient)& first =
        equal[static_cast<size_t>(k - 1)][static_cast<size_t>(faces(k).Orientation())];
    entity[static_cast<size_t>(k - 1)] = first.IsNull() ? same[static_cast<size_t>(k - 1)] : first;
  }
  return entity;
}

/// The file entity of every face of `shape` (issue 17 §3): the STEP instance id "#1234" and the entity's name, or the
/// IGES directory entry "D17" and its name; "" where OpenCASCADE's transfer cannot trace a face back.
void labelFaces(XSControl_Reader& reader, const TopoDS_Shape& shape, FaceLabels& labels) {
  const Handle(XSControl_WorkSession) session = reader.WS();
  const Handle(XSControl_TransferReader) transfer = session.IsNull() ? nullptr : session->TransferReader();
  const Handle(Interface_InterfaceModel) model = reader.Model();
  const Handle(StepData_StepModel) stepModel = Handle(StepData_StepModel)::DownCast(model);
  const Handle(IGESData_IGESModel) igesModel = Handle(IGESData_IGESModel)::DownCast(model);
  const int before = labels.faces.Extent();
  for (TopExp_Explorer ex(shape, TopAbs_FACE); ex.More(); ex.Next()) labels.faces.Add(ex.Current());
  // Faces already labelled keep their labels; the new ones (in the explorer's order, each with the orientation of
  // its first occurrence) are looked up together.
  TopTools_IndexedMapOfShape added;
  for (int k = before + 1; k <= labels.faces.Extent(); ++k) added.Add(labels.faces(k));
  const std::vector<Handle(Standard_Transient)> entities = faceEntities(transfer, added);
  for (const Handle(Standard_Transient)& entity : entities) {
    FaceLabels::Label label;
    if (!entity.IsNull() && !stepModel.IsNull()) {
      if (const int id = stepModel->IdentLabel(entity); id > 0) label.entity = fmt::format("#{}", id);
      const Handle(StepRepr_RepresentationItem) item = Handle(StepRepr_RepresentationItem)::DownCast(entity);
      if (!item.IsNull() && !item->Name().IsNull()) label.name = item->Name()->ToCString();
    } else if (!entity.IsNull() && !igesModel.IsNull()) {
      const Handle(IGESData_IGESEntity) iges = Handle(IGESData_IGESEntity)::DownCast(entity);
      if (!iges.IsNull()) {
        if (const int dnum = igesModel->DNum(iges); dnum > 0) label.entity = fmt::format("D{}", dnum);
        if (iges->HasName() && !iges->NameValue().IsNull()) label.name = iges->NameValue()->ToCString();
      }
    }
    labels.labels.push_back(std::move(label));
  }
}

}  // namespace

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

OcctSignalGuard::OcctSignalGuard() {
  if (guardDepth++ > 0) return;
  outer_ = true;
  // OSD::SetSignal replaces the handlers of many signals (SIGINT, SIGHUP, ...): all are saved, and all but the
  // guarded ones put back at once (Ctrl-C still ends seam).
  std::array<struct sigaction, NSIG> before{};
  for (int sig = 1; sig < NSIG; ++sig) ::sigaction(sig, nullptr, &before[static_cast<size_t>(sig)]);
  traps_ = fegetexcept();
  OSD::SetSignal(OSD_SignalMode_Set, false);
  for (int sig = 1; sig < NSIG; ++sig)
    if (std::find(kGuardedSignals.begin(), kGuardedSignals.end(), sig) == kGuardedSignals.end())
      ::sigaction(sig, &before[static_cast<size_t>(sig)], nullptr);  // SIGKILL/SIGSTOP: refused, never changed
  for (size_t k = 0; k < kGuardedSignals.size(); ++k) saved_[k] = before[static_cast<size_t>(kGuardedSignals[k])];
}

OcctSignalGuard::~OcctSignalGuard() {
  --guardDepth;
  if (!outer_) return;
  for (size_t k = 0; k < kGuardedSignals.size(); ++k) ::sigaction(kGuardedSignals[k], &saved_[k], nullptr);
  fedisableexcept(FE_ALL_EXCEPT);
  if (traps_ != 0) feenableexcept(traps_);
}

/// Reads the file into one shape (STEP or IGES), with OpenCASCADE's errors, crashes and overlong transfers turned
/// into messages.
Handle(TDocStd_Document) newCadDocument() {
  Handle(TDocStd_Document) doc;
  XCAFApp_Application::GetApplication()->NewDocument("MDTV-XCAF", doc);
  return doc;
}

TopoDS_Shape documentShape(const Handle(TDocStd_Document)& document) {
  const Handle(XCAFDoc_ShapeTool) tool = XCAFDoc_DocumentTool::ShapeTool(document->Main());
  TDF_LabelSequence roots;
  tool->GetFreeShapes(roots);
  if (roots.Length() == 1) return XCAFDoc_ShapeTool::GetShape(roots.Value(1));
  TopoDS_Compound c;
  BRep_Builder b;
  b.MakeCompound(c);
  for (int i = 1; i <= roots.Length(); ++i) {
    const TopoDS_Shape s = XCAFDoc_ShapeTool::GetShape(roots.Value(i));
    if (!s.IsNull()) b.Add(c, s);
  }
  return roots.IsEmpty() ? TopoDS_Shape() : TopoDS_Shape(c);
}

Result<TopoDS_Shape> readShape(const fs::path& file, CadFormat format, std::vector<std::string>* warnings,
                               std::chrono::seconds timeLimit, FaceLabels* labels, FileUnits* units,
                               const Handle(TDocStd_Document)* document) {
  if (Status st = io::checkInputFile(file, io::kMaxCadFileBytes); !st) return st;  // a FIFO, a directory, too large
  int stepInstances = -1;
  if (Status st = checkReals(file, format, &stepInstances); !st) return st;
  silenceOcct();
  pinSessionUnitToMillimetres();
  const char* kind = format == CadFormat::kStep ? "STEP" : "IGES";
  const std::string name = file.string();
  OcctSignalGuard guard;
  // OpenCASCADE's IGES parser is not reentrant (its state is global): one IGES parse at a time. The lock is taken
  // outside the try block: a signal inside OpenCASCADE returns to OCC_CATCH_SIGNALS by longjmp, which would skip the
  // destructor of a lock taken after it (the mutex stayed locked and the next read hung: fuzz_iges, 2026-12-03).
  std::unique_lock<std::mutex> igesLock(igesParserMutex(), std::defer_lock);
  if (format == CadFormat::kIges) igesLock.lock();
  try {
    OCC_CATCH_SIGNALS
    if (format == CadFormat::kIges) IGESControl_Controller::Init();
    // With a document, OpenCASCADE's XDE readers (STEPCAFControl / IGESCAFControl) transfer the shapes together
    // with their names, colours and layers; their underlying reader is the plain one, checked the same way.
    std::unique_ptr<XSControl_Reader> plain;
    std::unique_ptr<STEPCAFControl_Reader> stepCaf;
    std::unique_ptr<IGESCAFControl_Reader> igesCaf;
    XSControl_Reader* reader = nullptr;
    if (document != nullptr && format == CadFormat::kStep) {
      stepCaf = std::make_unique<STEPCAFControl_Reader>();
      stepCaf->SetColorMode(true);
      stepCaf->SetNameMode(true);
      stepCaf->SetLayerMode(true);
      reader = &stepCaf->ChangeReader();
    } else if (document != nullptr) {
      igesCaf = std::make_unique<IGESCAFControl_Reader>();
      igesCaf->SetColorMode(true);
      igesCaf->SetNameMode(true);
      igesCaf->SetLayerMode(true);
      reader = igesCaf.get();
    } else {
      if (format == CadFormat::kStep)
        plain = std::make_unique<STEPControl_Reader>();
      else
        plain = std::make_unique<IGESControl_Reader>();
      reader = plain.get();
    }
    IFSelect_ReturnStatus st = IFSelect_RetVoid;
    if (format == CadFormat::kIges) {
      // The counts are checked on OpenCASCADE's own split of the file before its readers allocate from them.
      if (Status counts = checkIgesCounts(file); !counts) return counts;
      st = reader->ReadFile(file.c_str());
      igesLock.unlock();
    } else {
      st = stepCaf ? stepCaf->ReadFile(file.c_str()) : reader->ReadFile(file.c_str());
    }
    if (st != IFSelect_RetDone) return invalidInput(fmt::format("{}: not a readable {} file", name, kind));
    // Entities the reader could not load (a truncated or corrupted file) are dropped by OpenCASCADE: count them.
    // (Interface_InterfaceModel::IsErrorEntity; WS()->ModelCheckList() throws on valid IGES files.)
    int failedEntities = 0;
    const Handle(Interface_InterfaceModel) model = reader->Model();
    for (int k = 1; k <= model->NbEntities(); ++k)
      if (model->IsErrorEntity(k)) ++failedEntities;
    // The reader stops at an entity it cannot parse (OpenCASCADE catches its own crash there, once the guard's
    // handlers are in place) and keeps what it loaded before: that partial model is not the file.
    // A STEP file whose every entity instance was loaded is read although the reader failed on something else: a
    // malformed header line (issue 35 §4: FILE_DESCRIPTION((('...')),'2;1') from one exporter), said as a warning.
    std::string headerDefect;
    if (const Handle(Interface_Check)& global = model->GlobalCheck(); global->HasFailed()) {
      if (stepInstances <= 0 || stepInstances != model->NbEntities() || failedEntities > 0)
        return invalidInput(fmt::format("{}: OpenCASCADE's {} reader reports \"{}\" ({} entities loaded{}); the file "
                                        "is corrupt or truncated",
                                        name, kind, global->CFail(1), model->NbEntities(),
                                        stepInstances > 0 ? fmt::format(" of {}", stepInstances) : std::string()));
      headerDefect = fmt::format("{}: OpenCASCADE's STEP reader reports \"{}\" outside the data (a malformed header); "
                                 "all {} entities were read",
                                 name, global->CFail(1), stepInstances);
    }
    if (units != nullptr) {
      units->units = {};
      if (format == CadFormat::kStep)
        readStepUnits(static_cast<STEPControl_Reader&>(*reader), units->units);
      else
        readIgesUnits(Handle(IGESData_IGESModel)::DownCast(model), units->units);
    }
    const int roots = reader->NbRootsForTransfer();
    const Handle(DeadlineIndicator) deadline = new DeadlineIndicator(std::chrono::duration<double>(timeLimit).count());
    int transferred = 0;
    TopoDS_Shape docShape;
    if (document != nullptr) {
      Handle(TDocStd_Document) doc = *document;  // the readers take a non-const handle
      const bool ok = stepCaf ? stepCaf->Transfer(doc, deadline->Start()) : igesCaf->Transfer(doc, deadline->Start());
      docShape = documentShape(*document);
      transferred = ok && !docShape.IsNull() ? roots : 0;
    } else {
      transferred = reader->TransferRoots(deadline->Start());
    }
    if (deadline->expired())
      return invalidInput(fmt::format("{}: OpenCASCADE's transfer of the {} roots (shape healing) was stopped after "
                                      "{} s; the file is probably corrupt (huge or inconsistent values)",
                                      name, kind, timeLimit.count()));
    if (transferred == 0 || (document == nullptr && reader->NbShapes() == 0))
      return invalidInput(fmt::format("{}: the {} file holds no shape or surface that can be transferred{}", name,
                                      kind,
                                      failedEntities > 0
                                          ? fmt::format(" ({} entities failed to load: truncated or corrupt?)",
                                                        failedEntities)
                                          : std::string()));
    std::vector<std::string> pending;
    if (warnings == nullptr) warnings = &pending;
    {
      if (!headerDefect.empty()) warnings->push_back(headerDefect);
      if (failedEntities > 0)
        warnings->push_back(fmt::format("{}: {} entities of the {} file failed to load (truncated or corrupt?); "
                                        "the shapes that refer to them are missing or incomplete",
                                        name, failedEntities, kind));
      if (transferred < roots)
        warnings->push_back(fmt::format("{}: only {} of {} root entities transferred to shapes; the rest of the model "
                                        "is missing",
                                        name, transferred, roots));
    }
    // Without `warnings` (the B-rep check), they go with the faces of this file to convertFaces on this thread.
    pendingReadWarnings = {file, std::move(pending)};
    TopoDS_Shape shape = document != nullptr ? docShape : reader->OneShape();
    if (labels != nullptr) labelFaces(*reader, shape, *labels);
    if (units != nullptr && units->statedUnitMm) {
      // The user states the coordinates' unit (--units): rescale from the header's unit to it.
      const double scale = *units->statedUnitMm / units->units.millimetresPerFileUnit;
      if (std::isfinite(scale) && scale > 0.0 && std::abs(scale - 1.0) > kSameUnitRelTol) {
        gp_Trsf trsf;
        trsf.SetScale(gp_Pnt(0, 0, 0), scale);
        BRepBuilderAPI_Transform transform(shape, trsf, /*copy=*/true);
        if (!transform.IsDone())
          return invalidInput(fmt::format("{}: OpenCASCADE could not rescale the model to the stated unit", name));
        if (labels != nullptr) {
          FaceLabels scaled;
          for (int i = 1; i <= labels->faces.Extent(); ++i) {
            const TopoDS_Shape now = transform.ModifiedShape(labels->faces(i));
            if (scaled.faces.Contains(now)) continue;
            scaled.faces.Add(now);
            scaled.labels.push_back(labels->labels[static_cast<size_t>(i - 1)]);
          }
          *labels = std::move(scaled);
        }
        shape = transform.Shape();
        units->units.statedScale = scale;
        if (units->units.declaredResolutionMm) *units->units.declaredResolutionMm *= scale;
      }
    }
    return shape;
  } catch (const Standard_Failure& f) {
    if (isSignal(f))
      return invalidInput(fmt::format("{}: OpenCASCADE crashed reading the {} file ({}); the file is corrupt",
                                      name, kind, f.GetMessageString()));
    return invalidInput(fmt::format("{}: OpenCASCADE failed to read the file: {}", name, f.GetMessageString()));
  }
}

void applyFaceLabels(CadImport& import, const std::vector<TopoDS_Face>& faces, const FaceLabels& labels) {
  for (CadFace& f : import.faces) {
    if (f.faceIndex < 1 || f.faceIndex > static_cast<int>(faces.size())) continue;
    const int i = labels.faces.FindIndex(faces[static_cast<size_t>(f.faceIndex - 1)]);
    if (i < 1) continue;
    f.entity = labels.labels[static_cast<size_t>(i - 1)].entity;
    f.entityName = labels.labels[static_cast<size_t>(i - 1)].name;
  }
}

}  // namespace detail

Handle(Geom_BSplineSurface) detail::toOcctSurface(const BSplineSurface& s) { return toOcct(s); }

std::optional<CadFormat> cadFormatOf(const fs::path& file) {
  const std::string ext = lower(file.extension().string());
  if (ext == ".step" || ext == ".stp") return CadFormat::kStep;
  if (ext == ".iges" || ext == ".igs") return CadFormat::kIges;
  return std::nullopt;
}

ModelUnits cadModelUnits(const CadImport& import, const ToleranceOverrides& overrides) {
  ModelUnits u;
  u.length = LengthUnit::kMillimetre;
  u.fileUnit = import.units.fileUnit;
  // The user's unit (--units, or CadReadOptions::statedUnitMm when it rescaled the file) rather than the header's.
  u.source = overrides.units || import.units.statedScale != 1.0 ? UnitSource::kOption : UnitSource::kFileHeader;
  u.declaredResolution = import.units.declaredResolutionMm;
  std::tie(u.display, u.displaySource) = detail::shownCadUnit(overrides, import.units.fileUnit);
  return u;
}

namespace detail {

std::pair<std::optional<LengthUnit>, UnitSource> shownCadUnit(const ToleranceOverrides& overrides,
                                                              const std::string& fileUnit) {
  if (overrides.display) return {overrides.display, UnitSource::kDisplayOption};
  if (overrides.units) return {overrides.units, UnitSource::kOption};
  const std::optional<LengthUnit> own = lengthUnitOfFileName(fileUnit);
  return {own, own ? UnitSource::kFileHeader : UnitSource::kNone};
}

}  // namespace detail

Result<CadImport> readCadFile(const fs::path& file, const CadReadOptions& options) {
  const std::optional<CadFormat> format = cadFormatOf(file);
  if (!format)
    return invalidInput(fmt::format("{}: not a STEP (.step/.stp) or IGES (.iges/.igs) file name", file.string()));
  std::vector<std::string> readWarnings;
  detail::FaceLabels labels;
  detail::FileUnits units;
  units.statedUnitMm = options.statedUnitMm;
  Result<TopoDS_Shape> shape =
      detail::readShape(file, *format, &readWarnings, detail::kTransferTimeLimit, &labels, &units);
  if (!shape) return shape.status();
  std::vector<TopoDS_Face> faces;
  for (TopExp_Explorer ex(*shape, TopAbs_FACE); ex.More(); ex.Next()) faces.push_back(TopoDS::Face(ex.Current()));
  Result<CadImport> out = detail::convertFaces(file, faces, options);
  if (out) detail::applyFaceLabels(*out, faces, labels);
  if (out && out->model.trimmedFaces > 0) {
    // The trims as plain data (Model::brep), so that a JSON output keeps them (issue 34 §1); when they cannot
    // be carried onto the patches, the model stays without them and the patch-only writers refuse it.
    std::string whyNot;
    std::vector<std::string> notes;
    std::vector<Patch> asRead = out->model.patches;  // brepFromFaces may continue patches; undone without a B-rep
    std::vector<int> invalidFaces;
    out->model.brep = detail::brepFromFaces(*shape, faces, *out, whyNot, notes, &invalidFaces);
    if (out->model.brep) {
      if (Status st = validateBRep(out->model, *out->model.brep, file.string()); !st) {
        out->model.brep.reset();
        whyNot = st.message();
      }
    }
    if (out->model.brep) {
      for (const std::string& n : notes) out->warnings.push_back(fmt::format("{}: {}", file.string(), n));
      if (!invalidFaces.empty()) {
        std::vector<std::string> names;
        for (int f : invalidFaces) names.push_back(fmt::format("F{} (brep face {})", f, f - 1));
        out->warnings.push_back(fmt::format(
            "{}: OpenCASCADE's BRepCheck_Analyzer finds {} invalid as read, a wire whose edges do not connect: "
            "kept as read, with {} loops open (\"open_as_read\"), in every output",
            file.string(), fmt::join(names, ", "), invalidFaces.size() > 1 ? "their" : "its"));
      }
    } else {
      out->model.patches = std::move(asRead);
      if (!invalidFaces.empty()) {
        std::vector<std::string> names, brepIds;
        for (int f : invalidFaces) {
          names.push_back(fmt::format("F{}", f));
          brepIds.push_back(std::to_string(f - 1));
        }
        const bool many = invalidFaces.size() > 1;
        whyNot += fmt::format("; OpenCASCADE's BRepCheck_Analyzer finds {} {} (brep face{} {}) invalid as read, a "
                              "wire whose edges do not connect: STEP/IGES outputs keep {} as read",
                              many ? "faces" : "face", fmt::join(names, ", "), many ? "s" : "",
                              fmt::join(brepIds, ", "), many ? "them" : "it");
      }
      out->warnings.push_back(
          fmt::format("{}: the trims of the {} trimmed faces cannot be kept as plain data ({}): "
                      "outputs other than STEP/IGES from this file are refused",
                      file.string(), out->model.trimmedFaces, whyNot));
    }
  }
  if (out) out->warnings.insert(out->warnings.begin(), readWarnings.begin(), readWarnings.end());
  if (out) out->units = units.units;
  return out;
}

namespace detail {

Result<CadImport> convertFacesUnguarded(const fs::path& file, const std::vector<TopoDS_Face>& faces,
                                        const CadReadOptions& options, int& current);

Result<CadImport> convertFaces(const fs::path& file, const std::vector<TopoDS_Face>& faces,
                               const CadReadOptions& options) {
  if (faces.empty())
    return Status(ErrorCode::kInvalidInput, fmt::format("{}: the file contains no faces or surfaces", file.string()));
  // A crash inside OpenCASCADE (a corrupt face) ends the conversion with an error: the state it leaves is not
  // trusted for the other faces.
  OcctSignalGuard guard;
  int current = 0;  // the face being converted, for the message
  try {
    OCC_CATCH_SIGNALS
    Result<CadImport> out = convertFacesUnguarded(file, faces, options, current);
    if (out && pendingReadWarnings.first == file)
      out->warnings.insert(out->warnings.begin(), pendingReadWarnings.second.begin(), pendingReadWarnings.second.end());
    pendingReadWarnings = {};
    return out;
  } catch (const Standard_Failure& f) {
    return invalidInput(fmt::format("{}: face {}: OpenCASCADE {}: {}", file.string(), current,
                                    isSignal(f) ? "crashed (the file is corrupt)" : "failed", f.GetMessageString()));
  }
}

Result<CadImport> convertFacesUnguarded(const fs::path& file, const std::vector<TopoDS_Face>& faces,
                                        const CadReadOptions& options, int& current) {
  CadImport out;
  // Model size for the approximation tolerance: the parameter-box corners of every face, evaluated. Each face's
  // parameter box is kept for the conversion below (BRepTools::UVBounds walks all its pcurves).
  BoundingBox box;
  std::vector<std::optional<std::array<double, 4>>> uvBounds(faces.size());
  for (size_t k = 0; k < faces.size(); ++k) {
    const TopoDS_Face& f = faces[k];
    ++current;
    try {
      double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
      BRepTools::UVBounds(f, u0, u1, v0, v1);
      uvBounds[k] = std::array{u0, u1, v0, v1};
      const Handle(Geom_Surface) s = BRep_Tool::Surface(f);
      if (s.IsNull()) continue;
      for (double u : {u0, 0.5 * (u0 + u1), u1})
        for (double v : {v0, 0.5 * (v0 + v1), v1}) {
          const gp_Pnt p = s->Value(u, v);
          box.add(Vec3(p.X(), p.Y(), p.Z()));
        }
    } catch (const Standard_Failure& failure) {
      if (isSignal(failure)) throw;
    }
  }
  const double approxTol = options.approximationRelTol * std::max(box.empty() ? 1.0 : box.diagonal(), 1e-300);

  int index = 0;
  for (const TopoDS_Face& face : faces) {
    current = ++index;
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
      if (const auto& b = uvBounds[static_cast<size_t>(index - 1)]) {
        u0 = (*b)[0];
        u1 = (*b)[1];
        v0 = (*b)[2];
        v1 = (*b)[3];
      } else {
        BRepTools::UVBounds(face, u0, u1, v0, v1);  // it failed above: fails the same way here
      }
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
      if (isSignal(f)) throw;
      // One unreadable face does not lose the model: it is skipped, and said so.
      out.warnings.push_back(fmt::format("{}: face {} ({}) skipped: OpenCASCADE failed: {}", file.string(), index,
                                         info.surfaceType, f.GetMessageString()));
    }
  }
  if (out.model.patches.empty())
    return Status(ErrorCode::kInvalidInput, fmt::format("{}: no face could be read", file.string()));
  out.model.trimmedFaces = static_cast<int>(
      std::count_if(out.faces.begin(), out.faces.end(), [](const CadFace& f) { return f.trimmed; }));
  return out;
}

}  // namespace detail

namespace {

/// OpenCASCADE's own words for what it refuses in a surface or a shape, said in the user's words (issue 39 goal 5);
/// its text stays at the end, in parentheses, for a bug report.
std::string occtInPlainWords(const std::string& occt) {
  struct Known {
    const char* fragment;
    const char* words;
  };
  static const Known kKnown[] = {
      {"Weights values too small", "a weight is too small for OpenCASCADE (at most 1e-290 is refused)"},
      {"interval values too close", "two distinct knots are closer than OpenCASCADE can tell apart"},
      {"invalid degree", "a degree is outside OpenCASCADE's range 1..25"},
      {"FindFromKey", "OpenCASCADE lost track of a face while sewing or writing (patches that coincide or fold "
                      "onto themselves)"},
  };
  for (const Known& k : kKnown)
    if (occt.find(k.fragment) != std::string::npos) return fmt::format("{} (OpenCASCADE: {})", k.words, occt);
  return fmt::format("OpenCASCADE failed (its message: {})", occt.empty() ? "none" : occt);
}

/// The smallest weight that OpenCASCADE's IGES writer and reader carry through a round trip: a patch with a weight
/// of 1e-9 is read back, one of 1e-10 is written as an entity that its reader transfers to nothing (measured
/// 2026-11-28 with OpenCASCADE 7.6, a bilinear patch with three weights 1; whatever the other weights are).
constexpr double kIgesMinWeight = 1e-9;

/// Why OpenCASCADE cannot take patch `s` as a Geom_BSplineSurface, in the user's words, or "" when it can: the
/// checks of Geom_BSplineSurface's constructor (degree at most Geom_BSplineSurface::MaxDegree(), every weight above
/// gp::Resolution(), distinct knots at least two representable numbers apart) and, for IGES, weights of at least
/// kIgesMinWeight; made before the patch is handed over so that no error comes back as OpenCASCADE's text.
std::string exportProblem(const BSplineSurface& s, CadFormat format) {
  const int maxDegree = Geom_BSplineSurface::MaxDegree();
  for (const auto& [dir, degree] : {std::pair{"u", s.degreeU()}, std::pair{"v", s.degreeV()}}) {
    if (degree > maxDegree)
      return fmt::format("its {} degree {} is above {}, the largest that OpenCASCADE (and so STEP/IGES export) "
                         "supports; approximate it by a patch of lower degree, or keep the model as JSON",
                         dir, degree, maxDegree);
  }
  if (s.isRational()) {
    const double least = format == CadFormat::kIges ? kIgesMinWeight : gp::Resolution();
    for (int i = 0; i < s.numU(); ++i)
      for (int j = 0; j < s.numV(); ++j)
        if (s.weight(i, j) < least || s.weight(i, j) <= gp::Resolution())
          return fmt::format("weight [{}][{}] = {} is too small for OpenCASCADE's {} (weights must be at least {}); "
                             "scale all the weights of the patch up by one factor (the surface stays the same)",
                             i, j, s.weight(i, j), format == CadFormat::kIges ? "IGES" : "STEP", least);
  }
  for (const auto& [dir, knots] : {std::pair{"u", &s.knotsU()}, std::pair{"v", &s.knotsV()}}) {
    const std::vector<double>& t = knots->values();
    for (size_t k = 1; k < t.size(); ++k) {
      const double a = t[k - 1], b = t[k];
      // OpenCASCADE's test (BSplCLib): distinct knots closer than Epsilon(|a|), one unit in the last place.
      if (b != a && b - a <= std::nextafter(std::abs(a), std::numeric_limits<double>::infinity()) - std::abs(a))
        return fmt::format("{} knots {} ({}) and {} ({}) differ by one unit in the last place, which OpenCASCADE "
                           "cannot tell apart; make them equal or move them apart",
                           dir, k - 1, a, k, b);
    }
  }
  return "";
}

/// Most patches an export error names (the rest are counted).
constexpr size_t kMaxNamedCulprits = 8;

/// `names` quoted and separated by commas, the first kMaxNamedCulprits of them, then "and N more".
std::string quotedNames(const std::vector<std::string>& names) {
  std::string out;
  for (size_t k = 0; k < names.size() && k < kMaxNamedCulprits; ++k)
    out += fmt::format("{}\"{}\"", k == 0 ? "" : ", ", names[k]);
  if (names.size() > kMaxNamedCulprits) out += fmt::format(" and {} more", names.size() - kMaxNamedCulprits);
  return out;
}

/// The patches as B-spline faces, sewn with `tol` into a shell (a compound when sewing gives nothing).
Result<TopoDS_Shape> sewnPatchShape(const Model& model, const fs::path& file, CadFormat format, double tol) {
  std::vector<TopoDS_Face> faces;
    for (const Patch& p : model.patches) {
      if (p.surface.dim() != 3)
        return invalidInput(fmt::format("{}: patch \"{}\" is not 3-D", file.string(), p.name));
      if (const std::string why = exportProblem(p.surface, format); !why.empty())
        return invalidInput(fmt::format("{}: patch \"{}\" cannot be written as STEP/IGES: {}; nothing written",
                                        file.string(), p.name, why));
      try {
        OCC_CATCH_SIGNALS
        const Handle(Geom_BSplineSurface) s = toOcct(p.surface);
        BRepBuilderAPI_MakeFace mf(s, Precision::Confusion());
        if (!mf.IsDone())
          return invalidInput(fmt::format("{}: patch \"{}\": OpenCASCADE cannot make a face of it; nothing written",
                                          file.string(), p.name));
        faces.push_back(mf.Face());
      } catch (const Standard_Failure& f) {
        return invalidInput(fmt::format("{}: patch \"{}\" cannot be written as STEP/IGES: {}; nothing written",
                                        file.string(), p.name, occtInPlainWords(f.GetMessageString())));
      }
    }
    TopoDS_Shape shape;
    if (faces.size() == 1) return TopoDS_Shape(faces.front());
    BRepBuilderAPI_Sewing sewing(tol);
    for (const TopoDS_Face& f : faces) sewing.Add(f);
    sewing.Perform();
    // Sewing removes a face without area (every control point within the sewing tolerance of one point or one
    // curve): name each such patch instead of writing fewer faces than patches.
    std::vector<std::string> degenerate;
    for (size_t k = 0; k < faces.size() && std::isfinite(tol); ++k)  // (a model 1e300 across: no such measure)
      if (sewing.IsDegenerated(faces[k])) degenerate.push_back(model.patches[k].name);
    if (!degenerate.empty()) {
      const bool one = degenerate.size() == 1;
      return invalidInput(fmt::format("{}: {} {} {} no area at the sewing tolerance {:.3g} (every control point on "
                                      "one point or one curve): sewing removes {}; nothing written",
                                      file.string(), one ? "patch" : "patches", quotedNames(degenerate),
                                      one ? "has" : "have", tol, one ? "it" : "them"));
    }
    shape = sewing.SewedShape();
    if (shape.IsNull()) {
      TopoDS_Compound c;
      BRep_Builder b;
      b.MakeCompound(c);
      for (const TopoDS_Face& f : faces) b.Add(c, f);
      shape = c;
    }
    return shape;
}


/// Writes a file atomically: `print` writes into a temporary file in the output's folder (a short name,
/// io::temporaryPathFor, made with O_EXCL), `verify` checks the temporary file, and only then is it renamed over
/// `file`. The temporary file is removed on every way out but the rename. OpenCASCADE runs under the signal guard.
Status writeAtomically(const fs::path& file, const std::function<bool(std::ostream&)>& print,
                       const std::function<Status(const fs::path&)>& verify) {
  fs::path temp;
  for (int attempt = 0;; ++attempt) {
    temp = io::temporaryPathFor(file);
    const int fd = ::open(temp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      ::close(fd);
      break;
    }
    const int err = errno;  // captured before anything else can change it
    if (err != EEXIST || attempt >= kTemporaryAttempts)
      return ioError(file, fmt::format("cannot create temporary file {}: {}", temp.string(),
                                       std::generic_category().message(err)));
  }
  io::RemoveOnExit removeTemporary{temp};
  {
    detail::OcctSignalGuard guard;
    try {
      OCC_CATCH_SIGNALS
      std::ofstream os(temp, std::ios::binary | std::ios::trunc);
      if (!os) return ioError(file, "cannot create temporary file " + temp.string());
      const bool printed = print(os);
      os.close();
      if (os.fail()) return ioError(file, "error while writing the file");
      // The writer refused the model (a transfer that did not succeed, a shape its writer does not take): the
      // model's problem, not the disk's.
      if (!printed)
        return invalidInput(fmt::format("{}: OpenCASCADE's writer refused the model; nothing written", file.string()));
    } catch (const Standard_Failure& f) {
      return invalidInput(fmt::format("{}: {} while writing the model; nothing written", file.string(),
                                      isSignal(f) ? fmt::format("OpenCASCADE crashed ({})", f.GetMessageString())
                                                  : occtInPlainWords(f.GetMessageString())));
    }
  }
  if (Status st = verify(temp); !st) return st;
  std::error_code renameError;
  fs::rename(temp, file, renameError);
  if (renameError) return ioError(file, "cannot replace file: " + renameError.message());  // temporary removed
  removeTemporary.keep();
  return Status::ok();
}

/// A STEP model printed with 17 significant digits per real (the writers' default keeps 12).
bool printStep(const Handle(StepData_StepModel)& model, std::ostream& os) {
  StepData_StepWriter sw(model);
  sw.FloatWriter().SetFormat(kRealFormat);
  sw.SendModel(StepAP214::Protocol());
  return sw.Print(os);
}

/// An IGES model printed with 17 significant digits per real (the writers' default keeps 9).
bool printIges(const Handle(IGESData_IGESModel)& model, std::ostream& os) {
  IGESData_IGESWriter iw(model);
  iw.FloatWriter().SetFormat(kRealFormat);
  iw.SendModel(IGESSelect_WorkLibrary::DefineProtocol());
  return iw.Print(os);
}

Status writePatchesCadFile(const Model& model, const fs::path& file, CadFormat format, const CadWriteOptions& options);

/// Most trial writes made to find the patches a failed write cannot hold (failingPatches).
constexpr int kMaxCulpritProbes = 64;

/// The patches of `model` that OpenCASCADE cannot write even alone, found by bisection (a half that writes and reads
/// back is cleared whole; a failing single patch is a culprit), each trial written to a temporary file next to
/// `file` and removed. At most kMaxCulpritProbes trials: `complete` says whether every part was decided.
std::vector<std::string> failingPatches(const Model& model, const fs::path& file, CadFormat format,
                                        const CadWriteOptions& options, bool& complete) {
  std::vector<std::string> culprits;
  int probes = 0;
  complete = true;
  std::function<void(size_t, size_t)> search = [&](size_t lo, size_t hi) {
    if (lo >= hi) return;
    if (probes >= kMaxCulpritProbes) {
      complete = false;
      return;
    }
    ++probes;
    Model part;
    part.patches.assign(model.patches.begin() + static_cast<std::ptrdiff_t>(lo),
                        model.patches.begin() + static_cast<std::ptrdiff_t>(hi));
    const fs::path trial = io::temporaryPathFor(file);
    const io::RemoveOnExit removeTrial{trial};
    if (writePatchesCadFile(part, trial, format, options)) return;
    if (hi - lo == 1) {
      culprits.push_back(model.patches[lo].name);
      return;
    }
    const size_t mid = lo + (hi - lo) / 2;
    search(lo, mid);
    search(mid, hi);
  };
  // The whole model failed already: its halves first.
  const size_t n = model.patches.size();
  if (n == 1) {
    culprits.push_back(model.patches[0].name);
  } else {
    search(0, n / 2);
    search(n / 2, n);
  }
  return culprits;
}

}  // namespace

Status writeCadFile(const Model& model, const fs::path& file, CadFormat format, const CadWriteOptions& options) {
  if (model.patches.empty()) return invalidInput(fmt::format("{}: the model has no patches to write", file.string()));
  // A model with its B-rep topology (a JSON with "brep", a STEP/IGES read by readCadFile) is written as that
  // B-rep: every trim, shared edge, shell and solid (issue 34 §1).
  if (model.brep && !options.sewingTolerance) return writeBRepCadFile(model, file, format).status();
  if (Status st = checkNoTrimsLost(model, file.string()); !st) return st;
  Status st = writePatchesCadFile(model, file, format, options);
  // Errors that name their patch already (exportProblem, a face OpenCASCADE cannot make) need no search.
  if (st || st.code() != ErrorCode::kInvalidInput || st.message().find("patch \"") != std::string::npos) return st;
  // OpenCASCADE refused the model or dropped part of it without saying which patch: name the patches that fail
  // alone (issue 39: messages that name the patch), or say that none does.
  bool complete = true;
  const std::vector<std::string> culprits = failingPatches(model, file, format, options, complete);
  std::string why;
  if (!culprits.empty())
    why = fmt::format("{} {} cannot be written even alone{}", culprits.size() == 1 ? "patch" : "patches",
                      quotedNames(culprits),
                      complete ? "" : " (the search stopped early: there may be more)");
  else if (complete)
    why = "every patch writes alone: the failure comes from patches together (coinciding or overlapping ones)";
  else
    why = "no single patch was found that fails alone (the search stopped early)";
  return Status(st.code(), fmt::format("{} ({})", st.message(), why));
}

namespace {

/// writeCadFile of a model without a B-rep: its patches as B-spline faces, sewn.
Status writePatchesCadFile(const Model& model, const fs::path& file, CadFormat format, const CadWriteOptions& options) {
  silenceOcct();
  pinSessionUnitToMillimetres();
  const double tol = options.sewingTolerance.value_or(1e-6 * model.boundingBox().diagonal());
  TopoDS_Shape shape;
  {
    detail::OcctSignalGuard guard;
    try {
      OCC_CATCH_SIGNALS
      Result<TopoDS_Shape> made = sewnPatchShape(model, file, format, tol);
      if (!made) return made.status();
      shape = *made;
    } catch (const Standard_Failure& f) {
      return invalidInput(fmt::format("{}: {} while sewing the {} patches into one shell; nothing written",
                                      file.string(),
                                      isSignal(f) ? fmt::format("OpenCASCADE crashed ({})", f.GetMessageString())
                                                  : occtInPlainWords(f.GetMessageString()),
                                      model.patches.size()));
    }
  }
  const int faces = static_cast<int>(model.patches.size());
  return writeAtomically(
      file,
      [&](std::ostream& os) {
        // The writers' default real format keeps 12 significant digits (STEP) or 9 (IGES); seam writes 17 so that
        // every control point, weight and knot survives a round trip (issue 8: STEP -> JSON -> STEP is exact).
        if (format == CadFormat::kStep) {
          // Before the writer: it takes the unit and schema when it is made. Set after it, the unit was the one
          // an earlier write in the same process had left (a convert of a file in centimetres: this model then
          // came out a tenth of its size, area 1/100).
          Interface_Static::SetCVal("write.step.schema", "AP214IS");
          Interface_Static::SetCVal("write.step.unit", "MM");
          STEPControl_Writer w;
          return w.Transfer(shape, STEPControl_AsIs) == IFSelect_RetDone && printStep(w.Model(), os);
        }
        IGESControl_Controller::Init();
        IGESControl_Writer w("MM", 1);  // B-rep mode
        if (!w.AddShape(shape)) return false;
        w.ComputeModel();
        return printIges(w.Model(), os);
      },
      // What was written is read back: OpenCASCADE drops faces it cannot represent (knots near +-1e307, all control
      // points equal, coordinates near 1e+-300) without an error.
      [&](const fs::path& temp) { return verifyWritten(temp, file, format, faces); });
}

}  // namespace

namespace detail {

void forEachOnThreads(int n, int threads, const std::function<void(int)>& task) {
  std::vector<std::exception_ptr> failed(static_cast<size_t>(std::max(n, 0)));
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    tbb::parallel_for(0, n, [&](int k) {
      try {
        OCC_CATCH_SIGNALS  // the thread that runs the task: its own handler (inside the try, which catches it)
        task(k);
      } catch (...) {
        failed[static_cast<size_t>(k)] = std::current_exception();
      }
    });
  });
  for (const std::exception_ptr& e : failed)
    if (e) std::rethrow_exception(e);
}

std::string cadUnitName(double millimetresPerUnit, CadFormat format) {
  struct Known {
    double mm;
    const char* step;
    const char* iges;
  };
  static constexpr std::array<Known, 5> kKnown{{{1.0, "MM", "MM"},
                                               {25.4, "INCH", "IN"},
                                               {304.8, "FT", "FT"},
                                               {1000.0, "M", "M"},
                                               {10.0, "CM", "CM"}}};
  for (const Known& k : kKnown)
    if (std::abs(millimetresPerUnit - k.mm) <= kSameUnitRelTol * k.mm) return format == CadFormat::kStep ? k.step : k.iges;
  return "MM";
}

ShapeCounts countShape(const TopoDS_Shape& shape, const AreaOptions& area) {
  ShapeCounts c;
  TopTools_IndexedMapOfShape faces, wires, edges, shells, solids;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  TopExp::MapShapes(shape, TopAbs_WIRE, wires);
  TopExp::MapShapes(shape, TopAbs_EDGE, edges);
  TopExp::MapShapes(shape, TopAbs_SHELL, shells);
  TopExp::MapShapes(shape, TopAbs_SOLID, solids);
  c.faces = faces.Extent();
  c.wires = wires.Extent();
  c.edges = edges.Extent();
  c.shells = shells.Extent();
  c.solids = solids.Extent();
  for (int i = 1; i <= faces.Extent(); ++i) {
    const TopoDS_Face& f = TopoDS::Face(faces(i));
    double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
    BRepTools::UVBounds(f, u0, u1, v0, v1);
    int w = 0, e = 0;
    if (!naturallyBounded(f, {u0, u1, v0, v1}, w, e)) ++c.trimmedFaces;
  }
  TopTools_IndexedDataMapOfShapeListOfShape edgeFaces;
  TopExp::MapShapesAndAncestors(shape, TopAbs_EDGE, TopAbs_FACE, edgeFaces);
  for (int i = 1; i <= edgeFaces.Extent(); ++i) {
    const TopoDS_Edge& e = TopoDS::Edge(edgeFaces.FindKey(i));
    const TopTools_ListOfShape& around = edgeFaces.FindFromIndex(i);
    if (around.Extent() == 1 && !BRep_Tool::Degenerated(e) && !BRep_Tool::IsClosed(e, TopoDS::Face(around.First())))
      ++c.freeEdges;
  }
  // The faces one by one (the sum over the shape's faces that BRepGProp::SurfaceProperties of the shape makes),
  // on several threads: each face is read only (its surface and pcurves), each task catches its own signals, and
  // the first failure in face order is raised here, as the serial loop would raise it.
  c.faceAreas.assign(static_cast<size_t>(c.faces), 0.0);
  forEachOnThreads(c.faces, area.threads, [&](int k) {
    const size_t at = static_cast<size_t>(k);
    if (area.known != nullptr && area.known->faceAreas.size() == c.faceAreas.size() &&
        (area.changed == nullptr || !area.changed->count(k + 1))) {
      c.faceAreas[at] = area.known->faceAreas[at];
      return;
    }
    GProp_GProps props;
    if (area.relEps > 0.0)
      BRepGProp::SurfaceProperties(faces(k + 1), props, area.relEps);
    else
      BRepGProp::SurfaceProperties(faces(k + 1), props);
    c.faceAreas[at] = props.Mass();
  });
  for (const double a : c.faceAreas) c.area += a;
  return c;
}

namespace {

/// Empty when `got` keeps what `expected` counts (faces, trimmed faces, solids, area within `areaRelTol`); else what
/// was lost.
std::string countsLost(const ShapeCounts& expected, const ShapeCounts& got, double areaRelTol) {
  std::string lost;
  auto add = [&](const char* what, int want, int have) {
    if (want != have) lost += fmt::format("{}{} {} instead of {}", lost.empty() ? "" : ", ", have, what, want);
  };
  add("faces", expected.faces, got.faces);
  // Fewer trimmed faces is a trim lost; more is a natural boundary read back a little off its iso-line (a reader
  // that rebuilds pcurves from the 3-D curves: bearing.iges -> STEP), which the area check covers.
  if (got.trimmedFaces < expected.trimmedFaces) add("trimmed faces", expected.trimmedFaces, got.trimmedFaces);
  add("solids", expected.solids, got.solids);
  const double scale = std::max(std::abs(expected.area), std::abs(got.area));
  if (!(std::abs(expected.area - got.area) <= areaRelTol * scale))
    lost += fmt::format("{}area {:.9g} instead of {:.9g}", lost.empty() ? "" : ", ", got.area, expected.area);
  return lost;
}

}  // namespace

Status writeCadDocument(const Handle(TDocStd_Document) & document, const fs::path& file, CadFormat format,
                        const std::string& unitName, const ShapeCounts& expected,
                        std::vector<std::string>* notes, double areaRelTol, double areaRelEps,
                        WrittenBack* writtenBack, int threads, bool countReadBack) {
  silenceOcct();
  pinSessionUnitToMillimetres();
  // The document's shapes are in millimetres (the readers convert to OpenCASCADE's session unit), whatever unit the
  // XDE reader recorded for it: the writers scale from the document's unit to `unitName`.
  XCAFDoc_DocumentTool::SetLengthUnit(document, 1.0, UnitsMethods_LengthUnit_Millimeter);
  // IGES has two ways to write a B-rep: OpenCASCADE's B-rep mode (MSBO solids, entity 186), which keeps solids but
  // lost trims of trj3_s1-al-214.stp (80 trimmed faces read back instead of 76), and the faces mode (trimmed
  // surfaces, entity 144: what CAD systems write), which keeps every trim but writes solids as their faces. The
  // B-rep mode is tried first; when what it wrote loses something, the faces mode, and the note says so.
  auto attempt = [&](int igesBRepMode, const ShapeCounts& want) {
    return writeAtomically(
        file,
        [&](std::ostream& os) {
          if (format == CadFormat::kStep) {
            // Before the writer: it takes the unit and schema when it is made. The controller first: its statics
            // do not exist before a STEP reader or writer was made (an IGES file converted to STEP), and setting them
            // before that did nothing (the file came out in mm).
            STEPCAFControl_Controller::Init();
            Interface_Static::SetCVal("write.step.schema", "AP214IS");
            Interface_Static::SetCVal("write.step.unit", unitName.c_str());
            STEPCAFControl_Writer w;
            w.SetColorMode(true);
            w.SetNameMode(true);
            w.SetLayerMode(true);
            if (!w.Transfer(document, STEPControl_AsIs)) return false;
            return printStep(w.ChangeWriter().Model(), os);
          }
          IGESControl_Controller::Init();
          Interface_Static::SetCVal("write.iges.unit", unitName.c_str());
          Interface_Static::SetIVal("write.iges.brep.mode", igesBRepMode);
          IGESCAFControl_Writer w;
          {  // likewise, the global section's unit (flag and name) and the coordinates' scale
            IGESData_BasicEditor editor(w.Model(), IGESSelect_WorkLibrary::DefineProtocol());
            editor.SetUnitName(unitName.c_str());
            editor.ApplyUnit(true);
          }
          w.SetColorMode(true);
          w.SetNameMode(true);
          w.SetLayerMode(true);
          if (!w.Transfer(document)) return false;
          w.ComputeModel();
          return printIges(w.Model(), os);
        },
        [&](const fs::path& temp) -> Status {
          std::vector<std::string> warnings;
          FaceLabels labels;
          FileUnits units;
          Result<TopoDS_Shape> back = writtenBack != nullptr
                                          ? readShape(temp, format, &warnings, kTransferTimeLimit, &labels, &units)
                                          : readShape(temp, format, &warnings, kTransferTimeLimit);
          if (!back)
            return invalidInput(fmt::format("{}: OpenCASCADE cannot read back what it wrote ({}); nothing written",
                                            file.string(), back.status().message()));
          const std::string lost =
              countReadBack || format == CadFormat::kIges
                  ? countsLost(want, countShape(*back, AreaOptions{areaRelEps, threads}),
                               std::max(areaRelTol, format == CadFormat::kStep ? kKeptAreaRelTol : kKeptAreaRelTolIges))
                  : std::string();
          if (!lost.empty())
            return invalidInput(fmt::format("{}: not written: OpenCASCADE's {} writer would lose part of the model "
                                            "(read back: {})",
                                            file.string(), format == CadFormat::kStep ? "STEP" : "IGES", lost));
          if (writtenBack != nullptr)
            *writtenBack = {*back, std::move(labels), std::move(units), std::move(warnings)};
          return Status::ok();
        });
  };
  if (format == CadFormat::kStep) return attempt(0, expected);
  const Status brep = attempt(1, expected);
  if (brep || expected.solids == 0) return brep;
  ShapeCounts facesOnly = expected;
  facesOnly.solids = 0;
  if (Status st = attempt(0, facesOnly); !st) return st;
  if (notes != nullptr)
    notes->push_back(fmt::format("{}: the {} solids are written as their faces (IGES trimmed surfaces, entity 144): "
                                 "OpenCASCADE's IGES B-rep mode would have lost part of the model ({}); every face "
                                 "and trim is kept",
                                 file.string(), expected.solids, brep.message()));
  return Status::ok();
}

}  // namespace detail

}  // namespace seam::occt
