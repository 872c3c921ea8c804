// seam info FILE [--json] [--units UNIT]: what a model holds (patches, curves, degrees, sizes, spans, bounding boxes).
#include <fmt/format.h>

#include <string>
#include <vector>

#include "check_json.h"
#include "cli_util.h"
#include "command_registry.h"
#include "seam/core/tolerances.h"

namespace seam::cli {

namespace {

/// Number of non-empty knot spans inside the domain [t_p, t_n] (knots closer than kKnotRelTol x the
/// knot-vector length are one knot, as in KnotVector).
int nonEmptySpans(const KnotVector& knots, int degree, int numPoints) {
  const std::vector<double>& t = knots.values();
  const double tol = kKnotRelTol * (t.back() - t.front());
  int spans = 0;
  for (int k = degree; k < numPoints; ++k) {
    if (t[static_cast<size_t>(k) + 1] - t[static_cast<size_t>(k)] > tol) ++spans;
  }
  return spans;
}

/// A curve whose knots are exactly degree+1 zeros then degree+1 ones is what a "bezier" curve reads as.
bool isBezierCurve(const BSplineCurve& c) {
  if (c.numPoints() != c.degree() + 1) return false;
  const std::vector<double>& t = c.knots().values();
  for (size_t k = 0; k < t.size(); ++k) {
    if (t[k] != (static_cast<int>(k) <= c.degree() ? 0.0 : 1.0)) return false;
  }
  return true;
}

/// A box's corners times `scale` (the shown unit, issue 38 §1).
OrderedJson boxJson(const BoundingBox& box, double scale) {
  if (box.empty()) return OrderedJson{{"min", nullptr}, {"max", nullptr}};
  const Vec3 lo = box.min * scale, hi = box.max * scale;
  return OrderedJson{{"min", {lo.x(), lo.y(), lo.z()}}, {"max", {hi.x(), hi.y(), hi.z()}}};
}

std::string boxCell(const BoundingBox& box, bool max, double scale) {
  if (box.empty()) return "-";
  const Vec3 p = (max ? box.max : box.min) * scale;
  return formatVector(p.data(), 3);
}

std::string intervalText(const Interval& i) {
  return "[" + formatNumber(i.lo) + ", " + formatNumber(i.hi) + "]";
}

OrderedJson infoJson(const std::string& file, const Model& model, const ModelUnits& units) {
  const double scale = units.displayScale();
  OrderedJson patches = OrderedJson::array();
  for (const Patch& p : model.patches) {
    const BSplineSurface& s = p.surface;
    const Interval du = s.domainU();
    const Interval dv = s.domainV();
    patches.push_back({{"name", p.name},
                       {"type", p.kind == PatchKind::kBezier ? "bezier" : "bspline"},
                       {"degree", {s.degreeU(), s.degreeV()}},
                       {"points", {s.numU(), s.numV()}},
                       {"spans",
                        {nonEmptySpans(s.knotsU(), s.degreeU(), s.numU()),
                         nonEmptySpans(s.knotsV(), s.degreeV(), s.numV())}},
                       {"rational", s.isRational()},
                       {"domain", {{"u", {du.lo, du.hi}}, {"v", {dv.lo, dv.hi}}}},
                       {"bbox", boxJson(controlBox(s), scale)}});
  }
  OrderedJson curves = OrderedJson::array();
  for (const Curve& c : model.curves) {
    const Interval d = c.curve.domain();
    curves.push_back({{"name", c.name},
                      {"type", isBezierCurve(c.curve) ? "bezier" : "bspline"},
                      {"degree", c.curve.degree()},
                      {"points", c.curve.numPoints()},
                      {"dimension", c.curve.dim()},
                      {"spans", nonEmptySpans(c.curve.knots(), c.curve.degree(), c.curve.numPoints())},
                      {"rational", c.curve.isRational()},
                      {"domain", {d.lo, d.hi}},
                      {"bbox", boxJson(controlBox(c.curve), scale)}});
  }
  const BoundingBox box = model.boundingBox();
  OrderedJson summary = {{"patches", model.patches.size()},
                         {"curves", model.curves.size()},
                         {"bbox", boxJson(box, scale)},
                         {"diagonal", box.diagonal() * scale}};
  return OrderedJson{
      {"file", file}, {"units", unitsJson(units.shown())}, {"patches", patches}, {"curves", curves}, {"summary", summary}};
}

std::string infoTable(const std::string& file, const Model& model, const ModelUnits& units) {
  const double scale = units.displayScale();
  std::vector<std::vector<std::string>> rows;
  for (const Patch& p : model.patches) {
    const BSplineSurface& s = p.surface;
    const BoundingBox box = controlBox(s);
    rows.push_back({"patch", p.name, p.kind == PatchKind::kBezier ? "bezier" : "bspline",
                    fmt::format("{}x{}", s.degreeU(), s.degreeV()), fmt::format("{}x{}", s.numU(), s.numV()),
                    fmt::format("{}x{}", nonEmptySpans(s.knotsU(), s.degreeU(), s.numU()),
                                nonEmptySpans(s.knotsV(), s.degreeV(), s.numV())),
                    s.isRational() ? "yes" : "no",
                    intervalText(s.domainU()) + " x " + intervalText(s.domainV()), boxCell(box, false, scale),
                    boxCell(box, true, scale)});
  }
  for (const Curve& c : model.curves) {
    const BSplineCurve& k = c.curve;
    const BoundingBox box = controlBox(k);
    rows.push_back(
        {"curve", c.name, isBezierCurve(k) ? "bezier" : "bspline", std::to_string(k.degree()),
         std::to_string(k.numPoints()), std::to_string(nonEmptySpans(k.knots(), k.degree(), k.numPoints())),
         k.isRational() ? "yes" : "no", intervalText(k.domain()), boxCell(box, false, scale), boxCell(box, true, scale)});
  }
  const BoundingBox box = model.boundingBox();
  std::string out = fmt::format("{}: {} patch{}, {} curve{}\n", file, model.patches.size(),
                                model.patches.size() == 1 ? "" : "es", model.curves.size(),
                                model.curves.size() == 1 ? "" : "s");
  out += unitText(units.shown()) + "\n";
  if (!rows.empty()) {
    out += "\n" + formatTable({"kind", "name", "type", "degree", "points", "spans", "rational", "domain",
                               "bbox min", "bbox max"},
                              rows);
  }
  out += "\nbounding box: " +
         (box.empty() ? std::string("empty")
                      : boxCell(box, false, scale) + " to " + boxCell(box, true, scale) + ", diagonal " +
                            withUnit(formatNumber(box.diagonal() * scale), units.shown())) +
         "\n";
  return out;
}

void addInfo(CLI::App& app, int& exit) {
  struct Options {
    std::string file;
    bool json = false;
    ToleranceOverrides units;  // only its --units and --display-units
  };
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand("info", "Describe the patches and curves of a model file");
  cmd->add_option("FILE", options->file, modelFileHelp())->required();
  cmd->add_flag("--json", options->json, "Print JSON instead of a table");
  addUnitsOption(*cmd, options->units);
  addDisplayUnitsOption(*cmd, options->units);
  cmd->callback([options, &exit]() {
    ModelUnits units;
    const std::optional<Model> model = loadModel(options->file, options->units, &units);
    if (!model || !displayUnitsApply(options->file, units)) {
      exit = kExitBadInput;
      return;
    }
    if (options->json) {
      printJson(infoJson(options->file, *model, units));
    } else {
      fmt::print("{}", infoTable(options->file, *model, units));
    }
    exit = kExitOk;
  });
}

}  // namespace

static CommandRegistrar registerInfo("info", addInfo);

}  // namespace seam::cli
