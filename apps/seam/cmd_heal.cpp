// seam heal FILE -o OUT.json [--continuity G0|G1|G2] [--method auto|successive|local] [--max-gap D] [--crease-angle DEG]
//           [--json]
// Finds every seam whose gap is below --max-gap and joins the open ones region by region (repair/heal.h: successive
// joins, each step kept only if it makes no seam worse; the local G1 scheme; auto = the better of the two, the
// smaller displacement where both reach the request); seams kinked by more than --crease-angle (alias --max-angle,
// default 20 degrees) are design creases, left as designed ("crease kept"); prints
// every seam before and after in plain words (gap, kink angle, crease, fold), every region and how far the surfaces
// moved. Exit 0 when every such seam meets the requested continuity, 1 otherwise (OUT.json is still written and
// holds everything achieved), 2 bad input.
// STEP/IGES -> STEP/IGES is healed as a B-rep (occt::healBRepFile: every face, trim, edge and solid kept, faces
// moved along their pcurves); so is any other model with trimmed faces and its B-rep (a JSON with "brep", STEP/IGES
// -> JSON: occt::healBRepModel), into a JSON that keeps the B-rep or into STEP/IGES.
#include <fmt/format.h>

#include <cmath>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli_util.h"
#include "command_registry.h"
#include "repair_units_json.h"
#ifdef SEAM_HAVE_OCCT
#include "brep_heal_json.h"
#endif
#include "seam/continuity/model_check.h"
#include "seam/continuity/verdict.h"
#include "seam/io/json.h"
#include "seam/repair/heal.h"
#include "seam/repair/join.h"
#include "seam/repair/report_json_value.h"
#ifdef SEAM_HAVE_OCCT
#include "seam/occt/brep_heal.h"
#endif

