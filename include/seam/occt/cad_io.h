#pragma once
// STEP and IGES import/export through OpenCASCADE (target seam::occt, built with SEAM_WITH_OCCT=ON).
//
// Import: every face of the file becomes a (rational) B-spline patch. B-spline faces keep their control points,
// weights and knots exactly; Bezier and analytic faces (planes, cylinders, cones, spheres, tori, surfaces of
// revolution and extrusion, offsets) are converted exactly where OpenCASCADE can (GeomConvert), else approximated
// (GeomConvert_ApproxSurface) and the achieved error is reported. A face bounded by its natural edges (one wire of
// iso-parameter edges on its parameter box) becomes a plain patch; a trimmed face becomes the patch of its
// parameter box and is flagged `trimmed` (its trimming loop is listed in CadFace; seam analyses its patch edges).
// Files holding bare surfaces without faces (a STEP file of B_SPLINE_SURFACE_WITH_KNOTS only) are read too.
// Coordinates are in millimetres (OpenCASCADE's unit conversion on read and write): a file in inches has its
// coordinates multiplied by 25.4. The unit the file declares and its declared precision are kept (CadUnits).
//
// Export: B-spline faces (one per patch, knots and control points unchanged) sewn into a shell with the
// distance tolerance, written as STEP (AP214) or IGES (5.3, B-rep mode); written atomically. A model with trimmed
// faces (Model::trimmedFaces) is refused: its patches are the faces' parameter boxes. STEP/IGES -> STEP/IGES goes
// through convertCadFile instead, which keeps the B-rep.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "seam/core/result.h"
#include "seam/core/tolerances.h"
#include "seam/core/units.h"
#include "seam/continuity/verdict.h"
#include "seam/model/model.h"

