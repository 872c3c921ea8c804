// seam regularity FILE [--curve NAME | --patch NAME] [--ell L] [--json]: regularity certificates
// (Dyn-Levin-Yad-Shalom, Lau) per curve segment / surface sub-net, Theorems 2.7 / 3.5, and the defect search.
// Exit 1 when a verdict is "fails" or the search finds a critical point or self-intersection.
#include <fmt/format.h>

#include <chrono>
#include <iostream>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "cli_util.h"
#include "command_registry.h"
#include "regularity_json.h"
#include "seam/regularity/regularity.h"

namespace seam::cli {

namespace {

using namespace seam::regularity;

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

/// The plain-language verdict of one curve or patch (issue 17 §6): cusps (points where the curve's tangent or the
/// surface's normal vanishes, the search's critical points) and self-intersections first; the certificates' names go
/// to the details line.
std::string plainVerdict(const std::string& object, const Counts& counts, int cusps, int intersections,
                         const SearchSummary& s) {
  if (counts.fails == 0 && cusps == 0 && intersections == 0) {
    if (counts.na == 0) return fmt::format("{}: smooth and regular: no cusp, no self-intersection (certified)", object);
    return fmt::format("{}: no cusp and no self-intersection found{}; regularity not certified on {} piece{}", object,
                       s.complete && s.unresolved == 0 ? "" : " (search incomplete)", counts.na,
                       counts.na == 1 ? "" : "s");
  }
  std::vector<std::string> found;
  if (cusps > 0) found.push_back(fmt::format("{} cusp{} (the tangent or normal vanishes)", cusps, cusps == 1 ? "" : "s"));
  if (intersections > 0)
    found.push_back(fmt::format("{} self-intersection{}", intersections, intersections == 1 ? "" : "s"));
  if (counts.fails > 0)
    found.push_back(fmt::format("{} piece{} not certified regular", counts.fails, counts.fails == 1 ? "" : "s"));
  std::string text;
  for (const std::string& f : found) text += (text.empty() ? "" : ", ") + f;
  return fmt::format("{}: PROBLEM: {}", object, text);
}

std::string searchText(int critical, int intersections, const SearchSummary& s) {
  return fmt::format("search: {} critical point{}, {} self-intersection{} (resolution {}, distance {}{}{})", critical,
                     critical == 1 ? "" : "s", intersections, intersections == 1 ? "" : "s",
                     formatNumber(s.resolution), formatNumber(s.distance),
                     s.unresolved > 0 ? fmt::format(", {} unresolved", s.unresolved) : "",
                     s.complete ? "" : ", budget exhausted");
}

/// The placeholder value of the (large) segments / sub-nets array in the curve / patch object of the JSON output,
/// which is streamed in its place.
constexpr const char* kPlaceholder = "\x01items\x01";

/// Streams JSON text in the layout of jsonText (cli_util.h) without building the whole document: a 200 000-segment
/// curve is a tree of millions of nodes otherwise (seconds and gigabytes for nothing).
class JsonStream {
 public:
  ~JsonStream() { flush(); }
  /// jsonText(v) of a value nested `indent` spaces deep (its own first line not indented).
  void value(const OrderedJson& v, int indent) {
    std::string text = jsonText(v);
    text.pop_back();  // the final newline
    append(text, indent);
    if (out_.size() > (1u << 20)) flush();
  }
  /// An array of `count` objects made by item(k), nested `indent` spaces deep.
  template <class Fn>
  void array(size_t count, int indent, Fn item) {
    if (count == 0) {
      out_ += "[]";
      return;
    }
    const std::string pad(static_cast<size_t>(indent + 2), ' ');
    out_ += "[\n";
    for (size_t k = 0; k < count; ++k) {
      if (k > 0) out_ += ",\n";
      out_ += pad;
      item(k);
    }
    out_ += "\n" + std::string(static_cast<size_t>(indent), ' ') + "]";
  }
  /// An object nested `indent` deep whose value kPlaceholder is replaced by items(indent + 2).
  template <class Fn>
  void objectWithItems(const OrderedJson& v, int indent, Fn items) {
    std::string text = jsonText(v);
    text.pop_back();  // the final newline
    std::string mark = jsonText(OrderedJson(kPlaceholder));
    mark.pop_back();
    const size_t at = text.find(mark);
    append(text.substr(0, at), indent);
    items(indent + 2);
    append(text.substr(at + mark.size()), indent);
  }
  void raw(std::string_view s) { out_ += s; }
  void flush() {
    std::cout << out_;
    out_.clear();
  }

