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

#include "check_json.h"
#include "seam/continuity/verdict.h"
#include "seam/io/file.h"
#include "seam/io/json.h"
#include "seam/repair/heal.h"
#include "seam/repair/report_json.h"
#include "seam/report/report.h"
#include "seam/model/model.h"
#include "seam/version.h"
#ifdef SEAM_HAVE_OCCT
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
};

Model readAnyModel(const std::filesystem::path& file, std::vector<std::string>& warnings) {
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
  PyModel m{readAnyModel(file, warnings), file.string()};
  if (!warnings.empty()) {
    py::module_ warn = py::module_::import("warnings");
    for (const std::string& w : warnings) warn.attr("warn")(fmt::format("{}: {}", file.string(), w));
  }
  return m;
}

/// The (n, 2) parameter array of evaluate/derivatives: a (2,) array is one point.
py::array_t<double> asUV(py::array_t<double, py::array::c_style | py::array::forcecast> uv,
                         const std::string& object) {
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
py::array_t<double> derivatives(const PyModel& m, const std::string& name, const py::array_t<double>& uvIn,
                                int order) {
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

py::array_t<double> evaluate(const PyModel& m, const std::string& name, const py::array_t<double>& uvIn) {
  py::array_t<double> d = derivatives(m, name, uvIn, 0);
  return d.reshape({d.shape(0), d.shape(3)});
}

/// Curve points and derivatives: shape (n, order+1, dim), [i, k] = d^k C / dt^k at t[i].
py::array_t<double> evaluateCurve(const PyModel& m, const std::string& name,
                                  py::array_t<double, py::array::c_style | py::array::forcecast> tIn,
                                  int order) {
  const Curve* c = m.model.findCurve(name);
  if (c == nullptr) throw py::value_error(fmt::format("{}: no curve named \"{}\"", m.source, name));
  const std::string object = fmt::format("{}: curve \"{}\"", m.source, name);
  if (order < 0 || order > 32) throw py::value_error(fmt::format("{}: derivative order {} is not in 0..32", object, order));
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

cli::FileCheckOptions checkOptions(std::optional<double> tolDistance, std::optional<double> tolAngle,
                                   std::optional<double> tolCurvature, std::optional<double> creaseAngle,
                                   const std::optional<std::string>& require, const std::string& sort,
                                   std::optional<size_t> top, const std::string& only, bool patches) {
  cli::FileCheckOptions o;
  o.tol.distance = positive("tol_distance", tolDistance);
  o.tol.angleDeg = positive("tol_angle", tolAngle);
  o.tol.curvatureRel = positive("tol_curvature", tolCurvature);
  o.require = parseRequire(require);
  if (creaseAngle) {
    if (!validCreaseAngle(*creaseAngle))
      throw py::value_error("crease_angle must be an angle in degrees in (0, 180]");
    o.selection.creaseAngleDeg = *creaseAngle;
  }
  const Result<SeamSortKey> key = parseSeamSortKey(sort);
  if (!key) throw py::value_error("sort: " + key.status().message());
  o.selection.sort = *key;
  if (only != "problems" && only != "all")
    throw py::value_error(fmt::format("only: \"{}\" is not \"problems\" (gaps and kinks) or \"all\"", only));
  o.selection.onlyProblems = only == "problems";
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
      r = cli::checkModel(m.model, m.source, o);
    } catch (const std::bad_alloc&) {
      r = Status(ErrorCode::kInvalidInput, m.source + ": out of memory while checking the model");
    }
  }
  return finishCheck(r, m.source);
}


/// heal: the healed model and the dict of `seam heal --json` (without its "output").
py::tuple heal(const PyModel& m, const std::string& continuity, const std::string& method,
               std::optional<double> maxGap, std::optional<double> creaseAngle) {
  HealOptions ho;
  if (continuity == "G0") ho.continuity = GeometricClass::kG0;
  else if (continuity == "G1") ho.continuity = GeometricClass::kG1;
  else throw py::value_error(fmt::format("continuity: \"{}\" is not G0 or G1 (G2: join seam by seam)", continuity));
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
  Result<HealResult> r = Status(ErrorCode::kIoError, "not healed");
  std::string json;
  {
    py::gil_scoped_release release;
    r = healModel(m.model, ho);
    if (r) json = healReportJson(r->report);
  }
  if (!r) raise(r.status().withContext(m.source));
  PyModel healed{std::move(r->model), m.source + " (healed)"};
  return py::make_tuple(std::move(healed), py::module_::import("json").attr("loads")(json));
}

/// report: the HTML page of `seam report` for a patch model, written atomically; returns the path.
std::string writeReport(const PyModel& m, const std::filesystem::path& out, const std::optional<std::string>& title) {
  if (m.model.patches.empty()) throw py::value_error(m.source + ": the model has no patches: nothing to check");
  if (const Status s = io::checkOutputFile(out); !s) raise(s);
  Status written = Status::ok();
  {
    py::gil_scoped_release release;
    ModelCheckOptions mo;
    mo.tolerances = Tolerances::forModelSize(m.model.boundingBox().diagonal());
    mo.seam.keepSamples = true;
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
  if (ext != ".json") throw py::value_error(fmt::format("{}: save writes .json models (use `seam convert` for STEP/IGES)", out.string()));
  if (const Status s = io::checkOutputFile(out); !s) raise(s);
  if (const Status s = io::writeModelJson(m.model, out); !s) raise(s);
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

  mod.def("heal", &heal, py::arg("model"), py::kw_only(), py::arg("continuity") = "G1", py::arg("method") = "auto",
          py::arg("max_gap") = py::none(), py::arg("crease_angle") = py::none(),
          "Makes every seam G1 (or G0) where it can, never worse: (healed Model, the dict of `seam heal --json`)");
  mod.def("report", &writeReport, py::arg("model"), py::arg("path"), py::kw_only(), py::arg("title") = py::none(),
          "Writes the self-contained HTML report of `seam report` (patch models) atomically; returns the path");
  mod.def("save", &save, py::arg("model"), py::arg("path"), "Writes a model as .json (atomically)");

  auto checkDoc =
      "Continuity of every seam, corner and free edge: the dict of `seam check FILE --json` with the same options "
      "(a STEP/IGES path is checked as a B-rep unless patches=True). Raises ValueError/OSError on bad input.";
  mod.def("check",
          [](const std::filesystem::path& path, std::optional<double> tolDistance, std::optional<double> tolAngle,
             std::optional<double> tolCurvature, std::optional<double> creaseAngle,
             const std::optional<std::string>& require, const std::string& sort, std::optional<size_t> top,
             const std::string& only, bool patches) {
            return checkPath(path, checkOptions(tolDistance, tolAngle, tolCurvature, creaseAngle, require, sort, top,
                                                only, patches));
          },
          py::arg("path"), py::kw_only(), py::arg("tol_distance") = py::none(), py::arg("tol_angle") = py::none(),
          py::arg("tol_curvature") = py::none(), py::arg("crease_angle") = py::none(), py::arg("require") = py::none(),
          py::arg("sort") = "file", py::arg("top") = py::none(), py::arg("only") = "all", py::arg("patches") = false,
          checkDoc);
  mod.def("check",
          [](const PyModel& m, std::optional<double> tolDistance, std::optional<double> tolAngle,
             std::optional<double> tolCurvature, std::optional<double> creaseAngle,
             const std::optional<std::string>& require, const std::string& sort, std::optional<size_t> top,
             const std::string& only) {
            return checkLoaded(m, checkOptions(tolDistance, tolAngle, tolCurvature, creaseAngle, require, sort, top,
                                               only, false));
          },
          py::arg("model"), py::kw_only(), py::arg("tol_distance") = py::none(), py::arg("tol_angle") = py::none(),
          py::arg("tol_curvature") = py::none(), py::arg("crease_angle") = py::none(), py::arg("require") = py::none(),
          py::arg("sort") = "file", py::arg("top") = py::none(), py::arg("only") = "all", checkDoc);
}
