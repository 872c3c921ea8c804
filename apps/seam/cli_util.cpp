#include "cli_util.h"

#include <fmt/format.h>

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <pthread.h>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <new>

#include "check_json.h"
#include "command_registry.h"
#include "json_text.h"
#include "seam/core/tolerance_presets.h"
#include "seam/io/file.h"
#include "seam/io/json.h"
#ifdef SEAM_HAVE_OCCT
#include "seam/occt/cad_io.h"
#endif

namespace seam::cli {

std::function<void(int, int, int)> brepProgressPrinter(const std::filesystem::path& file) {
  return [file](int faces, int done, int total) {
    if (faces > static_cast<int>(kProgressPatches))
      std::cerr << fmt::format("seam: {}: {} faces, {} of {} edges checked\n", file.string(), faces, done, total);
  };
}

namespace {
/// Limits above this (about 115 days) are no limit: steady_clock durations must not overflow.
constexpr double kLongestTimeLimitSeconds = 1e7;

/// The whole-run time limit (issue 39 §1): one watcher thread per process, started by startRunTimeLimit before the
/// command line is parsed, with the default limit; --time-limit moves its deadline (0 removes it). The stage is what
/// the command says it is doing (setActivity, CadTimeLimit). Leaked on purpose: the detached watcher may still wait on
/// it while the process exits.
struct RunLimit {
  std::mutex mutex;
  std::condition_variable changed;
  /// From the first stage on (the command's first file): parsing the command line is not counted, so that the
  /// message always names a file and a stage.
  std::optional<std::chrono::steady_clock::time_point> start;
  double seconds = kDefaultCadTimeLimitSeconds;  // 0: none
  bool explicitLimit = false;                    // --time-limit was given
  std::string stage;                             // "FILE: reading", ...
};
RunLimit& runLimit() {
  static RunLimit* r = new RunLimit;
  return *r;
}

constexpr size_t kWatcherStackBytes = 256 * 1024;

[[noreturn]] void stopAtTheLimit(const std::string& stage, double seconds) {
  // The main thread may be inside OpenCASCADE, which cannot be interrupted: remove the temporary files of outputs
  // being written (no output exists before its rename), say where the time ran out and end the process.
  io::removeTemporaryFiles();
  const std::string message = fmt::format(
      "seam: error: {}{}took longer than the time limit of {} s and was stopped (--time-limit bounds the whole "
      "command: reading, analysing, repairing, meshing and writing; a corrupt STEP/IGES file can keep OpenCASCADE's "
      "shape healing busy for minutes); allow more time with --time-limit SECONDS, or 0 for no limit\n",
      stage, stage.empty() ? "the command " : " ", formatNumber(seconds));
  size_t written = 0;
  while (written < message.size()) {
    const ssize_t n = ::write(STDERR_FILENO, message.data() + written, message.size() - written);
    if (n <= 0) break;
    written += static_cast<size_t>(n);
  }
  ::_exit(kExitBadInput);
}

void runTimeLimitWatcher() {
  RunLimit& r = runLimit();
  std::unique_lock<std::mutex> lock(r.mutex);
  for (;;) {
    if (!r.start || !(r.seconds > 0.0) || r.seconds > kLongestTimeLimitSeconds) {
      r.changed.wait(lock);
      continue;
    }
    const auto deadline = *r.start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                        std::chrono::duration<double>(r.seconds));
    if (r.changed.wait_until(lock, deadline) == std::cv_status::timeout &&
        std::chrono::steady_clock::now() >= deadline)
      stopAtTheLimit(r.stage, r.seconds);
  }
}
}  // namespace

void setActivity(std::string stage) {
  RunLimit& r = runLimit();
  bool first = false;
  {
    const std::lock_guard<std::mutex> lock(r.mutex);
    r.stage = std::move(stage);
    first = !r.start.has_value();
    if (first) r.start = std::chrono::steady_clock::now();
  }
  if (first) r.changed.notify_all();
}

void startRunTimeLimit() {
  // A small stack (the thread only waits and writes one message): under an address-space cap (prlimit --as) a
  // default 8 MB stack would be taken from what the command may use.
  pthread_attr_t attr;
  if (::pthread_attr_init(&attr) != 0) return;
  ::pthread_attr_setstacksize(&attr, kWatcherStackBytes);
  pthread_t thread;
  const int created = ::pthread_create(&thread, &attr, [](void*) -> void* {
    runTimeLimitWatcher();
    return nullptr;
  }, nullptr);
  ::pthread_attr_destroy(&attr);
  if (created == 0) ::pthread_detach(thread);
}

