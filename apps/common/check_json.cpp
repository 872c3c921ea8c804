// The JSON of `seam check --json` (check_json.h): moved here from apps/seam/cmd_check.cpp so that the CLI and the
// Python module build it with the same code.
#include "check_json.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <functional>
#include <new>
#include <utility>

#include "seam/continuity/seam.h"
#include "seam/io/file.h"
#ifdef SEAM_HAVE_OCCT
#include "seam/occt/cad_io.h"
#endif

namespace seam::cli {

namespace {

OrderedJson verdictCountsJson(const std::array<int, 5>& n) {
  OrderedJson j;
  for (size_t k = 0; k < n.size(); ++k) j[std::string(toString(static_cast<SeamVerdict>(k)))] = n[k];
  return j;
}


OrderedJson point(const Vec3& p) { return OrderedJson::array({p.x(), p.y(), p.z()}); }
OrderedJson range(const Interval& i) { return OrderedJson::array({i.lo, i.hi}); }

const std::string& patchName(const Model& m, int index) { return m.patches[static_cast<size_t>(index)].name; }

OrderedJson seamJson(const SeamReport& r, double creaseAngleDeg) {
  auto worst = [](const WorstLocation& w) { return OrderedJson{{"t", w.t}, {"point", point(w.point)}}; };
  OrderedJson j{{"a", r.a},
                {"a_edge", std::string(edgeName(r.aEdge))},
                {"b", r.b},
                {"b_edge", std::string(edgeName(r.bEdge))},
                {"overlap", range(r.overlapA)},
                {"g0_max", r.g0Max},
                {"g1_max_deg", r.g1MaxDeg},
                {"g2_max", r.g2Max},
                {"g2_rel_max", r.g2RelMax},
                {"lambda_range", range(r.lambdaRange)},
                {"kappa_range", range(r.kappaRange)},
                {"verdict", std::string(toString(seamVerdict(r, creaseAngleDeg)))},
                {"geometric", std::string(toString(r.geometric))},
                {"parametric", std::string(toString(r.parametric))},
                {"certified", r.certified},
                {"worst", {{"g0", worst(r.g0Worst)}, {"g1", worst(r.g1Worst)}, {"g2", worst(r.g2Worst)}}}};
  j["overlap_b"] = range(r.overlapB);
  j["reversed"] = r.reversed;
  j["correspondence"] = std::string(toString(r.correspondence));
  j["g0_sampled"] = r.g0Sampled;
  j["end_mismatch"] = r.endMismatch;
  j["g1_sampled_deg"] = r.g1SampledDeg;
  j["g2_sampled"] = r.g2Sampled;
  j["g2_rel_sampled"] = r.g2RelSampled;
  j["g2_residual_max"] = r.g2ResidualMax;
  j["c1_mismatch"] = r.c1Mismatch;
  j["c2_mismatch"] = r.c2Mismatch;
  j["notes"] = r.notes;
  return j;
}

OrderedJson failedSeamJson(const Model& m, const EdgePair& p, const Status& error) {
  return OrderedJson{{"a", patchName(m, p.a.patch)},
                     {"a_edge", std::string(edgeName(p.a.edge))},
                     {"b", patchName(m, p.b.patch)},
                     {"b_edge", std::string(edgeName(p.b.edge))},
                     {"overlap", range(p.overlapA)},
                     {"verdict", "error"},
                     {"geometric", nullptr},
                     {"parametric", nullptr},
                     {"certified", nullptr},
                     {"g0_max", nullptr},
                     {"g1_max_deg", nullptr},
                     {"g2_max", nullptr},
                     {"g2_rel_max", nullptr},
                     {"error", error.message()}};
}

OrderedJson optionalNumber(const std::optional<double>& x) { return x ? OrderedJson(*x) : OrderedJson(nullptr); }

OrderedJson cornerJson(const Model& m, const CornerReport& c) {
  OrderedJson patches = OrderedJson::array();
  for (const PatchCorner& k : c.corners) patches.push_back(patchName(m, k.patch));
  OrderedJson j{{"point", point(c.point)},
                {"patches", patches},
                {"valence", c.valence},
                {"normal_spread_deg", optionalNumber(c.normalSpreadDeg)},
                {"g1_residual", c.fourPatch ? OrderedJson(c.fourPatch->g1Residual) : OrderedJson(nullptr)},
                {"g2_residual", c.fourPatch ? optionalNumber(c.fourPatch->g2Residual) : OrderedJson(nullptr)}};
  j["closed"] = c.closed;
  j["degenerate"] = c.degenerate;
  j["corner_gap"] = c.cornerGap;
  if (c.fourPatch) {
    OrderedJson numbering = OrderedJson::array();
    for (int k : c.fourPatch->corner) numbering.push_back(patchName(m, c.corners[static_cast<size_t>(k)].patch));
    j["paper_patches"] = numbering;
    OrderedJson seams = OrderedJson::array();
    for (const VertexSeam& s : c.fourPatch->seams) {
      seams.push_back({{"from", s.from},
                       {"to", s.to},
                       {"lambda", s.lambda},
                       {"kappa", s.kappa},
                       {"d_lambda", s.dLambda},
                       {"d_kappa", s.dKappa},
                       {"mu", optionalNumber(s.mu)},
                       {"nu", optionalNumber(s.nu)},
                       {"g1", s.g1},
                       {"g2", s.g2}});
    }
    j["seams"] = seams;
    j["g1_relations"] = OrderedJson(std::vector<double>(c.fourPatch->g1Relations.begin(), c.fourPatch->g1Relations.end()));
    j["g2_relations"] = c.fourPatch->g2Relations
                            ? OrderedJson(std::vector<double>(c.fourPatch->g2Relations->begin(),
                                                              c.fourPatch->g2Relations->end()))
                            : OrderedJson(nullptr);
  }
  if (!c.notes.empty()) j["notes"] = c.notes;
  return j;
}

OrderedJson tolerancesJson(const Tolerances& t, std::optional<double> pairing, double creaseAngleDeg,
                           DistanceSource source) {
  OrderedJson j{{"distance", t.distance},
                {"distance_source", toString(source)},
                {"angle_deg", t.angleDeg},
                {"curvature_rel", t.curvatureRel},
                {"parametric", t.parametric},
                {"crease_angle_deg", creaseAngleDeg}};
  if (pairing) j["pairing"] = *pairing;
  return j;
}

OrderedJson summaryJson(const ModelCheckReport& r, const std::optional<GeometricClass>& require) {
  const ModelCheckSummary& s = r.summary;
  OrderedJson geometric, parametric;
  for (int k = 0; k < 4; ++k) {
    geometric[std::string(toString(static_cast<GeometricClass>(k)))] = s.geometric[static_cast<size_t>(k)];
    parametric[std::string(toString(static_cast<ParametricClass>(k)))] = s.parametric[static_cast<size_t>(k)];
  }
  OrderedJson j{{"seams", s.seams},
                {"worst_geometric", std::string(toString(s.worstGeometric))},
                {"worst_parametric", std::string(toString(s.worstParametric))},
                {"geometric", geometric},
                {"parametric", parametric},
                {"certified", s.certifiedSeams},
                {"failed", s.failedSeams},
                {"g0_max", s.g0Max},
                {"g1_max_deg", s.g1MaxDeg},
                {"g2_max", s.g2Max},
                {"g2_rel_max", s.g2RelMax},
                {"corners", s.corners},
                {"four_valent_corners", s.fourValentCorners},
                {"degenerate_corners", s.degenerateCorners},
                {"normal_spread_max_deg", s.normalSpreadMaxDeg},
                {"corner_g1_residual_max", s.cornerG1ResidualMax},
                {"corner_g2_residual_max", optionalNumber(s.cornerG2ResidualMax)},
                {"free_edges", s.freeEdges},
                {"degenerate_edges", s.degenerateEdges},
                {"coincident_edge_groups", s.coincidentEdgeGroups}};
  j["require"] = require ? OrderedJson(std::string(toString(*require))) : OrderedJson(nullptr);
  j["below_required"] = s.belowRequired;
  return j;
}

OrderedJson worstJson(const std::vector<const SeamReport*>& reports, double creaseAngleDeg,
                      const std::function<OrderedJson(size_t)>& name) {
  const WorstDefects w = worstDefects(reports, creaseAngleDeg);
  auto one = [&](const std::optional<size_t>& k, bool kink) {
    if (!k) return OrderedJson(nullptr);
    const SeamReport& x = *reports[*k];
    OrderedJson j = name(*k);
    j["gap"] = x.g0Max;
    j["angle_deg"] = x.g1MaxDeg;
    j["point"] = point(kink ? x.g1Worst.point : x.g0Worst.point);
    return j;
  };
  return OrderedJson{{"worst_kink", one(w.kink, true)}, {"worst_gap", one(w.gap, false)}};
}

/// The verdict counts and the worst kink / gap of a patch-model check, added to the JSON summary.
void addVerdictSummary(OrderedJson& summary, const Model& m, const ModelCheckReport& r, double creaseAngleDeg) {
  const std::vector<const SeamReport*> reports = reportsOf(r);
  summary["verdicts"] = verdictCountsJson(countVerdicts(reports, creaseAngleDeg));
  const OrderedJson worst = worstJson(reports, creaseAngleDeg, [&](size_t k) {
    const EdgePair& p = r.seams[k].pair;
    return OrderedJson{{"index", k},
                       {"a", patchName(m, p.a.patch)},
                       {"a_edge", std::string(edgeName(p.a.edge))},
                       {"b", patchName(m, p.b.patch)},
                       {"b_edge", std::string(edgeName(p.b.edge))}};
  });
  for (const auto& [key, value] : worst.items()) summary[key] = value;
}

}  // namespace

OrderedJson unitsJson(const ModelUnits& units) {
  OrderedJson j;
  j["length"] = units.length ? OrderedJson(units.name()) : OrderedJson(nullptr);
  j["file_unit"] = units.fileUnit.empty() ? OrderedJson(nullptr) : OrderedJson(units.fileUnit);
  j["source"] = toString(units.source);
  j["declared_resolution"] = optionalNumber(units.declaredResolution);
  return j;
}

OrderedJson noPatchesJson(const std::string& name, const ModelUnits& units) {
  OrderedJson geometric{{"none", 0}, {"G0", 0}, {"G1", 0}, {"G2", 0}};
  OrderedJson verdicts{{"gap", 0}, {"kink", 0}, {"crease", 0}, {"G1", 0}, {"G2", 0}};
  return OrderedJson{{"model", {{"patches", 0}}},
                     {"units", unitsJson(units)},
                     {"tolerances", nullptr},
                     {"seams", OrderedJson::array()},
                     {"corners", OrderedJson::array()},
                     {"free_edges", OrderedJson::array()},
                     {"summary", {{"seams", 0}, {"certified", 0}, {"failed", 0}, {"worst_geometric", nullptr},
                                  {"geometric", geometric}, {"g0_max", nullptr}, {"g1_max_deg", nullptr},
                                  {"g2_max", nullptr}, {"corners", 0}, {"free_edges", 0}, {"degenerate_edges", 0},
                                  {"require", nullptr}, {"below_required", 0}, {"verdicts", verdicts},
                                  {"worst_kink", nullptr}, {"worst_gap", nullptr}}},
                     {"note", fmt::format("{}: the model has no patches: nothing to check", name)}};
}

std::vector<const SeamReport*> reportsOf(const ModelCheckReport& r) {
  std::vector<const SeamReport*> reports;
  reports.reserve(r.seams.size());
  for (const ModelSeam& s : r.seams) reports.push_back(s.report ? &*s.report : nullptr);
  return reports;
}

OrderedJson modelCheckJson(const Model& m, const ModelCheckReport& report, const std::vector<size_t>& order,
                           const std::optional<GeometricClass>& require, std::optional<double> pairing,
                           double creaseAngleDeg, const ModelUnits& units, DistanceSource distanceSource) {
  OrderedJson seams = OrderedJson::array();
  for (size_t k : order) {
    const ModelSeam& s = report.seams[k];
    OrderedJson j = s.report ? seamJson(*s.report, creaseAngleDeg) : failedSeamJson(m, s.pair, s.error);
    j["index"] = k;
    seams.push_back(std::move(j));
  }
  OrderedJson corners = OrderedJson::array();
  for (const ModelCorner& c : report.corners) corners.push_back(cornerJson(m, c.report));
  OrderedJson free = OrderedJson::array();
  for (const FreeEdge& f : report.freeEdges) {
    OrderedJson e{{"patch", patchName(m, f.edge.patch)}, {"edge", std::string(edgeName(f.edge.edge))}};
    e["range"] = range(f.range);
    e["partial"] = f.partial;
    free.push_back(e);
  }
  OrderedJson degenerate = OrderedJson::array();
  for (const DegenerateEdge& d : report.degenerateEdges)
    degenerate.push_back({{"patch", patchName(m, d.edge.patch)},
                          {"edge", std::string(edgeName(d.edge.edge))},
                          {"point", point(d.point)}});
  OrderedJson coincident = OrderedJson::array();
  for (const CoincidentEdges& c : report.coincidentEdges) {
    OrderedJson edges = OrderedJson::array();
    for (const EdgeRef& e : c.edges)
      edges.push_back({{"patch", patchName(m, e.patch)}, {"edge", std::string(edgeName(e.edge))}});
    coincident.push_back({{"point", point(c.point)}, {"edges", edges}});
  }
  OrderedJson summary = summaryJson(report, require);
  addVerdictSummary(summary, m, report, creaseAngleDeg);
  return OrderedJson{{"model", {{"patches", m.patches.size()}}},
                     {"units", unitsJson(units)},
                     {"tolerances", tolerancesJson(report.tolerances, pairing, creaseAngleDeg, distanceSource)},
                     {"seams", seams},
                     {"corners", corners},
                     {"free_edges", free},
                     {"degenerate_edges", degenerate},
                     {"coincident_edges", coincident},
                     {"summary", summary}};
}

OrderedJson withInputFile(const std::filesystem::path& file, const OrderedJson& check) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  OrderedJson format = nullptr;
  if (ext == ".json" || ext == ".bpt") format = ext.substr(1);
  if (ext == ".step" || ext == ".stp") format = "step";
  if (ext == ".iges" || ext == ".igs") format = "iges";
  OrderedJson out{{"file", file.string()}, {"format", format}};
  for (const auto& [key, value] : check.items())
    if (key != "file") out[key] = value;
  return out;
}