namespace seam::cli {

namespace {

struct HealCliOptions {
  std::string file, out, continuity = "G1", method = "auto";
  std::optional<double> maxGap, maxAngle;
  double fairness = kDefaultG2Fairness;
  ToleranceOverrides tol;  // --tol-* / --preset / --units, as `seam check`
  bool json = false;
};

#ifdef SEAM_HAVE_OCCT
/// `seam heal` of a STEP/IGES file into STEP/IGES: the B-rep kept (occt::healBRepFile); or, with `model` (a JSON
/// model with trimmed faces, its "brep"), of that model into any model file (occt::healBRepModel, then saveModel:
/// the JSON keeps the B-rep too). Returns the exit code.
int healBRep(const HealCliOptions& o, const HealOptions& ho, const Model* model = nullptr) {
  occt::BRepHealOptions bo;
  bo.tolerances = o.tol;
  bo.continuity = ho.continuity;
  bo.maxGap = o.maxGap;
  if (o.maxAngle) bo.creaseAngleDeg = *o.maxAngle;
  if (o.method != "auto") {
    printError("--method: a STEP/IGES B-rep is healed face by face along its pcurves (--method auto only)");
    return kExitBadInput;
  }
  Result<occt::BRepHealReport> res = Status(ErrorCode::kIoError, "not healed");
  if (model == nullptr) {
    const CadTimeLimit limit(o.file, "healing");
    res = occt::healBRepFile(o.file, o.out, bo);
  } else {
    const std::optional<occt::CadFormat> outFormat = occt::cadFormatOf(o.out);
    Result<occt::BRepModelHeal> healed = [&] {
      const CadTimeLimit limit(o.file, "healing");
      return occt::healBRepModel(*model, o.file, outFormat.value_or(occt::CadFormat::kStep), bo);
    }();
    if (!healed) {
      printError(healed.status().message());
      return kExitBadInput;
    }
    if (!saveModel(healed->model, o.out)) return kExitBadInput;  // .json keeps the B-rep; .step/.iges by extension
    res = std::move(healed->report);
  }
  if (!res) {
    printError(res.status().message());
    return kExitBadInput;
  }
  const occt::BRepHealReport& r = *res;
  for (const std::string& w : r.warnings) std::cerr << "seam: warning: " << w << "\n";
  if (o.json) {
    printJson(brepHealJson(r, o.file, o.out));
  } else {
    // Lengths in the shown unit (issue 38 §1: the file's own, or --display-units); the report's are mm.
    const double scale = r.units.displayScale();
    const ModelUnits shown = r.units.shown();
    const std::string unit = shown.length ? shown.name() : "mm";
    const auto len = [scale](double x) { return formatNumber(x * scale); };
    std::vector<std::vector<std::string>> rows;
    for (const occt::BRepHealSeam& s : r.seams) {
      if (s.action == "already G1" || s.action == "already G0" || s.action == "crease kept") continue;
      rows.push_back({std::to_string(s.edge), s.a + (s.entityA.empty() ? "" : " " + s.entityA),
                      s.b + (s.entityB.empty() ? "" : " " + s.entityB),
                      s.moved.empty() ? "-" : fmt::format("{} {}", s.moved, len(s.movedBy)),
                      len(s.before.g0Max), formatNumber(s.before.g1MaxDeg),
                      brepSeamState(s.before, r.creaseAngleDeg), s.after ? len(s.after->g0Max) : "?",
                      s.after ? formatNumber(s.after->g1MaxDeg) : "?",
                      s.after ? brepSeamState(*s.after, r.creaseAngleDeg) : "?", s.action, s.worse ? "WORSE" : ""});
    }
    std::string text = fmt::format("seam heal {} (B-rep kept; {} requested, gaps up to {} {}, creases above {} deg "
                                   "keep their angle; tolerances {} {}, {} deg)\n{}\n",
                                   o.file, toString(r.requested), len(r.maxGap), unit,
                                   formatNumber(r.creaseAngleDeg), len(r.tolerances.distance), unit,
                                   formatNumber(r.tolerances.angleDeg), unitText(shown));
    text += rows.empty() ? std::string("no seam needs healing\n")
                         : formatTable({"edge", "face A", "face B", fmt::format("moved ({})", unit),
                                        fmt::format("gap before ({})", unit), "angle before (deg)", "before",
                                        fmt::format("gap after ({})", unit), "angle after (deg)", "after",
                                        "action", ""},
                                       rows,
                                       {true, false, false, false, true, true, false, true, true, false, false, false});
    std::string changed;
    double largest = 0.0;
    for (const occt::BRepFaceMove& m : r.faceMoves) {
      changed += fmt::format("{}{} {} {} (control points {} {})", changed.empty() ? "" : ", ", m.face,
                             len(m.sampled), unit, len(m.bound), unit);
      largest = std::max(largest, m.sampled);
    }
    text += fmt::format("\nfaces changed: {}\n", changed.empty() ? "none" : changed);
    if (!r.faceMoves.empty())
      text += fmt::format("largest surface displacement: {} {}, measured inside the trims on a {} x {} grid (bound: {} "
                          "{}, the largest control-point move)\n",
                          len(largest), unit, occt::kHealFoldGrid, occt::kHealFoldGrid,
                          len(r.maxSurfaceDisplacement), unit);
    text += fmt::format("kept: faces {} -> {}, trimmed faces {} -> {}, edges {} -> {}, solids {} -> {}; area {} -> "
                        "{} {}²; OpenCASCADE's BRepCheck valid {} -> {}\n",
                        r.before.faces, r.after.faces, r.before.trimmedFaces, r.after.trimmedFaces, r.before.edges,
                        r.after.edges, r.before.solids, r.after.solids, formatNumber(r.before.area * scale * scale),
                        formatNumber(r.after.area * scale * scale), unit, r.before.valid ? "yes" : "no", r.after.valid ? "yes" : "no");
    text += fmt::format("seams to heal: {}; reaching {}: {}; worse than before: {}\n", r.seamsToHeal,
                        toString(r.requested), r.seamsHealed, r.seamsWorse);
    for (const std::string& n : r.notes) text += "note: " + n + "\n";
    text += fmt::format("output: {} (unit {})\n", o.out, r.unit);
    text += r.achieved ? fmt::format("{} achieved on every seam to heal\n", toString(r.requested))
                       : fmt::format("requested {} NOT achieved on every seam; the output holds what was achieved, "
                                     "the rest is left as it was\n",
                                     toString(r.requested));
    fmt::print("{}", text);
  }
  return r.achieved ? kExitOk : kExitGeometryProblem;
}
#endif

void addHeal(CLI::App& app, int& exit) {
  using Options = HealCliOptions;
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "heal",
      "Close the gaps and kinks of every seam of a model (G0, G1 or G2). A trimmed model (STEP/IGES, or a JSON with "
      "its \"brep\") is healed as a B-rep, G0 or G1: every face, trim, edge and solid kept");
  cmd->add_option("FILE", o->file, modelFileHelp())->required();
  cmd->add_option("-o,--output", o->out, "Output model file (written atomically)")->required();
  cmd->add_option("--continuity", o->continuity, "G0, G1 or G2 (default G1; G2 by the network solve: biquintic output)");
  cmd->add_option("--method", o->method,
                  fmt::format("auto (default: successive, then the local scheme where it falls short), successive "
                              "or local; where the local scheme does not apply, the G1 network solve (regions of up "
                              "to {} patches)",
                              kMaxG1NetworkPatches));
  cmd->add_option("--max-gap", o->maxGap,
                  "Largest gap to close, in the model's length unit (default 1% of the bounding-box diagonal); for a "
                  "trimmed B-rep in the shown unit (the file's own, or --display-units; default 1 mm)");
  cmd->add_option("--crease-angle,--max-angle", o->maxAngle,
                  "Seams whose angle is above this (degrees, in (0, 180]) are design creases, left as designed "
                  "(default 20; 180 heals every seam)");
  cmd->add_option("--fairness", o->fairness,
                  "G2, and G1 where the local scheme does not apply: weight of the fairness term of the network "
                  "solve (default 10; 0: least control-point change only, faster, but curvature may grow sharply)");
  addToleranceOptions(*cmd, o->tol);
  addDisplayUnitsOption(*cmd, o->tol);
  cmd->add_flag("--json", o->json, "Print JSON instead of a table");
  cmd->callback([o, &exit]() {
    exit = kExitBadInput;
    if (!validToleranceOptions(o->tol)) return;
    HealOptions ho;
    auto cont = parseContinuity(o->continuity);
    if (!cont) return printError("--continuity: " + cont.status().message());
    ho.continuity = *cont;
    auto method = parseHealMethod(o->method);
    if (!method) return printError("--method: " + method.status().message());
    ho.method = *method;
    if (o->maxGap && !(*o->maxGap >= 0.0)) return printError("--max-gap must be a non-negative length");
    ho.maxGap = o->maxGap;
    if (o->maxAngle && !(*o->maxAngle > 0.0 && *o->maxAngle <= 180.0))
      return printError("--crease-angle must be an angle in degrees in (0, 180]");
    ho.maxAngleDeg = o->maxAngle;
    if (!(o->fairness >= 0.0 && std::isfinite(o->fairness)))
      return printError("--fairness must be a finite number >= 0");
    ho.g2Fairness = o->fairness;
    if (!checkOutputPath(o->file, o->out)) return;
    if (isCadFile(o->file) && isCadFile(o->out)) {
#ifdef SEAM_HAVE_OCCT
      exit = healBRep(*o, ho);
      return;
#endif
    }
    ModelUnits units;
    const std::optional<Model> model = loadModel(o->file, o->tol, &units);
    if (!model) return;
    if (model->brep && model->trimmedFaces > 0) {
      // A JSON model with trimmed faces is healed as its B-rep (issue 34 §2): never as patches without their trims.
#ifdef SEAM_HAVE_OCCT
      exit = healBRep(*o, ho, &*model);
      return;
#else
      return printError(fmt::format("{}: not healed: the model has {} trimmed faces (its \"brep\"), and this build "
                                    "has no OpenCASCADE to heal a B-rep; nothing written",
                                    o->file, model->trimmedFaces));
#endif
    }
    // The heal of an untrimmed patch model reports in the model's own unit.
    if (o->tol.display && units.shownUnit() != units.length)
      return printError(fmt::format("{}: --display-units applies to the heal of a trimmed B-rep; an untrimmed patch "
                                    "model is healed and reported in its own unit ({})",
                                    o->file, units.length ? units.name() : "none"));
    units.display.reset();
    // The classification tolerances as `seam check` resolves them: absolute (0.001 mm) for a model with a length unit.
    const ResolvedTolerances resolved = resolveTolerances(o->tol, units, model->boundingBox().diagonal());
    ho.tolerances = resolved.tolerances;
    if (model->patches.empty()) {  // only curves, or nothing: the output is the input, unchanged
      if (!saveModel(*model, o->out)) return;
      fmt::print("{}: the model has no patches: nothing to heal; wrote {} unchanged\n", o->file, o->out);
      exit = kExitOk;
      return;
    }
    auto res = healModel(*model, ho);
    if (!res) return printError(fmt::format("{}: {}", o->file, res.status().message()));
    const HealReport& r = res->report;
    if (!saveModel(res->model, o->out)) return;  // .json, .step/.stp, .iges/.igs by extension
    if (o->json) {
      OrderedJson j = healReportValue(r);
      addRepairUnits(j, units, resolved);
      j["output"] = o->out;
      printJson(j);
    } else {
      // The state of a seam in the words of `seam check`.
      auto state = [&r](const SeamReport& x) { return std::string(toString(seamVerdict(x, r.maxAngleDeg))); };
      std::vector<std::vector<std::string>> rows;
      for (const HealSeam& s : r.seams) {
        rows.push_back({fmt::format("{}:{} / {}:{}", s.a, edgeName(s.aEdge), s.b, edgeName(s.bEdge)),
                        std::to_string(s.region + 1), s.action, s.moved.empty() ? "-" : s.moved,
                        s.edgeMoved > 0.0 ? formatNumber(s.edgeMoved) : "0",
                        formatNumber(s.before.g0Max), formatNumber(s.before.g1MaxDeg), state(s.before),
                        s.after ? formatNumber(s.after->g0Max) : "?", s.after ? formatNumber(s.after->g1MaxDeg) : "?",
                        s.after ? state(*s.after) : "?",
                        fmt::format("{}/{}", s.before.certified ? "yes" : "no",
                                    s.after && s.after->certified ? "yes" : "no"),
                        s.worse ? "WORSE" : ""});
        if (r.requested == GeometricClass::kG2) {  // curvature jumps (relative, %), before and after
          auto jump = [](const SeamReport& x) {
            return meets(x.geometric, GeometricClass::kG1) ? formatNumber(100.0 * x.g2RelMax) : std::string("-");
          };
          rows.back().insert(rows.back().begin() + 8, jump(s.before));
          rows.back().insert(rows.back().begin() + 12, s.after ? jump(*s.after) : "?");
        }
      }
      std::string text = fmt::format("seam heal {} ({} requested, method {}, gaps up to {}, creases above {} deg "
                                     "left as designed)\n",
                                     o->file, toString(r.requested), toString(r.method),
                                     withUnit(formatNumber(r.maxGap), units), formatNumber(r.maxAngleDeg));
      text += unitLine(units, resolved, r.maxAngleDeg) + "\n";
      const std::string gapUnit = units.length ? " (" + units.name() + ")" : "";
      // "edge moved": how far the seam's two boundary curves moved (the larger), in the model's unit.
      std::vector<std::string> head = {"seam", "region", "action", "patch moved", "edge moved" + gapUnit,
                                       "gap before" + gapUnit, "angle before (deg)", "before", "gap after" + gapUnit,
                                       "angle after (deg)", "after", "certified before/after", ""};
      std::vector<bool> right = {false, true, false, false, true, true, true, false, true, true, false, false, false};
      if (r.requested == GeometricClass::kG2) {
        head.insert(head.begin() + 8, "curvature jump before (%)");
        right.insert(right.begin() + 8, true);
        head.insert(head.begin() + 12, "curvature jump after (%)");
        right.insert(right.begin() + 12, true);
      }
      text += formatTable(head, rows, right);
      std::vector<std::vector<std::string>> regions;
      for (size_t g = 0; g < r.regions.size(); ++g) {
        const HealRegion& x = r.regions[g];
        std::string names;
        for (size_t i = 0; i < x.patches.size() && i < 6; ++i) names += (i ? ", " : "") + x.patches[i];
        if (x.patches.size() > 6) names += fmt::format(", ... ({} patches)", x.patches.size());
        regions.push_back({std::to_string(g + 1), names, x.method, fmt::format("{} of {}", x.seamsAchieved, x.seams),
                           x.achieved ? "yes" : "no"});
      }
      text += "\n" + formatTable({"region", "patches", "method", "seams reaching " + std::string(toString(r.requested)),
                                  "achieved"},
                                 regions, {true, false, false, false, false});
      // The regions' notes below the table, wrapped, one clause per line.
      for (size_t g = 0; g < r.regions.size(); ++g)
        if (!r.regions[g].note.empty())
          text += fmt::format("region {}: {}\n", g + 1, wrapText(r.regions[g].note, 110, "    "));
      for (const HealStep& st : r.steps) {
        if (!st.accepted) text += fmt::format("step reverted: {} stays as it was: {}\n", st.patch, st.reason);
        else if (!st.kept)
          text += fmt::format("step not kept: {} stays as it was (region {} keeps {})\n", st.patch, st.region + 1,
                              r.regions[static_cast<size_t>(st.region)].method);
      }
      if (r.creasesKept > 0)
        text += fmt::format("creases, left as designed (angle above {} deg): {}{}\n", formatNumber(r.maxAngleDeg),
                            r.creasesKept,
                            r.creaseGapsClosed > 0
                                ? fmt::format("; the gap of {} closed or narrowed, the angle kept", r.creaseGapsClosed)
                                : std::string());
      // Each changed patch with its largest surface displacement.
      std::vector<std::string> changed;
      for (const HealPatch& p : r.patches)
        changed.push_back(fmt::format("{} ({})", p.name, withUnit(formatNumber(p.maxSurfaceDisplacement), units)));
      text += fmt::format("\npatches changed: {}\n", changed.empty() ? "none" : wrapList(changed, 110, "    "));
      text += fmt::format("largest surface displacement: {} ({} of the patch's size{}); control points: {}, moved "
                          "points: {}\n",
                          withUnit(formatNumber(r.maxSurfaceDisplacement), units),
                          formatNumber(r.maxSurfaceDisplacementRel),
                          r.surfaceDisplacementCertified ? ", a certified bound" : ", sampled",
                          formatNumber(r.maxDisplacement), r.movedPoints);
      text += fmt::format("seams reaching {}: {} of {}; worse than before: {}\n", toString(r.requested),
                          r.seamsAchieved, r.seamsToReach, r.seamsWorse);
      // Below G2 the heal certifies G0 and G1 only (the G2 subdivision is skipped): "G1" means G1 or better.
      text += fmt::format("worst after healing: {}{} (gap {}, angle {} deg)\n", toString(r.worst),
                          r.requested != GeometricClass::kG2 && r.worst == GeometricClass::kG1
                              ? " or better (a G0/G1 heal does not check G2; `seam check` the output for it)"
                              : "",
                          withUnit(formatNumber(r.worstG0), units), formatNumber(r.worstG1Deg));
      for (const std::string& n : r.notes) text += "note: " + n + "\n";
      text += fmt::format("output: {}\n", o->out);
      text += r.achieved ? fmt::format("{} achieved on every seam\n", toString(r.requested))
                         : fmt::format("requested {} NOT achieved on every seam; the output holds what was achieved, "
                                       "the rest is left as it was\n",
                                       toString(r.requested));
      fmt::print("{}", text);
    }
    exit = r.achieved ? kExitOk : kExitGeometryProblem;
  });
}

}  // namespace

static CommandRegistrar registerHeal("heal", addHeal);

}  // namespace seam::cli