void suspendRunTimeLimitUnlessGiven() {
  RunLimit& r = runLimit();
  {
    const std::lock_guard<std::mutex> lock(r.mutex);
    if (r.explicitLimit) return;
    r.seconds = 0.0;
  }
  r.changed.notify_all();
}

void addTimeLimitOption(CLI::App& app) {
  // Inherited by the subcommands added after this: `seam check f.step --time-limit 60` reaches this option.
  app.fallthrough();
  // Read as decimal text (std::from_chars): CLI11's number conversion takes "0x10" as 16 and "0b11" as 3.
  app.add_option_function<std::string>(
      "--time-limit",
      [](const std::string& text) {
        double seconds = 0.0;
        const char* end = text.data() + text.size();
        const auto [ptr, ec] = std::from_chars(text.data(), end, seconds, std::chars_format::general);
        if (text.empty() || ec != std::errc() || ptr != end || !std::isfinite(seconds) || seconds < 0.0)
          throw CLI::ValidationError("--time-limit", fmt::format("\"{}\" is not a decimal number of seconds >= 0 "
                                                                 "(0: no limit)",
                                                                 text));
        RunLimit& r = runLimit();
        {
          const std::lock_guard<std::mutex> lock(r.mutex);
          r.seconds = seconds;
          r.explicitLimit = true;
        }
        r.changed.notify_all();
      },
      fmt::format("Seconds the whole command may take (reading, analysing, repairing, meshing, writing) before seam "
                  "stops with exit code 2, naming the stage (default {}; 0: no limit; `batch`: per file, see its "
                  "--timeout); before or after the command",
                  formatNumber(kDefaultCadTimeLimitSeconds)));
}

void addDigitsOption(CLI::App& app) {
  app.add_option_function<std::string>(
      "--digits",
      [](const std::string& text) {
        int digits = 0;
        const char* end = text.data() + text.size();
        const auto [ptr, ec] = std::from_chars(text.data(), end, digits);
        if (text.empty() || ec != std::errc() || ptr != end || digits < 1 || digits > kMaxDisplayDigits)
          throw CLI::ValidationError(
              "--digits", fmt::format("\"{}\" is not a whole number from 1 to {}", text, kMaxDisplayDigits));
        setDisplayDigits(digits);
      },
      fmt::format("Significant digits of the numbers in tables and text (default {}; {}: every number exactly, as "
                  "in the JSON, which is always exact); before or after the command",
                  kDefaultDisplayDigits, kMaxDisplayDigits));
}

// Only the main thread writes the stage, so it may read it without the lock.
const std::string& activity() { return runLimit().stage; }

CadTimeLimit::CadTimeLimit(std::filesystem::path file, std::string what) : previous_(activity()) {
  setActivity(fmt::format("{}: {} the file", file.string(), what));
}

CadTimeLimit::~CadTimeLimit() { setActivity(previous_); }

