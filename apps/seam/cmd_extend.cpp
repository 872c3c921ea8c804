// seam extend FILE --patch A --edge u1 --order N --gamma .. --alpha .. --beta0 .. --beta1 .. [--degree M]
//             --name NEW -o OUT.json
// Appends a patch that meets edge `--edge` of patch A with GC^N by construction (Zheng-Wang-Liang, Theorem 6 with
// sigma = 0, eq. 4.8): c_s = gamma_s, p_s = alpha_s, q_s(v) = beta0_s (1 - v) + beta1_s v.
#include <fmt/format.h>

#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "cli_util.h"
#include "command_registry.h"
#include "seam/io/file.h"
#include "seam/io/json.h"
#include "seam/rational/connecting.h"
#include "seam/rational/construction.h"
#include "seam/rational/expression.h"

namespace seam::cli {

namespace {

/// Largest --degree accepted: the construction's cost grows steeply with the degree (100 000 ran for more than
/// 30 s), and no CAD system takes degrees this high (OpenCASCADE stops at 25).
constexpr int kMaxExtendDegree = 64;

struct ExtendOptions {
  std::string file;
  std::string patch;
  std::string edge;
  int order = 1;
  std::vector<double> gamma, alpha, beta0, beta1;
  int degree = -1;
  std::string name;
  std::string output;
};

int runExtend(const ExtendOptions& o) {
  auto edge = parseEdge(o.edge);
  if (!edge) {
    printError("--edge: " + edge.status().message());
    return kExitBadInput;
  }
  if (o.order < 1 || o.order > rational::kMaxGcnOrder) {
    printError(fmt::format("--order {} out of range [1, {}]", o.order, rational::kMaxGcnOrder));
    return kExitBadInput;
  }
  if (o.degree > kMaxExtendDegree) {
    printError(fmt::format("--degree {} is above the largest degree accepted, {}", o.degree, kMaxExtendDegree));
    return kExitBadInput;
  }
  const std::pair<const char*, const std::vector<double>*> lists[] = {
      {"--gamma", &o.gamma}, {"--alpha", &o.alpha}, {"--beta0", &o.beta0}, {"--beta1", &o.beta1}};
  for (const auto& [flag, values] : lists)
    if (static_cast<int>(values->size()) != o.order) {
      printError(fmt::format("{} needs {} values (one per order 1..{}), found {}", flag, o.order, o.order,
                             values->size()));
      return kExitBadInput;
    }
  if (!checkOutputPath(o.file, o.output)) return kExitBadInput;
  if (!checkModelText(o.file)) return kExitBadInput;
  auto model = rational::readModelWithExpressions(o.file);
  if (!model) {
    printError(model.status().message());
    return kExitBadInput;
  }
  const Patch* a = model->model.findPatch(o.patch);
  if (!a) {
    printError(model->findExpression(o.patch)
                   ? fmt::format("{}: patch \"{}\" is an expression patch; seam extend needs a B-spline / NURBS patch",
                                 o.file, o.patch)
                   : fmt::format("{}: no patch named \"{}\"", o.file, o.patch));
    return kExitBadInput;
  }
  if (model->model.findPatch(o.name) || model->model.findCurve(o.name) || model->findExpression(o.name)) {
    printError(fmt::format("{}: the name \"{}\" is already used (--name must be new)", o.file, o.name));
    return kExitBadInput;
  }
  const rational::ShapeParameters shape{o.gamma, o.alpha, o.beta0, o.beta1};
  rational::ExtensionOptions eo;
  eo.degree = o.degree;
  auto surface = rational::extendSurface(a->surface, *edge, shape, eo);
  if (!surface) {
    printError(fmt::format("patch \"{}\" edge {}: {}", o.patch, edgeName(*edge), surface.status().message()));
    return surface.status().code() == ErrorCode::kNoSolution ? kExitGeometryProblem : kExitBadInput;
  }
  // The output: the input file's JSON with the new patch appended (expression patches and key order are kept).
  Model added;
  added.patches.push_back(Patch{o.name, PatchKind::kBezier, *surface});
  OrderedJson root, patchJson;
  try {
    auto text = io::readFile(o.file);
    if (!text) {
      printError(text.status().message());
      return kExitBadInput;
    }
    root = o.file.size() > 5 && o.file.substr(o.file.size() - 5) == ".json" ? OrderedJson::parse(*text)
                                                                              : OrderedJson::parse(io::modelToJson(model->model));
    patchJson = OrderedJson::parse(io::modelToJson(added))["patches"][0];
  } catch (const std::exception& e) {
    printError(fmt::format("{}: {}", o.file, e.what()));
    return kExitBadInput;
  }
  if (!root.contains("patches")) root["patches"] = OrderedJson::array();
  root["patches"].push_back(patchJson);
  if (!writeOutputFile(o.output, jsonText(root))) return kExitBadInput;
  // The user's words first (issue 17 §6), the paper's name (GC^n, Zheng-Wang-Liang) in the details line.
  std::cout << fmt::format("added patch \"{}\" matching {}:{} with {} (by construction) -> {}\n", o.name, o.patch,
                           edgeName(*edge), continuityWords(o.order), o.output);
  std::cout << fmt::format("details: degree {} x {}, {}; GC^{} (Zheng-Wang-Liang connecting construction)\n",
                           surface->degreeU(), surface->degreeV(), surface->isRational() ? "rational" : "polynomial",
                           o.order);
  return kExitOk;
}

void addExtend(CLI::App& app, int& exit) {
  auto o = std::make_shared<ExtendOptions>();
  CLI::App* cmd = app.add_subcommand(
      "extend", "Append a patch meeting an edge with GC^N by construction (Zheng-Wang-Liang, Theorem 6, eq. 4.8)");
  cmd->add_option("FILE", o->file, modelFileHelp())->required();
  cmd->add_option("--patch", o->patch, "The patch to extend (B-spline / NURBS, one Bezier span along the edge)")
      ->required();
  cmd->add_option("--edge", o->edge, "Its edge: u0, u1, v0 or v1")->required();
  cmd->add_option("--order", o->order, "N: the order of geometric continuity (>= 1)")->required();
  cmd->add_option("--gamma", o->gamma, "gamma_1..gamma_N: c_s, the weight connecting functions")->required();
  cmd->add_option("--alpha", o->alpha, "alpha_1..alpha_N: p_s (alpha_1 > 0 for a proper join)")->required();
  cmd->add_option("--beta0", o->beta0, "beta0_1..beta0_N: q_s at the start of the edge")->required();
  cmd->add_option("--beta1", o->beta1, "beta1_1..beta1_N: q_s at the end of the edge")->required();
  cmd->add_option("--degree", o->degree,
                  "Degree M of the new patch across the edge (default max(degree, N); at most 64)");
  cmd->add_option("--name", o->name, "Name of the new patch")->required();
  cmd->add_option("-o,--output", o->output, "Output model file (.json)")->required();
  cmd->callback([o, &exit]() { exit = runExtend(*o); });
}

}  // namespace

static CommandRegistrar registerExtend("extend", addExtend);

}  // namespace seam::cli
