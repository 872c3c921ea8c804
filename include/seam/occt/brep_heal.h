#pragma once
// Healing of a trimmed B-rep (STEP/IGES) that keeps it a B-rep (issue 34 §2): every face, trim loop, edge, shell and
// solid, the names and colours of the file (OpenCASCADE's XDE), the file's unit.
//
// First, a gap of the trims alone (the edge's 3-D curve lies on both surfaces within the tolerance, but the
// pcurves' images are further apart: OpenCASCADE's readers compute pcurves to the edge's tolerance) is closed by
// projecting both pcurves again from the 3-D curve (ShapeFix_Edge): no surface moves, the trims move by at most the
// gap. Then, for every seam (an edge shared by two faces) whose gap lies between the distance tolerance and the merge distance,
// or whose angle lies between the G1 tolerance and the crease angle, one of the two faces is moved: the face whose
// surface is a (non-periodic, unshared) B-spline surface, the one with more control points when both are. Its
// control points in a band along the edge's pcurve move by the least-squares solution of least norm of linear
// conditions sampled along the pcurve (the surface is linear in its control points, rational ones too with the
// weights fixed):
//  * position: S_F(c_F(t)) = the closest point of the partner's boundary image S_G(c_G(s)) (no equal-parameter
//    assumption: s is found by projection);
//  * G1 (seams below the crease angle, `continuity` G1): n_G . S_F,u = n_G . S_F,v = 0 at those points, so that the
//    tangent planes agree; creases keep their angle (n_F . dS_u = n_F . dS_v = 0, the face's own tangent plane along
//    the edge held to first order) and only their gap closes;
//  * every other seam of the face (not healed, or healed before) is held: dS = 0 and n_F . dS_u = n_F . dS_v = 0
//    along it; free edges (the model's own boundary) are not held, so that a kink that reaches them can be removed
//    there too (the least-norm solution moves them as little as the conditions allow).
// Trims stay where they are in parameter space: pcurves are not touched. The 3-D curves of the moved faces' edges
// are rebuilt from a pcurve on a face that did not move (GeomLib::BuildCurve3d), edge tolerances set to what the
// geometry needs (ShapeAnalysis_Edge::CheckSameParameter) and vertex tolerances raised to match
// (BRepLib::UpdateTolerances).
// Never worse: the healed shape is checked again by seam's B-rep check (the pcurve route, certified where it can
// be); a face that makes any of its seams worse (gap or angle grown beyond the tolerance), that folds (its normal
// reverses at a sample inside its trims) or whose area changes by more than kHealFaceAreaRel is put back exactly as
// it was, and the seams say why.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "seam/continuity/seam.h"
#include "seam/core/result.h"
#include "seam/core/tolerances.h"
#include "seam/model/model.h"
#include "seam/occt/brep_check.h"
#include "seam/occt/cad_io.h"