std::string lowerExtension(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool isCadFile(const std::filesystem::path& file) {
  const std::string ext = lowerExtension(file);
  return ext == ".step" || ext == ".stp" || ext == ".iges" || ext == ".igs";
}

void addToleranceOptions(CLI::App& cmd, ToleranceOverrides& overrides) {
  cmd.add_option("--tol-distance", overrides.distance,
                 "G0 tolerance, in the unit lengths are shown in (the file's own for STEP/IGES, --units for "
                 "JSON/.bpt, or --display-units); default 0.001 mm for models with a length unit, 1e-6 x "
                 "bounding-box diagonal for unit-less ones");
  cmd.add_option("--tol-angle", overrides.angleDeg,
                 fmt::format("G1 tolerance in degrees; default {} deg for models with a length unit (STEP/IGES, or "
                             "--units), {} deg for unit-less ones",
                             kDefaultCadAngleDeg, kStrictAngleDeg));
  cmd.add_option("--tol-curvature", overrides.curvatureRel, "G2 tolerance, relative; default 0.01");
  // Added after the --tol-* options: CLI11 runs the callbacks in this order, so an explicit --tol-* value is already
  // set when the preset fills the others (whatever the order on the command line).
  std::vector<std::string> names;
  for (const TolerancePreset& p : kTolerancePresets) names.emplace_back(p.name);
  cmd.add_option_function<std::string>(
         "--preset",
         [&overrides](const std::string& name) { applyTolerancePreset(overrides, name); },
         "Tolerances of a CAD system: catia (0.001 mm, 0.5 deg), rhino (0.001 mm, 1 deg, curvature 5 %), nx "
         "(0.0254 mm, 0.5 deg); distances converted to the model's unit (taken as model units for a unit-less "
         "model); --tol-* options override single values")
      ->check(CLI::IsMember(names));
  addUnitsOption(cmd, overrides);
}

namespace {

/// A length-unit option (--units, --display-units) that sets `target`; an unknown name is a usage error.
void addLengthUnitOption(CLI::App& cmd, const std::string& name, std::optional<LengthUnit>& target,
                         const std::string& help) {
  cmd.add_option_function<std::string>(
         name, [&target](const std::string& unit) { target = parseLengthUnit(unit); }, help)
      ->check([](const std::string& unit) -> std::string {
        if (parseLengthUnit(unit)) return "";
        return fmt::format("\"{}\" is not a length unit (use {}, or inch)", unit, unitNames());
      })
      ->type_name("UNIT");
}

}  // namespace

void addUnitsOption(CLI::App& cmd, ToleranceOverrides& overrides) {
  addLengthUnitOption(
      cmd, "--units", overrides.units,
      "Length unit of the model's numbers: mm, cm, m, in (or inch) or ft. JSON/.bpt: declares the unit of the "
      "unit-less model (presets and the default tolerance become absolute). STEP/IGES: only for a file whose header "
      "is wrong: its coordinates are taken in this unit whatever the header says. To show lengths in another unit, "
      "use --display-units");
}

void addDisplayUnitsOption(CLI::App& cmd, ToleranceOverrides& overrides) {
  addLengthUnitOption(cmd, "--display-units", overrides.display,
                      "Unit of every length in the output (tables, JSON, report): mm, cm, m, in (or inch) or ft; "
                      "default the model's own (a STEP/IGES file's header unit). The model is not changed; "
                      "--tol-distance and --max-gap are read in this unit");
}

bool displayUnitsApply(const std::string& file, const ModelUnits& units) {
  const Status st = displayUnitsStatus(file, units);
  if (!st) printError(st.message());
  return st.isOk();
}

std::string unitNames() {
  std::string names;
  for (const LengthUnitInfo& u : kLengthUnits) names += (names.empty() ? "" : ", ") + std::string(u.name);
  return names;
}

std::string unitLine(const ModelUnits& units, const ResolvedTolerances& tol, double creaseAngleDeg,
                     std::optional<double> pairing) {
  const Tolerances& t = tol.tolerances;
  return fmt::format("{}\ngap tolerance {} ({}), angle {} deg ({}), curvature {} relative{}; crease angle {} deg\n",
                     unitText(units), withUnit(formatNumber(t.distance), units),
                     distanceSourceText(tol.distanceSource, tol.preset), formatNumber(t.angleDeg),
                     angleSourceText(tol.angleSource, tol.preset), formatNumber(t.curvatureRel),
                     pairing ? fmt::format(", pairing {}", withUnit(formatNumber(*pairing), units)) : "",
                     formatNumber(creaseAngleDeg));
}

bool validToleranceOptions(const ToleranceOverrides& overrides) {
  for (const auto& [name, value] : {std::pair{"--tol-distance", overrides.distance},
                                    std::pair{"--tol-angle", overrides.angleDeg},
                                    std::pair{"--tol-curvature", overrides.curvatureRel}}) {
    if (value && !(std::isfinite(*value) && *value > 0.0)) {
      printError(fmt::format("{} must be a positive number, got {}", name, *value));
      return false;
    }
  }
  return true;
}


std::string modelFileHelp() {
#ifdef SEAM_HAVE_OCCT
  return "Model file (.json, .bpt, .step/.stp, .iges/.igs)";
#else
  return "Model file (.json, .bpt; STEP/IGES need a build with SEAM_WITH_OCCT)";
#endif
}

std::string continuityWords(int order) {
  switch (order) {
    case 0: return "position continuity (no gap)";
    case 1: return "tangent continuity";
    case 2: return "curvature continuity";
    default: return order > 2 ? fmt::format("continuity of order {}", order) : "no continuity";
  }
}

void printError(std::string_view message) {
  std::cout.flush();
  std::cerr << "seam: error: " << message << "\n";
}

namespace {

std::optional<Model> loadModelUnguarded(const std::filesystem::path& file, const ToleranceOverrides& overrides,
                                        ModelUnits* units, std::vector<std::string>* warnings) {
  if (units != nullptr) *units = declaredModelUnits(overrides);
  if (isCadFile(file)) {
    // A directory, a FIFO or a device is refused here with the same words as for .json/.bpt.
    if (!checkInputPath(file)) return std::nullopt;
#ifdef SEAM_HAVE_OCCT
    occt::CadReadOptions ro;
    if (overrides.units) ro.statedUnitMm = lengthUnitInfo(*overrides.units).millimetres;
    Result<occt::CadImport> cad = [&] {
      const CadTimeLimit limit(file, "reading");
      return occt::readCadFile(file, ro);
    }();
    if (!cad) {
      printError(cad.status().message());
      return std::nullopt;
    }
    for (const std::string& w : cad->warnings) std::cerr << "seam: warning: " << w << "\n";
    if (warnings != nullptr) *warnings = cad->warnings;
    int trimmed = 0, approximated = 0;
    for (const occt::CadFace& f : cad->faces) {
      trimmed += f.trimmed ? 1 : 0;
      approximated += f.exact ? 0 : 1;
    }
    if (trimmed > 0)
      std::cerr << fmt::format("seam: note: {}: {} of {} faces are trimmed; each is analysed as the patch of its "
                               "parameter box\n",
                               file.string(), trimmed, cad->faces.size());
    if (approximated > 0)
      std::cerr << fmt::format("seam: note: {}: {} faces were approximated (see `seam info`)\n", file.string(),
                               approximated);
    if (units != nullptr) *units = occt::cadModelUnits(*cad, overrides);
    return std::move(cad->model);
#else
    printError(fmt::format("{}: STEP/IGES support needs a build with SEAM_WITH_OCCT=ON (scripts/setup.sh does)",
                           file.string()));
    return std::nullopt;
#endif
  }
  Result<Model> model = io::readModel(file);
  if (!model) {
    printError(model.status().message());
    return std::nullopt;
  }
  return std::move(model).value();
}

}  // namespace

std::optional<Model> loadModel(const std::filesystem::path& file) { return loadModel(file, {}, nullptr); }


std::optional<Model> loadModel(const std::filesystem::path& file, const ToleranceOverrides& overrides,
                               ModelUnits* units, std::vector<std::string>* warnings) {
  try {
    setActivity(fmt::format("{}: reading the model", file.string()));
    std::optional<Model> model = loadModelUnguarded(file, overrides, units, warnings);
    if (model) {
      Eigen::Index points = 0;
      for (const Patch& p : model->patches) points += p.surface.points().rows();
      setActivity(fmt::format("{}: working on its model of {} patches and {} curves ({} control points)",
                              file.string(), model->patches.size(), model->curves.size(), points));
    }
    return model;
  } catch (const std::bad_alloc&) {
    printError(fmt::format("{}: the model is too large: out of memory while reading it", file.string()));
    return std::nullopt;
  }
}

bool checkInputPath(const std::filesystem::path& file) {
  const Status s = io::checkInputFile(file, isCadFile(file) ? io::kMaxCadFileBytes : io::kMaxModelFileBytes);
  if (!s) printError(s.message());
  return s.isOk();
}

bool checkModelText(const std::filesystem::path& file) {
  if (lowerExtension(file) != ".json") return true;
  const Result<std::string> text = io::readFile(file);
  const Status s = text ? io::checkJsonText(*text, file.string()) : text.status();
  if (!s) printError(s.message());
  return s.isOk();
}

bool checkOutputPath(const std::filesystem::path& in, const std::filesystem::path& out) {
  namespace fs = std::filesystem;
  std::error_code ec;
  bool same = fs::exists(out, ec) && fs::exists(in, ec) && fs::equivalent(in, out, ec);
  if (!same && !ec) {
    const fs::path a = fs::weakly_canonical(in, ec);
    const fs::path b = ec ? fs::path() : fs::weakly_canonical(out, ec);
    same = !ec && a == b;
  }
  if (same) {
    printError(fmt::format("{}: the output would overwrite the input {}; choose another output file", out.string(),
                           in.string()));
    return false;
  }
  if (Status s = io::checkOutputFile(out); !s) {
    printError(s.message());
    return false;
  }
  return true;
}

bool saveModel(const Model& model, const std::filesystem::path& file) {
  const std::string ext = lowerExtension(file);
  Status st = io::checkOutputFile(file);  // the STEP/IGES writer renames over the target too
  if (!st.isOk()) {
    printError(st.message());
    return false;
  }
  if (isCadFile(file)) {
#ifdef SEAM_HAVE_OCCT
    st = occt::writeCadFile(model, file, *occt::cadFormatOf(file));
#else
    st = Status(ErrorCode::kUnsupported, fmt::format("{}: writing STEP/IGES needs OpenCASCADE: rebuild with "
                                                     "-DSEAM_WITH_OCCT=ON", file.string()));
#endif
  } else if (ext == ".json") {
    st = io::writeModelJson(model, file);
  } else {
    st = invalidInput(fmt::format("{}: unknown output format (use .json, .step/.stp or .iges/.igs)", file.string()));
  }
  if (!st.isOk()) {
    printError(st.message());
    return false;
  }
  return true;
}

std::string jsonText(const OrderedJson& value) {
  std::string out;
  appendJsonText(out, value, 0);
  out += "\n";
  return out;
}

void printJson(const OrderedJson& value) { std::cout << jsonText(value) << std::flush; }

std::string formatVector(const double* values, int count) {
  std::string s = "[";
  for (int k = 0; k < count; ++k) {
    if (k > 0) s += ", ";
    s += formatNumber(values[k]);
  }
  return s + "]";
}

std::string wrapText(std::string_view text, size_t width, std::string_view indent) {
  std::string out, line;
  auto flush = [&] {
    if (line.empty()) return;
    if (!out.empty()) out += "\n" + std::string(indent);
    out += line;
    line.clear();
  };
  size_t i = 0;
  while (i < text.size()) {
    const size_t space = text.find(' ', i);
    std::string_view word = text.substr(i, space == std::string_view::npos ? std::string_view::npos : space - i);
    i = space == std::string_view::npos ? text.size() : space + 1;
    if (word.empty()) continue;
    const size_t room = width > indent.size() && !out.empty() ? width - indent.size() : width;
    if (!line.empty() && line.size() + 1 + word.size() > room) flush();
    line += (line.empty() ? "" : " ") + std::string(word);
    if (word.back() == ';') flush();  // one clause per line
  }
  flush();
  return out;
}

std::string wrapList(const std::vector<std::string>& items, size_t width, std::string_view indent) {
  std::string out;
  size_t lineLength = 0;
  for (size_t k = 0; k < items.size(); ++k) {
    const std::string piece = items[k] + (k + 1 < items.size() ? "," : "");
    if (lineLength > 0 && lineLength + 1 + piece.size() > width) {
      out += "\n" + std::string(indent);
      lineLength = indent.size();
    } else if (lineLength > 0) {
      out += ' ';
      ++lineLength;
    }
    out += piece;
    lineLength += piece.size();
  }
  return out;
}

std::string formatTable(const std::vector<std::string>& header,
                        const std::vector<std::vector<std::string>>& rows,
                        const std::vector<bool>& rightAligned) {
  std::vector<size_t> width(header.size(), 0);
  auto measure = [&](const std::vector<std::string>& row) {
    for (size_t c = 0; c < row.size() && c < width.size(); ++c) width[c] = std::max(width[c], row[c].size());
  };
  measure(header);
  for (const auto& row : rows) measure(row);

  auto line = [&](const std::vector<std::string>& row) {
    std::string s;
    for (size_t c = 0; c < width.size(); ++c) {
      const std::string& cell = c < row.size() ? row[c] : std::string();
      const bool right = c < rightAligned.size() && rightAligned[c];
      if (c > 0) s += "  ";
      s += right ? fmt::format("{:>{}}", cell, width[c]) : fmt::format("{:<{}}", cell, width[c]);
    }
    while (!s.empty() && s.back() == ' ') s.pop_back();
    return s + "\n";
  };
  std::string out = line(header);
  size_t total = 0;
  for (size_t c = 0; c < width.size(); ++c) total += width[c] + (c > 0 ? 2 : 0);
  out += std::string(total, '-') + "\n";
  for (const auto& row : rows) out += line(row);
  return out;
}

bool writeOutputFile(const std::filesystem::path& file, const std::string& content) {
  const Status status = io::writeFileAtomically(file, content);
  if (!status) {
    printError(status.message());
    return false;
  }
  return true;
}

}  // namespace seam::cli