 private:
  void append(const std::string& text, int indent) {
    const std::string pad = "\n" + std::string(static_cast<size_t>(indent), ' ');
    for (char c : text) {
      if (c == '\n') {
        out_ += pad;
      } else {
        out_ += c;
      }
    }
  }
  std::string out_;
};

/// Progress lines on stderr for long runs: nothing during the first second, then at most one line a second, on
/// any stderr (a terminal or a log), like the progress of `seam check` on large B-reps. Its callbacks are called
/// from the threads that analyse the objects at once; the one line a second is whichever object's comes first.
class ProgressPrinter {
 public:
  explicit ProgressPrinter(std::string file) : file_(std::move(file)), start_(Clock::now()), last_(start_) {}
  ProgressCallback callback(const std::string& object) {
    return [this, object](std::string_view stage, long done, long total) {
      const Clock::time_point now = Clock::now();
      const std::lock_guard<std::mutex> lock(mutex_);
      if (now - start_ < std::chrono::seconds(1) || now - last_ < std::chrono::seconds(1)) return;
      last_ = now;
      const double elapsed = std::chrono::duration<double>(now - start_).count();
      std::cerr << fmt::format("seam: {}: {}: {} {} of {} ({:.1f} s)\n", file_, object, stage, done, total, elapsed);
    };
  }

 private:
  using Clock = std::chrono::steady_clock;
  std::string file_;
  Clock::time_point start_;
  Clock::time_point last_;
  std::mutex mutex_;
};

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
  cmd->add_option("FILE", o->file, modelFileHelp())->required();
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
    ProgressPrinter progress(o->file);

    // Everything is analysed before anything is printed (a failing object prints its error and nothing else: the
    // first in the file's order). `collect` moves the results out, or returns false at the first error.
    bool problem = false;
    const auto collect = [&](const auto& objects, auto& got, const char* kind, auto& results) {
      for (size_t i = 0; i < objects.size(); ++i) {
        if (!got[i]) {
          printError(fmt::format("{}: {} \"{}\": {}", o->file, kind, objects[i]->name, got[i].status().message()));
          exit = kExitBadInput;
          return false;
        }
        problem = problem || got[i]->anyFails();
        results.push_back(std::move(got[i]).value());
      }
      return true;
    };
    std::vector<const BSplineCurve*> curveOf;
    for (const Curve* c : curves) curveOf.push_back(&c->curve);
    std::vector<Result<CurveRegularity>> curveGot = analyzeCurves(
        curveOf, options, [&](size_t i) { return progress.callback("curve \"" + curves[i]->name + "\""); });
    std::vector<CurveRegularity> curveResults;
    if (!collect(curves, curveGot, "curve", curveResults)) return;
    std::vector<const BSplineSurface*> surfaceOf;
    for (const Patch* p : patches) surfaceOf.push_back(&p->surface);
    std::vector<Result<SurfaceRegularity>> patchGot = analyzeSurfaces(
        surfaceOf, options, [&](size_t i) { return progress.callback("patch \"" + patches[i]->name + "\""); });
    std::vector<SurfaceRegularity> patchResults;
    if (!collect(patches, patchGot, "patch", patchResults)) return;
    exit = problem ? kExitGeometryProblem : kExitOk;

