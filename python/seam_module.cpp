// The Python module `seam` (extension _seam; python/seam/__init__.py re-exports it): load models, evaluate patches
// and curves on NumPy arrays, check models with the dicts of `seam check --json` (apps/common/check_json.h: the
// same builder as the CLI). Bad input raises ValueError (invalid data, unknown names, parameters outside the
// domain), OSError (a file that cannot be read) or RuntimeError (a check that failed); messages name the file, the
// object and the problem, as the CLI's do.
#include <fmt/format.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>
#include <pybind11/stl/filesystem.h>

#include <cmath>
#include <filesystem>
#include <mutex>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include "brep_report.h"
#include "check_json.h"
#include "fill_json.h"
#include "regularity_json.h"
#include "repair_units_json.h"
#include "seam/construct/fill.h"
#include "seam/core/tolerance_presets.h"
#include "seam/core/units.h"
#include "seam/continuity/verdict.h"
#include "seam/io/file.h"
#include "seam/io/json.h"
#include "seam/repair/corner_join.h"
#include "seam/repair/heal.h"
#include "seam/repair/join.h"
#include "seam/repair/report_json.h"
#include "seam/report/report.h"
#include "seam/model/model.h"
#include "seam/regularity/regularity.h"
#include "seam/version.h"
#ifdef SEAM_HAVE_OCCT
#include "brep_heal_json.h"
#include "seam/occt/brep_heal.h"
#include "seam/occt/cad_io.h"
#endif

namespace py = pybind11;

