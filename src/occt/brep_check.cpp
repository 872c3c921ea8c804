// OCC_CATCH_SIGNALS converts a signal raised inside OpenCASCADE into a Standard_Failure only when this macro is set
// (as in cad_io.cpp; see docs/reliability.md, "OpenCASCADE guards").
#ifndef OCC_CONVERT_SIGNALS
#define OCC_CONVERT_SIGNALS
#endif
#include "seam/occt/brep_check.h"

#include <fmt/format.h>

#include <BRepAdaptor_Curve.hxx>
#include <BRepBndLib.hxx>
#include <BRepBuilderAPI_Sewing.hxx>
#include <BRepLib.hxx>
#include <BRepTools.hxx>
#include <BRep_Tool.hxx>
#include <Bnd_Box.hxx>
#include <Geom2dConvert.hxx>
#include <Geom2dAdaptor_Curve.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <Geom2d_BSplineCurve.hxx>
#include <Geom2d_Curve.hxx>
#include <Geom2d_TrimmedCurve.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Geom_Surface.hxx>
#include <OSD_Signal.hxx>
#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_DataMapOfShapeInteger.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <algorithm>
#include <chrono>
#include <array>
#include <bit>
#include <cstdint>
#include <cmath>
#include <exception>
#include <map>
#include <memory>
#include <mutex>
#include <numbers>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <tbb/task_group.h>

#include "continuity/sampling.h"
#include "occt/brep_check_internal.h"
#include "occt/brep_edge.h"
#include "occt/brep_model.h"
#include "occt/cad_internal.h"
#include "occt/face_mesh.h"
#include "occt/pcurve_correspondence.h"