    if (o->json) {
      // {"file": ..., "curves": [...], "patches": [...]} in jsonText's layout, streamed.
      JsonStream out;
      out.raw("{\n  \"file\": ");
      out.value(OrderedJson(o->file), 2);
      out.raw(",\n  \"curves\": ");
      out.array(curveResults.size(), 2, [&](size_t i) {
        const CurveRegularity& r = curveResults[i];
        out.objectWithItems(regularityCurveJson(curves[i]->name, r, OrderedJson(kPlaceholder)), 4, [&](int indent) {
          out.array(r.segments.size(), indent, [&](size_t k) { out.value(regularitySegmentJson(r.segments[k], r.dim), indent + 2); });
        });
      });
      out.raw(",\n  \"patches\": ");
      out.array(patchResults.size(), 2, [&](size_t i) {
        const SurfaceRegularity& r = patchResults[i];
        out.objectWithItems(regularityPatchJson(patches[i]->name, r, OrderedJson(kPlaceholder)), 4, [&](int indent) {
          out.array(r.subnets.size(), indent, [&](size_t k) { out.value(regularitySubnetJson(r.subnets[k], r.dim), indent + 2); });
        });
      });
      out.raw("\n}\n");
      out.flush();
      std::cout << std::flush;
      return;
    }

    std::vector<std::vector<std::string>> rows;
    std::vector<std::string> summary;
    for (size_t i = 0; i < curveResults.size(); ++i) {
      const CurveRegularity& r = curveResults[i];
      const std::string& name = curves[i]->name;
      Counts counts;
      for (const SegmentVerdict& s : r.segments) {
        counts.add(s.verdict);
        rows.push_back({"curve " + name, std::to_string(s.index), interval(s.interval),
                        s.uniform ? "uniform" : "non-uniform", std::string(verdictName(s.verdict)),
                        std::string(conditionName(s.condition)),
                        s.verdict == Verdict::kCertified ? "-" : witnessText(s.result, r.dim),
                        s.defectNearby ? "yes" : "no"});
      }
      summary.push_back(plainVerdict("curve " + name, counts, static_cast<int>(r.search->criticalPoints.size()),
                                     static_cast<int>(r.search->selfIntersections.size()), r.search->summary));
      summary.push_back(fmt::format("  details: {} (Dyn-Levin-Yad-Shalom conditions); ell certified: {}; {}",
                                    counts.text("segments"),
                                    r.ellCertified ? std::to_string(*r.ellCertified) : "none",
                                    searchText(static_cast<int>(r.search->criticalPoints.size()),
                                               static_cast<int>(r.search->selfIntersections.size()),
                                               r.search->summary)));
    }
    for (size_t i = 0; i < patchResults.size(); ++i) {
      const SurfaceRegularity& r = patchResults[i];
      const std::string& name = patches[i]->name;
      Counts counts;
      for (const SubnetVerdict& s : r.subnets) {
        counts.add(s.verdict);
        rows.push_back({"patch " + name, fmt::format("{},{}", s.indexU, s.indexV),
                        interval(s.u) + " x " + interval(s.v),
                        s.uniformU && s.uniformV ? "uniform" : "non-uniform", std::string(verdictName(s.verdict)),
                        std::string(conditionName(s.condition)),
                        s.verdict == Verdict::kCertified ? "-" : witnessText(s.result, r.dim),
                        s.defectNearby ? "yes" : "no"});
      }
      const bool haveEll = r.ellU.has_value();
      summary.push_back(plainVerdict("patch " + name, counts, static_cast<int>(r.search->criticalPoints.size()),
                                     static_cast<int>(r.search->selfIntersections.size()), r.search->summary));
      summary.push_back(fmt::format("  details: {} (Dyn-Levin-Yad-Shalom conditions); ell certified: {}; {}",
                                    counts.text("sub-nets"),
                                    haveEll ? fmt::format("{} x {}", *r.ellU, *r.ellV) : "none",
                                    searchText(static_cast<int>(r.search->criticalPoints.size()),
                                               static_cast<int>(r.search->selfIntersections.size()),
                                               r.search->summary)));
    }
    if (!rows.empty()) {
      fmt::print("{}", formatTable({"object", "index", "parameters", "knots", "certificate", "condition (paper)",
                                    "witness", "defect nearby"},
                                   rows));
    }
    fmt::print("\n");
    for (const std::string& line : summary) fmt::print("{}\n", line);
    fmt::print("{}\n", problem ? "result: problems found (cusps, self-intersections or uncertified pieces)"
                               : "result: no problem found");
  });
}

}  // namespace

static CommandRegistrar registerRegularity("regularity", addRegularity);

}  // namespace seam::cli
