// seam gcn FILE --seam A:ea B:eb [--order N] [--json]
// Geometric continuity of order n between rational patches (Zheng-Wang-Liang): the highest GC^n and rational C^n
// orders along the seam, the residual of each order, the connecting functions sampled along A's edge, and for
// B-spline / NURBS pairs the certified verdict of Theorem 5 with the degrees of its polynomials.
#include <fmt/format.h>

#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli_util.h"
#include "command_registry.h"
#include "seam/rational/expression.h"
#include "seam/rational/gcn.h"

namespace seam::cli {

namespace {

/// Orders tested when --order is not given (then the exit code is 1 only when the patches do not even meet).
constexpr int kDefaultGcnOrder = 3;
/// Connecting-function samples printed in the text report (the JSON has all of them).
constexpr size_t kPrintedSamples = 5;

struct GcnCliOptions {
  std::string file;
  std::vector<std::string> seam;
  int order = kDefaultGcnOrder;
  bool json = false;
};

struct SideRef {
  std::string name;
  Edge edge = Edge::U0;
};

std::optional<SideRef> parseSide(const std::string& text) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon == 0) {
    printError(fmt::format("--seam: \"{}\" must be PATCH:EDGE (edge u0, u1, v0 or v1)", text));
    return std::nullopt;
  }
  auto e = parseEdge(text.substr(colon + 1));
  if (!e) {
    printError(fmt::format("--seam: \"{}\": {}", text, e.status().message()));
    return std::nullopt;
  }
  return SideRef{text.substr(0, colon), *e};
}

OrderedJson numbers(const std::vector<double>& v) {
  OrderedJson a = OrderedJson::array();
  for (double x : v) a.push_back(x);
  return a;
}

OrderedJson reportJson(const rational::GcnReport& r, int order) {
  OrderedJson j;
  j["gc_order"] = r.gcOrder;
  j["c_order"] = r.cOrder;
  j["certified"] = r.certified;
  j["residuals"] = numbers(r.residuals);
  OrderedJson cf;
  std::vector<double> s;
  for (const auto& x : r.sampled.samples) s.push_back(x.s);
  cf["s"] = numbers(s);
  OrderedJson c = OrderedJson::array(), p = OrderedJson::array(), q = OrderedJson::array();
  for (int i = 0; i <= r.gcOrder; ++i) {
    std::vector<double> ci, pi, qi;
    for (const auto& x : r.sampled.samples) {
      ci.push_back(x.c[static_cast<size_t>(i)]);
      if (i >= 1) {
        pi.push_back(x.p[static_cast<size_t>(i - 1)]);
        qi.push_back(x.q[static_cast<size_t>(i - 1)]);
      }
    }
    c.push_back(numbers(ci));
    if (i >= 1) {
      p.push_back(numbers(pi));
      q.push_back(numbers(qi));
    }
  }
  cf["c"] = c;
  cf["p"] = p;
  cf["q"] = q;
  j["connecting_functions"] = cf;
  j["order"] = order;
  j["case"] = r.certified || !r.exact.empty() ? std::string(rational::toString(r.gcnCase)) : std::string("sampled");
  j["seam"] = {{"a", r.a},
               {"a_edge", std::string(edgeName(r.aEdge))},
               {"b", r.b},
               {"b_edge", std::string(edgeName(r.bEdge))},
               {"overlap_a", {r.overlapA.lo, r.overlapA.hi}},
               {"overlap_b", {r.overlapB.lo, r.overlapB.hi}},
               {"slope", r.slope},
               {"offset", r.offset}};
  // psi1 (3.3) is the transversal pbar_1 = 1 across B; psi2 (3.6) has the coefficients p_i, q_i above.
  std::vector<double> pbar(static_cast<size_t>(order), 0.0), qbar(static_cast<size_t>(order), 0.0);
  if (order >= 1) pbar[0] = 1.0;
  j["psi"] = {{"pbar", numbers(pbar)},
              {"qbar", numbers(qbar)},
              {"cn_claim_verified", r.sampled.cnClaimVerified},
              {"cartesian_mismatch", numbers(r.sampled.cartesianMismatch)}};
  j["sampled"] = {{"gc_order", r.sampled.gcOrder},
                  {"c_order", r.sampled.cOrder},
                  {"residuals", numbers(r.sampled.residuals)}};
  OrderedJson degrees = OrderedJson::array();
  for (const auto& piece : r.exact) {
    OrderedJson d = OrderedJson::array();
    for (const auto& e : piece.result.degrees)
      d.push_back({{"name", e.name}, {"found", e.found}, {"bound", e.bound}, {"after_elimination", e.afterElimination}});
    degrees.push_back({{"t", {piece.t.lo, piece.t.hi}},
                       {"gc_order", piece.result.gcOrder},
                       {"minor", piece.result.functions.minor},
                       {"roots_of_d", numbers(piece.result.functions.rootsOfD)},
                       {"degrees", d}});
  }
  j["exact_pieces"] = degrees;
  OrderedJson notes = OrderedJson::array();
  for (const auto& n : r.notes) notes.push_back(n);
  j["notes"] = notes;
  return j;
}