#ifdef SEAM_HAVE_OCCT
namespace {
/// "E<n>": a B-rep edge where a patch model names a patch edge (a_edge, b_edge, free edges).
std::string brepEdgeName(int edge) { return fmt::format("E{}", edge); }
}  // namespace

OrderedJson brepCheckJson(const occt::BRepCheckReport& r, const std::vector<size_t>& order,
                          const std::optional<GeometricClass>& require, double creaseAngleDeg) {
  int below = 0;
  for (const occt::BRepSeam& s : r.seams)
    if (require && s.report.geometric < *require) ++below;
  std::vector<const SeamReport*> reports;
  for (const occt::BRepSeam& s : r.seams) reports.push_back(&s.report);
  const Tolerances& tol = r.tolerances;
  OrderedJson seams = OrderedJson::array();
  for (size_t k : order) {
    const occt::BRepSeam& s = r.seams[k];
    OrderedJson j = seamJson(s.report, creaseAngleDeg);
    j["a_edge"] = brepEdgeName(s.edge);  // the shared B-rep edge, the same on both faces
    j["b_edge"] = brepEdgeName(s.edge);
    j["index"] = k;
    j["edge"] = s.edge;
    j["route"] = s.viaPatchEdges ? "patch edges (Bernstein form)" : "pcurves (sampled)";
    j["occt_continuity"] = s.occtContinuity;
    seams.push_back(std::move(j));
  }
  OrderedJson free = OrderedJson::array();
  for (const occt::BRepFreeEdge& f : r.freeEdges)
    free.push_back({{"patch", f.face}, {"edge", brepEdgeName(f.edge)}, {"edge_index", f.edge},
                    {"midpoint", point(f.midpoint)}});
  OrderedJson nonManifold = OrderedJson::array();
  for (const occt::BRepNonManifoldEdge& e : r.nonManifoldEdges)
    nonManifold.push_back({{"edge", e.edge}, {"faces", e.faces}, {"midpoint", point(e.midpoint)}});
  double g0Max = 0.0, g1MaxDeg = 0.0, g2Max = 0.0;
  for (const SeamReport* x : reports) {
    g0Max = std::max(g0Max, x->g0Max);
    g1MaxDeg = std::max(g1MaxDeg, x->g1MaxDeg);
    g2Max = std::max(g2Max, x->g2Max);
  }
  // Each face by its entity in the file: "#1234" (STEP) or "D17" (IGES directory entry), and its name.
  OrderedJson faceNames = OrderedJson::array();
  auto orNull = [](const std::string& x) { return x.empty() ? OrderedJson(nullptr) : OrderedJson(x); };
  for (const occt::CadFace& f : r.import.faces)
    faceNames.push_back({{"patch", f.patch}, {"entity", orNull(f.entity)}, {"name", orNull(f.entityName)}});
  OrderedJson out{{"model", {{"patches", r.import.faces.size()},
                             {"faces", r.import.faces.size()},
                             {"sewn", r.sewn},
                             {"face_names", faceNames}}},
                  {"units", unitsJson(r.units)},
                  {"tolerances", {{"distance", tol.distance}, {"distance_source", toString(r.distanceSource)},
                                  {"angle_deg", tol.angleDeg},
                                  {"curvature_rel", tol.curvatureRel}, {"crease_angle_deg", creaseAngleDeg}}},
                  {"seams", seams},
                  {"corners", OrderedJson::array()},  // not analysed for B-rep files (summary.corners is null)
                  {"free_edges", free},
                  {"non_manifold_edges", nonManifold},
                  {"summary", {{"seams", r.seams.size()},
                               {"certified", r.certifiedSeams},
                               {"failed", 0},  // an edge OpenCASCADE fails on is not a seam: unanalysed_edges
                               {"worst_geometric", std::string(toString(r.worstGeometric))},
                               {"geometric", {{"none", r.geometric[0]}, {"G0", r.geometric[1]},
                                              {"G1", r.geometric[2]}, {"G2", r.geometric[3]}}},
                               {"g0_max", g0Max},
                               {"g1_max_deg", g1MaxDeg},
                               {"g2_max", g2Max},
                               {"corners", nullptr},
                               {"free_edges", r.freeEdges.size()},
                               {"non_manifold_edges", r.nonManifoldEdges.size()},
                               {"degenerate_edges", r.degenerateEdges},
                               {"loose_edges", r.looseEdges},
                               {"unanalysed_edges", r.unanalysedEdges},
                               {"agree_with_occt_g1", r.occtAgreement}}}};
  out["summary"]["require"] = require ? OrderedJson(std::string(toString(*require))) : OrderedJson(nullptr);
  out["summary"]["below_required"] = below;
  out["summary"]["verdicts"] = verdictCountsJson(countVerdicts(reports, creaseAngleDeg));
  const OrderedJson worst = worstJson(reports, creaseAngleDeg, [&](size_t k) {
    const occt::BRepSeam& s = r.seams[k];
    return OrderedJson{{"index", k}, {"a", s.a}, {"a_edge", brepEdgeName(s.edge)}, {"b", s.b},
                       {"b_edge", brepEdgeName(s.edge)}, {"edge", s.edge}};
  });
  for (const auto& [key, value] : worst.items()) out["summary"][key] = value;
  return out;
}
#endif

