#pragma once
// Helpers shared by the seam subcommands: loading a model with errors on stderr, printing JSON and
// fixed-width tables, formatting numbers, writing output files atomically.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "seam/core/tolerances.h"
#include "seam/core/units.h"
#include "seam/model/model.h"
#include "units_text.h"  // formatNumber, withUnit, unitText (apps/common: shared with the Python module)

namespace seam::cli {

/// JSON with keys kept in insertion order (what the commands print).
using OrderedJson = nlohmann::ordered_json;

/// Models with more patches (faces) than this get progress lines on stderr.
inline constexpr size_t kProgressPatches = 300;

/// A B-rep check progress callback (faces, edges done, edges in all) that prints a line on stderr for models above
/// kProgressPatches faces and stays silent below.
std::function<void(int, int, int)> brepProgressPrinter(const std::filesystem::path& file);

/// Default of `seam --time-limit`: wall-clock seconds that reading and analysing one STEP/IGES file may take. Every
/// real file seam has met takes a few seconds; a corrupt one can keep OpenCASCADE's shape healing busy for minutes
/// in code that never looks at a clock (docs/reliability.md, "Time limit").
inline constexpr double kDefaultCadTimeLimitSeconds = 300.0;

/// Adds the global `--time-limit SECONDS` option (0 = no limit) to the application; it may be given before or after
/// the command's name.
void addTimeLimitOption(CLI::App& app);
/// Adds the global `--digits N` option (significant digits of text output, setDisplayDigits; 1 to
/// kMaxDisplayDigits); before or after the command's name (after addTimeLimitOption, which makes options fall
/// through to the commands).
void addDigitsOption(CLI::App& app);

/// The whole-run time limit (--time-limit, default kDefaultCadTimeLimitSeconds, counted from the command's first
/// stage, i.e. once the command line is parsed and the first file is opened): main starts its watcher before parsing. When the limit passes, the watcher removes the temporary files
/// of outputs being written, prints "seam: error: <stage> took longer than the time limit of N s ..." on stderr and
/// ends the process with exit code 2 (kExitBadInput) at once (OpenCASCADE cannot be interrupted; outputs are renamed
/// into place only when complete). The stage is the last setActivity / CadTimeLimit. The CLI only.
void startRunTimeLimit();
/// For commands whose run is bounded per input in their own way (`batch --timeout`): no whole-run limit unless
/// --time-limit was given.
void suspendRunTimeLimitUnlessGiven();

/// While alive, names the stage ("<file>: <what> the file", `what`: "reading", "checking", ...) for the whole-run
/// time limit's message; the previous stage comes back on destruction.
class CadTimeLimit {
 public:
  CadTimeLimit(std::filesystem::path file, std::string what);
  ~CadTimeLimit();
  CadTimeLimit(const CadTimeLimit&) = delete;
  CadTimeLimit& operator=(const CadTimeLimit&) = delete;

