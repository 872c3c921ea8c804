// seam join FILE --move S:v0 --to T:v0 [--continuity G0|G1|G2] [--method auto|bspline|bezier-strip|least-squares]
//           [--ell L] [--average] [--max-gap D] [--max-displacement REL] [--crease-angle DEG] -o OUT.json [--json]
// Moves the fewest rows of control points of S (or of S and T with --average) so that the seam meets the requested
// continuity, writes the model to OUT.json (atomically; the input is never overwritten unless -o names it), and
// prints the seam before and after. Exit 0 achieved, 1 not achieved (OUT.json is still written), 2 bad input.
#include <fmt/format.h>

#include <cmath>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli_util.h"
#include "command_registry.h"
#include "repair_units_json.h"
#include "seam/io/json.h"
#include "seam/repair/join.h"
#include "seam/repair/report_json_value.h"

namespace seam::cli {

namespace {

struct PatchEdge {
  std::string patch;
  Edge edge = Edge::U0;
};

/// "NAME:edge" (the last ':' separates, so patch names may contain ':').
std::optional<PatchEdge> parsePatchEdge(const std::string& text, const char* option) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0) {
    printError(fmt::format("{} expects PATCH:EDGE (e.g. S1:v0), got \"{}\"", option, text));
    return std::nullopt;
  }
  auto e = parseEdge(text.substr(colon + 1));
  if (!e) {
    printError(fmt::format("{}: {}", option, e.status().message()));
    return std::nullopt;
  }
  return PatchEdge{text.substr(0, colon), *e};
}

std::string yesNo(bool b) { return b ? "yes" : "no"; }

std::string measureTable(const SeamReport& b, const SeamReport& a, const ModelUnits& units) {
  std::vector<std::vector<std::string>> rows = {
      // Table precision (issue 17 §6): angles to 0.001 deg, gaps and jumps to 4 significant digits (JSON: full).
      {units.length ? "G0 gap (" + units.name() + ")" : "G0 gap", formatNumber(b.g0Max), formatNumber(a.g0Max)},
      {"G1 angle (deg)", formatNumber(b.g1MaxDeg), formatNumber(a.g1MaxDeg)},
      {units.length ? "G2 jump (1/" + units.name() + ")" : "G2 jump (1/length)", formatNumber(b.g2Max),
       formatNumber(a.g2Max)},
      {"lambda range", "[" + formatNumber(b.lambdaRange.lo) + ", " + formatNumber(b.lambdaRange.hi) + "]",
       "[" + formatNumber(a.lambdaRange.lo) + ", " + formatNumber(a.lambdaRange.hi) + "]"},
      {"geometric", std::string(toString(b.geometric)), std::string(toString(a.geometric))},
      {"parametric", std::string(toString(b.parametric)), std::string(toString(a.parametric))},
      {"certified", yesNo(b.certified), yesNo(a.certified)},
  };
  return formatTable({"measure", "before", "after"}, rows, {false, true, true});
}