namespace seam::occt {

enum class CadFormat { kStep, kIges };

/// The CAD format named by a file extension (.step/.stp/.iges/.igs, any case), or nullopt.
std::optional<CadFormat> cadFormatOf(const std::filesystem::path& file);

struct CadReadOptions {
  /// Tolerance of approximations for faces OpenCASCADE cannot convert exactly, relative to the model's
  /// bounding-box diagonal (1e-6, the default distance tolerance of `seam check`).
  double approximationRelTol = 1e-6;
  /// The unit of the file's coordinates in millimetres, when the user states it (`--units`): it replaces the unit
  /// of the file's header (a file whose header says MM but whose numbers are metres: statedUnitMm = 1000), and the
  /// model is rescaled to millimetres accordingly. nullopt: the header's unit.
  std::optional<double> statedUnitMm;
};

/// The length unit of a STEP/IGES file (issue 17 §2).
struct CadUnits {
  /// The length unit as the file names it: STEP, the name OpenCASCADE's STEPControl_Reader::FileUnits gives
  /// ("MM", "INCH", "FOOT", "CM", "M", ...); IGES, global parameter 15 ("MM", "IN", ...). "" when the file names
  /// none.
  std::string fileUnit;
  /// What OpenCASCADE multiplied the file's coordinates by to get millimetres (25.4 for inches).
  double millimetresPerFileUnit = 1.0;
  /// The factor seam applied on top of it for CadReadOptions::statedUnitMm (statedUnitMm / millimetresPerFileUnit;
  /// 1 without it).
  double statedScale = 1.0;
  /// The precision the file declares, in millimetres (scaled like the coordinates): STEP, the length
  /// UNCERTAINTY_MEASURE_WITH_UNIT of its representation context; IGES, global parameter 19 (minimum
  /// user-intended resolution). nullopt when the file declares none (or a non-positive value).
  std::optional<double> declaredResolutionMm;
};

/// What the reader did with one face.
struct CadFace {
  std::string patch;            ///< name of the patch made from it ("F<n>", 1-based in file order)
  int faceIndex = 0;            ///< n: the face's 1-based position in the file (faces that fail are skipped)
  std::string surfaceType;      ///< OpenCASCADE surface type before conversion (e.g. "Geom_BSplineSurface")
  bool exact = true;            ///< false: approximated, see approximationError
  double approximationError = 0.0;
  bool trimmed = false;         ///< not bounded by its natural (iso-parameter) edges
  bool reversed = false;        ///< face orientation reversed with respect to its surface normal
  int wires = 0;                ///< number of boundary loops (1 outer + holes)
  int edges = 0;                ///< edges on the outer loop
  /// The face's entity in the file (issue 17 §3): "#1234" (STEP instance id) or "D17" (IGES directory entry
  /// number); "" when OpenCASCADE cannot trace the face back to one.
  std::string entity;
  std::string entityName;       ///< the entity's name in the file ("" when it has none)
};

struct CadImport {
  Model model;
  std::vector<CadFace> faces;  ///< one per patch, same order
  std::vector<std::string> warnings;
  CadUnits units;              ///< the file's length unit and declared precision; the model is in millimetres
};

/// The length unit of an imported model: millimetres, with the file's unit name and declared precision; the
/// source is --units when `overrides.units` states the coordinates' unit, else the file header.
ModelUnits cadModelUnits(const CadImport& import, const ToleranceOverrides& overrides = {});

/// Reads a STEP or IGES file. Errors (kIoError / kParseError / kInvalidInput) name the file and, where there is
/// one, the face; a file with no faces or surfaces is an error.
Result<CadImport> readCadFile(const std::filesystem::path& file, const CadReadOptions& options = {});

struct CadWriteOptions {
  /// Sewing tolerance; default 1e-6 x the model's bounding-box diagonal.
  std::optional<double> sewingTolerance;
};

/// Writes the patches of `model` as B-spline faces sewn into a shell (STEP or IGES by `format`).
Status writeCadFile(const Model& model, const std::filesystem::path& file, CadFormat format,
                    const CadWriteOptions& options = {});

/// What convertCadFile read and wrote (counted by OpenCASCADE on the input; the output, read back, has the same
/// faces, trimmed faces, solids and area, else nothing is written).
struct CadConvertReport {
  int faces = 0, trimmedFaces = 0, edges = 0, freeEdges = 0, shells = 0, solids = 0;
  double area = 0.0;        ///< total face area, mm²
  CadUnits units;           ///< the input's unit
  std::string writtenUnit;  ///< the unit the output declares ("MM", "INCH"/"IN", ...): the input's own
  std::vector<std::string> warnings;
  /// Seams of the written file, read back, that are worse than the input's at their place (one line each, naming the
  /// seam and why); empty when none is or when they were not compared.
  std::vector<std::string> seamsWorse;
  int seamsCompared = -1;  ///< seams of the written file compared with the input's; -1 when not compared
};

/// What convertCadFile does beyond the conversion itself.
struct CadConvertOptions {
  /// Check the seams of the input and of the written file (as read back) and list those the round trip through
  /// OpenCASCADE's writer and reader makes worse (CadConvertReport::seamsWorse): two B-rep checks, about as long
  /// as `seam check` of the file each. false: not compared (seamsCompared = -1).
  bool compareSeams = true;
  /// Tolerances of the comparison (a seam is worse when its gap or angle grows beyond max(before, tolerance) by a
  /// tenth of the tolerance, or a crease's angle changes by more than the angle tolerance); unset members take the
  /// defaults of `seam check` for the file's unit.
  ToleranceOverrides tolerances;
  double creaseAngleDeg = kDefaultCreaseAngleDeg;  ///< above it a seam is a design crease (its angle is kept)
  int threads = 0;                                 ///< threads of the checks; 0: all hardware threads
};

/// STEP/IGES -> STEP/IGES keeping the B-rep (issue 34 §1): every face with its wires, shared edges and vertices,
/// shells and solids, read and written through OpenCASCADE's XDE (STEPCAFControl / IGESCAFControl), so names,
/// colours and layers survive where XDE carries them. Surfaces and pcurves are written with 17 significant digits:
/// bit for bit. The output is in the input's length unit. Written atomically, then read back and compared with the
/// input (faces, trimmed faces, solids, area); a writer that would lose anything is an error and nothing is written.
/// `options.statedUnitMm` (--units) is refused: it rescales, and a conversion keeps the file as it is.
Result<CadConvertReport> convertCadFile(const std::filesystem::path& in, const std::filesystem::path& out,
                                        const CadReadOptions& options = {}, const CadConvertOptions& convert = {});

}  // namespace seam::occt