void printText(const rational::GcnReport& r, int order) {
  std::string out = fmt::format("seam {}:{} / {}:{}  (A's edge t in [{}, {}], B's edge = {} t + {})\n", r.a,
                                edgeName(r.aEdge), r.b, edgeName(r.bEdge), formatNumber(r.overlapA.lo),
                                formatNumber(r.overlapA.hi), formatNumber(r.slope), formatNumber(r.offset));
  const std::string how =
      r.certified ? fmt::format("certified: Theorem 5 on {} Bezier piece(s), case {}", r.exact.size(),
                                rational::toString(r.gcnCase))
                  : fmt::format("sampled at {} points (not certified)", r.sampled.samples.size());
  out += fmt::format("GC order: {}   rational C order: {}   (orders 0..{} tested; {})\n",
                     r.gcOrder < 0 ? std::string("none") : std::to_string(r.gcOrder),
                     r.cOrder < 0 ? std::string("none") : std::to_string(r.cOrder), order, how);
  std::vector<std::vector<std::string>> rows;
  for (size_t m = 0; m < r.residuals.size(); ++m)
    rows.push_back({std::to_string(m), formatNumber(r.residuals[m]),
                    static_cast<int>(m) <= r.gcOrder ? "yes" : "no"});
  out += formatTable({"order", "relative residual", "holds"}, rows, {false, true, false});
  if (!r.exact.empty()) {
    const auto& piece = r.exact.front();
    out += fmt::format("degrees of the polynomials of (4.1) on t in [{}, {}] (minor <.,.,.>_{}):\n",
                       formatNumber(piece.t.lo), formatNumber(piece.t.hi), piece.result.functions.minor);
    std::vector<std::vector<std::string>> d;
    for (const auto& e : piece.result.degrees)
      d.push_back({e.name, std::to_string(e.found), std::to_string(e.bound), std::to_string(e.afterElimination)});
    out += formatTable({"polynomial", "found", "bound", "after elimination"}, d, {false, true, true, true});
  }
  if (r.gcOrder >= 0 && !r.sampled.samples.empty()) {
    out += "connecting functions (psi1: pbar_1 = 1 across B; psi2: p_i, q_i):\n";
    std::vector<std::string> header{"s"};
    for (int i = 0; i <= r.gcOrder; ++i) header.push_back(fmt::format("c{}", i));
    for (int i = 1; i <= r.gcOrder; ++i) header.push_back(fmt::format("p{}", i));
    for (int i = 1; i <= r.gcOrder; ++i) header.push_back(fmt::format("q{}", i));
    std::vector<std::vector<std::string>> cr;
    const size_t n = r.sampled.samples.size();
    const size_t step = std::max<size_t>(1, n / kPrintedSamples);
    for (size_t k = 0; k < n; k += step) {
      const auto& x = r.sampled.samples[k];
      std::vector<std::string> row{formatNumber(x.s)};
      for (int i = 0; i <= r.gcOrder; ++i) row.push_back(formatNumber(x.c[static_cast<size_t>(i)]));
      for (int i = 1; i <= r.gcOrder; ++i) row.push_back(formatNumber(x.p[static_cast<size_t>(i - 1)]));
      for (int i = 1; i <= r.gcOrder; ++i) row.push_back(formatNumber(x.q[static_cast<size_t>(i - 1)]));
      cr.push_back(std::move(row));
    }
    out += formatTable(header, cr, std::vector<bool>(header.size(), true));
    out += fmt::format("r(psi2) and rbar(psi1) agree to order {}: {}\n", r.gcOrder,
                       r.sampled.cnClaimVerified ? "yes" : "no");
  }
  for (const auto& n : r.notes) out += "note: " + n + "\n";
  std::cout << out;
}

