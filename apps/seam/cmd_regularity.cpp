// seam regularity FILE [--curve NAME | --patch NAME] [--ell L] [--json]: regularity certificates
// (Dyn-Levin-Yad-Shalom, Lau) per curve segment / surface sub-net, Theorems 2.7 / 3.5, and the defect search.
// Exit 1 when a verdict is "fails" or the search finds a critical point or self-intersection.
#include <fmt/format.h>

#include <memory>
#include <string>
#include <vector>

#include "cli_util.h"
#include "command_registry.h"
#include "seam/regularity/regularity.h"

namespace seam::cli {

namespace {

using namespace seam::regularity;

OrderedJson point(const Vec3& p, int dim) {
  OrderedJson a = OrderedJson::array();
  for (int k = 0; k < dim; ++k) a.push_back(p[k]);
  return a;
}

OrderedJson checkJson(const Check& c, int dim) {
  OrderedJson j;
  j["check"] = std::string(checkKindName(c.kind));
  if (c.r1 > 0) j["r1"] = c.r1;
  if (c.r2 > 0) j["r2"] = c.r2;
  if (c.separation.separated) {
    j["normal"] = point(c.separation.plane.normal, dim);
    j["offset"] = c.separation.plane.offset;
    j["exact"] = c.separation.planeExact;
  } else {
    j["witness"] = point(c.separation.witness, dim);
    if (!c.coneDirection.isZero()) j["cone_direction"] = point(c.coneDirection, dim);
  }
  return j;
}

/// "certificate" (certified) or "witness" / "failed_check" (otherwise) of a verdict.
void verdictJson(OrderedJson& j, Verdict v, Condition c, const ConditionResult& r, int dim) {
  j["verdict"] = std::string(verdictName(v));
  j["condition"] = c == Condition::kNone ? OrderedJson(nullptr) : OrderedJson(std::string(conditionName(c)));
  if (v == Verdict::kCertified) {
    OrderedJson checks = OrderedJson::array();
    for (const Check& k : r.checks) checks.push_back(checkJson(k, dim));
    j["certificate"] = {{"checks", checks}};
  } else if (const Check* f = r.failure()) {
    j["witness"] = point(f->separation.witness, dim);
    j["failed_check"] = checkJson(*f, dim);
  }
}

OrderedJson summaryJson(const SearchSummary& s) {
  return {{"resolution", s.resolution}, {"distance", s.distance}, {"unresolved", s.unresolved},
          {"complete", s.complete},     {"truncated", s.truncated}};
}

std::string witnessText(const ConditionResult& r, int dim) {
  const Check* f = r.failure();
  if (!f) return "-";
  std::string s = std::string(checkKindName(f->kind));
  if (f->r1 > 0) s += fmt::format(" r1={}", f->r1);
  if (f->r2 > 0) s += fmt::format(" r2={}", f->r2);
  return s + " at " + formatVector(f->separation.witness.data(), dim);
}

std::string interval(const Interval& i) { return "[" + formatNumber(i.lo) + ", " + formatNumber(i.hi) + "]"; }

struct Counts {
  int certified = 0, fails = 0, na = 0;
  void add(Verdict v) { (v == Verdict::kCertified ? certified : v == Verdict::kFails ? fails : na)++; }
  [[nodiscard]] std::string text(const char* unit) const {
    return fmt::format("{} {}: {} certified, {} fails, {} not-applicable", certified + fails + na, unit, certified,
                       fails, na);
  }
};

std::string searchText(int critical, int intersections, const SearchSummary& s) {
  return fmt::format("search: {} critical point{}, {} self-intersection{} (resolution {}, distance {}{}{})", critical,
                     critical == 1 ? "" : "s", intersections, intersections == 1 ? "" : "s",
                     formatNumber(s.resolution), formatNumber(s.distance),
                     s.unresolved > 0 ? fmt::format(", {} unresolved", s.unresolved) : "",
                     s.complete ? "" : ", budget exhausted");
}

void addRegularity(CLI::App& app, int& exit) {
  struct Options {
    std::string file;
    std::string curve;
    std::string patch;
    int ell = RegularityOptions{}.maxEll;
    bool json = false;
  };
  auto o = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(
      "regularity", "Certify curve segments and surface sub-nets free of critical points and self-intersections");
  cmd->add_option("FILE", o->file, "Model file (.json or .bpt)")->required();
  CLI::Option* curveOpt = cmd->add_option("--curve", o->curve, "Only this curve");
  CLI::Option* patchOpt = cmd->add_option("--patch", o->patch, "Only this patch");
  curveOpt->excludes(patchOpt);
  cmd->add_option("--ell", o->ell, "Try Theorems 2.7 / 3.5 up to orders k + L (default 2)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--json", o->json, "Print JSON instead of a table");
  cmd->callback([o, &exit]() {
    const std::optional<Model> model = loadModel(o->file);
    if (!model) {
      exit = kExitBadInput;
      return;
    }
    std::vector<const Curve*> curves;
    std::vector<const Patch*> patches;
    if (!o->curve.empty()) {
      const Curve* c = model->findCurve(o->curve);
      if (!c) {
        printError(fmt::format("{}: no curve named \"{}\"", o->file, o->curve));
        exit = kExitBadInput;
        return;
      }
      curves.push_back(c);
    } else if (!o->patch.empty()) {
      const Patch* p = model->findPatch(o->patch);
      if (!p) {
        printError(fmt::format("{}: no patch named \"{}\"", o->file, o->patch));
        exit = kExitBadInput;
        return;
      }
      patches.push_back(p);
    } else {
      for (const Curve& c : model->curves) curves.push_back(&c);
      for (const Patch& p : model->patches) patches.push_back(&p);
    }
    RegularityOptions options;
    options.maxEll = o->ell;

    bool problem = false;
    OrderedJson jc = OrderedJson::array();
    OrderedJson jp = OrderedJson::array();
    std::vector<std::vector<std::string>> rows;
    std::vector<std::string> summary;
    for (const Curve* c : curves) {
      Result<CurveRegularity> r = analyzeCurve(c->curve, options);
      if (!r) {
        printError(fmt::format("{}: curve \"{}\": {}", o->file, c->name, r.status().message()));
        exit = kExitBadInput;
        return;
      }
      problem = problem || r->anyFails();
      Counts counts;
      OrderedJson segs = OrderedJson::array();
      for (const SegmentVerdict& s : r->segments) {
        counts.add(s.verdict);
        OrderedJson j = {{"index", s.index}, {"interval", {s.interval.lo, s.interval.hi}}, {"uniform", s.uniform}};
        verdictJson(j, s.verdict, s.condition, s.result, r->dim);
        j["defect_nearby"] = s.defectNearby;
        segs.push_back(j);
        rows.push_back({"curve " + c->name, std::to_string(s.index), interval(s.interval),
                        s.uniform ? "uniform" : "non-uniform", std::string(verdictName(s.verdict)),
                        std::string(conditionName(s.condition)),
                        s.verdict == Verdict::kCertified ? "-" : witnessText(s.result, r->dim),
                        s.defectNearby ? "yes" : "no"});
      }
      OrderedJson crit = OrderedJson::array();
      OrderedJson inter = OrderedJson::array();
      for (const CurveCriticalPoint& x : r->search->criticalPoints) {
        crit.push_back({{"t", x.t}, {"point", point(x.point, r->dim)}, {"speed", x.speed}});
      }
      for (const CurveSelfIntersection& x : r->search->selfIntersections) {
        inter.push_back({{"t1", x.t1}, {"t2", x.t2}, {"point", point(x.point, r->dim)}, {"distance", x.distance}});
      }
      jc.push_back({{"name", c->name},
                    {"order", r->order},
                    {"segments", segs},
                    {"ell_certified", r->ellCertified ? OrderedJson(*r->ellCertified) : OrderedJson(nullptr)},
                    {"critical_points", crit},
                    {"self_intersections", inter},
                    {"search", summaryJson(r->search->summary)}});
      summary.push_back(fmt::format(
          "curve {}: {}; ell certified: {}; {}", c->name, counts.text("segments"),
          r->ellCertified ? std::to_string(*r->ellCertified) : "none",
          searchText(static_cast<int>(crit.size()), static_cast<int>(inter.size()), r->search->summary)));
    }
    for (const Patch* p : patches) {
      Result<SurfaceRegularity> r = analyzeSurface(p->surface, options);
      if (!r) {
        printError(fmt::format("{}: patch \"{}\": {}", o->file, p->name, r.status().message()));
        exit = kExitBadInput;
        return;
      }
      problem = problem || r->anyFails();
      Counts counts;
      OrderedJson subs = OrderedJson::array();
      for (const SubnetVerdict& s : r->subnets) {
        counts.add(s.verdict);
        OrderedJson j = {{"index", {s.indexU, s.indexV}},
                         {"u", {s.u.lo, s.u.hi}},
                         {"v", {s.v.lo, s.v.hi}},
                         {"uniform", s.uniformU && s.uniformV}};
        verdictJson(j, s.verdict, s.condition, s.result, r->dim);
        j["defect_nearby"] = s.defectNearby;
        subs.push_back(j);
        rows.push_back({"patch " + p->name, fmt::format("{},{}", s.indexU, s.indexV),
                        interval(s.u) + " x " + interval(s.v),
                        s.uniformU && s.uniformV ? "uniform" : "non-uniform", std::string(verdictName(s.verdict)),
                        std::string(conditionName(s.condition)),
                        s.verdict == Verdict::kCertified ? "-" : witnessText(s.result, r->dim),
                        s.defectNearby ? "yes" : "no"});
      }
      OrderedJson crit = OrderedJson::array();
      OrderedJson inter = OrderedJson::array();
      for (const SurfaceCriticalPoint& x : r->search->criticalPoints) {
        crit.push_back({{"u", x.u}, {"v", x.v}, {"point", point(x.point, r->dim)}, {"normal_norm", x.normalNorm}});
      }
      for (const SurfaceSelfIntersection& x : r->search->selfIntersections) {
        inter.push_back({{"u1", x.u1},
                         {"v1", x.v1},
                         {"u2", x.u2},
                         {"v2", x.v2},
                         {"point", point(x.point, r->dim)},
                         {"distance", x.distance}});
      }
      const bool haveEll = r->ellU.has_value();
      jp.push_back({{"name", p->name},
                    {"order", {r->orderU, r->orderV}},
                    {"subnets", subs},
                    {"ell_certified", haveEll ? OrderedJson({*r->ellU, *r->ellV}) : OrderedJson(nullptr)},
                    {"critical_points", crit},
                    {"self_intersections", inter},
                    {"search", summaryJson(r->search->summary)}});
      summary.push_back(fmt::format(
          "patch {}: {}; ell certified: {}; {}", p->name, counts.text("sub-nets"),
          haveEll ? fmt::format("{} x {}", *r->ellU, *r->ellV) : "none",
          searchText(static_cast<int>(crit.size()), static_cast<int>(inter.size()), r->search->summary)));
    }
    if (o->json) {
      printJson(OrderedJson{{"file", o->file}, {"curves", jc}, {"patches", jp}});
    } else {
      if (!rows.empty()) {
        fmt::print("{}", formatTable({"object", "index", "parameters", "knots", "verdict", "condition",
                                      "witness", "defect nearby"},
                                     rows));
      }
      fmt::print("\n");
      for (const std::string& s : summary) fmt::print("{}\n", s);
      fmt::print("{}\n", problem ? "result: problems found" : "result: no problem found");
    }
    exit = problem ? kExitGeometryProblem : kExitOk;
  });
}

}  // namespace

static CommandRegistrar registerRegularity("regularity", addRegularity);

}  // namespace seam::cli