namespace {

bool isCad(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".step" || ext == ".stp" || ext == ".iges" || ext == ".igs";
}

Result<FileCheck> checkFileUnguarded(const std::filesystem::path& file, const FileCheckOptions& o) {
  FileCheck out;
  if (isCad(file)) {
    if (const Status s = io::checkInputFile(file, io::kMaxCadFileBytes); !s) return s;
#ifdef SEAM_HAVE_OCCT
    if (!o.patches) {
      const double crease = o.selection.creaseAngleDeg;
      occt::BRepCheckOptions bo;
      bo.tolerances = o.tol;
      Result<occt::BRepCheckReport> r = occt::checkBRepFile(file, bo);
      if (!r) return r.status();
      std::vector<const SeamReport*> reports;
      for (const occt::BRepSeam& s : r->seams) {
        reports.push_back(&s.report);
        if (o.require && s.report.geometric < *o.require) out.belowRequired = true;
      }
      out.json = withInputFile(file, brepCheckJson(*r, selectSeams(reports, o.selection), o.require, crease));
      out.warnings = r->import.warnings;
      return out;
    }
#else
    return Status(ErrorCode::kUnsupported,
                  fmt::format("{}: STEP/IGES support needs a build with SEAM_WITH_OCCT=ON (scripts/setup.sh does)",
                              file.string()));
#endif
  }
  Model model;
  ModelUnits units;
  if (o.tol.units) {
    units.length = o.tol.units;
    units.source = UnitSource::kOption;
  }
#ifdef SEAM_HAVE_OCCT
  if (isCad(file)) {
    occt::CadReadOptions ro;
    if (o.tol.units) ro.statedUnitMm = lengthUnitInfo(*o.tol.units).millimetres;
    Result<occt::CadImport> cad = occt::readCadFile(file, ro);
    if (!cad) return cad.status();
    out.warnings = cad->warnings;
    units = occt::cadModelUnits(*cad, o.tol);
    model = std::move(cad->model);
  } else
#endif
  {
    Result<Model> m = io::readModel(file);
    if (!m) return m.status();
    model = std::move(m).value();
  }
  Result<FileCheck> checked = checkModel(model, file.string(), o, units);
  if (!checked) return checked;
  checked->warnings = std::move(out.warnings);
  return checked;
}

}  // namespace

