// seam corner FILE (--three S:E1:E2 T:E1:E2 H:E | --four P1:N:P P2:N:P P3:N:P P4:N:P) [--method auto|bspline]
//             [--fallback bezier-strip|least-squares] [--max-gap D] -o OUT.json [--json]
// Lai-Lian-Cassidy §4.1 (repair/corner_join.h): checks and reports the knot proportionality conditions at a corner
// of three (Fig. 1) or four C1 bicubic B-spline patches and joins them G1 by successive joins (Theorem 1 where the
// conditions hold, the fallback otherwise).
//   --three: S:<edge against S~>:<edge along S^>  S~:<edge against S>:<edge along S^>  S^:<edge meeting both>
//   --four:  Sk:<edge against S(k+1)>:<edge against S(k-1)> for k = 1..4 in cyclic order around the vertex.
// Every seam is reported before and after (gap, kink angle, crease / fold, certified) with the largest surface
// displacement; a join that would make any seam worse is undone (the output is then the input).
// Exit 0 when every seam at the corner is G1, 1 otherwise (OUT.json is still written), 2 bad input.
#include <fmt/format.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli_util.h"
#include "command_registry.h"
#include "seam/continuity/verdict.h"
#include "seam/continuity/model_check.h"
#include "seam/io/json.h"
#include "seam/repair/corner_join.h"
#include "seam/repair/heal.h"
#include "seam/repair/report_json.h"