 private:
  std::string previous_;
};

/// Prints "seam: error: <message>" on stderr.
void printError(std::string_view message);

/// The file's extension in lower case (".json", ".step", ...; "" when it has none).
std::string lowerExtension(const std::filesystem::path& file);

/// True for .step/.stp/.iges/.igs (any case).
bool isCadFile(const std::filesystem::path& file);

/// The --tol-distance / --tol-angle / --tol-curvature / --preset / --units options shared by the commands that
/// classify seams (a --units name that is not one of unitNames() is a usage error: exit 2).
void addToleranceOptions(CLI::App& cmd, ToleranceOverrides& overrides);
/// False (with a message on stderr) when a given tolerance is not a positive finite number.
bool validToleranceOptions(const ToleranceOverrides& overrides);

/// The help text of a command's FILE argument: "Model file (.json, .bpt, .step/.stp, .iges/.igs)", or in a build
/// without OpenCASCADE "Model file (.json, .bpt; STEP/IGES need a build with SEAM_WITH_OCCT)".
std::string modelFileHelp();

/// A continuity class in a CAD user's words: "position continuity (no gap)" (G0), "tangent continuity" (G1),
/// "curvature continuity" (G2); "no continuity" otherwise. For the first line of join/corner/extend output.
std::string continuityWords(int order);

/// Loads a model: STEP/IGES through seam::occt::readCadFile (when built with OpenCASCADE), else io::readModel; on failure prints the message on stderr and returns nullopt
/// (the command then exits with kExitBadInput).
std::optional<Model> loadModel(const std::filesystem::path& file);
/// loadModel with the units: a STEP/IGES file is read with `overrides.units` as the unit of its coordinates (when
/// given); `units` (when not null) receives the model's length unit: mm from the header (or --units) for STEP/IGES,
/// `overrides.units` or none for JSON/.bpt.
/// `warnings` (when not null) receives the reader's warnings (STEP/IGES: entities lost, roots not transferred,
/// faces skipped or approximated), which are also printed on stderr.
std::optional<Model> loadModel(const std::filesystem::path& file, const ToleranceOverrides& overrides,
                               ModelUnits* units, std::vector<std::string>* warnings = nullptr);

/// What the command is working on, for the messages of the whole-run time limit and of an out-of-memory that
/// reaches main ("FILE: reading the model", "FILE: working on its model of 12 patches"); loadModel and CadTimeLimit
/// set it, and the first call starts the time limit's clock. Empty before any file is read. Main thread only.
void setActivity(std::string text);
const std::string& activity();

/// --units alone (for commands without tolerances, e.g. info): sets overrides.units.
void addUnitsOption(CLI::App& cmd, ToleranceOverrides& overrides);
/// `--display-units UNIT` (issue 38 §1): the unit every length of the output is shown in (overrides.display).
/// Added by the commands that convert their output: check, report, batch, info, and heal of a B-rep.
void addDisplayUnitsOption(CLI::App& cmd, ToleranceOverrides& overrides);
/// False (with an error naming `file`) when --display-units was given for a unit-less model: nothing to convert
/// from. The caller exits with kExitBadInput.
bool displayUnitsApply(const std::string& file, const ModelUnits& units);

/// "mm, cm, m, in, ft": the names --units accepts.
std::string unitNames();
/// The two header lines of `check` and `report` text: the model's length unit and where it comes from (and the
/// file's declared resolution), then "gap tolerance 0.001 mm (default for ...), angle ... deg, curvature ...
/// relative[, pairing ...]; crease angle ... deg". Each ends with a newline.
std::string unitLine(const ModelUnits& units, const ResolvedTolerances& tol, double creaseAngleDeg,
                     std::optional<double> pairing = std::nullopt);

/// False (with the message on stderr) when `file` is not a regular file of at most the size its format may have
/// (io::checkInputFile: kMaxCadFileBytes for STEP/IGES, kMaxModelFileBytes otherwise). loadModel calls it; the
/// commands that hand a STEP/IGES file to OpenCASCADE directly (the B-rep check and report) call it first.
bool checkInputPath(const std::filesystem::path& file);

/// For readers outside io::readModel (the expression models of gcn and extend): a .json file that
/// io::checkJsonText refuses (a NUL byte, nesting deeper than a model can need) or that is not a readable regular
/// file gets its message on stderr and false; other extensions true.
bool checkModelText(const std::filesystem::path& file);

/// JSON text: objects indented by two spaces, arrays of numbers/strings on one line, doubles with round-trip
/// precision, non-finite doubles as null. Ends with a newline.
std::string jsonText(const OrderedJson& value);
/// Prints jsonText(value) on stdout.
void printJson(const OrderedJson& value);

/// "[x, y, z]" with formatNumber for each coordinate.
std::string formatVector(const double* values, int count);

/// A fixed-width text table: a header row, a rule, then the rows; columns are padded to their widest cell,
/// the first column left-aligned and the others as given by `rightAligned` (default: left). Ends with a
/// newline.
std::string formatTable(const std::vector<std::string>& header,
                        const std::vector<std::vector<std::string>>& rows,
                        const std::vector<bool>& rightAligned = {});

/// `text` broken at spaces into lines of at most `width` characters (a longer word stays whole), every line but the
/// first starting with `indent`; "; " also ends a line, so that the clauses of a long note stand one per line.
/// No trailing newline.
std::string wrapText(std::string_view text, size_t width, std::string_view indent);
/// `items` joined by ", " into lines of at most `width` characters, broken only between items (an item stays whole),
/// every line but the first starting with `indent`. No trailing newline.
std::string wrapList(const std::vector<std::string>& items, size_t width, std::string_view indent);

/// Writes a model by extension (.json; .step/.stp/.iges/.igs when built with OpenCASCADE), atomically; on failure
/// prints the message on stderr and returns false. Every command that writes a model uses it.
bool saveModel(const Model& model, const std::filesystem::path& file);

/// False (with a message on stderr) when `out` cannot be the output of a command reading `in`: it is the input
/// itself (std::filesystem::equivalent: the same file under another name, a hard link), or an existing symbolic
/// link, FIFO, device node or directory (io::checkOutputFile). Every command that writes a file calls it before
/// doing any work, so that the input is never overwritten.
bool checkOutputPath(const std::filesystem::path& in, const std::filesystem::path& out);

/// Writes `content` to `file` atomically; on failure prints the message on stderr and returns false.
bool writeOutputFile(const std::filesystem::path& file, const std::string& content);

}  // namespace seam::cli
