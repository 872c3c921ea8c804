// seam fill FILE (--quad A B C | --hole [--around P1 ... P8] | --fillet STRIP1 STRIP2) [--degree 4|5|6]
//           [--name NEW] -o OUT.json [--json]
// Exact G1 constructions with Bezier patches (Johansson Section 4): the 4th patch at a vertex, a patch
// filling a four-sided hole, a fillet between two strips. The input patches are copied unchanged, the new
// ones appended; every new seam and corner is verified with the certified checks. Exit 1 when the result is
// not G1 everywhere it should be (or the surrounding of a hole is not G1), 2 for bad input.
#include <fmt/format.h>

#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cli_util.h"
#include "command_registry.h"
#include "repair_units_json.h"
#include "fill_json.h"
#include "seam/construct/fill.h"
#include "seam/io/json.h"

namespace seam::cli {

namespace {

/// Bi-degree from which the search for a solvable degree starts raising when the constraints are
/// inconsistent.
constexpr int kMaxFillDegree = 8;

struct FillCliOptions {
  std::string file;
  std::vector<std::string> quad;
  bool hole = false;
  std::vector<std::string> around;
  std::vector<std::string> fillet;
  int degree = 5;
  std::string name;
  std::string output;
  ToleranceOverrides tol;  // --tol-* / --preset / --units, as `seam check`
  bool json = false;
};

std::vector<std::string> splitNames(const std::string& list) {
  std::vector<std::string> out;
  std::stringstream ss(list);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

std::string rangeText(const Interval& i) {
  return "[" + formatNumber(i.lo) + ", " + formatNumber(i.hi) + "]";
}

std::string fillTable(const FillResult& fill, const FillCheck* check, const Model& full, const ModelUnits& units) {
  std::string out;
  if (!fill.patches.empty()) {
    std::vector<std::vector<std::string>> rows;
    for (const FilledPatch& p : fill.patches) {
      const G1PatchResult& c = p.construction;
      rows.push_back({p.patch.name, p.role, fmt::format("{}x{}", c.patch.degreeU(), c.patch.degreeV()),
                      c.exact ? "yes" : "no", std::to_string(c.freeParameters), formatNumber(c.energy)});
    }
    out += "new patches\n" + formatTable({"name", "role", "degree", "exact", "free", "energy"}, rows) + "\n";
    rows.clear();
    for (const FillSeam& s : fill.seams) {
      auto list = [](const BernsteinPoly& p) {
        std::string t;
        for (Eigen::Index k = 0; k < p.coeffs().rows(); ++k)
          t += (k ? " " : "") + formatNumber(p.coeffs()(k, 0));
        return t;
      };
      rows.push_back({s.newPatch + "." + std::string(edgeName(s.newEdge)),
                      s.neighbour + "." + std::string(edgeName(s.neighbourEdge)), list(s.functions.lambda),
                      list(s.functions.kappa)});
    }
    out += "connecting functions (Bernstein coefficients in the neighbour's edge parameter)\n" +
           formatTable({"new edge", "neighbour edge", "lambda", "kappa"}, rows) + "\n";
  }
  auto seamRows = [](const std::vector<SeamReport>& reps) {
    std::vector<std::vector<std::string>> rows;
    for (const SeamReport& r : reps) {
      rows.push_back({r.a + "." + std::string(edgeName(r.aEdge)), r.b + "." + std::string(edgeName(r.bEdge)),
                      std::string(toString(r.geometric)), r.certified ? "yes" : "no",
                      r.g1Identity ? "yes" : "no", formatNumber(r.g0Max), formatNumber(r.g1MaxDeg),
                      rangeText(r.lambdaRange), rangeText(r.kappaRange)});
    }
    return rows;
  };
  const std::vector<std::string> seamHeader = {"a",      "b",          "class",  "certified", "identity",
                                               units.length ? "G0 max (" + units.name() + ")" : "G0 max",
                                               "G1 max deg", "lambda", "kappa"};
  if (!fill.surrounding.empty()) {
    out += "surrounding seams\n" + formatTable(seamHeader, seamRows(fill.surrounding)) + "\n";
  }
  if (check) {
    out += "new seams\n" + formatTable(seamHeader, seamRows(check->seams)) + "\n";
    std::vector<std::vector<std::string>> rows;
    for (const CornerReport& c : check->corners) {
      std::string names;
      for (const PatchCorner& pc : c.corners)
        names += (names.empty() ? "" : " ") + full.patches[static_cast<size_t>(pc.patch)].name;
      rows.push_back({formatVector(c.point.data(), 3), std::to_string(c.valence), c.closed ? "yes" : "no",
                      c.normalSpreadDeg ? formatNumber(*c.normalSpreadDeg) : "-",
                      c.fourPatch ? formatNumber(c.fourPatch->g1Residual) : "-", names});
    }
    out +=
        "corners\n" +
        formatTable({"point", "valence", "closed", "normal spread deg", "Thm 1 residual", "patches"}, rows) +
        "\n";
  }
  for (const std::string& n : fill.notes) out += "note: " + n + "\n";
  if (check) {
    for (const std::string& p : check->problems) out += "problem: " + p + "\n";
  }
  return out;
}

void runFill(const FillCliOptions& o, int& exit) {
  if (!checkOutputPath(o.file, o.output)) {
    exit = kExitBadInput;
    return;
  }
  if (!validToleranceOptions(o.tol)) {
    exit = kExitBadInput;
    return;
  }
  ModelUnits units;
  const std::optional<Model> model = loadModel(o.file, o.tol, &units);
  units.display.reset();  // lengths in the model's unit (--display-units: check, report, info, batch, heal)
  if (!model) {
    exit = kExitBadInput;
    return;
  }
  FillOptions options;
  // The tolerances as `seam check` resolves them: absolute (0.001 mm) for a model with a length unit.
  const ResolvedTolerances resolved = resolveTolerances(o.tol, units, model->boundingBox().diagonal());
  options.tolerances = resolved.tolerances;
  options.name = o.name;
  options.patch.degreeU = options.patch.degreeV = o.degree;
  options.patch.maxDegree = kMaxFillDegree;
  options.patch.kappaZero = o.degree == 6;  // Sarraga's degree: kappa == 0 (Section 4.2, end)
  Result<FillResult> fill = Status(ErrorCode::kInvalidInput, "no mode");
  std::string mode;
  if (!o.quad.empty()) {
    mode = "quad";
    fill = fillQuad(*model, o.quad[0], o.quad[1], o.quad[2], options);
  } else if (o.hole) {
    mode = "hole";
    fill = fillHole(*model, o.around, options);
  } else {
    mode = "fillet";
    fill = fillFillet(*model, splitNames(o.fillet[0]), splitNames(o.fillet[1]), options);
  }
  if (!fill) {
    printError(fmt::format("{}: {}", o.file, fill.status().message()));
    exit = kExitBadInput;
    return;
  }
  const Model full = withFill(*model, *fill);
  std::optional<FillCheck> check;
  bool g1 = fill->surroundingG1;
  if (fill->surroundingG1) {
    Result<FillCheck> c = checkFill(*model, *fill, options);
    if (!c) {
      printError(fmt::format("{}: verification failed: {}", o.file, c.status().message()));
      exit = kExitGeometryProblem;
      return;
    }
    check = std::move(c).value();
    g1 = check->g1;  // certified within the tolerances; "exact" per patch says whether the identities hold
    if (!saveModel(full, o.output)) {  // .json, .step/.stp, .iges/.igs by extension
      exit = kExitBadInput;
      return;
    }
  }
  if (o.json) {
    OrderedJson j = fillJson(mode, *fill, check ? &*check : nullptr, full, options.patch,
                             fill->surroundingG1 ? std::optional<std::string>(o.output) : std::nullopt);
    addRepairUnits(j, units, resolved);
    printJson(j);
  } else {
    fmt::print("{}\ngap tolerance {} ({}), angle {} deg ({})\n", unitText(units),
               withUnit(formatNumber(resolved.tolerances.distance), units),
               distanceSourceText(resolved.distanceSource, resolved.preset), formatNumber(resolved.tolerances.angleDeg),
               angleSourceText(resolved.angleSource, resolved.preset));
    fmt::print("{}", fillTable(*fill, check ? &*check : nullptr, full, units));
    if (!fill->surroundingG1) {
      fmt::print("result: the surface around the hole is not G1; nothing was built and {} was not written\n",
                 o.output);
    } else {
      fmt::print("result: {} (written to {})\n", g1 ? "G1 everywhere" : "NOT G1 everywhere", o.output);
    }
  }
  exit = g1 ? kExitOk : kExitGeometryProblem;
}

void addFill(CLI::App& app, int& exit) {
  auto o = std::make_shared<FillCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "fill", "Exact G1 Bezier patches (Johansson Section 4): the 4th patch at a vertex, a hole, a fillet");
  cmd->add_option("FILE", o->file, modelFileHelp())->required();
  CLI::Option* quad =
      cmd->add_option("--quad", o->quad,
                      "Build the 4th patch at the vertex of corner patch A and its neighbours B, C")
          ->expected(3);
  CLI::Option* hole = cmd->add_flag("--hole", o->hole, "Fill four-sided holes bounded by free edges");
  CLI::Option* around =
      cmd->add_option("--around", o->around, "Look for the hole among these patches only (the 8 around it)")
          ->expected(1, 8);
  CLI::Option* fillet =
      cmd->add_option("--fillet", o->fillet,
                      "Fillet between two strips, each a comma-separated list of patch names in order")
          ->expected(2);
  cmd->add_option("--degree", o->degree,
                  "Bi-degree of the new patches (4, 5, or 6 = Sarraga's with kappa = 0)")
      ->check(CLI::IsMember({4, 5, 6}));
  cmd->add_option("--name", o->name, "Name of the new patch (more get _2, _3, ...)");
  cmd->add_option("-o", o->output, "Output model (input patches unchanged + new patches)")->required();
  addToleranceOptions(*cmd, o->tol);
  cmd->add_flag("--json", o->json, "Print JSON instead of tables");
  around->needs(hole);
  quad->excludes(hole)->excludes(fillet);
  hole->excludes(fillet);
  cmd->callback([o, cmd, &exit]() {
    if (o->quad.empty() && !o->hole && o->fillet.empty()) {
      printError("fill: one of --quad, --hole, --fillet is required");
      exit = kExitBadInput;
      return;
    }
    (void)cmd;
    runFill(*o, exit);
  });
}

}  // namespace

static CommandRegistrar registerFill("fill", addFill);

}  // namespace seam::cli
