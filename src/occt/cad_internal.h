#pragma once
// Shared by the OpenCASCADE readers and the B-rep check.
#include <OSD_Signal.hxx>
#include <Standard_Failure.hxx>
#include <signal.h>
#include <Geom_BSplineSurface.hxx>
#include <Message_ProgressIndicator.hxx>
#include <TDocStd_Document.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "seam/occt/cad_io.h"

namespace seam::occt::detail {

/// True when OpenCASCADE turned a signal (a crash inside it) into this failure, not an ordinary exception.
inline bool isSignal(const Standard_Failure& f) { return f.IsKind(STANDARD_TYPE(OSD_Signal)); }

/// How a check or heal names a signal inside OpenCASCADE: on a file that reads, the crash is not evidence that the
/// file is corrupt (the overlap search's concurrent classifiers crashed on valid files, issue 39).
inline constexpr const char* kCrashedOnTheModel = "crashed on this model (a defect of the file or of OpenCASCADE)";

/// A face's parameter box [u0, u1] x [v0, v1].
struct ParamBox {
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
};

/// The side of `box` along which the edge's pcurve on `face` runs (an iso-parameter edge), within
/// kIsoEdgeRelTol of the box size; with `wholeSide`, only when it also runs from one corner of that side to the other.
std::optional<Edge> boxSideOf(const TopoDS_Edge& edge, const TopoDS_Face& face, const ParamBox& box, bool wholeSide);

/// While alive, OpenCASCADE's handlers catch SIGSEGV, SIGBUS, SIGILL and SIGFPE (floating-point traps off): a crash
/// inside OpenCASCADE, under a try block that starts with OCC_CATCH_SIGNALS (compiled with OCC_CONVERT_SIGNALS, as
/// cad_io.cpp is), jumps back there and is thrown as a Standard_Failure of kind OSD_Signal. On destruction the
/// previous handlers and trap mask come back, so a crash in seam's own code still crashes (and sanitizers still
/// report). Only the outermost of nested guards installs; the handlers are process-wide, so no other thread may run
/// OpenCASCADE unguarded meanwhile. See docs/reliability.md, "OpenCASCADE guards".
class OcctSignalGuard {
 public:
  OcctSignalGuard();
  ~OcctSignalGuard();
  OcctSignalGuard(const OcctSignalGuard&) = delete;
  OcctSignalGuard& operator=(const OcctSignalGuard&) = delete;

 private:
  bool outer_ = false;
  int traps_ = 0;                          ///< floating-point exceptions that trapped before
  std::array<struct sigaction, 4> saved_{};  ///< previous handlers of the guarded signals
};

/// Stops OpenCASCADE's progress-aware loops (the transfer, shape healing, BRepMesh) once `seconds` have passed
/// (0 or less: never). UserBreak may be called from OpenCASCADE's worker threads (BRepMesh in parallel).
class DeadlineIndicator : public Message_ProgressIndicator {
 public:
  explicit DeadlineIndicator(double seconds)
      : bounded_(seconds > 0.0),
        deadline_(std::chrono::steady_clock::now() +
                  std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                      std::chrono::duration<double>(bounded_ ? std::min(seconds, kLongestSeconds) : 0.0))) {}
  Standard_Boolean UserBreak() override {
    if (bounded_ && !expired_.load() && std::chrono::steady_clock::now() > deadline_) expired_ = true;
    return expired_.load();
  }
  void Show(const Message_ProgressScope&, const Standard_Boolean) override {}
  [[nodiscard]] bool expired() const { return expired_.load(); }

 private:
  static constexpr double kLongestSeconds = 1e7;  // steady_clock durations must not overflow
  bool bounded_;
  std::chrono::steady_clock::time_point deadline_;
  std::atomic<bool> expired_{false};
};

/// Upper bound on OpenCASCADE's transfer of a file's roots into shapes (shape healing included): a corrupt file can
/// keep the healing busy for minutes; every real file seam has met transfers in a few seconds.
constexpr std::chrono::seconds kTransferTimeLimit{60};