namespace seam::python {

namespace {

/// OpenCASCADE's STEP/IGES readers keep global state: one CAD file at a time per process (the GIL is released
/// around every read and check, so Python threads may otherwise overlap).
std::mutex& cadMutex() {
  static std::mutex m;
  return m;
}

bool isCadPath(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".step" || ext == ".stp" || ext == ".iges" || ext == ".igs";
}

[[noreturn]] void raise(const Status& s) {
  switch (s.code()) {
    case ErrorCode::kIoError:
      PyErr_SetString(PyExc_OSError, s.message().c_str());
      throw py::error_already_set();
    case ErrorCode::kInvalidInput:
    case ErrorCode::kNotFound:
    case ErrorCode::kDegenerate:
    case ErrorCode::kUnsupported:
      throw py::value_error(s.message());
    default:
      throw std::runtime_error(s.message());
  }
}

/// nlohmann JSON -> Python objects (dicts keep the CLI's key order; non-finite numbers are None, as the CLI prints
/// them null).
py::object toPython(const cli::OrderedJson& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null:
      return py::none();
    case nlohmann::json::value_t::boolean:
      return py::bool_(j.get<bool>());
    case nlohmann::json::value_t::number_integer:
      return py::int_(j.get<long long>());
    case nlohmann::json::value_t::number_unsigned:
      return py::int_(j.get<unsigned long long>());
    case nlohmann::json::value_t::number_float: {
      const double x = j.get<double>();
      return std::isfinite(x) ? py::object(py::float_(x)) : py::object(py::none());
    }
    case nlohmann::json::value_t::string:
      return py::str(j.get_ref<const std::string&>());
    case nlohmann::json::value_t::array: {
      py::list l;
      for (const auto& x : j) l.append(toPython(x));
      return l;
    }
    case nlohmann::json::value_t::object: {
      py::dict d;
      for (const auto& [key, value] : j.items()) d[py::str(key)] = toPython(value);
      return d;
    }
    default:
      return py::none();
  }
}

/// A loaded model and the file it came from (for messages).
struct PyModel {
  Model model;
  std::string source;
  /// The unit of the model's numbers as the CLI resolves it for the same file: millimetres from a STEP/IGES header,
  /// none for JSON/.bpt (units= on a call gives one, as --units does).
  ModelUnits units;
};

Model readAnyModel(const std::filesystem::path& file, [[maybe_unused]] std::vector<std::string>& warnings,
                   [[maybe_unused]] ModelUnits* units = nullptr) {
  Result<Model> model = Status(ErrorCode::kIoError, "not read");
  {
    py::gil_scoped_release release;
    try {
#ifdef SEAM_HAVE_OCCT
      if (isCadPath(file)) {
        std::lock_guard lock(cadMutex());
        Result<occt::CadImport> cad = occt::readCadFile(file);
        if (cad) {
          warnings = cad->warnings;
          // The notes `seam check` prints on stderr for the same file, as Python warnings (issue 38 goal 10).
          int trimmed = 0, approximated = 0;
          for (const occt::CadFace& f : cad->faces) {
            trimmed += f.trimmed ? 1 : 0;
            approximated += f.exact ? 0 : 1;
          }
          if (trimmed > 0)
            warnings.push_back(fmt::format("{} of {} faces are trimmed; each is analysed as the patch of its parameter "
                                           "box by check(model), as a B-rep with its trims by check(path)",
                                           trimmed, cad->faces.size()));
          if (approximated > 0) warnings.push_back(fmt::format("{} faces were approximated", approximated));
          if (units != nullptr) *units = occt::cadModelUnits(*cad);
          model = std::move(cad->model);
        } else {
          model = cad.status();
        }
      } else
#endif
      {
        model = io::readModel(file);
      }
    } catch (const std::bad_alloc&) {
      model = Status(ErrorCode::kInvalidInput,
                     fmt::format("{}: the model is too large: out of memory while reading it", file.string()));
    }
  }
  if (!model) raise(model.status());
  return std::move(model).value();
}

PyModel load(const std::filesystem::path& file) {
  std::vector<std::string> warnings;
  ModelUnits units;
  Model model = readAnyModel(file, warnings, &units);
  PyModel m{std::move(model), file.string(), units};
  if (!warnings.empty()) {
    py::module_ warn = py::module_::import("warnings");
    for (const std::string& w : warnings) warn.attr("warn")(fmt::format("{}: {}", file.string(), w));
  }
  return m;
}

using RealArray = py::array_t<double, py::array::c_style | py::array::forcecast>;

/// Parameters given as any array-like of real numbers (integers or floats), as doubles. Complex numbers (whose
/// imaginary part a cast to double would drop), booleans, strings and objects are refused with a ValueError.
RealArray asRealArray(const py::object& x, const std::string& object, const char* what) {
  py::array a = py::array::ensure(x);
  if (!a) throw py::value_error(fmt::format("{}: {} must be an array of real numbers", object, what));
  const char kind = a.dtype().kind();
  if (kind == 'c')
    throw py::value_error(fmt::format("{}: {} holds complex numbers; parameters must be real", object, what));
  if (kind != 'i' && kind != 'u' && kind != 'f')
    throw py::value_error(fmt::format("{}: {} must be an array of real numbers, not of dtype {}", object, what,
                                      py::str(a.dtype()).cast<std::string>()));
  return RealArray::ensure(a);
}

/// The shape of an array as numpy prints it: "(2, 2)".
std::string shapeText(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) s += fmt::format("{}{}", k == 0 ? "" : ", ", a.shape(k));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

/// The (n, 2) parameter array of evaluate/derivatives: a (2,) array is one point.
py::array_t<double> asUV(const py::object& uvIn, const std::string& object) {
  RealArray uv = asRealArray(uvIn, object, "uv");
  if (uv.ndim() == 1 && uv.shape(0) == 2) return uv.reshape({py::ssize_t{1}, py::ssize_t{2}});
  if (uv.ndim() != 2 || uv.shape(1) != 2)
    throw py::value_error(fmt::format("{}: uv must be an array of shape (n, 2) (pairs u, v), not of {} dimensions",
                                      object, uv.ndim()));
  return uv;
}

const Patch& findPatch(const PyModel& m, const std::string& name) {
  const Patch* p = m.model.findPatch(name);
  if (p == nullptr) {
    std::string names;
    for (const Patch& q : m.model.patches) names += (names.empty() ? "" : ", ") + q.name;
    throw py::value_error(
        fmt::format("{}: no patch named \"{}\" (patches: {})", m.source, name, names.empty() ? "none" : names));
  }
  return *p;
}

void checkParameter(const std::string& object, const char* name, double value, const Interval& domain) {
  if (!std::isfinite(value)) throw py::value_error(fmt::format("{}: {} = {} is not a finite number", object, name, value));
  if (!domain.contains(value))
    throw py::value_error(fmt::format("{}: {} = {} is outside the parameter domain [{}, {}]", object, name, value,
                                      domain.lo, domain.hi));
}

/// All derivatives up to `order` at n parameter pairs: shape (n, order+1, order+1, dim), [i, k, l] =
/// d^(k+l) S / du^k dv^l at uv[i]; entries with k + l > order are NaN (not computed).
py::array_t<double> derivatives(const PyModel& m, const std::string& name, const py::object& uvIn, int order) {
  const Patch& p = findPatch(m, name);
  const std::string object = fmt::format("{}: patch \"{}\"", m.source, name);
  constexpr int kMaxOrder = 32;
  if (order < 0 || order > kMaxOrder)
    throw py::value_error(fmt::format("{}: derivative order {} is not in 0..{}", object, order, kMaxOrder));
  const py::array_t<double> uv = asUV(uvIn, object);
  const auto in = uv.unchecked<2>();
  const py::ssize_t n = uv.shape(0);
  for (py::ssize_t i = 0; i < n; ++i) {
    checkParameter(object, "u", in(i, 0), p.surface.domainU());
    checkParameter(object, "v", in(i, 1), p.surface.domainV());
  }
  const int dim = p.surface.dim();
  const py::ssize_t o1 = order + 1;
  py::array_t<double> out({n, o1, o1, py::ssize_t{dim}});
  auto o = out.mutable_unchecked<4>();
  {
    py::gil_scoped_release release;
    for (py::ssize_t i = 0; i < n; ++i) {
      const std::vector<std::vector<VecX>> d = p.surface.derivatives(in(i, 0), in(i, 1), order);
      for (py::ssize_t k = 0; k < o1; ++k)
        for (py::ssize_t l = 0; l < o1; ++l)
          for (int c = 0; c < dim; ++c)
            o(i, k, l, c) = k + l <= order ? d[static_cast<size_t>(k)][static_cast<size_t>(l)][c]
                                           : std::numeric_limits<double>::quiet_NaN();
    }
  }
  return out;
}

py::array_t<double> evaluate(const PyModel& m, const std::string& name, const py::object& uvIn) {
  py::array_t<double> d = derivatives(m, name, uvIn, 0);
  return d.reshape({d.shape(0), d.shape(3)});
}

/// Curve points and derivatives: shape (n, order+1, dim), [i, k] = d^k C / dt^k at t[i].
py::array_t<double> evaluateCurve(const PyModel& m, const std::string& name, const py::object& tObj, int order) {
  const Curve* c = m.model.findCurve(name);
  if (c == nullptr) throw py::value_error(fmt::format("{}: no curve named \"{}\"", m.source, name));
  const std::string object = fmt::format("{}: curve \"{}\"", m.source, name);
  if (order < 0 || order > 32) throw py::value_error(fmt::format("{}: derivative order {} is not in 0..32", object, order));
  RealArray tIn = asRealArray(tObj, object, "t");
  // A number or an (n,) array; a (2, 2) array was flattened into 4 parameters: refused, its shape is not a list.
  if (tIn.ndim() > 1)
    throw py::value_error(fmt::format("{}: t must be a number or an array of shape (n,), not of shape {}", object,
                                      shapeText(tIn)));
  const py::array_t<double> t = tIn.reshape({tIn.size()});
  const auto in = t.unchecked<1>();
  for (py::ssize_t i = 0; i < t.shape(0); ++i) checkParameter(object, "t", in(i), c->curve.domain());
  const int dim = c->curve.dim();
  py::array_t<double> out({t.shape(0), py::ssize_t{order + 1}, py::ssize_t{dim}});
  auto o = out.mutable_unchecked<3>();
  for (py::ssize_t i = 0; i < t.shape(0); ++i) {
    const Matrix d = c->curve.derivatives(in(i), order);
    for (int k = 0; k <= order; ++k)
      for (int a = 0; a < dim; ++a) o(i, k, a) = d(k, a);
  }
  return out;
}

std::optional<GeometricClass> parseRequire(const std::optional<std::string>& s) {
  if (!s) return std::nullopt;
  if (*s == "G0") return GeometricClass::kG0;
  if (*s == "G1") return GeometricClass::kG1;
  if (*s == "G2") return GeometricClass::kG2;
  throw py::value_error(fmt::format("require: \"{}\" is not G0, G1 or G2", *s));
}

std::optional<double> positive(const char* name, std::optional<double> x) {
  if (x && !(std::isfinite(*x) && *x > 0.0))
    throw py::value_error(fmt::format("{} must be a positive finite number, not {}", name, *x));
  return x;
}

/// units= and preset= as the CLI's --units and --preset: the same library parsers (core/units.h,
/// core/tolerance_presets.h); an unknown name raises ValueError.
void applyUnitsAndPreset(ToleranceOverrides& tol, const std::optional<std::string>& units,
                         const std::optional<std::string>& preset) {
  if (units) {
    tol.units = parseLengthUnit(*units);
    if (!tol.units) {
      std::string names;
      for (const LengthUnitInfo& u : kLengthUnits) {
        names += names.empty() ? "" : ", ";
        names += u.name;
      }
      throw py::value_error(fmt::format("units: \"{}\" is not a length unit (use {})", *units, names));
    }
  }
  if (preset && !applyTolerancePreset(tol, *preset)) {
    std::string names;
    for (const TolerancePreset& p : kTolerancePresets) {
      names += names.empty() ? "" : ", ";
      names += p.name;
    }
    throw py::value_error(fmt::format("preset: \"{}\" is not a preset (use {})", *preset, names));
  }
}

cli::FileCheckOptions checkOptions(std::optional<double> tolDistance, std::optional<double> tolAngle,
                                   std::optional<double> tolCurvature, std::optional<double> creaseAngle,
                                   const std::optional<std::string>& require, const std::string& sort,
                                   std::optional<size_t> top, const std::string& only, bool patches,
                                   const std::optional<std::string>& units, const std::optional<std::string>& preset,
                                   const std::optional<std::string>& displayUnits) {
  cli::FileCheckOptions o;
  o.tol.distance = positive("tol_distance", tolDistance);
  o.tol.angleDeg = positive("tol_angle", tolAngle);
  o.tol.curvatureRel = positive("tol_curvature", tolCurvature);
  applyUnitsAndPreset(o.tol, units, preset);
  if (displayUnits) {  // as --display-units (issue 38 §1)
    o.tol.display = parseLengthUnit(*displayUnits);
    if (!o.tol.display)
      throw py::value_error(fmt::format("display_units: \"{}\" is not a length unit (use mm, cm, m, in, ft, or inch)",
                                        *displayUnits));
  }
  o.require = parseRequire(require);
  if (creaseAngle) {
    if (!validCreaseAngle(*creaseAngle))
      throw py::value_error("crease_angle must be an angle in degrees in (0, 180]");
    o.selection.creaseAngleDeg = *creaseAngle;
  }
  const Result<SeamSortKey> key = parseSeamSortKey(sort);
  if (!key) throw py::value_error("sort: " + key.status().message());
  o.selection.sort = *key;
  const Result<SeamFilter> filter = parseSeamFilter(only);
  if (!filter) throw py::value_error("only: " + filter.status().message());
  o.selection.only = *filter;
  o.selection.top = top;
  o.patches = patches;
  return o;
}

py::object finishCheck(Result<cli::FileCheck>& r, const std::string& source) {
  if (!r) raise(r.status());
  if (!r->warnings.empty()) {
    py::module_ warn = py::module_::import("warnings");
    for (const std::string& w : r->warnings) warn.attr("warn")(fmt::format("{}: {}", source, w));
  }
  return toPython(r->json);
}

py::object checkPath(const std::filesystem::path& file, const cli::FileCheckOptions& o) {
  Result<cli::FileCheck> r = Status(ErrorCode::kIoError, "not checked");
  {
    py::gil_scoped_release release;
    if (isCadPath(file)) {
      std::lock_guard lock(cadMutex());
      r = cli::checkFile(file, o);
    } else {
      r = cli::checkFile(file, o);
    }
  }
  return finishCheck(r, file.string());
}

py::object checkLoaded(const PyModel& m, const cli::FileCheckOptions& o) {
  Result<cli::FileCheck> r = Status(ErrorCode::kIoError, "not checked");
  {
    py::gil_scoped_release release;
    try {
      // units= gives a loaded model the unit of its numbers, as --units does for a JSON/.bpt file; a STEP/IGES
      // model has its file's (millimetres).
      ModelUnits units = m.units;
      if (o.tol.units) {
        units.length = o.tol.units;
        units.source = UnitSource::kOption;
        units.display = o.tol.units;  // a loaded model's numbers in the stated unit are shown in it
        units.displaySource = UnitSource::kOption;
      }
      if (o.tol.display) {
        units.display = o.tol.display;
        units.displaySource = UnitSource::kDisplayOption;
      }
      r = cli::checkModel(m.model, m.source, o, units);
    } catch (const std::bad_alloc&) {
      r = Status(ErrorCode::kInvalidInput, m.source + ": out of memory while checking the model");
    }
  }
  return finishCheck(r, m.source);
}


/// The tolerances of a repair on a loaded model as `seam heal/join/fill MODEL.json [--units U] [--preset P]` resolve
/// them: unit-less (relative defaults) unless units= gives the model's numbers a length unit (then absolute, 0.001 mm
/// by default), preset= as --preset. The dicts carry them in "units" and "tolerances" as the CLI's --json does.
struct RepairUnits {
  ModelUnits units;
  ResolvedTolerances tol;
};
RepairUnits repairTolerances(const PyModel& m, const std::optional<std::string>& units,
                             const std::optional<std::string>& preset) {
  ToleranceOverrides overrides;
  applyUnitsAndPreset(overrides, units, preset);
  RepairUnits r;
  r.units = m.units;  // a STEP/IGES model's millimetres, as the CLI's heal of the same file
  r.units.display.reset();  // the repairs report in the model's unit (the B-rep heal's JSON names its own)
  if (overrides.units) {
    r.units.length = overrides.units;
    r.units.source = UnitSource::kOption;
  }
  r.tol = resolveTolerances(overrides, r.units, m.model.boundingBox().diagonal());
  return r;
}

/// The JSON text of a repair report with "units" and "tolerances" added (repair_units_json.h) as a Python dict.
py::object repairDict(const std::string& json, const RepairUnits& ru) {
  cli::OrderedJson j = cli::OrderedJson::parse(json);
  cli::addRepairUnits(j, ru.units, ru.tol);
  return toPython(j);
}

/// heal of a model with trimmed faces: the B-rep heal of the STEP/IGES file it was read from (occt::healBRepFile,
/// as `seam heal FILE -o OUT.step`: every face, trim, edge and solid kept), into a temporary file of the same format
/// that is read back as the healed model, then removed; a model that holds its B-rep but no file of it (a JSON with
/// "brep", a model healed before) is healed as that B-rep (occt::healBRepModel, as `seam heal IN.json`).
py::tuple healBRep(const PyModel& m, const HealOptions& ho, const std::string& method,
                   const std::optional<std::string>& units, const std::optional<std::string>& preset) {
#ifdef SEAM_HAVE_OCCT
  const std::filesystem::path in = m.source;
  const bool fromFile = isCadPath(in) && std::filesystem::is_regular_file(in);
  if (!fromFile && !m.model.brep)
    throw py::value_error(fmt::format("{}: {} faces of the model are trimmed but it holds no B-rep: a trimmed model "
                                      "is healed as a B-rep, never as patches without their trims",
                                      m.source, m.model.trimmedFaces));
  if (method != "auto")
    throw py::value_error("method: a STEP/IGES B-rep is healed face by face along its pcurves (method=\"auto\" only)");
  occt::BRepHealOptions bo;
  applyUnitsAndPreset(bo.tolerances, units, preset);
  bo.continuity = ho.continuity;
  bo.maxGap = ho.maxGap;
  if (ho.maxAngleDeg) bo.creaseAngleDeg = *ho.maxAngleDeg;
  std::optional<occt::BRepModelHeal> healed;
  if (fromFile) {
    std::filesystem::path temp = io::temporaryPathFor(std::filesystem::temp_directory_path() / "healed");
    temp += in.extension();
    const io::RemoveOnExit remove{temp};
    Result<occt::BRepHealReport> r = Status(ErrorCode::kIoError, "not healed");
    {
      py::gil_scoped_release release;
      std::lock_guard lock(cadMutex());
      r = occt::healBRepFile(in, temp, bo);
    }
    if (!r) raise(r.status());
    std::vector<std::string> readWarnings;  // the input's, as load() gave them; they name the temporary file
    healed = occt::BRepModelHeal{std::move(r).value(), readAnyModel(temp, readWarnings)};
  } else {
    Result<occt::BRepModelHeal> r = Status(ErrorCode::kIoError, "not healed");
    {
      py::gil_scoped_release release;
      std::lock_guard lock(cadMutex());
      r = occt::healBRepModel(m.model, m.source, occt::CadFormat::kStep, bo);
    }
    if (!r) raise(r.status());
    healed = std::move(r).value();
  }
  if (!healed->report.warnings.empty()) {
    py::module_ warn = py::module_::import("warnings");
    for (const std::string& w : healed->report.warnings) warn.attr("warn")(fmt::format("{}: {}", m.source, w));
  }
  py::object dict = toPython(cli::brepHealJson(healed->report, m.source, std::nullopt));
  return py::make_tuple(PyModel{std::move(healed->model), m.source + " (healed)", m.units}, std::move(dict));
#else
  (void)ho;
  (void)method;
  (void)units;
  (void)preset;
  throw py::value_error(fmt::format("{}: {} faces of the model are trimmed, and this build has no OpenCASCADE to heal "
                                    "a B-rep", m.source, m.model.trimmedFaces));
#endif
}

/// heal: the healed model and the dict of `seam heal --json` (without its "output").
py::tuple heal(const PyModel& m, const std::string& continuity, const std::string& method,
               std::optional<double> maxGap, std::optional<double> creaseAngle, const std::optional<std::string>& units,
               const std::optional<std::string>& preset, double fairness) {
  HealOptions ho;
  if (!(fairness >= 0.0 && std::isfinite(fairness))) throw py::value_error("fairness must be a finite number >= 0");
  ho.g2Fairness = fairness;
  if (continuity == "G0") ho.continuity = GeometricClass::kG0;
  else if (continuity == "G1") ho.continuity = GeometricClass::kG1;
  else if (continuity == "G2") ho.continuity = GeometricClass::kG2;
  else throw py::value_error(fmt::format("continuity: \"{}\" is not G0, G1 or G2", continuity));
  const Result<HealMethod> hm = parseHealMethod(method);
  if (!hm) throw py::value_error("method: " + hm.status().message());
  ho.method = *hm;
  ho.maxGap = positive("max_gap", maxGap);
  if (creaseAngle) {
    if (!(*creaseAngle > 0.0 && *creaseAngle <= 180.0))
      throw py::value_error("crease_angle must be an angle in degrees in (0, 180]");
    ho.maxAngleDeg = creaseAngle;
  }
  if (m.model.patches.empty()) throw py::value_error(m.source + ": the model has no patches: nothing to heal");
  if (m.model.trimmedFaces > 0) return healBRep(m, ho, method, units, preset);
  const RepairUnits tol = repairTolerances(m, units, preset);
  ho.tolerances = tol.tol.tolerances;
  Result<HealResult> r = Status(ErrorCode::kIoError, "not healed");
  std::string json;
  {
    py::gil_scoped_release release;
    r = healModel(m.model, ho);
    if (r) json = healReportJson(r->report);
  }
  if (!r) raise(r.status().withContext(m.source));
  PyModel healed{std::move(r->model), m.source + " (healed)", m.units};
  return py::make_tuple(std::move(healed), repairDict(json, tol));
}

/// report: the HTML page of `seam report` for a patch model, written atomically; returns the path.
std::string writeBRepReport(const std::filesystem::path& file, const std::filesystem::path& out,
                            const std::optional<std::string>& title, const std::optional<std::string>& units,
                            const std::optional<std::string>& preset, const Model* model);

std::string writeReport(const PyModel& m, const std::filesystem::path& out, const std::optional<std::string>& title) {
  if (m.model.patches.empty()) throw py::value_error(m.source + ": the model has no patches: nothing to check");
#ifdef SEAM_HAVE_OCCT
  // A model with its trimmed faces' topology (a JSON with "brep", or loaded from STEP/IGES): the B-rep page, as
  // `seam report` of the JSON.
  if (m.model.brep) return writeBRepReport(m.source, out, title, std::nullopt, std::nullopt, &m.model);
#endif
  if (const Status s = io::checkOutputFile(out); !s) raise(s);
  Status written = Status::ok();
  {
    py::gil_scoped_release release;
    ModelCheckOptions mo;
    mo.tolerances = Tolerances::forModelSize(m.model.boundingBox().diagonal());
    mo.seam.keepSamples = true;
    mo.findOverlaps = true;  // as `seam report`
    const Result<ModelCheckReport> checked = checkModel(m.model, mo);
    if (!checked) {
      written = checked.status().withContext(m.source);
    } else {
      report::HtmlReportOptions ro;
      ro.title = title ? *title : "seam report: " + std::filesystem::path(m.source).filename().string();
      written = io::writeFileAtomically(out, report::htmlReport(m.model, *checked, ro));
    }
  }
  if (!written) raise(written);
  return out.string();
}

void save(const PyModel& m, const std::filesystem::path& out) {
  std::string ext = out.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (const Status s = io::checkOutputFile(out); !s) raise(s);
#ifdef SEAM_HAVE_OCCT
  // STEP/IGES as `seam convert x.json y.step`: a model with its B-rep (one loaded or healed from STEP/IGES) keeps
  // every face, trim, edge and solid; a trimmed model without it is refused; untrimmed patches are sewn.
  if (const std::optional<occt::CadFormat> format = occt::cadFormatOf(out)) {
    Status written = Status::ok();
    {
      py::gil_scoped_release release;
      std::lock_guard lock(cadMutex());
      written = occt::writeCadFile(m.model, out, *format);
    }
    if (!written) raise(written);
    return;
  }
#endif
  if (ext != ".json")
    throw py::value_error(fmt::format("{}: save writes .json, .step/.stp and .iges/.igs models", out.string()));
  if (const Status s = io::writeModelJson(m.model, out); !s) raise(s);
}


/// report of a STEP/IGES path: the page of `seam report FILE` (apps/common/brep_report.h, the CLI's builder),
/// written atomically; returns the path.
std::string writeBRepReport(const std::filesystem::path& file, const std::filesystem::path& out,
                            const std::optional<std::string>& title, const std::optional<std::string>& units,
                            const std::optional<std::string>& preset, const Model* model = nullptr) {
  ToleranceOverrides tol;
  applyUnitsAndPreset(tol, units, preset);
  if (const Status s = io::checkOutputFile(out); !s) raise(s);
  if (model == nullptr)
    if (const Status s = io::checkInputFile(file, io::kMaxCadFileBytes); !s) raise(s);
  report::HtmlReportOptions ro;
  ro.title = title ? *title : "seam report: " + file.filename().string();
  Result<cli::BRepReportPage> page = Status(ErrorCode::kIoError, "not read");
  Status written = Status::ok();
  {
    py::gil_scoped_release release;
    std::lock_guard lock(cadMutex());
    try {
      page = cli::brepReportPage(file, tol, ro, {}, model);
    } catch (const std::bad_alloc&) {
      page = Status(ErrorCode::kInvalidInput, file.string() + ": out of memory while checking the model");
    }
    if (page) written = io::writeFileAtomically(out, page->html);
  }
  if (!page) raise(page.status());
  if (!written) raise(written);
  if (!page->warnings.empty()) {
    py::module_ warn = py::module_::import("warnings");
    for (const std::string& w : page->warnings) warn.attr("warn")(w);
  }
  return out.string();
}

/// JSON text of the library's report builders (repair/report_json.h) -> a Python dict, keys in order.
py::object jsonToPython(const std::string& text) { return toPython(cli::OrderedJson::parse(text)); }

Edge edgeArg(const char* what, const std::string& name) {
  const Result<Edge> e = parseEdge(name);
  if (!e) throw py::value_error(fmt::format("{}: {}", what, e.status().message()));
  return *e;
}

GeometricClass continuityArg(const std::string& name) {
  const Result<GeometricClass> c = parseContinuity(name);
  if (!c) throw py::value_error("continuity: " + c.status().message());
  return *c;
}

std::optional<double> nonNegative(const char* name, std::optional<double> x) {
  if (x && !(std::isfinite(*x) && *x >= 0.0))
    throw py::value_error(fmt::format("{} must be a non-negative finite number, not {}", name, *x));
  return x;
}

double creaseAngleArg(std::optional<double> a) {
  if (a && !validCreaseAngle(*a)) throw py::value_error("crease_angle must be an angle in degrees in (0, 180]");
  return a.value_or(kDefaultCreaseAngleDeg);
}

/// join: `seam join FILE --move P:E --to Q:E`: (the joined model, the dict of `seam join --json` without "output").
py::tuple join(const PyModel& m, const std::string& movePatch, const std::string& moveEdge, const std::string& toPatch,
               const std::string& toEdge, const std::string& continuity, const std::string& method,
               std::optional<double> ell, bool average, std::optional<double> maxGap,
               std::optional<double> maxDisplacement, std::optional<double> creaseAngle,
               const std::optional<std::string>& units, const std::optional<std::string>& preset) {
  JoinOptions jo;
  const Edge me = edgeArg("move_edge", moveEdge), te = edgeArg("to_edge", toEdge);
  jo.continuity = continuityArg(continuity);
  const Result<JoinMethod> jm = parseJoinMethod(method);
  if (!jm) throw py::value_error("method: " + jm.status().message());
  jo.method = *jm;
  if (ell && !std::isfinite(*ell)) throw py::value_error("ell must be a finite number");
  jo.ell = ell;
  jo.average = average;
  jo.maxGap = nonNegative("max_gap", maxGap);
  if (maxDisplacement) jo.maxDisplacementRel = *nonNegative("max_displacement", maxDisplacement);
  jo.creaseAngleDeg = creaseAngleArg(creaseAngle);
  const RepairUnits tol = repairTolerances(m, units, preset);
  jo.tolerances = tol.tol.tolerances;
  Result<JoinResult> r = Status(ErrorCode::kIoError, "not joined");
  std::string json;
  {
    py::gil_scoped_release release;
    r = joinSeam(m.model, movePatch, me, toPatch, te, jo);
    if (r) json = joinReportJson(r->report);
  }
  if (!r) raise(r.status().withContext(m.source));
  PyModel joined{std::move(r->model), m.source + " (joined)", m.units};
  return py::make_tuple(std::move(joined), repairDict(json, tol));
}

/// One "PATCH:EDGE[:EDGE]" corner argument of `seam corner`, as a sequence (patch, edge[, edge]).
std::pair<std::string, std::vector<Edge>> cornerArg(const char* what, const std::vector<std::string>& item,
                                                    size_t edges) {
  if (item.size() != edges + 1)
    throw py::value_error(fmt::format("{}: expected (patch{}), got {} items", what,
                                      edges == 2 ? ", edge, edge" : ", edge", item.size()));
  std::vector<Edge> e;
  for (size_t k = 1; k <= edges; ++k) e.push_back(edgeArg(what, item[k]));
  return {item[0], e};
}

/// corner: `seam corner --three` / `--four` (Lai-Lian-Cassidy §4.1): (model, the dict of `seam corner --json`).
py::tuple corner(const PyModel& m, const std::optional<std::vector<std::vector<std::string>>>& three,
                 const std::optional<std::vector<std::vector<std::string>>>& four, const std::string& method,
                 const std::string& fallback, std::optional<double> maxGap) {
  if (three.has_value() == four.has_value()) throw py::value_error("corner: give exactly one of three= or four=");
  CornerJoinOptions co;
  const Result<JoinMethod> jm = parseJoinMethod(method);
  if (!jm) throw py::value_error("method: " + jm.status().message());
  co.method = *jm;
  const Result<JoinMethod> fb = parseJoinMethod(fallback);
  if (!fb) throw py::value_error("fallback: " + fb.status().message());
  co.fallback = *fb;
  co.maxGap = nonNegative("max_gap", maxGap);
  Status status = Status::ok();
  std::string json;
  Model out;
  if (three) {
    if (three->size() != 3) throw py::value_error("three: expected (S, edge, edge), (S~, edge, edge), (S^, edge)");
    const auto s = cornerArg("three", (*three)[0], 2), t = cornerArg("three", (*three)[1], 2),
               h = cornerArg("three", (*three)[2], 1);
    const ThreePatchCorner c{s.first, t.first, h.first, s.second[0], t.second[0], s.second[1], t.second[1],
                             h.second[0]};
    py::gil_scoped_release release;
    Result<ThreePatchJoinResult> r = joinThreePatchCorner(m.model, c, co);
    if (r) {
      json = threePatchJoinJson(*r);
      out = std::move(r->model);
    } else {
      status = r.status();
    }
  } else {
    if (four->size() != 4) throw py::value_error("four: expected four (patch, edge to next, edge to previous)");
    FourPatchCorner c;
    for (size_t k = 0; k < 4; ++k) {
      const auto p = cornerArg("four", (*four)[k], 2);
      c.patches[k] = p.first;
      c.toNext[k] = p.second[0];
      c.toPrev[k] = p.second[1];
    }
    py::gil_scoped_release release;
    Result<FourPatchJoinResult> r = joinFourPatchCorner(m.model, c, co);
    if (r) {
      json = fourPatchJoinJson(*r);
      out = std::move(r->model);
    } else {
      status = r.status();
    }
  }
  if (!status) raise(status.withContext(m.source));
  return py::make_tuple(PyModel{std::move(out), m.source + " (corner joined)", m.units}, jsonToPython(json));
}

/// fill: `seam fill` (Johansson §4): (the model with the new patches appended, or None when nothing was built, and
/// the dict of `seam fill --json`; its "output" is None).
py::tuple fill(const PyModel& m, const std::optional<std::vector<std::string>>& quad, bool hole,
               const std::vector<std::string>& around,
               const std::optional<std::pair<std::vector<std::string>, std::vector<std::string>>>& fillet, int degree,
               const std::string& name, const std::optional<std::string>& units,
               const std::optional<std::string>& preset) {
  const int modes = (quad ? 1 : 0) + (hole ? 1 : 0) + (fillet ? 1 : 0);
  if (modes != 1) throw py::value_error("fill: give exactly one of quad=(A, B, C), hole=True, fillet=(strip1, strip2)");
  if (!around.empty() && !hole) throw py::value_error("fill: around= needs hole=True");
  if (quad && quad->size() != 3)
    throw py::value_error(fmt::format("quad: expected three patch names (corner, b, c), got {}", quad->size()));
  if (degree != 4 && degree != 5 && degree != 6)
    throw py::value_error(fmt::format("degree: {} is not 4, 5 or 6 (Sarraga's, kappa = 0)", degree));
  constexpr int kMaxFillDegree = 8;  // as `seam fill`
  FillOptions options;
  options.name = name;
  options.patch.degreeU = options.patch.degreeV = degree;
  options.patch.maxDegree = kMaxFillDegree;
  options.patch.kappaZero = degree == 6;
  const RepairUnits tol = repairTolerances(m, units, preset);
  options.tolerances = tol.tol.tolerances;
  const std::string mode = quad ? "quad" : hole ? "hole" : "fillet";
  Status status = Status::ok();
  cli::OrderedJson json;
  std::optional<Model> full;
  {
    py::gil_scoped_release release;
    Result<FillResult> r = quad   ? fillQuad(m.model, (*quad)[0], (*quad)[1], (*quad)[2], options)
                           : hole ? fillHole(m.model, around, options)
                                  : fillFillet(m.model, fillet->first, fillet->second, options);
    if (!r) {
      status = r.status().withContext(m.source);
    } else {
      Model withNew = withFill(m.model, *r);
      std::optional<FillCheck> check;
      if (r->surroundingG1) {
        Result<FillCheck> c = checkFill(m.model, *r, options);
        if (!c) status = Status(ErrorCode::kNoSolution, fmt::format("{}: verification failed: {}", m.source,
                                                                   c.status().message()));
        else check = std::move(c).value();
      }
      if (status) {
        json = cli::fillJson(mode, *r, check ? &*check : nullptr, withNew, options.patch, std::nullopt);
        cli::addRepairUnits(json, tol.units, tol.tol);
        if (r->surroundingG1) full = std::move(withNew);
      }
    }
  }
  if (!status) raise(status);
  py::object model = full ? py::cast(PyModel{std::move(*full), m.source + " (filled)", m.units}) : py::none();
  return py::make_tuple(model, toPython(json));
}

/// regularity: the dict of `seam regularity FILE [--patch P | --curve C] [--ell L] --json`.
py::object regularityOf(const PyModel& m, const std::optional<std::string>& patch,
                        const std::optional<std::string>& curve, int ell) {
  if (patch && curve) throw py::value_error("regularity: give patch= or curve=, not both");
  if (ell < 0) throw py::value_error(fmt::format("ell must be >= 0, not {}", ell));
  std::vector<const Curve*> curves;
  std::vector<const Patch*> patches;
  if (curve) {
    const Curve* c = m.model.findCurve(*curve);
    if (c == nullptr) throw py::value_error(fmt::format("{}: no curve named \"{}\"", m.source, *curve));
    curves.push_back(c);
  } else if (patch) {
    patches.push_back(&findPatch(m, *patch));
  } else {
    for (const Curve& c : m.model.curves) curves.push_back(&c);
    for (const Patch& p : m.model.patches) patches.push_back(&p);
  }
  regularity::RegularityOptions options;
  options.maxEll = ell;
  std::vector<std::string> curveNames, patchNames;
  std::vector<regularity::CurveRegularity> curveResults;
  std::vector<regularity::SurfaceRegularity> patchResults;
  Status status = Status::ok();
  cli::OrderedJson json;
  {
    py::gil_scoped_release release;
    // Every object on TBB's threads (regularity::analyzeSurfaces); the first error in the model's order is raised.
    std::vector<const BSplineCurve*> curveOf;
    std::vector<const BSplineSurface*> surfaceOf;
    for (const Curve* c : curves) curveOf.push_back(&c->curve);
    for (const Patch* p : patches) surfaceOf.push_back(&p->surface);
    std::vector<Result<regularity::CurveRegularity>> cr = regularity::analyzeCurves(curveOf, options);
    std::vector<Result<regularity::SurfaceRegularity>> pr = regularity::analyzeSurfaces(surfaceOf, options);
    for (size_t i = 0; i < curves.size() && status; ++i) {
      if (!cr[i]) status = Status(cr[i].status().code(), fmt::format("{}: curve \"{}\": {}", m.source,
                                                                    curves[i]->name, cr[i].status().message()));
      else curveNames.push_back(curves[i]->name), curveResults.push_back(std::move(cr[i]).value());
    }
    for (size_t i = 0; i < patches.size() && status; ++i) {
      if (!pr[i]) status = Status(pr[i].status().code(), fmt::format("{}: patch \"{}\": {}", m.source,
                                                                    patches[i]->name, pr[i].status().message()));
      else patchNames.push_back(patches[i]->name), patchResults.push_back(std::move(pr[i]).value());
    }
    if (status) json = cli::regularityJson(m.source, curveNames, curveResults, patchNames, patchResults);
  }
  if (!status) raise(status);
  return toPython(json);
}

/// A model from JSON text (the format of docs/format.md); `source` names it in messages.
PyModel loads(const std::string& text, const std::string& source) {
  Result<Model> r = io::parseModelJson(text, source);
  if (!r) raise(r.status());
  return PyModel{std::move(r).value(), source, {}};
}

/// The control points of a patch: (nu, nv, dim), [i, j] the point with index i along u, j along v.
py::array_t<double> controlPoints(const PyModel& m, const std::string& name) {
  const BSplineSurface& s = findPatch(m, name).surface;
  py::array_t<double> out({py::ssize_t{s.numU()}, py::ssize_t{s.numV()}, py::ssize_t{s.dim()}});
  auto o = out.mutable_unchecked<3>();
  for (int i = 0; i < s.numU(); ++i)
    for (int j = 0; j < s.numV(); ++j)
      for (int c = 0; c < s.dim(); ++c) o(i, j, c) = s.point(i, j)[c];
  return out;
}

}  // namespace

}  // namespace seam::python