namespace seam::occt {

namespace fs = std::filesystem;

namespace {

/// True when the failure is a signal caught inside OpenCASCADE (a crash, converted by detail::OcctSignalGuard).
using detail::isSignal;

int countFreeEdges(const TopoDS_Shape& s) {
  TopTools_IndexedDataMapOfShapeListOfShape m;
  TopExp::MapShapesAndAncestors(s, TopAbs_EDGE, TopAbs_FACE, m);
  int n = 0;
  for (int i = 1; i <= m.Extent(); ++i)
    if (m.FindFromIndex(i).Extent() == 1 && !BRep_Tool::Degenerated(TopoDS::Edge(m.FindKey(i))) &&
        !BRep_Tool::IsClosed(TopoDS::Edge(m.FindKey(i)), TopoDS::Face(m.FindFromIndex(i).First())))
      ++n;
  return n;
}

}  // namespace

Result<BRepCheckReport> checkBRepFile(const fs::path& file, const BRepCheckOptions& options) {
  const std::optional<CadFormat> format = cadFormatOf(file);
  if (!format)
    return invalidInput(fmt::format("{}: not a STEP (.step/.stp) or IGES (.iges/.igs) file name", file.string()));
  std::vector<std::string> readWarnings;
  detail::FaceLabels labels;
  detail::FileUnits units;
  units.statedUnitMm = options.read.statedUnitMm;
  if (options.tolerances.units) units.statedUnitMm = lengthUnitInfo(*options.tolerances.units).millimetres;
  Result<TopoDS_Shape> read =
      detail::readShape(file, *format, &readWarnings, detail::kTransferTimeLimit, &labels, &units);
  if (!read) return read.status();
  return detail::checkBRepShape(*read, file, std::move(labels), units, readWarnings, options);
}

namespace detail {

Result<BRepCheckReport> checkBRepShape(const TopoDS_Shape& input, const fs::path& file, FaceLabels labels,
                                       const FileUnits& units, const std::vector<std::string>& readWarnings,
                                       const BRepCheckOptions& options, const EdgeFilter& onlyEdges) {
  const auto started = std::chrono::steady_clock::now();  // the view's meshing budget scales with the check's time
  BRepCheckReport out;
  // Every OpenCASCADE call of the check (bounding box, sewing, BRepLib::ContinuityOfFaces, pcurves, evaluation of
  // the faces' surfaces) runs under the guard: a signal inside it comes back as a Standard_Failure of kind
  // OSD_Signal and ends the check with an error (the state a crash leaves is not trusted); any other
  // Standard_Failure on one edge leaves that edge "not analysed", with a warning, and the check goes on.
  detail::OcctSignalGuard guard;
  try {
    OCC_CATCH_SIGNALS
    TopoDS_Shape shape = input;
    Bnd_Box box;
    BRepBndLib::Add(shape, box);
    const double diag = box.IsVoid() ? 1.0 : std::sqrt(box.SquareExtent());
    TopTools_IndexedMapOfShape faceMap;
    TopExp::MapShapes(shape, TopAbs_FACE, faceMap);
    // The solid of each face of the input (1-based, TopExp::MapShapes order; for the overlap search's pairs),
    // carried over to the sewn faces below: the sewn shape has no solids.
    TopTools_DataMapOfShapeInteger solidOfFace;
    {
      TopTools_IndexedMapOfShape solids;
      TopExp::MapShapes(input, TopAbs_SOLID, solids);
      for (int k = 1; k <= solids.Extent(); ++k)
        for (TopExp_Explorer ex(solids(k), TopAbs_FACE); ex.More(); ex.Next())
          if (!solidOfFace.IsBound(ex.Current())) solidOfFace.Bind(ex.Current(), k);
    }
    if (options.sewFreeEdges && faceMap.Extent() > 1 && countFreeEdges(shape) > 0) {
      BRepBuilderAPI_Sewing sewing(options.sewingRelTol * diag);
      sewing.Add(shape);
      sewing.Perform();
      if (!sewing.SewedShape().IsNull()) {
        shape = sewing.SewedShape();
        out.sewn = true;
        // The sewn faces keep the entities of the faces they were made from. The faces are sub-shapes of what was
        // added (the file's one shape): their history is ModifiedSubShape; Modified knows only the added shape
        // itself, and missed every face sewing rebuilt (issue 17 §3: all of bearing.iges, the fuselage, ...).
        detail::FaceLabels sewn;
        for (int i = 1; i <= labels.faces.Extent(); ++i) {
          const TopoDS_Shape& original = labels.faces(i);
          const TopoDS_Shape now =
              sewing.IsModifiedSubShape(original) ? sewing.ModifiedSubShape(original) : original;
          if (!sewn.faces.Contains(now)) {
            sewn.faces.Add(now);
            sewn.labels.push_back(labels.labels[static_cast<size_t>(i - 1)]);
          }
        }
        labels = std::move(sewn);
        TopTools_DataMapOfShapeInteger sewnSolid;
        for (TopTools_DataMapIteratorOfDataMapOfShapeInteger it(solidOfFace); it.More(); it.Next()) {
          const TopoDS_Shape& original = it.Key();
          const TopoDS_Shape now =
              sewing.IsModifiedSubShape(original) ? sewing.ModifiedSubShape(original) : original;
          if (!sewnSolid.IsBound(now)) sewnSolid.Bind(now, it.Value());
        }
        solidOfFace.Exchange(sewnSolid);
      }
      faceMap.Clear();
      TopExp::MapShapes(shape, TopAbs_FACE, faceMap);
    }
    std::vector<TopoDS_Face> faces;
    for (int i = 1; i <= faceMap.Extent(); ++i) faces.push_back(TopoDS::Face(faceMap(i)));
    Result<CadImport> imported = detail::convertFaces(file, faces, options.read);
    if (!imported) return imported.status();
    out.import = std::move(imported).value();
    detail::applyFaceLabels(out.import, faces, labels);
    out.import.warnings.insert(out.import.warnings.begin(), readWarnings.begin(), readWarnings.end());
    std::map<int, size_t> patchOfFace;  // 1-based face index -> patch index
    for (size_t k = 0; k < out.import.faces.size(); ++k) patchOfFace[out.import.faces[k].faceIndex] = k;
    out.import.units = units.units;
    out.units = cadModelUnits(out.import, options.tolerances);
    const ResolvedTolerances resolved =
        resolveTolerances(options.tolerances, out.units, out.import.model.boundingBox().diagonal());
    out.tolerances = resolved.tolerances;
    out.distanceSource = resolved.distanceSource;
    out.angleSource = resolved.angleSource;
    SeamOptions seamOpt = options.seam;
    seamOpt.tol = out.tolerances;
    const double size = out.import.model.boundingBox().diagonal();
    const SpansCache spansCache(out.import.model.patches);
    const FaceBoxCache faceBoxes(faceMap);

    TopTools_IndexedDataMapOfShapeListOfShape edgeFaces;
    TopExp::MapShapesAndAncestors(shape, TopAbs_EDGE, TopAbs_FACE, edgeFaces);
    const EdgeCheckContext edgeContext{file,    faceMap, edgeFaces,       onlyEdges, out.import, patchOfFace,
                                       out.tolerances, seamOpt, size, options.threads, faceBoxes, spansCache};
    const int nEdges = edgeFaces.Extent(), nFaces = faceMap.Extent();
    // The edges in blocks of kProgressEdgeStep: each block on options.threads threads, then merged in edge order
    // (the report does not depend on the number of threads) and reported to the progress callback on this thread.
    if (options.progress) options.progress(nFaces, 0, nEdges);
    tbb::task_arena arena(options.threads > 0 ? options.threads : tbb::task_arena::automatic);
    std::vector<EdgeOutcome> block;
    for (int first = 1; first <= nEdges; first += kProgressEdgeStep) {
      if (options.progress && first > 1) options.progress(nFaces, first - 1, nEdges);
      const int n = std::min(kProgressEdgeStep, nEdges - first + 1);
      block.assign(static_cast<size_t>(n), EdgeOutcome{});
      if (options.threads == 1) {
        // In the one-thread arena: the nested parallel loops of an edge (certifyPCurveSeam's leaves) run here too.
        arena.execute([&] {
          for (int k = 0; k < n; ++k) block[static_cast<size_t>(k)] = analyseEdge(edgeContext, first + k);
        });
      } else {
        arena.execute([&] {
          tbb::parallel_for(0, n, [&](int k) { block[static_cast<size_t>(k)] = analyseEdge(edgeContext, first + k); });
        });
      }
      for (EdgeOutcome& o : block) {
        switch (o.kind) {
          case EdgeOutcome::kNone: break;
          case EdgeOutcome::kDegenerate: ++out.degenerateEdges; break;
          case EdgeOutcome::kLoose: ++out.looseEdges; break;
          case EdgeOutcome::kNonManifold: out.nonManifoldEdges.push_back(std::move(o.nonManifold)); break;
          case EdgeOutcome::kFree: out.freeEdges.push_back(std::move(o.free)); break;
          case EdgeOutcome::kSeam: out.seams.push_back(std::move(o.seam)); break;
          case EdgeOutcome::kUnanalysed:
            out.import.warnings.push_back(std::move(o.warning));
            ++out.unanalysedEdges;
            break;
        }
      }
    }
    if (options.progress) options.progress(nFaces, nEdges, nEdges);
    if (options.findOverlaps && !onlyEdges) {  // faces lying on each other, inside their trims (issue 38 §11)
      OverlapOptions oo = options.overlap;
      oo.threads = options.threads;
      detail::BRepOverlapSearch found = detail::findBRepOverlaps(faceMap, out.tolerances.distance, oo);
      out.overlaps = std::move(found.overlaps);
      out.overlapFacesSkipped = found.skippedFaces;
      out.overlapsSearched = true;
      auto solidOf = [&](int face) {
        const TopoDS_Shape& f = faceMap(face + 1);
        return solidOfFace.IsBound(f) ? solidOfFace.Find(f) : 0;
      };
      for (const FaceOverlap& o : out.overlaps) out.overlapSolids.emplace_back(solidOf(o.a), solidOf(o.b));
    }
    if (options.meshFaces) {
      // The view's meshes: kFaceMeshDeflectionRel x the diagonal, doubled (after removing the triangulation) while
      // the meshes exceed the vertex budget, at most kFaceMeshCoarsenings times.
      std::vector<bool> wanted;
      if (options.meshTrimmedOnly)
        for (const CadFace& f : out.import.faces) {
          if (f.faceIndex < 1) continue;  // 1-based; 0 = not traced to a face of the file
          if (wanted.size() < static_cast<size_t>(f.faceIndex)) wanted.resize(static_cast<size_t>(f.faceIndex), false);
          wanted[static_cast<size_t>(f.faceIndex - 1)] = f.trimmed;
        }
      out.meshDeflection = options.meshDeflectionRel * diag;
      const double checkSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
      const double budget = options.meshBudgetFactor > 0.0
                                ? std::max(options.meshBudgetMinSeconds, options.meshBudgetFactor * checkSeconds)
                                : 0.0;
      const Handle(detail::DeadlineIndicator) deadline = new detail::DeadlineIndicator(budget);  // over all attempts
      for (int attempt = 0;; ++attempt) {
        out.faceMeshes = detail::meshFaces(shape, faces, out.meshDeflection, wanted, deadline);
        if (deadline->expired()) {
          out.meshStoppedAfterSeconds = budget;
          break;
        }
        size_t vertices = 0;
        for (const BRepFaceMesh& m : out.faceMeshes) vertices += m.points.size();
        if (options.meshVertexBudget <= 0 || vertices <= static_cast<size_t>(options.meshVertexBudget) ||
            attempt == kFaceMeshCoarsenings)
          break;
        BRepTools::Clean(shape);
        out.meshDeflection *= 2.0;
      }
    }
  } catch (const Standard_Failure& f) {
    return Status(ErrorCode::kInvalidInput,
                  fmt::format("{}: OpenCASCADE {} during the B-rep check: {}", file.string(),
                              isSignal(f) ? detail::kCrashedOnTheModel : "failed", f.GetMessageString()));
  }
  for (const BRepSeam& s : out.seams) {
    ++out.geometric[static_cast<size_t>(s.report.geometric)];
    out.worstGeometric = std::min(out.worstGeometric, s.report.geometric);
    if (s.report.certified) ++out.certifiedSeams;
    const bool seamSmooth = s.report.geometric >= GeometricClass::kG1;
    const bool occtSmooth = s.occtContinuity != "C0" && s.occtContinuity != "?";
    if (seamSmooth == occtSmooth) ++out.occtAgreement;
  }
  return out;
}

std::string seamWorseThan(const SeamReport& after, const SeamReport& before, const Tolerances& tol, double creaseDeg,
                          const ModelUnits& units) {
  const double gapLimit = std::max(before.g0Max, tol.distance) + kWorseSlackRel * tol.distance;
  const std::optional<LengthUnit> shown = units.shownUnit();
  const std::string unit = shown ? std::string(" ") + lengthUnitInfo(*shown).name : std::string();
  // Angles are judged on seam's strict scale whatever the verdict's tolerance: with the CAD default (0.5 deg) a kink
  // of 0.62 deg could otherwise grow to 0.66 and a 0.1-degree seam to 0.5 without counting as worse.
  const double strict = tol.strictAngleDeg();
  if (after.g0Max > gapLimit)
    return fmt::format("its gap would grow from {:.3g} to {:.3g}{}", before.g0Max * units.displayScale(),
                       after.g0Max * units.displayScale(), unit);
  if (before.g1MaxDeg > creaseDeg) {
    if (std::abs(after.g1MaxDeg - before.g1MaxDeg) > strict)
      return fmt::format("its crease angle would change from {:.4g} to {:.4g} deg", before.g1MaxDeg, after.g1MaxDeg);
    return {};
  }
  const double angleLimit = std::max(before.g1MaxDeg, strict) + kWorseSlackRel * strict;
  if (after.g1MaxDeg > angleLimit)
    return fmt::format("its angle would grow from {:.3g} to {:.3g} deg", before.g1MaxDeg, after.g1MaxDeg);
  return {};
}

std::vector<SeamWorse> seamsWorse(const std::vector<BRepSeam>& before, const std::vector<BRepSeam>& after,
                                  const Tolerances& tol, double creaseDeg, const ModelUnits& units) {
  std::vector<SeamWorse> worse;
  for (const BRepSeam& s : after) {
    if (s.curve.empty()) continue;
    SeamWorse w;
    for (const BRepSeam* b : nearestSeams(before, seamMidpoint(s), tol.distance, seamMidpoint)) {
      std::string why = seamWorseThan(s.report, b->report, tol, creaseDeg, units);
      if (why.empty()) {
        w.before = nullptr;
        break;
      }
      if (w.before == nullptr) w = {b, &s, std::move(why)};
    }
    if (w.before != nullptr) worse.push_back(std::move(w));
  }
  return worse;
}

}  // namespace detail

/// Here rather than in brep_model.cpp: the model's B-rep is built there (detail::shapeFromBRep), checked here, so
/// that brep_model.cpp needs no part of the check (the CAD fuzz harnesses link it alone).
Result<BRepCheckReport> checkBRepModel(const Model& model, const fs::path& file,
                                       const BRepCheckOptions& options) {
  Result<TopoDS_Shape> shape = detail::shapeFromBRep(model, file.string());
  if (!shape) return shape.status();
  detail::FileUnits units;
  units.units.fileUnit = "";
  units.units.millimetresPerFileUnit = 1.0;
  return detail::checkBRepShape(*shape, file, detail::FaceLabels{}, units, {}, options);
}

void scaleLengths(BRepCheckReport& r, double scale) {
  r.tolerances.distance *= scale;
  for (BRepSeam& s : r.seams) {
    scaleLengths(s.report, scale);
    for (Vec3& p : s.curve) p *= scale;
  }
  for (BRepFreeEdge& f : r.freeEdges) {
    f.midpoint *= scale;
    for (Vec3& p : f.curve) p *= scale;
  }
  for (BRepNonManifoldEdge& e : r.nonManifoldEdges) e.midpoint *= scale;
  for (FaceOverlap& o : r.overlaps) {
    o.maxDistance *= scale;
    o.point *= scale;
  }
  for (BRepFaceMesh& m : r.faceMeshes)
    for (Vec3& p : m.points) p *= scale;
  r.meshDeflection *= scale;
}

void toShownUnits(BRepCheckReport& r) {
  const double scale = r.units.displayScale();
  if (scale != 1.0) scaleLengths(r, scale);
  r.units = r.units.shown();
}

}  // namespace seam::occt