/// Reads a STEP or IGES file into one shape; errors name the file. Roots that fail to transfer, and entities the
/// reader could not load, are counted in `warnings`; without `warnings`, they are kept for the next convertFaces of
/// the same file on this thread (which puts them first in CadImport::warnings). A transfer running past `timeLimit`
/// is an error.
/// The file entity of every face of a transferred shape: labels[i - 1] belongs to faces(i).
struct FaceLabels {
  struct Label {
    std::string entity;  ///< "#1234" (STEP) or "D17" (IGES directory entry), "" when unknown
    std::string name;
  };
  TopTools_IndexedMapOfShape faces;
  std::vector<Label> labels;
};

/// The length unit of a file (issue 17 §2): in, `statedUnitMm` (the user's --units: the file's coordinates are in
/// units of this many mm whatever the header says); out, what the header declares and the scale applied.
struct FileUnits {
  std::optional<double> statedUnitMm;  ///< in: CadReadOptions::statedUnitMm
  CadUnits units;                      ///< out
};

/// With `units`, the header's length unit and precision are read, and a shape whose stated unit differs from the
/// header's is scaled (BRepBuilderAPI_Transform) so that it is in millimetres; `labels` follow the scaled faces.
/// With `document` (newCadDocument), the file is read through OpenCASCADE's XDE readers into it (names, colours and
/// layers kept; the document is not rescaled: only the returned shape is, for a stated unit) and the shape returned
/// is the document's (documentShape).
Result<TopoDS_Shape> readShape(const std::filesystem::path& file, CadFormat format,
                               std::vector<std::string>* warnings = nullptr,
                               std::chrono::seconds timeLimit = kTransferTimeLimit, FaceLabels* labels = nullptr,
                               FileUnits* units = nullptr, const Handle(TDocStd_Document)* document = nullptr);

/// A new, empty XDE document (XCAFApp_Application, format MDTV-XCAF).
Handle(TDocStd_Document) newCadDocument();
/// The shapes of a document's free (top-level) labels: the one shape, or a compound of them; null when none.
TopoDS_Shape documentShape(const Handle(TDocStd_Document)& document);

/// Counts of a shape, all by OpenCASCADE: what a conversion or a repair must keep (issue 34 §1).
struct ShapeCounts {
  int faces = 0, trimmedFaces = 0, wires = 0, edges = 0, freeEdges = 0, shells = 0, solids = 0;
  double area = 0.0;  ///< BRepGProp::SurfaceProperties of each face, summed in face order, in the unit squared
  std::vector<double> faceAreas;  ///< by face, in TopExp::MapShapes order (index 0 = the first face)
};
/// How countShape integrates the area.
struct AreaOptions {
  /// > 0: BRepGProp's adaptive integration to that relative error (the default Gauss rule is off by up to 1e-3
  /// on faces whose pcurves have hundreds of poles on rational patches: linkrods.step from JSON).
  double relEps = 0.0;
  /// Threads over the faces (0: all hardware threads). The sum is taken in face order, so the area does not
  /// depend on the number of threads.
  int threads = 0;
  /// The counts of the same shape before an in-place change (the same faces in the same order): their faces'
  /// areas are taken as they are, except those of `changed` (1-based face indices), which are integrated again.
  const ShapeCounts* known = nullptr;
  const std::set<int>* changed = nullptr;
};
ShapeCounts countShape(const TopoDS_Shape& shape, const AreaOptions& area);
inline ShapeCounts countShape(const TopoDS_Shape& shape, double areaRelEps = 0.0) {
  return countShape(shape, AreaOptions{areaRelEps});
}
/// Copies the counts into a report that has the same members (CadConvertReport, BRepWriteReport).
template <typename Report>
void setCounts(Report& report, const ShapeCounts& c) {
  report.faces = c.faces;
  report.trimmedFaces = c.trimmedFaces;
  report.edges = c.edges;
  report.freeEdges = c.freeEdges;
  report.shells = c.shells;
  report.solids = c.solids;
  report.area = c.area;
}
/// The adaptive integration's relative error for the areas of shapes made from a topology (Model::brep).
inline constexpr double kPreciseAreaRelEps = 1e-9;