PYBIND11_MODULE(_seam, mod) {
  using namespace seam;
  using namespace seam::python;
  mod.doc() = "seam: geometric continuity of spline surfaces (G0/G1/G2 seams, certified bounds)";
  mod.attr("__version__") = kVersion;
#ifdef SEAM_HAVE_OCCT
  mod.attr("has_occt") = true;
#else
  mod.attr("has_occt") = false;
#endif

  py::class_<PyModel>(mod, "Model", "A model: named patches and curves, read from .json, .bpt, .step/.stp, .iges/.igs")
      .def_readonly("source", &PyModel::source, "The file the model was read from")
      .def_property_readonly("patch_names", [](const PyModel& m) {
        std::vector<std::string> n;
        for (const Patch& p : m.model.patches) n.push_back(p.name);
        return n;
      })
      .def_property_readonly("curve_names", [](const PyModel& m) {
        std::vector<std::string> n;
        for (const Curve& c : m.model.curves) n.push_back(c.name);
        return n;
      })
      .def("domain", [](const PyModel& m, const std::string& name) {
        const Patch& p = findPatch(m, name);
        const Interval u = p.surface.domainU(), v = p.surface.domainV();
        return py::make_tuple(py::make_tuple(u.lo, u.hi), py::make_tuple(v.lo, v.hi));
      }, py::arg("patch"), "The parameter domain ((u0, u1), (v0, v1)) of a patch")
      .def("bounding_box", [](const PyModel& m) {
        const BoundingBox b = m.model.boundingBox();
        py::array_t<double> out({py::ssize_t{2}, py::ssize_t{3}});
        auto o = out.mutable_unchecked<2>();
        for (int c = 0; c < 3; ++c) o(0, c) = b.min[c], o(1, c) = b.max[c];
        return out;
      }, "Rows min and max of the control points' box")
      .def("control_points", &controlPoints, py::arg("patch"),
           "The control points of a patch: (nu, nv, dim), [i, j] = index i along u, j along v")
      .def("__len__", [](const PyModel& m) { return m.model.patches.size(); })
      .def("__repr__", [](const PyModel& m) {
        return fmt::format("<seam.Model {} patches, {} curves from {}>", m.model.patches.size(), m.model.curves.size(),
                           m.source);
      });

  mod.def("load", &load, py::arg("path"),
          "Reads a model (.json, .bpt; .step/.stp/.iges/.igs when built with OpenCASCADE). Raises OSError when the "
          "file cannot be read, ValueError when it is invalid.");
  mod.def("evaluate", &evaluate, py::arg("model"), py::arg("patch"), py::arg("uv"),
          "Points of a patch at an (n, 2) array of (u, v): an (n, dim) array");
  mod.def("derivatives", &derivatives, py::arg("model"), py::arg("patch"), py::arg("uv"), py::arg("order"),
          "Derivatives of a patch: (n, order+1, order+1, dim), [i, k, l] = d^(k+l) S / du^k dv^l at uv[i] "
          "(NaN where k + l > order)");
  mod.def("evaluate_curve", &evaluateCurve, py::arg("model"), py::arg("curve"), py::arg("t"), py::arg("order") = 0,
          "Points and derivatives of a curve: (n, order+1, dim), [i, k] = d^k C / dt^k at t[i]");

  mod.def("loads", &loads, py::arg("text"), py::arg("source") = "<string>",
          "A model from JSON text in seam's model format (docs/format.md); source names it in messages. Raises "
          "ValueError when it is invalid.");
  mod.def("dumps", [](const PyModel& m) { return io::modelToJson(m.model); }, py::arg("model"),
          "The model as JSON text (what save writes)");
  mod.def("join", &join, py::arg("model"), py::arg("move_patch"), py::arg("move_edge"), py::arg("to_patch"),
          py::arg("to_edge"), py::kw_only(), py::arg("continuity") = "G1", py::arg("method") = "auto",
          py::arg("ell") = py::none(), py::arg("average") = false, py::arg("max_gap") = py::none(),
          py::arg("max_displacement") = py::none(), py::arg("crease_angle") = py::none(), py::arg("units") = py::none(),
          py::arg("preset") = py::none(),
          "`seam join`: moves edge move_edge ('u0', 'u1', 'v0', 'v1') of move_patch onto edge to_edge of to_patch "
          "with the requested continuity (G0, G1, G2), never making the seam worse: (joined Model, the dict of "
          "`seam join --json`). ValueError for bad input (unknown patch, edges that do not meet, a gap above max_gap, "
          "a method that does not apply). units= and preset= as --units and --preset (the classification "
          "tolerances; the dict's \"units\" and \"tolerances\").");
  mod.def("corner", &corner, py::arg("model"), py::kw_only(), py::arg("three") = py::none(),
          py::arg("four") = py::none(), py::arg("method") = "auto", py::arg("fallback") = "bezier-strip",
          py::arg("max_gap") = py::none(),
          "`seam corner` (Lai-Lian-Cassidy §4.1): three=((S, e, e), (S~, e, e), (S^, e)) or four=((P1, next, prev), "
          "...): (Model, the dict of `seam corner --json`)");
  mod.def("fill", &fill, py::arg("model"), py::kw_only(), py::arg("quad") = py::none(), py::arg("hole") = false,
          py::arg("around") = std::vector<std::string>{}, py::arg("fillet") = py::none(), py::arg("degree") = 5,
          py::arg("name") = "", py::arg("units") = py::none(), py::arg("preset") = py::none(),
          "`seam fill` (exact G1 Bezier patches, Johansson §4): quad=(corner, b, c) the 4th patch at a vertex, "
          "hole=True [around=names] four-sided holes, fillet=(strip1, strip2): (the model with the new patches "
          "appended, or None when a hole's surrounding is not G1 and nothing was built, the dict of "
          "`seam fill --json`)");
  mod.def("regularity", &regularityOf, py::arg("model"), py::kw_only(), py::arg("patch") = py::none(),
          py::arg("curve") = py::none(), py::arg("ell") = regularity::RegularityOptions{}.maxEll,
          "`seam regularity --json`: control-net regularity certificates and the search for cusps and "
          "self-intersections of every curve and patch (or one): the dict {file, curves, patches}");
  mod.def("regularity",
          [](const std::filesystem::path& file, const std::optional<std::string>& patch,
             const std::optional<std::string>& curve, int ell) { return regularityOf(load(file), patch, curve, ell); },
          py::arg("file"), py::kw_only(), py::arg("patch") = py::none(), py::arg("curve") = py::none(),
          py::arg("ell") = regularity::RegularityOptions{}.maxEll, "`seam regularity FILE --json` of a model file");
  mod.def("heal", &heal, py::arg("model"), py::kw_only(), py::arg("continuity") = "G1", py::arg("method") = "auto",
          py::arg("max_gap") = py::none(), py::arg("crease_angle") = py::none(), py::arg("units") = py::none(),
          py::arg("preset") = py::none(), py::arg("fairness") = kDefaultG2Fairness,
          "Makes every seam G1 (or G0, or G2 by the network solve) where it can, never worse: (healed Model, the dict "
          "of `seam heal --json`); "
          "units= and preset= as --units and --preset; fairness= as --fairness (G2)");
  mod.def("report", &writeReport, py::arg("model"), py::arg("path"), py::kw_only(), py::arg("title") = py::none(),
          "Writes the self-contained HTML report of `seam report` (patch models) atomically; returns the path");
  mod.def("report",
          [](const std::filesystem::path& file, const std::filesystem::path& out, const std::optional<std::string>& title,
             const std::optional<std::string>& units, const std::optional<std::string>& preset) {
            if (isCadPath(file)) return writeBRepReport(file, out, title, units, preset);
            if (units || preset)
              throw py::value_error(fmt::format("{}: units= and preset= apply to the B-rep report of a STEP/IGES "
                                                "file", file.string()));
            return writeReport(load(file), out, title);
          },
          py::arg("file"), py::arg("path"), py::kw_only(), py::arg("title") = py::none(),
          py::arg("units") = py::none(), py::arg("preset") = py::none(),
          "`seam report FILE -o PATH`: a .json/.bpt model file, or the B-rep report of a STEP/IGES file (every "
          "shared edge, OpenCASCADE alongside, trimmed faces shaded); returns the path");
  mod.def("save", &save, py::arg("model"), py::arg("path"), "Writes a model as .json, or as STEP/IGES by the extension (the B-rep of a model loaded or healed from STEP/IGES kept), atomically");

  auto checkDoc =
      "Continuity of every seam, corner and free edge: the dict of `seam check FILE --json` with the same options "
      "(a STEP/IGES path is checked as a B-rep unless patches=True; display_units= as --display-units: every "
      "length in that unit, a STEP/IGES file's own by default). Raises ValueError/OSError on bad input.";
  mod.def("check",
          [](const std::filesystem::path& path, std::optional<double> tolDistance, std::optional<double> tolAngle,
             std::optional<double> tolCurvature, std::optional<double> creaseAngle,
             const std::optional<std::string>& require, const std::string& sort, std::optional<size_t> top,
             const std::string& only, bool patches, const std::optional<std::string>& units,
             const std::optional<std::string>& preset, const std::optional<std::string>& displayUnits) {
            return checkPath(path, checkOptions(tolDistance, tolAngle, tolCurvature, creaseAngle, require, sort, top,
                                                only, patches, units, preset, displayUnits));
          },
          py::arg("path"), py::kw_only(), py::arg("tol_distance") = py::none(), py::arg("tol_angle") = py::none(),
          py::arg("tol_curvature") = py::none(), py::arg("crease_angle") = py::none(), py::arg("require") = py::none(),
          py::arg("sort") = "file", py::arg("top") = py::none(), py::arg("only") = "all", py::arg("patches") = false,
          py::arg("units") = py::none(), py::arg("preset") = py::none(), py::arg("display_units") = py::none(),
          checkDoc);
  mod.def("check",
          [](const PyModel& m, std::optional<double> tolDistance, std::optional<double> tolAngle,
             std::optional<double> tolCurvature, std::optional<double> creaseAngle,
             const std::optional<std::string>& require, const std::string& sort, std::optional<size_t> top,
             const std::string& only, const std::optional<std::string>& units,
             const std::optional<std::string>& preset, const std::optional<std::string>& displayUnits) {
            return checkLoaded(m, checkOptions(tolDistance, tolAngle, tolCurvature, creaseAngle, require, sort, top,
                                               only, false, units, preset, displayUnits));
          },
          py::arg("model"), py::kw_only(), py::arg("tol_distance") = py::none(), py::arg("tol_angle") = py::none(),
          py::arg("tol_curvature") = py::none(), py::arg("crease_angle") = py::none(), py::arg("require") = py::none(),
          py::arg("sort") = "file", py::arg("top") = py::none(), py::arg("only") = "all",
          py::arg("units") = py::none(), py::arg("preset") = py::none(), py::arg("display_units") = py::none(),
          checkDoc);
}
