// seam's B-rep check against OpenCASCADE's own read + sew + EncodeRegularity, file by file (issue 16 goal 6).
//
// The OpenCASCADE side does the job the way an OpenCASCADE user would: STEPControl_Reader / IGESControl_Reader
// (ReadFile, TransferRoots, OneShape), then, as seam's checkBRepFile does, BRepBuilderAPI_Sewing with 1e-4 x the
// bounding-box diagonal when the shape has more than one face and free edges, then BRepLib::EncodeRegularity(shape,
// angle) with seam's default angle tolerance (0.01 degrees). The seam side is `checkBRepFile(file)` with default
// options (read, the same sewing, conversion of every face to an exact patch, one certified check per shared edge,
// OpenCASCADE's ContinuityOfFaces alongside). Both run in this process, interleaved (reference, seam, reference,
// seam, ...), so the shared libraries are loaded once and both see the same load; the table gives the best CPU time
// (user + sys of the process, getrusage) and the best wall time of each over the repetitions.
//
//   build-dir/bench/occt_brep_reference [--reps N] [FILE...]   (default: the 8 STEP/IGES files of ../shared/data)
//   build-dir/bench/occt_brep_reference --occt-only FILE       (one reference run: for /usr/bin/time, whole process)
//   build-dir/bench/occt_brep_reference --max-certified-degree N [FILE...]
//       seam's side with SeamOptions::maxCertifiedDegree = N instead of kBRepMaxCertifiedDegree (256 gives the limit
//       the B-rep check had before 2026-12-01: what certifying the composed pcurves up to degree 1000 costs)
//   build-dir/bench/occt_brep_reference --trimmed-grid N [FILE...]
//       also the generated model of issue 37 goal 2: N x N trimmed B-spline faces, each on its own bicubic surface
//       (a segment of one wavy 100 mm height field, a quarter of a face wider on every side than its trim), sewn,
//       2 N (N - 1) seams (N = 43: 1 849 faces, 3 612 seams), written as STEP into the temporary folder first.
//
// Not a Google Benchmark: each run takes 0.1-5 s and the point is the per-file table. Never run as a test.
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepLib.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <Geom_BSplineSurface.hxx>
#include <IGESControl_Controller.hxx>
#include <IGESControl_Reader.hxx>
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Precision.hxx>
#include <STEPControl_Reader.hxx>
#include <STEPControl_Writer.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>

#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include "seam/core/tolerances.h"
#include "seam/occt/brep_check.h"

namespace fs = std::filesystem;