int runGcn(const GcnCliOptions& o, bool orderGiven) {
  if (o.seam.size() != 2) {
    printError("--seam needs two arguments: A:EDGE B:EDGE");
    return kExitBadInput;
  }
  const auto sa = parseSide(o.seam[0]), sb = parseSide(o.seam[1]);
  if (!sa || !sb) return kExitBadInput;
  if (o.order < 0 || o.order > rational::kMaxGcnOrder) {
    printError(fmt::format("--order {} out of range [0, {}]", o.order, rational::kMaxGcnOrder));
    return kExitBadInput;
  }
  if (!checkModelText(o.file)) return kExitBadInput;
  auto model = rational::readModelWithExpressions(o.file);
  if (!model) {
    printError(model.status().message());
    return kExitBadInput;
  }
  rational::GcnOptions opt;
  opt.order = o.order;
  opt.seam.tol = Tolerances::forModelSize(model->model.boundingBox().diagonal());
  const Patch* pa = model->model.findPatch(sa->name);
  const Patch* pb = model->model.findPatch(sb->name);
  Result<rational::GcnReport> rep = invalidInput("no analysis");
  if (pa && pb) {
    rep = rational::analyzeGcn(*pa, sa->edge, *pb, sb->edge, opt);
  } else {
    auto surface = [&](const SideRef& s, const Patch* p) -> Result<rational::HomogeneousSurface> {
      if (p) return rational::homogeneousSurface(p->surface, p->name);
      const rational::ExpressionPatch* e = model->findExpression(s.name);
      if (!e) return invalidInput(fmt::format("{}: no patch named \"{}\"", o.file, s.name));
      return rational::compileExpressionPatch(*e);
    };
    auto a = surface(*sa, pa), b = surface(*sb, pb);
    if (!a || !b) {
      printError((!a ? a : b).status().message());
      return kExitBadInput;
    }
    rep = rational::analyzeGcn(*a, sa->edge, *b, sb->edge, opt);
  }
  if (!rep) {
    printError(rep.status().message());
    const ErrorCode code = rep.status().code();
    return code == ErrorCode::kDegenerate || code == ErrorCode::kNotFound ? kExitGeometryProblem : kExitBadInput;
  }
  if (o.json)
    printJson(reportJson(*rep, o.order));
  else
    printText(*rep, o.order);
  if (orderGiven) return rep->gcOrder < o.order ? kExitGeometryProblem : kExitOk;
  return rep->gcOrder < 0 ? kExitGeometryProblem : kExitOk;
}

void addGcn(CLI::App& app, int& exit) {
  auto o = std::make_shared<GcnCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "gcn", "Geometric continuity GC^n of rational patches along a seam (Zheng-Wang-Liang): orders, residuals, "
             "connecting functions");
  cmd->add_option("FILE", o->file, modelFileHelp() + " (a .json model may hold \"expression\" patches)")->required();
  cmd->add_option("--seam", o->seam, "The seam: A:EDGE B:EDGE (edges u0, u1, v0, v1)")->expected(2)->required();
  CLI::Option* order = cmd->add_option(
      "--order", o->order,
      fmt::format("Highest order N to test (default {}); with --order the exit code is 1 when GC^N is not reached, "
                  "without it only when the patches do not meet", kDefaultGcnOrder));
  cmd->add_flag("--json", o->json, "Print the report as JSON");
  cmd->callback([o, order, &exit]() { exit = runGcn(*o, order->count() > 0); });
}

}  // namespace

static CommandRegistrar registerGcn("gcn", addGcn);

}  // namespace seam::cli