Result<FileCheck> checkModel(const Model& model, const std::string& name, const FileCheckOptions& o,
                             const ModelUnits& units) {
  FileCheck out;
  if (model.patches.empty()) {  // as `seam check`: only curves, or "patches": []
    out.json = withInputFile(name, noPatchesJson(name, units));
    return out;
  }
  ModelCheckOptions mo;
  const ResolvedTolerances resolved = resolveTolerances(o.tol, units, model.boundingBox().diagonal());
  mo.tolerances = resolved.tolerances;
  mo.require = o.require;
  Result<ModelCheckReport> r = seam::checkModel(model, mo);
  if (!r) return r.status().withContext(name);
  out.belowRequired = o.require && r->summary.belowRequired > 0;
  out.json = withInputFile(name, modelCheckJson(model, *r, selectSeams(reportsOf(*r), o.selection), o.require,
                                               r->pairingTolerance, o.selection.creaseAngleDeg, units,
                                               resolved.distanceSource));
  return out;
}

Result<FileCheck> checkFile(const std::filesystem::path& file, const FileCheckOptions& options) {
  try {
    return checkFileUnguarded(file, options);
  } catch (const std::bad_alloc&) {
    return Status(ErrorCode::kInvalidInput,
                  fmt::format("{}: the model is too large: out of memory while reading it", file.string()));
  }
}

}  // namespace seam::cli