namespace seam::cli {

namespace {

/// "NAME:e1[:e2]" split at the last one or two ':' (patch names may contain ':').
struct PatchEdges {
  std::string patch;
  std::vector<Edge> edges;
};
std::optional<PatchEdges> parsePatchEdges(const std::string& text, int count, const char* option) {
  PatchEdges r;
  std::string rest = text;
  for (int k = 0; k < count; ++k) {
    const auto colon = rest.rfind(':');
    if (colon == std::string::npos || colon == 0) {
      printError(fmt::format("{} expects PATCH{} (e.g. S1{}), got \"{}\"", option, count == 2 ? ":EDGE:EDGE" : ":EDGE",
                             count == 2 ? ":v0:u0" : ":u1", text));
      return std::nullopt;
    }
    auto e = parseEdge(rest.substr(colon + 1));
    if (!e) {
      printError(fmt::format("{}: {}", option, e.status().message()));
      return std::nullopt;
    }
    r.edges.insert(r.edges.begin(), *e);
    rest = rest.substr(0, colon);
  }
  r.patch = rest;
  return r;
}

std::string conditionsTable(const std::vector<ConditionCheck>& checks) {
  std::vector<std::vector<std::string>> rows;
  for (const ConditionCheck& k : checks)
    rows.push_back({std::string(toString(k.condition)), formatNumber(k.residual), formatNumber(k.tolerance),
                    k.holds ? "yes" : "NO", k.detail});
  return formatTable({"condition", "residual", "tolerance", "holds", "worst"}, rows, {false, true, true, false, false});
}

// The state of a seam in the words of `seam check` (gap, kink, crease, G1, G2).
std::string state(const SeamReport& x) { return std::string(toString(seamVerdict(x))); }

/// "achieved", or why not, for the first line of the output.
std::string cornerOutcome(const CornerJoinReport& r) {
  if (r.achieved) return "achieved";
  return r.reverted ? "NOT achieved (the corner is left as it was)" : "NOT achieved at every seam";
}

std::string reportText(const CornerJoinReport& r) {
  std::string text;
  for (const CornerJoinStep& s : r.steps) {
    std::string moved, onto;
    for (const std::string& m : s.moved) moved += (moved.empty() ? "" : ", ") + m;
    for (const std::string& m : s.onto) onto += (onto.empty() ? "" : ", ") + m;
    if (moved.empty()) moved = "nothing";
    text += fmt::format("join {} onto {}{}: {} ({}); max displacement {}, {} points\n", moved, onto,
                        r.reverted ? " (undone)" : "", toString(s.method), s.reason, formatNumber(s.maxDisplacement),
                        s.movedPoints);
    for (const std::string& n : s.notes) text += "  note: " + n + "\n";
  }
  std::vector<std::vector<std::string>> rows;
  for (const CornerSeam& s : r.seams) {
    const SeamReport* b = s.before ? &*s.before : nullptr;
    rows.push_back({fmt::format("{}:{} / {}:{}", s.a, edgeName(s.aEdge), s.b, edgeName(s.bEdge)),
                    b ? formatNumber(b->g0Max) : "?", b ? formatNumber(b->g1MaxDeg) : "?", b ? state(*b) : "?",
                    formatNumber(s.after.g0Max), formatNumber(s.after.g1MaxDeg), state(s.after),
                    fmt::format("{}/{}", b && b->certified ? "yes" : "no", s.after.certified ? "yes" : "no"),
                    s.worse ? "WORSE: " + s.worseWhy : ""});
  }
  text += "\n" + formatTable({"seam", "gap before", "kink before (deg)", "before", "gap after", "kink after (deg)",
                              "after", "certified before/after", ""},
                             rows, {false, true, true, false, true, true, false, false, false});
  if (r.reverted)
    text += fmt::format("the joins would make {} seam(s) worse: every patch is left as it was\n", r.seamsWorse);
  else
    text += fmt::format("largest surface displacement: {} ({} of the patch's size, a certified bound; {} found on a "
                        "grid); control points: {}\n",
                        formatNumber(r.maxSurfaceDisplacement), formatNumber(r.maxSurfaceDisplacementRel),
                        formatNumber(r.maxSurfaceDisplacementSampled), formatNumber(r.maxDisplacement));
  for (const std::string& n : r.notes) text += "note: " + n + "\n";
  return text;
}

void addCorner(CLI::App& app, int& exit) {
  struct Options {
    std::string file, out, method = "auto", fallback = "bezier-strip";
    std::vector<std::string> three, four;
    std::optional<double> maxGap;
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "corner", "Check the Lai-Lian-Cassidy §4.1 conditions at a corner of 3 or 4 patches and join them G1");
  cmd->add_option("FILE", o->file, modelFileHelp())->required();
  auto* three = cmd->add_option("--three", o->three, "S:E:E S~:E:E S^:E (Fig. 1)")->expected(3);
  auto* four = cmd->add_option("--four", o->four, "S1:N:P S2:N:P S3:N:P S4:N:P around a 4-valent vertex")->expected(4);
  three->excludes(four);
  cmd->add_option("--method", o->method, "auto (Theorem 1 where the conditions hold) or bspline (Theorem 1 or fail)");
  cmd->add_option("--fallback", o->fallback, "first join(s) without Theorem 1: bezier-strip (default) or least-squares");
  cmd->add_option("--max-gap", o->maxGap, "Largest gap to close (default 1% of the bounding-box diagonal)");
  cmd->add_option("-o,--output", o->out, "Output model file (written atomically)")->required();
  cmd->add_flag("--json", o->json, "Print JSON instead of a table");
  cmd->callback([o, &exit]() {
    exit = kExitBadInput;
    if (o->three.empty() && o->four.empty()) return printError("give --three or --four");
    CornerJoinOptions co;
    auto meth = parseJoinMethod(o->method);
    if (!meth) return printError("--method: " + meth.status().message());
    co.method = *meth;
    auto fb = parseJoinMethod(o->fallback);
    if (!fb) return printError("--fallback: " + fb.status().message());
    co.fallback = *fb;
    if (o->maxGap && !(*o->maxGap >= 0.0)) return printError("--max-gap must be a non-negative length");
    co.maxGap = o->maxGap;
    if (!checkOutputPath(o->file, o->out)) return;
    const std::optional<Model> model = loadModel(o->file);
    if (!model) return;
    bool achieved = false;
    if (!o->three.empty()) {
      const auto s = parsePatchEdges(o->three[0], 2, "--three");
      const auto t = parsePatchEdges(o->three[1], 2, "--three");
      const auto h = parsePatchEdges(o->three[2], 1, "--three");
      if (!s || !t || !h) return;
      const ThreePatchCorner c{s->patch, t->patch, h->patch, s->edges[0], t->edges[0], s->edges[1], t->edges[1],
                               h->edges[0]};
      auto res = joinThreePatchCorner(*model, c, co);
      if (!res) return printError(fmt::format("{}: {}", o->file, res.status().message()));
      if (!saveModel(res->model, o->out)) return;
      achieved = res->report.achieved;
      if (o->json) {
        OrderedJson j = OrderedJson::parse(threePatchJoinJson(*res));
        j["output"] = o->out;
        printJson(j);
      } else {
        std::string text = fmt::format("seam corner: match the three patches {}, {}, {} at their corner with tangent "
                                       "continuity: {}\n",
                                       c.s, c.sTilde, c.sHat, cornerOutcome(res->report));
        text += fmt::format("details: Lai-Lian-Cassidy Fig. 1 roles S = {}, S~ = {}, S^ = {}\n", c.s, c.sTilde, c.sHat);
        if (res->proportionality) {
          const ThreePatchProportionality& p = *res->proportionality;
          text += fmt::format("details: m = {}, m~ = {}, n = {}, n~ = {}, q = {}, corner at S^'s breakpoint K = {}\n",
                              p.m, p.mTilde, p.n, p.nTilde, p.q, p.cornerIndex);
          text += conditionsTable(p.checks) + "\n";
          for (const std::string& n : p.notes) text += "note: " + n + "\n";
        }
        text += reportText(res->report) + fmt::format("output: {}\n", o->out);
        text += achieved ? "G1 achieved\n"
                         : (res->report.reverted ? "G1 NOT achieved: the corner is left as it was (output = input)\n"
                                                 : "G1 NOT achieved at every seam; the output was written anyway\n");
        fmt::print("{}", text);
      }
    } else {
      FourPatchCorner c;
      for (size_t k = 0; k < 4; ++k) {
        const auto p = parsePatchEdges(o->four[k], 2, "--four");
        if (!p) return;
        c.patches[k] = p->patch;
        c.toNext[k] = p->edges[0];
        c.toPrev[k] = p->edges[1];
      }
      auto res = joinFourPatchCorner(*model, c, co);
      if (!res) return printError(fmt::format("{}: {}", o->file, res.status().message()));
      if (!saveModel(res->model, o->out)) return;
      achieved = res->report.achieved;
      if (o->json) {
        OrderedJson j = OrderedJson::parse(fourPatchJoinJson(*res));
        j["output"] = o->out;
        printJson(j);
      } else {
        std::string text = fmt::format("seam corner: match the four patches {}, {}, {}, {} around their common vertex "
                                       "with tangent continuity: {}\n",
                                       c.patches[0], c.patches[1], c.patches[2], c.patches[3],
                                       cornerOutcome(res->report));
        if (res->proportionality)
          text += "details: the §4.1 proportionality conditions (Lai-Lian-Cassidy, Theorem 1)\n" +
                  conditionsTable(res->proportionality->checks) + "\n";
        text += reportText(res->report) + fmt::format("output: {}\n", o->out);
        text += achieved ? "G1 achieved\n"
                         : (res->report.reverted ? "G1 NOT achieved: the corner is left as it was (output = input)\n"
                                                 : "G1 NOT achieved at every seam; the output was written anyway\n");
        fmt::print("{}", text);
      }
    }
    exit = achieved ? kExitOk : kExitGeometryProblem;
  });
}

}  // namespace

static CommandRegistrar registerCorner("corner", addCorner);

}  // namespace seam::cli