namespace {

struct Times {
  double cpu = 0.0, wall = 0.0;
};

double processCpu() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

template <class F>
Times timed(F&& f) {
  const double c0 = processCpu();
  const auto w0 = std::chrono::steady_clock::now();
  f();
  const auto w1 = std::chrono::steady_clock::now();
  return {processCpu() - c0, std::chrono::duration<double>(w1 - w0).count()};
}

bool isStep(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e == ".step" || e == ".stp";
}

int freeEdges(const TopoDS_Shape& s) {  // as seam's countFreeEdges (brep_check.cpp)
  TopTools_IndexedDataMapOfShapeListOfShape m;
  TopExp::MapShapesAndAncestors(s, TopAbs_EDGE, TopAbs_FACE, m);
  int n = 0;
  for (int i = 1; i <= m.Extent(); ++i)
    if (m.FindFromIndex(i).Extent() == 1 && !BRep_Tool::Degenerated(TopoDS::Edge(m.FindKey(i))) &&
        !BRep_Tool::IsClosed(TopoDS::Edge(m.FindKey(i)), TopoDS::Face(m.FindFromIndex(i).First())))
      ++n;
  return n;
}

struct Reference {
  int faces = 0, edges = 0, regular = 0;
  bool sewn = false;
};

/// Read + (sew) + EncodeRegularity: what an OpenCASCADE user runs to get every edge's regularity.
Reference occtReference(const fs::path& file) {
  Reference r;
  std::unique_ptr<XSControl_Reader> reader;
  if (isStep(file)) {
    reader = std::make_unique<STEPControl_Reader>();
  } else {
    IGESControl_Controller::Init();
    reader = std::make_unique<IGESControl_Reader>();
  }
  if (reader->ReadFile(file.c_str()) != IFSelect_RetDone) {
    std::fprintf(stderr, "%s: not readable\n", file.c_str());
    std::exit(2);
  }
  reader->TransferRoots();
  TopoDS_Shape shape = reader->OneShape();
  Bnd_Box box;
  BRepBndLib::Add(shape, box);
  const double diag = box.IsVoid() ? 1.0 : std::sqrt(box.SquareExtent());
  TopTools_IndexedMapOfShape faces;
  TopExp::MapShapes(shape, TopAbs_FACE, faces);
  if (faces.Extent() > 1 && freeEdges(shape) > 0) {
    BRepBuilderAPI_Sewing sewing(seam::occt::BRepCheckOptions{}.sewingRelTol * diag);
    sewing.Add(shape);
    sewing.Perform();
    if (!sewing.SewedShape().IsNull()) {
      shape = sewing.SewedShape();
      r.sewn = true;
    }
  }
  BRepLib::EncodeRegularity(shape, seam::Tolerances{}.angleDeg * std::numbers::pi / 180.0);
  TopTools_IndexedDataMapOfShapeListOfShape edgeFaces;
  TopExp::MapShapesAndAncestors(shape, TopAbs_EDGE, TopAbs_FACE, edgeFaces);
  TopTools_IndexedMapOfShape sewnFaces;
  TopExp::MapShapes(shape, TopAbs_FACE, sewnFaces);
  r.faces = sewnFaces.Extent();
  r.edges = edgeFaces.Extent();
  for (int i = 1; i <= edgeFaces.Extent(); ++i) {
    const TopTools_ListOfShape& around = edgeFaces.FindFromIndex(i);
    if (around.Extent() == 2 &&
        BRep_Tool::HasContinuity(TopoDS::Edge(edgeFaces.FindKey(i)), TopoDS::Face(around.First()),
                                 TopoDS::Face(around.Last())) &&
        BRep_Tool::Continuity(TopoDS::Edge(edgeFaces.FindKey(i)), TopoDS::Face(around.First()),
                              TopoDS::Face(around.Last())) != GeomAbs_C0)
      ++r.regular;
  }
  return r;
}

/// The --trimmed-grid model (above), written as STEP to `file`.
void writeTrimmedGrid(int n, const fs::path& file) {
  constexpr int kPoles = 48;  // of the parent height field, per direction
  constexpr double kSize = 100.0, kAmplitude = 6.0;
  TColgp_Array2OfPnt poles(1, kPoles, 1, kPoles);
  for (int i = 1; i <= kPoles; ++i)
    for (int j = 1; j <= kPoles; ++j) {
      const double x = kSize * (i - 1) / (kPoles - 1), y = kSize * (j - 1) / (kPoles - 1);
      poles(i, j) = gp_Pnt(x, y, kAmplitude * std::sin(0.13 * x) * std::cos(0.09 * y) + 0.02 * x);
    }
  TColStd_Array1OfReal knots(1, kPoles - 2);
  TColStd_Array1OfInteger mults(1, kPoles - 2);
  for (int k = 1; k <= kPoles - 2; ++k) {
    knots(k) = static_cast<double>(k - 1) / (kPoles - 3);
    mults(k) = k == 1 || k == kPoles - 2 ? 4 : 1;
  }
  const Handle(Geom_BSplineSurface) parent = new Geom_BSplineSurface(poles, knots, knots, mults, mults, 3, 3);
  BRepBuilderAPI_Sewing sewing(1e-6 * kSize);
  const double h = 1.0 / n, margin = 0.25 * h;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const double u0 = i * h, u1 = (i + 1) * h, v0 = j * h, v1 = (j + 1) * h;
      const Handle(Geom_BSplineSurface) own = Handle(Geom_BSplineSurface)::DownCast(parent->Copy());
      own->Segment(std::max(0.0, u0 - margin), std::min(1.0, u1 + margin), std::max(0.0, v0 - margin),
                   std::min(1.0, v1 + margin));
      sewing.Add(BRepBuilderAPI_MakeFace(own, u0, u1, v0, v1, Precision::Confusion()).Face());
    }
  sewing.Perform();
  STEPControl_Writer writer;
  if (writer.Transfer(sewing.SewedShape(), STEPControl_AsIs) != IFSelect_RetDone ||
      writer.Write(file.c_str()) != IFSelect_RetDone) {
    std::fprintf(stderr, "%s: not written\n", file.c_str());
    std::exit(2);
  }
}

}  // namespace