void addJoin(CLI::App& app, int& exit) {
  struct Options {
    std::string file, move, to, out;
    std::string continuity = "G1", method = "auto";
    std::optional<double> ell, maxGap, maxDisplacement, creaseAngle;
    ToleranceOverrides tol;  // --tol-* / --preset / --units, as `seam check`
    bool average = false, json = false;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("join", "Join two patches along a seam (G0/G1/G2) by moving control points");
  cmd->add_option("FILE", o->file, modelFileHelp())->required();
  cmd->add_option("--move", o->move, "The edge that moves, PATCH:EDGE (edges u0, u1, v0, v1)")->required();
  cmd->add_option("--to", o->to, "The edge it is joined to, PATCH:EDGE")->required();
  cmd->add_option("--continuity", o->continuity, "G0, G1 or G2 (default G1)");
  cmd->add_option("--method", o->method, "auto, bspline, bezier-strip or least-squares (default auto)");
  cmd->add_option("--ell", o->ell, "bezier-strip: the free parameter l = xi2/xi0 (default: least displacement)");
  cmd->add_flag("--average", o->average, "Move both patches onto their common middle (least-squares)");
  cmd->add_option("--max-gap", o->maxGap,
                  "Largest gap to close, in the model's length unit (default 1% of the bounding-box diagonal)");
  cmd->add_option("--max-displacement", o->maxDisplacement,
                  "Largest surface displacement, as a multiple of the moved patch's size (default 1: a join that "
                  "would move a patch by more than its own size is undone)");
  cmd->add_option("--crease-angle", o->creaseAngle,
                  "A seam whose angle is at or above this (degrees, in (0, 180]) is a design crease: G1/G2 joins leave "
                  "it as designed (default 20)");
  cmd->add_option("-o,--output", o->out, "Output model file (written atomically)")->required();
  addToleranceOptions(*cmd, o->tol);
  cmd->add_flag("--json", o->json, "Print JSON instead of a table");
  cmd->callback([o, &exit]() {
    exit = kExitBadInput;
    if (!validToleranceOptions(o->tol)) return;
    const auto mv = parsePatchEdge(o->move, "--move");
    const auto to = parsePatchEdge(o->to, "--to");
    if (!mv || !to) return;
    JoinOptions jo;
    auto cont = parseContinuity(o->continuity);
    if (!cont) return printError("--continuity: " + cont.status().message());
    jo.continuity = *cont;
    auto meth = parseJoinMethod(o->method);
    if (!meth) return printError("--method: " + meth.status().message());
    jo.method = *meth;
    jo.ell = o->ell;
    jo.average = o->average;
    if (o->maxGap && !(*o->maxGap >= 0.0)) return printError("--max-gap must be a non-negative length");
    jo.maxGap = o->maxGap;
    if (o->maxDisplacement) {
      if (!(*o->maxDisplacement >= 0.0) || !std::isfinite(*o->maxDisplacement))
        return printError("--max-displacement must be a non-negative multiple of the patch size");
      jo.maxDisplacementRel = *o->maxDisplacement;
    }
    if (o->creaseAngle && !validCreaseAngle(*o->creaseAngle))
      return printError("--crease-angle must be an angle in degrees in (0, 180]");
    jo.creaseAngleDeg = o->creaseAngle.value_or(kDefaultCreaseAngleDeg);
    if (!checkOutputPath(o->file, o->out)) return;
    ModelUnits units;
    const std::optional<Model> model = loadModel(o->file, o->tol, &units);
    units.display.reset();  // lengths in the model's unit (--display-units: check, report, info, batch, heal)
    if (!model) return;
    // The classification tolerances as `seam check` resolves them: absolute (0.001 mm) for a model with a length unit.
    const ResolvedTolerances resolved = resolveTolerances(o->tol, units, model->boundingBox().diagonal());
    jo.tolerances = resolved.tolerances;
    auto res = joinSeam(*model, mv->patch, mv->edge, to->patch, to->edge, jo);
    if (!res) return printError(fmt::format("{}: {}", o->file, res.status().message()));  // the file, then why
    const JoinReport& r = res->report;
    if (!saveModel(res->model, o->out)) return;  // .json, .step/.stp, .iges/.igs by extension
    if (o->json) {
      OrderedJson j = joinReportValue(r);
      addRepairUnits(j, units, resolved);
      j["output"] = o->out;
      printJson(j);
    } else {
      // The user's words first (issue 17 §6); the method and the paper's conditions in the details line.
      const int order = static_cast<int>(r.requested) - 1;  // GeometricClass: none, G0, G1, G2
      std::string text = fmt::format("seam join: match {}:{} to {}:{} with {} ({}): {}\n", mv->patch,
                                     edgeName(mv->edge), to->patch, edgeName(to->edge), continuityWords(order),
                                     toString(r.requested),
                                     r.achieved ? "achieved"
                                                : fmt::format("NOT achieved (the seam is {})", toString(r.after.geometric)));
      text += unitLine(units, resolved, jo.creaseAngleDeg.value_or(kDefaultCreaseAngleDeg));
      text += fmt::format("details: method {} ({})", toString(r.method), r.reason);
      if (r.proportionalKnots)
        text += fmt::format("; proportional knots (Def. 3.1): {}", yesNo(*r.proportionalKnots));
      text += "\n";
      text += "\n" + measureTable(r.before, r.after, units) + "\n";
      text += fmt::format("max control-point displacement: {}\n", withUnit(formatNumber(r.maxDisplacement), units));
      text += fmt::format("surface moved by at most {} (certified; {} found on a grid), {} % of the patch size\n",
                          withUnit(formatNumber(r.maxSurfaceDisplacement), units),
                          withUnit(formatNumber(r.maxSurfaceDisplacementSampled), units),
                          formatNumber(100.0 * r.maxSurfaceDisplacementRel));
      if (r.reverted) text += "the join was undone: the model is the input, unchanged (see the notes)\n";
      if (r.creaseKept) text += "crease, left as designed: the model is the input, unchanged\n";
      if (r.lambdaFixed && r.lambda0)
        text += fmt::format("lambda fixed to lambda0 = {} (the free solve would have folded the patch)\n",
                            formatNumber(*r.lambda0));
      if (r.weightsFixed) text += "rational: the moved rows kept their weights\n";
      std::string changed;
      for (const std::string& p : r.patchesChanged) changed += (changed.empty() ? "" : ", ") + p;
      text += fmt::format("moved points: {} (patches changed: {})\n", r.movedPoints, changed.empty() ? "none" : changed);
      if (!r.insertedKnotsU.empty() || !r.insertedKnotsV.empty())
        text += fmt::format("knots inserted: {} in u, {} in v\n", r.insertedKnotsU.size(), r.insertedKnotsV.size());
      if (r.stripInternalG1MaxDeg)
        text += fmt::format("strip: worst internal tangent-plane angle {} deg\n", formatNumber(*r.stripInternalG1MaxDeg));
      for (const std::string& n : r.notes) text += "note: " + n + "\n";
      text += fmt::format("output: {}\n", o->out);
      text += r.achieved ? fmt::format("{} achieved\n", toString(r.requested))
                         : fmt::format("requested {} NOT achieved (the seam is {}); the output was written anyway\n",
                                       toString(r.requested), toString(r.after.geometric));
      fmt::print("{}", text);
    }
    exit = r.achieved ? kExitOk : kExitGeometryProblem;
  });
}

}  // namespace

static CommandRegistrar registerJoin("join", addJoin);

}  // namespace seam::cli