/// What writeCadDocument read back from the file it wrote (its verification), for a caller that checks it further.
struct WrittenBack {
  TopoDS_Shape shape;
  FaceLabels labels;
  FileUnits units;
  std::vector<std::string> warnings;
};
/// Writes `document` as STEP (AP214) or IGES (5.3) into `file` atomically, with names, colours and layers,
/// every real with 17 significant digits (surfaces are kept bit for bit), in the length unit `unitName`
/// ("MM", "INCH", "FT", "M", "CM"; the document is in millimetres). What was written is read back and must
/// have the counts `expected` (faces, trimmed faces, solids; area within kKeptAreaRelTol, IGES
/// kKeptAreaRelTolIges): else nothing is written and the error says what OpenCASCADE lost. IGES: B-rep mode
/// (solids) first, else the faces mode, with a line in `notes` saying that the solids are written as their
/// faces. `areaRelTol` > 0 replaces the area tolerance (when it is larger); `areaRelEps` as in countShape,
/// for the area read back; `back`, when given, receives what was read back; `threads` as in AreaOptions.
/// `countReadBack` false leaves out the counts and areas of what was read back for STEP (a file nobody keeps: the
/// heal's baseline); IGES counts them always, to choose between its two modes.
Status writeCadDocument(const Handle(TDocStd_Document) & document, const std::filesystem::path& file,
                        CadFormat format, const std::string& unitName, const ShapeCounts& expected,
                        std::vector<std::string>* notes = nullptr, double areaRelTol = 0.0,
                        double areaRelEps = 0.0, WrittenBack* back = nullptr, int threads = 0,
                        bool countReadBack = true);

/// A written STEP B-rep's area may differ from what was written by this much (relative): surfaces written with 17
/// significant digits come back bit for bit, the trims are rebuilt from the 3-D curves by the reader (occ22470.igs ->
/// STEP: 1.5e-9); a lost or untrimmed face changes the area by far more.
inline constexpr double kKeptAreaRelTol = 1e-8;
/// The same for IGES: OpenCASCADE's IGES reader rebuilds trims from the 3-D curves, which move them by up to the
/// edge tolerances (trj3_s1-al-214.stp: 1e-5 of the area). Face and trimmed-face counts are compared exactly.
inline constexpr double kKeptAreaRelTolIges = 1e-4;

/// The STEP/IGES unit name of a length unit given in millimetres (1 -> "MM", 25.4 -> "INCH", 304.8 -> "FT",
/// 1000 -> "M", 10 -> "CM"); "MM" for anything else.
std::string cadUnitName(double millimetresPerUnit, CadFormat format);
/// The unit a STEP/IGES file's lengths are shown in (issue 38 §1) and where it comes from: --display-units, else the
/// unit --units states, else the header's own (`fileUnit`); nullopt (millimetres, the model's) for a header unit
/// outside kLengthUnits (a micron, a mile) or none.
std::pair<std::optional<LengthUnit>, UnitSource> shownCadUnit(const ToleranceOverrides& overrides,
                                                              const std::string& fileUnit);

/// A seam patch as an OpenCASCADE B-spline surface (knots, control points and weights unchanged).
Handle(Geom_BSplineSurface) toOcctSurface(const BSplineSurface& s);

/// Copies the entity and name of each face (CadFace::faceIndex, 1-based into `faces`) from `labels`.
void applyFaceLabels(CadImport& import, const std::vector<TopoDS_Face>& faces, const FaceLabels& labels);

/// One patch per face, in the given order (faces that fail are skipped with a warning naming them; CadImport::faces
/// stays aligned with the patches, and CadFace::patch is "F<n>" with n the face's 1-based position).
Result<CadImport> convertFaces(const std::filesystem::path& file, const std::vector<TopoDS_Face>& faces,
                               const CadReadOptions& options);

/// Runs task(k) for every k in [0, n) on `threads` threads (0: all hardware threads), each task under its own
/// OCC_CATCH_SIGNALS handler. A failure of a task (an exception, or a signal inside OpenCASCADE turned into one) is
/// kept, and once every task has ended the first in index order is raised here: what the serial loop would raise.
/// Each task may write only its own index's results and must read shared OpenCASCADE objects only.
void forEachOnThreads(int n, int threads, const std::function<void(int)>& task);

}  // namespace seam::occt::detail