int main(int argc, char** argv) {
  Message::DefaultMessenger()->RemovePrinters(STANDARD_TYPE(Message_Printer));
  int reps = 3;
  std::vector<fs::path> files;
  bool occtOnly = false;
  int trimmedGrid = 0;
  seam::occt::BRepCheckOptions options;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--reps" && i + 1 < argc) {
      reps = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--occt-only") {
      occtOnly = true;
    } else if (a == "--max-certified-degree" && i + 1 < argc) {
      options.seam.maxCertifiedDegree = std::max(1, std::atoi(argv[++i]));
    } else if (a == "--trimmed-grid" && i + 1 < argc) {
      trimmedGrid = std::max(2, std::atoi(argv[++i]));
    } else {
      files.emplace_back(a);
    }
  }
  if (files.empty()) {
    const fs::path data = fs::path(SEAM_SOURCE_DIR) / ".." / "shared" / "data";
    for (const char* f : {"step/boxed_sphere.step", "step/bug28366_fuselage.stp", "step/linkrods.step",
                          "step/trj3_s1-al-214.stp", "iges/BUC50025.igs", "iges/bearing.iges", "iges/occ22470.igs",
                          "iges/sunglasses_lens.igs"})
      files.push_back(data / f);
  }
  if (trimmedGrid > 0) {
    const fs::path grid = fs::temp_directory_path() / ("seam_trimmed_grid_" + std::to_string(trimmedGrid) + ".step");
    writeTrimmedGrid(trimmedGrid, grid);
    files.insert(files.begin(), grid);
  }
  if (occtOnly) {
    for (const fs::path& f : files) {
      const Reference r = occtReference(f);
      std::printf("%s: %d faces, %d edges, %d regular%s\n", f.filename().c_str(), r.faces, r.edges, r.regular,
                  r.sewn ? " (sewn)" : "");
    }
    return 0;
  }
  std::printf("%-26s %6s %6s | %9s %9s | %9s %9s | %6s %6s | %s | %s\n", "file", "faces", "seams", "OCCT cpu",
              "wall", "seam cpu", "wall", "cpu x", "wall x", "OCCT regular / seam G1+", "certified");
  for (const fs::path& f : files) {
    Times bestRef{std::numeric_limits<double>::max(), std::numeric_limits<double>::max()}, bestSeam = bestRef;
    Reference ref;
    int seams = 0, smooth = 0, certified = 0;
    for (int k = 0; k < reps; ++k) {
      const Times tr = timed([&] { ref = occtReference(f); });
      bool ok = true;
      const Times ts = timed([&] {
        auto r = seam::occt::checkBRepFile(f, options);
        ok = static_cast<bool>(r);
        if (ok) {
          seams = static_cast<int>(r->seams.size());
          certified = r->certifiedSeams;
          smooth = r->geometric[2] + r->geometric[3];
        }
      });
      if (!ok) {
        std::fprintf(stderr, "%s: seam's check failed\n", f.c_str());
        return 2;
      }
      bestRef = {std::min(bestRef.cpu, tr.cpu), std::min(bestRef.wall, tr.wall)};
      bestSeam = {std::min(bestSeam.cpu, ts.cpu), std::min(bestSeam.wall, ts.wall)};
    }
    std::printf("%-26s %6d %6d | %8.3fs %8.3fs | %8.3fs %8.3fs | %6.2f %6.2f | %d / %d | %d\n",
                f.filename().c_str(), ref.faces, seams, bestRef.cpu, bestRef.wall, bestSeam.cpu, bestSeam.wall,
                bestSeam.cpu / bestRef.cpu, bestSeam.wall / bestRef.wall, ref.regular, smooth, certified);
    std::fflush(stdout);
  }
  return 0;
}
