#pragma once
// The JSON of `seam check --json`, shared by the CLI (apps/seam/cmd_check.cpp, `seam batch`) and the Python module
// (python/seam_module.cpp): one builder, so a Python dict has exactly the keys of the CLI's output.
// Target seam_check_json (apps/common/CMakeLists.txt); docs/check-output.md describes the keys.
#include <nlohmann/json.hpp>

#include <filesystem>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "seam/continuity/model_check.h"
#include "seam/continuity/verdict.h"
#include "seam/core/result.h"
#include "seam/core/tolerances.h"
#include "seam/core/units.h"
#include "json_text.h"
#include "seam/model/model.h"
#ifdef SEAM_HAVE_OCCT
#include "seam/occt/brep_check.h"
#endif

namespace seam::cli {

/// The seam reports of a model check, null for a seam whose analysis failed (the input of selectSeams & co.).
std::vector<const SeamReport*> reportsOf(const ModelCheckReport& r);

/// `seam check --json` of a patch model: `order` lists the seams to print (selectSeams of the listing options),
/// `pairing` is the pairing tolerance of a whole-model check (nullopt for a single --seam).
/// `units` is the model's length unit (unitsJson), `distanceSource` and `angleSource` where tolerances.distance and
/// tolerances.angle_deg come from.
OrderedJson modelCheckJson(const Model& m, const ModelCheckReport& r, const std::vector<size_t>& order,
                           const std::optional<GeometricClass>& require, std::optional<double> pairing,
                           double creaseAngleDeg, const ModelUnits& units = {},
                           DistanceSource distanceSource = DistanceSource::kRelative,
                           const std::vector<std::string>& warnings = {},
                           AngleSource angleSource = AngleSource::kStrictDefault);

/// `seam check FILE --json` of a patch model written to `out` as jsonText(withInputFile(file, modelCheckJson(...)))
/// prints it, byte for byte, without building the document: each seam and corner record is written as it is
/// formatted (the same record code as modelCheckJson), and the text goes out in chunks of about 1 MiB. A 10 000-patch
/// check's JSON is 47 MB of text; its DOM took about 300 MB.
void writeModelCheckJson(std::ostream& out, const std::filesystem::path& file, const Model& m,
                         const ModelCheckReport& r, const std::vector<size_t>& order,
                         const std::optional<GeometricClass>& require, std::optional<double> pairing,
                         double creaseAngleDeg, const ModelUnits& units = {},
                         DistanceSource distanceSource = DistanceSource::kRelative,
                         const std::vector<std::string>& warnings = {},
                         AngleSource angleSource = AngleSource::kStrictDefault);

/// `seam check --json`'s "units" (issue 17 §2): {"length": "mm" | null (unit-less), "file_unit": the STEP/IGES
/// header's name ("MM", "INCH") | null, "source": "file header" | "--units" | "none (unit-less model)",
/// "declared_resolution": the file's declared precision in model units | null}.
OrderedJson unitsJson(const ModelUnits& units);

#ifdef SEAM_HAVE_OCCT
/// `seam check --json` of a STEP/IGES B-rep (every shared edge, OpenCASCADE's verdict alongside).
OrderedJson brepCheckJson(const occt::BRepCheckReport& r, const std::vector<size_t>& order,
                          const std::optional<GeometricClass>& require, double creaseAngleDeg);

/// `seam check FILE --json` of a STEP/IGES B-rep written to `out` as jsonText(withInputFile(file, brepCheckJson(...)))
/// prints it, byte for byte, without building the document (the same record code as brepCheckJson).
void writeBRepCheckJson(std::ostream& out, const std::filesystem::path& file, const occt::BRepCheckReport& r,
                        const std::vector<size_t>& order, const std::optional<GeometricClass>& require,
                        double creaseAngleDeg);
#endif

/// `check` with the input named first (issue 17 §3, docs/check.schema.json): {"file": FILE, "format": "json" | "bpt" |
/// "step" | "iges" (null for another name), "warnings": the reader's warnings (check's own "warnings", else []),
/// ...the other keys of `check`}. The values are moved out of `check` (a copy of a
/// large report's tree cost more than writing it).
OrderedJson withInputFile(const std::filesystem::path& file, OrderedJson check);

/// The check JSON of a model without patches (every key of the schema, empty lists, zero counts, and a `note`).
OrderedJson noPatchesJson(const std::string& name, const ModelUnits& units = {});

/// The options of a whole-file check (those of `seam check` that apply to a whole model).
struct FileCheckOptions {
  ToleranceOverrides tol;                ///< --tol-distance / --tol-angle / --tol-curvature / --preset / --units
  std::optional<GeometricClass> require; ///< --require
  SeamSelection selection;               ///< --crease-angle / --sort / --top / --only
  bool patches = false;                  ///< --patches: a STEP/IGES file's faces as patches, not its B-rep edges
};

/// One file checked whole, as `seam check FILE --json` with the same options prints it.
struct FileCheck {
  OrderedJson json;
  bool belowRequired = false;         ///< some seam is below `require` (the CLI's exit code 1)
  std::vector<std::string> warnings;  ///< the reader's warnings (the CLI prints them on stderr)
};

/// Loads and checks one model file (.json, .bpt; .step/.stp/.iges/.igs when built with OpenCASCADE). Errors: the
/// file is unreadable or invalid, or the check failed; the message names the file and the problem (the CLI's exit
/// code 2). Out of memory while reading is reported as an error too.
Result<FileCheck> checkFile(const std::filesystem::path& file, const FileCheckOptions& options = {});

/// An error naming `name` when --display-units was given for a unit-less model (nothing to convert from), else ok.
Status displayUnitsStatus(const std::string& name, const ModelUnits& units);

/// A loaded model checked whole, as checkFile does after reading it; `name` (the file or the model's name) prefixes
/// the error message of a failed check.
/// `units`: the model's length unit (a JSON/.bpt model gets options.tol.units; unit-less without it).
Result<FileCheck> checkModel(const Model& model, const std::string& name, const FileCheckOptions& options = {},
                             const ModelUnits& units = {});

}  // namespace seam::cli
