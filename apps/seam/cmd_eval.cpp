// seam eval FILE --patch NAME --uv U V [--derivs N] [--json]
// seam eval FILE --curve NAME --t T [--derivs N] [--json]
// The point and every partial derivative up to order N at a parameter.
#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli_util.h"
#include "command_registry.h"

namespace seam::cli {

namespace {

/// Highest derivative order `--derivs` accepts (the output has (N+1)(N+2)/2 vectors for a patch).
constexpr int kMaxDerivativeOrder = 32;

struct EvalOptions {
  std::string file;
  std::string patch;
  std::string curve;
  std::vector<double> uv;
  double t = 0.0;
  int derivs = 0;
  bool json = false;
};

OrderedJson vectorJson(const VecX& v) {
  OrderedJson a = OrderedJson::array();
  for (Eigen::Index k = 0; k < v.size(); ++k) a.push_back(v[k]);
  return a;
}

std::vector<std::string> tableRow(const std::string& label, const VecX& v) {
  std::vector<std::string> row{label};
  for (Eigen::Index k = 0; k < v.size(); ++k) row.push_back(formatNumber(v[k]));
  return row;
}

std::vector<std::string> tableHeader(int dim) {
  std::vector<std::string> header{"derivative"};
  const char* const axes[] = {"x", "y", "z"};
  for (int k = 0; k < dim; ++k) header.emplace_back(k < 3 ? axes[k] : fmt::format("c{}", k));
  return header;
}

/// Names of the objects of one kind, for "no patch named ..." messages (at most a few).
template <class T>
std::string nameList(const std::vector<T>& objects) {
  constexpr size_t kMaxListed = 10;
  if (objects.empty()) return "none";
  std::string s;
  for (size_t k = 0; k < objects.size() && k < kMaxListed; ++k) s += (k > 0 ? ", " : "") + objects[k].name;
  if (objects.size() > kMaxListed) s += fmt::format(", ... ({} in all)", objects.size());
  return s;
}

/// Checks that a parameter is finite and inside the domain; prints the problem otherwise.
bool checkParameter(const std::string& object, const char* name, double value, const Interval& domain) {
  if (!std::isfinite(value)) {
    printError(fmt::format("{}: {} = {} is not a finite number", object, name, value));
    return false;
  }
  if (!domain.contains(value)) {
    printError(fmt::format("{}: {} = {} is outside the parameter domain [{}, {}]", object, name, value,
                           domain.lo, domain.hi));
    return false;
  }
  return true;
}

int evalPatch(const EvalOptions& o, const Model& model) {
  const Patch* patch = model.findPatch(o.patch);
  if (patch == nullptr) {
    printError(
        fmt::format("{}: no patch named \"{}\" (patches: {})", o.file, o.patch, nameList(model.patches)));
    return kExitBadInput;
  }
  const std::string object = fmt::format("{}: patch \"{}\"", o.file, o.patch);
  const double u = o.uv[0];
  const double v = o.uv[1];
  if (!checkParameter(object, "u", u, patch->surface.domainU()) ||
      !checkParameter(object, "v", v, patch->surface.domainV())) {
    return kExitBadInput;
  }
  const std::vector<std::vector<VecX>> d = patch->surface.derivatives(u, v, o.derivs);
  if (o.json) {
    OrderedJson derivatives = OrderedJson::object();
    for (int order = 1; order <= o.derivs; ++order) {
      for (int k = order; k >= 0; --k) {
        derivatives[fmt::format("{},{}", k, order - k)] =
            vectorJson(d[static_cast<size_t>(k)][static_cast<size_t>(order - k)]);
      }
    }
    printJson(OrderedJson{
        {"patch", o.patch}, {"uv", {u, v}}, {"point", vectorJson(d[0][0])}, {"derivatives", derivatives}});
    return kExitOk;
  }
  std::vector<std::vector<std::string>> rows{tableRow("point", d[0][0])};
  for (int order = 1; order <= o.derivs; ++order) {
    for (int k = order; k >= 0; --k) {
      rows.push_back(tableRow(fmt::format("{},{}", k, order - k),
                              d[static_cast<size_t>(k)][static_cast<size_t>(order - k)]));
    }
  }
  std::vector<bool> right(static_cast<size_t>(patch->surface.dim()) + 1, true);
  right[0] = false;
  fmt::print("patch \"{}\" at u = {}, v = {}   (derivative k,l = d^(k+l) S / du^k dv^l)\n\n{}", o.patch,
             formatNumber(u), formatNumber(v), formatTable(tableHeader(patch->surface.dim()), rows, right));
  return kExitOk;
}

int evalCurve(const EvalOptions& o, const Model& model) {
  const Curve* curve = model.findCurve(o.curve);
  if (curve == nullptr) {
    printError(
        fmt::format("{}: no curve named \"{}\" (curves: {})", o.file, o.curve, nameList(model.curves)));
    return kExitBadInput;
  }
  const std::string object = fmt::format("{}: curve \"{}\"", o.file, o.curve);
  if (!checkParameter(object, "t", o.t, curve->curve.domain())) return kExitBadInput;
  const Matrix d = curve->curve.derivatives(o.t, o.derivs);
  auto rowVector = [&](int k) -> VecX { return d.row(k).transpose(); };
  if (o.json) {
    OrderedJson derivatives = OrderedJson::object();
    for (int k = 1; k <= o.derivs; ++k) derivatives[std::to_string(k)] = vectorJson(rowVector(k));
    printJson(OrderedJson{
        {"curve", o.curve}, {"t", o.t}, {"point", vectorJson(rowVector(0))}, {"derivatives", derivatives}});
    return kExitOk;
  }
  std::vector<std::vector<std::string>> rows{tableRow("point", rowVector(0))};
  for (int k = 1; k <= o.derivs; ++k) rows.push_back(tableRow(std::to_string(k), rowVector(k)));
  std::vector<bool> right(static_cast<size_t>(curve->curve.dim()) + 1, true);
  right[0] = false;
  fmt::print("curve \"{}\" at t = {}   (derivative k = d^k C / dt^k)\n\n{}", o.curve, formatNumber(o.t),
             formatTable(tableHeader(curve->curve.dim()), rows, right));
  return kExitOk;
}

void addEval(CLI::App& app, int& exit) {
  auto o = std::make_shared<EvalOptions>();
  CLI::App* cmd = app.add_subcommand("eval", "Evaluate a point and its derivatives on a patch or a curve");
  cmd->add_option("FILE", o->file, modelFileHelp())->required();
  CLI::Option* patch = cmd->add_option("--patch", o->patch, "Name of the patch to evaluate");
  CLI::Option* uv =
      cmd->add_option("--uv", o->uv, "Parameters U V on the patch")->expected(2)->allow_extra_args(false);
  CLI::Option* curve = cmd->add_option("--curve", o->curve, "Name of the curve to evaluate");
  CLI::Option* t = cmd->add_option("--t", o->t, "Parameter T on the curve");
  cmd->add_option(
      "--derivs", o->derivs,
      fmt::format("Highest derivative order N, 0 to {} (default 0: the point only)", kMaxDerivativeOrder));
  cmd->add_flag(
      "--json", o->json,
      "Print JSON: {\"point\": [..], \"derivatives\": {\"1,0\": [..], \"0,1\": [..], ...}} for a patch "
      "(key \"k,l\" = d^(k+l)/du^k dv^l), {\"1\": [..], \"2\": [..], ...} for a curve");
  patch->needs(uv);
  uv->needs(patch);
  curve->needs(t);
  t->needs(curve);
  patch->excludes(curve);
  cmd->footer("Give either --patch NAME --uv U V or --curve NAME --t T.\n");

  cmd->callback([o, &exit]() {
    if (o->patch.empty() && o->curve.empty()) {
      printError("eval: give --patch NAME --uv U V or --curve NAME --t T");
      exit = kExitBadInput;
      return;
    }
    if (o->derivs < 0 || o->derivs > kMaxDerivativeOrder) {
      printError(fmt::format("eval: --derivs {} is outside 0 to {}", o->derivs, kMaxDerivativeOrder));
      exit = kExitBadInput;
      return;
    }
    const std::optional<Model> model = loadModel(o->file);
    if (!model) {
      exit = kExitBadInput;
      return;
    }
    exit = o->patch.empty() ? evalCurve(*o, *model) : evalPatch(*o, *model);
  });
}

}  // namespace

static CommandRegistrar registerEval("eval", addEval);

}  // namespace seam::cli
