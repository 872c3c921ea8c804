// seam heal FILE -o OUT.json [--continuity G0|G1] [--max-gap D] [--json]
// Finds every seam whose gap is below --max-gap and joins the open ones by successive joins (repair/heal.h); prints
// every seam before and after and the worst result. Exit 0 when every such seam meets the requested continuity,
// 1 otherwise (OUT.json is still written), 2 bad input.
#include <fmt/format.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli_util.h"
#include "command_registry.h"
#include "seam/io/json.h"
#include "seam/repair/heal.h"
#include "seam/repair/join.h"
#include "seam/repair/report_json.h"

namespace seam::cli {

namespace {

void addHeal(CLI::App& app, int& exit) {
  struct Options {
    std::string file, out, continuity = "G1";
    std::optional<double> maxGap;
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("heal", "Close the gaps and kinks of every seam of a model (G0/G1)");
  cmd->add_option("FILE", o->file, "Model file (.json or .bpt)")->required();
  cmd->add_option("-o,--output", o->out, "Output model file (written atomically)")->required();
  cmd->add_option("--continuity", o->continuity, "G0 or G1 (default G1)");
  cmd->add_option("--max-gap", o->maxGap, "Largest gap to close (default 1% of the bounding-box diagonal)");
  cmd->add_flag("--json", o->json, "Print JSON instead of a table");
  cmd->callback([o, &exit]() {
    exit = kExitBadInput;
    HealOptions ho;
    auto cont = parseContinuity(o->continuity);
    if (!cont) return printError("--continuity: " + cont.status().message());
    ho.continuity = *cont;
    if (o->maxGap && !(*o->maxGap >= 0.0)) return printError("--max-gap must be a non-negative length");
    ho.maxGap = o->maxGap;
    const std::optional<Model> model = loadModel(o->file);
    if (!model) return;
    auto res = healModel(*model, ho);
    if (!res) return printError(res.status().message());
    const HealReport& r = res->report;
    if (!saveModel(res->model, o->out)) return;  // .json, .step/.stp, .iges/.igs by extension
    if (o->json) {
      OrderedJson j = OrderedJson::parse(healReportJson(r));
      j["output"] = o->out;
      printJson(j);
    } else {
      std::vector<std::vector<std::string>> rows;
      for (const HealSeam& s : r.seams) {
        const std::string after = s.after ? std::string(toString(s.after->geometric)) : "?";
        rows.push_back({fmt::format("{}:{} / {}:{}", s.a, edgeName(s.aEdge), s.b, edgeName(s.bEdge)), s.action,
                        s.moved.empty() ? "-" : s.moved, formatNumber(s.before.g0Max),
                        formatNumber(s.before.g1MaxDeg), std::string(toString(s.before.geometric)),
                        s.after ? formatNumber(s.after->g0Max) : "?", s.after ? formatNumber(s.after->g1MaxDeg) : "?",
                        after, s.after && s.after->certified ? "yes" : "no"});
      }
      std::string text = fmt::format("seam heal {} ({} requested, gaps up to {})\n\n", o->file, toString(r.requested),
                                     formatNumber(r.maxGap));
      text += formatTable({"seam", "action", "moved", "G0 before", "G1 before", "class", "G0 after", "G1 after",
                           "class", "certified"},
                          rows, {false, false, false, true, true, false, true, true, false, false});
      std::string changed;
      for (const std::string& p : r.patchesChanged) changed += (changed.empty() ? "" : ", ") + p;
      text += fmt::format("\npatches changed: {}\n", changed.empty() ? "none" : changed);
      text += fmt::format("max control-point displacement: {}, moved points: {}\n", formatNumber(r.maxDisplacement),
                          r.movedPoints);
      text += fmt::format("worst after healing: {} (gap {}, angle {} deg)\n", toString(r.worst),
                          formatNumber(r.worstG0), formatNumber(r.worstG1Deg));
      for (const std::string& n : r.notes) text += "note: " + n + "\n";
      text += fmt::format("output: {}\n", o->out);
      text += r.achieved ? fmt::format("{} achieved on every seam\n", toString(r.requested))
                         : fmt::format("requested {} NOT achieved on every seam; the output was written anyway\n",
                                       toString(r.requested));
      fmt::print("{}", text);
    }
    exit = r.achieved ? kExitOk : kExitGeometryProblem;
  });
}

}  // namespace

static CommandRegistrar registerHeal("heal", addHeal);

}  // namespace seam::cli