namespace seam::occt {

/// A healed face may change its area by at most this fraction (a larger change is not a repair of a seam).
inline constexpr double kHealFaceAreaRel = 0.02;
/// A healed model read back from what was written may differ in area from the model in memory by this much
/// (relative): the readers rebuild the trims of moved faces from their rebuilt 3-D edge curves, within the distance
/// tolerance (trj3_s1-al-214.stp: 4e-6). Face, trimmed-face and solid counts are compared exactly.
inline constexpr double kHealWrittenAreaRelTol = 1e-5;
/// Points per face side on the grid that looks for folds (normals reversed) inside a moved face's trims.
inline constexpr int kHealFoldGrid = 40;
/// Default merge distance (largest gap closed) of a B-rep heal, mm (the model is read in millimetres whatever the
/// file's unit): 1 mm, the size of a gap CAD repair tools treat as a defect rather than a missing face.
inline constexpr double kDefaultBRepMaxGapMm = 1.0;

struct BRepHealOptions {
  /// Classification tolerances (as `seam check` resolves them: 0.001 mm by default, or a preset).
  ToleranceOverrides tolerances;
  GeometricClass continuity = GeometricClass::kG1;  ///< G0 or G1
  /// Largest gap closed, in the shown unit (the file's own, or tolerances.display: --display-units, issue 38 §1);
  /// default kDefaultBRepMaxGapMm millimetres.
  std::optional<double> maxGap;
  /// Seams whose angle is above this (degrees) are design creases: their gap is closed, their angle kept.
  double creaseAngleDeg = 20.0;
  /// Condition samples per healed or held edge, at least; more where the edge crosses many knot spans.
  int samplesPerEdge = 48;
  /// Threads of the checks (BRepCheckOptions::threads).
  int threads = 0;
};

/// What a heal must keep, counted by OpenCASCADE.
struct BRepCounts {
  int faces = 0, trimmedFaces = 0, edges = 0, solids = 0;
  double area = 0.0;   ///< mm²
  bool valid = false;  ///< BRepCheck_Analyzer
};

/// One seam before and after.
struct BRepHealSeam {
  int edge = 0;                     ///< as `seam check` numbers it
  std::string a, b;                 ///< faces "F<n>", as `seam check` names them
  std::string entityA, entityB;     ///< the faces' entities in the file (#id, D<n>), "" when unknown
  SeamReport before;
  std::optional<SeamReport> after;  ///< absent when the check after did not find the seam
  /// "healed", "crease: gap closed", "left: <reason>", "already G1", "crease kept", "above --max-gap", ...
  std::string action;
  std::string moved;                ///< the face moved, "" when none
  /// How far the moved face moved (mm, BRepFaceMove::sampled of `moved`); 0 when none moved.
  double movedBy = 0.0;
  bool worse = false;               ///< after is worse than before (never in a written output: such faces revert)
  Vec3 midpoint = Vec3::Zero();     ///< the middle point of the edge (pairs the seams of the written file)
};

/// A face the heal moved and kept moved: how far, in mm.
struct BRepFaceMove {
  std::string face;      ///< "F<n>", as `seam check` names it
  double sampled = 0.0;  ///< the largest distance between the surface before and after, at the points of a
                         ///< kHealFoldGrid x kHealFoldGrid grid of the face's (u, v) box inside its trims (measured)
  double bound = 0.0;    ///< the largest control-point move: a bound of the surface's move (convex hull)
};

struct BRepHealReport {
  Tolerances tolerances;
  double maxGap = 0.0;             ///< mm
  double creaseAngleDeg = 20.0;
  GeometricClass requested = GeometricClass::kG1;
  std::string unit;                ///< the file's unit as written ("MM", "INCH", ...)
  /// The model's unit (mm: every length of this report) and the unit its lengths are shown in (ModelUnits::display:
  /// the file's own, or --display-units), as `seam check` of the input has them.
  ModelUnits units;
  std::vector<BRepHealSeam> seams;
  std::vector<std::string> facesChanged;
  std::vector<std::string> facesReverted;  ///< moved, then put back (each with a note saying why)
  /// Largest displacement of a healed surface, mm: max |dP| over its control points, a bound of the surface's
  /// displacement (convex hull, positive weights).
  double maxSurfaceDisplacement = 0.0;
  /// Every face moved and kept moved, in face order, with how far (issue 38 goal 6).
  std::vector<BRepFaceMove> faceMoves;
  int seamsToHeal = 0, seamsHealed = 0, seamsWorse = 0, creasesKept = 0;
  /// Edges whose trims alone had a gap (their 3-D curve on both surfaces): their pcurves were projected again.
  int trimsReprojected = 0;
  BRepCounts before, after;        ///< the model as read and as written
  int freeEdges = 0;               ///< edges bounding one face (not healed: the file's topology is kept)
  std::vector<std::string> notes;
  std::vector<std::string> warnings;
  bool achieved = false;           ///< every seam to heal reached the request
};

/// Reads `in` (STEP/IGES), heals it and writes `out` (STEP/IGES, atomically; read back and compared: counts, area,
/// and every seam of the file read back checked again against the input's, paired by edge midpoints; when one is
/// worse, the input is written unchanged instead and the report says why). Errors name the file; a model the heal
/// would make invalid (BRepCheck_Analyzer) where the input was valid is an error and nothing is written.
Result<BRepHealReport> healBRepFile(const std::filesystem::path& in, const std::filesystem::path& out,
                                    const BRepHealOptions& options = {});

/// The B-rep heal of a model that holds its B-rep (Model::brep: a JSON model with "brep", a model read from STEP or
/// IGES, or one healed before): the model written as `format` to a temporary file (writeCadFile: every face, trim,
/// edge and solid), healed by healBRepFile into another, and read back (readCadFile). Both temporary files are
/// removed; messages, warnings and notes name `source` instead (and "`source` (healed)"), faces keep the model's
/// patch names (when every face read back matches its patch in degrees and control-point counts; else F<n> with a
/// warning) and the seams carry no file entities. The coordinates are taken as millimetres, as seam's JSON of a
/// STEP/IGES file holds them.
struct BRepModelHeal {
  BRepHealReport report;
  Model model;  ///< the healed model, with its B-rep
};
Result<BRepModelHeal> healBRepModel(const Model& model, const std::string& source, CadFormat format = CadFormat::kStep,
                                    const BRepHealOptions& options = {});

}  // namespace seam::occt
