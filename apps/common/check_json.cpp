// The JSON of `seam check --json` (check_json.h): moved here from apps/seam/cmd_check.cpp so that the CLI and the
// Python module build it with the same code.
#include "check_json.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <functional>
#include <new>
#include <ostream>
#include <string_view>
#include <utility>

#include "seam/continuity/seam.h"
#include "seam/io/file.h"
#ifdef SEAM_HAVE_OCCT
#include "seam/occt/cad_io.h"
#endif

namespace seam::cli {

namespace {

OrderedJson verdictCountsJson(const std::array<int, kSeamVerdictCount>& n) {
  OrderedJson j;
  for (size_t k = 0; k < n.size(); ++k) j[std::string(toString(static_cast<SeamVerdict>(k)))] = n[k];
  return j;
}


OrderedJson point(const Vec3& p) { return OrderedJson::array({p.x(), p.y(), p.z()}); }

const std::string& patchName(const Model& m, int index) { return m.patches[static_cast<size_t>(index)].name; }

OrderedJson optionalNumber(const std::optional<double>& x) { return x ? OrderedJson(*x) : OrderedJson(nullptr); }

// ---- Records written once for two routes. Each record is a function template writing its members in order into
// an Out: DomObject (an OrderedJson object: modelCheckJson, the Python module's dicts, the B-rep check) or
// TextObject (JSON text streamed by writeModelCheckJson). Out has field(key, value) for numbers, bools, strings,
// null, Vec3 (a point), Interval (a range), optional numbers, lists of strings / numbers and DOM values;
// object(key, fill) for a nested object and objects(key, count, fill) for an array of objects.

class DomObject {
 public:
  explicit DomObject(OrderedJson& j) : j_(j) {}
  template <class T>
  void field(const char* key, const T& value) {
    j_[key] = dom(value);
  }
  template <class Fill>
  void object(const char* key, Fill&& fill) {
    OrderedJson sub = OrderedJson::object();
    DomObject o(sub);
    fill(o);
    j_[key] = std::move(sub);
  }
  template <class Fill>
  void objects(const char* key, size_t count, Fill&& fill) {
    OrderedJson list = OrderedJson::array();
    for (size_t k = 0; k < count; ++k) {
      OrderedJson item = OrderedJson::object();
      DomObject o(item);
      fill(o, k);
      list.push_back(std::move(item));
    }
    j_[key] = std::move(list);
  }

 private:
  static OrderedJson dom(const Vec3& p) { return point(p); }
  static OrderedJson dom(const Interval& i) { return OrderedJson::array({i.lo, i.hi}); }
  static OrderedJson dom(const std::optional<double>& x) { return optionalNumber(x); }
  static OrderedJson dom(std::string_view s) { return OrderedJson(std::string(s)); }
  template <class T>
  static OrderedJson dom(const T& x) {
    return OrderedJson(x);
  }
  OrderedJson& j_;
};

class TextObject {
 public:
  explicit TextObject(JsonTextWriter& w) : w_(w) {}
  template <class T>
  void field(const char* key, const T& value) {
    w_.key(key);
    put(value);
  }
  template <class Fill>
  void object(const char* key, Fill&& fill) {
    w_.key(key);
    w_.beginObject();
    fill(*this);
    w_.endObject();
  }
  template <class Fill>
  void objects(const char* key, size_t count, Fill&& fill) {
    w_.key(key);
    w_.beginArray();
    for (size_t k = 0; k < count; ++k) {
      w_.beginObject();
      fill(*this, k);
      w_.endObject();
    }
    w_.endArray();
  }

 private:
  void put(const Vec3& p) { w_.numbers(std::array<double, 3>{p.x(), p.y(), p.z()}); }
  void put(const Interval& i) { w_.numbers(std::array<double, 2>{i.lo, i.hi}); }
  void put(const std::optional<double>& x) {
    if (x) {
      w_.value(*x);
    } else {
      w_.value(nullptr);
    }
  }
  void put(const std::vector<std::string>& xs) { w_.strings(xs); }
  void put(const std::vector<double>& xs) { w_.numbers(xs); }
  template <size_t N>
  void put(const std::array<double, N>& xs) {
    w_.numbers(xs);
  }
  template <class T>
  void put(const T& x) {
    w_.value(x);
  }
  JsonTextWriter& w_;
};

/// The members of a seam record; aEdge / bEdge name the edges (a patch edge "u0", or a B-rep edge "E12").
template <class Out>
void seamFields(Out& o, const SeamReport& r, double creaseAngleDeg, std::string_view aEdge, std::string_view bEdge) {
  auto worst = [](const WorstLocation& w) {
    return [&w](auto& x) {
      x.field("t", w.t);
      x.field("point", w.point);
    };
  };
  o.field("a", r.a);
  o.field("a_edge", aEdge);
  o.field("b", r.b);
  o.field("b_edge", bEdge);
  o.field("overlap", r.overlapA);
  o.field("g0_max", r.g0Max);
  o.field("g1_max_deg", r.g1MaxDeg);
  if (r.g1PoleT) o.field("g1_pole_t", *r.g1PoleT);
  o.field("g2_max", r.g2Max);
  o.field("g2_rel_max", r.g2RelMax);
  o.field("lambda_range", r.lambdaRange);
  o.field("kappa_range", r.kappaRange);
  o.field("verdict", toString(seamVerdict(r, creaseAngleDeg)));
  o.field("geometric", toString(r.geometric));
  o.field("parametric", toString(r.parametric));
  o.field("certified", r.certified);
  o.object("worst", [&](auto& x) {
    x.object("g0", worst(r.g0Worst));
    x.object("g1", worst(r.g1Worst));
    x.object("g2", worst(r.g2Worst));
  });
  o.field("overlap_b", r.overlapB);
  o.field("reversed", r.reversed);
  o.field("correspondence", toString(r.correspondence));
  o.field("g0_sampled", r.g0Sampled);
  o.field("end_mismatch", r.endMismatch);
  o.field("g1_sampled_deg", r.g1SampledDeg);
  o.field("g2_sampled", r.g2Sampled);
  o.field("g2_rel_sampled", r.g2RelSampled);
  o.field("g2_residual_max", r.g2ResidualMax);
  o.field("c1_mismatch", r.c1Mismatch);
  o.field("c2_mismatch", r.c2Mismatch);
  o.field("notes", r.notes);
}

/// The members of a seam whose analysis failed.
template <class Out>
void failedSeamFields(Out& o, const Model& m, const EdgePair& p, const Status& error) {
  o.field("a", patchName(m, p.a.patch));
  o.field("a_edge", edgeName(p.a.edge));
  o.field("b", patchName(m, p.b.patch));
  o.field("b_edge", edgeName(p.b.edge));
  o.field("overlap", p.overlapA);
  o.field("verdict", "error");
  for (const char* key : {"geometric", "parametric", "certified", "g0_max", "g1_max_deg", "g2_max", "g2_rel_max"})
    o.field(key, nullptr);
  o.field("error", error.message());
}

/// The members of a seam of a patch-model check, `index` its place in the check's list.
template <class Out>
void modelSeamFields(Out& o, const Model& m, const ModelSeam& s, size_t index, double creaseAngleDeg) {
  if (s.report) {
    seamFields(o, *s.report, creaseAngleDeg, edgeName(s.report->aEdge), edgeName(s.report->bEdge));
  } else {
    failedSeamFields(o, m, s.pair, s.error);
  }
  o.field("index", index);
}

template <class Out>
void cornerFields(Out& o, const Model& m, const CornerReport& c) {
  std::vector<std::string> patches;
  patches.reserve(c.corners.size());
  for (const PatchCorner& k : c.corners) patches.push_back(patchName(m, k.patch));
  o.field("point", c.point);
  o.field("patches", patches);
  o.field("valence", c.valence);
  o.field("normal_spread_deg", c.normalSpreadDeg);
  o.field("curvature_spread", c.curvatureSpread);
  o.field("curvature_spread_rel", c.curvatureSpreadRel);
  if (c.fourPatch) {
    o.field("g1_residual", c.fourPatch->g1Residual);
    o.field("g2_residual", c.fourPatch->g2Residual);
  } else {
    o.field("g1_residual", nullptr);
    o.field("g2_residual", nullptr);
  }
  o.field("closed", c.closed);
  o.field("degenerate", c.degenerate);
  o.field("corner_gap", c.cornerGap);
  if (c.fourPatch) {
    const FourPatchVertex& f = *c.fourPatch;
    std::vector<std::string> numbering;
    for (int k : f.corner) numbering.push_back(patchName(m, c.corners[static_cast<size_t>(k)].patch));
    o.field("paper_patches", numbering);
    o.objects("seams", f.seams.size(), [&](auto& x, size_t k) {
      const VertexSeam& s = f.seams[k];
      x.field("from", s.from);
      x.field("to", s.to);
      x.field("lambda", s.lambda);
      x.field("kappa", s.kappa);
      x.field("d_lambda", s.dLambda);
      x.field("d_kappa", s.dKappa);
      x.field("mu", s.mu);
      x.field("nu", s.nu);
      x.field("g1", s.g1);
      x.field("g2", s.g2);
    });
    o.field("g1_relations", f.g1Relations);
    if (f.g2Relations) {
      o.field("g2_relations", *f.g2Relations);
    } else {
      o.field("g2_relations", nullptr);
    }
  }
  if (!c.notes.empty()) o.field("notes", c.notes);
}

OrderedJson tolerancesJson(const Tolerances& t, std::optional<double> pairing, double creaseAngleDeg,
                           DistanceSource source, AngleSource angleSource) {
  OrderedJson j{{"distance", t.distance},
                {"distance_source", toString(source)},
                {"angle_deg", t.angleDeg},
                {"angle_source", toString(angleSource)},
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
                {"corner_curvature_spread_rel_max", optionalNumber(s.cornerCurvatureSpreadRelMax)},
                {"free_edges", s.freeEdges},
                {"degenerate_edges", s.degenerateEdges},
                {"coincident_edge_groups", s.coincidentEdgeGroups},
                {"overlaps", r.overlapsSearched ? OrderedJson(s.overlaps) : OrderedJson(nullptr)}};
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

namespace {

/// The members of `seam check --json` of a patch model after "file" and "format" (modelCheckJson's keys).
template <class Out>
void modelCheckFields(Out& o, const Model& m, const ModelCheckReport& report, const std::vector<size_t>& order,
                      const std::optional<GeometricClass>& require, std::optional<double> pairing,
                      double creaseAngleDeg, const ModelUnits& units, DistanceSource distanceSource,
                      const std::vector<std::string>& warnings, AngleSource angleSource) {
  o.field("warnings", warnings);
  o.object("model", [&](auto& x) { x.field("patches", m.patches.size()); });
  o.field("units", unitsJson(units));
  o.field("tolerances", tolerancesJson(report.tolerances, pairing, creaseAngleDeg, distanceSource, angleSource));
  o.objects("seams", order.size(), [&](auto& x, size_t k) {
    modelSeamFields(x, m, report.seams[order[k]], order[k], creaseAngleDeg);
  });
  o.objects("corners", report.corners.size(),
            [&](auto& x, size_t k) { cornerFields(x, m, report.corners[k].report); });
  o.objects("free_edges", report.freeEdges.size(), [&](auto& x, size_t k) {
    const FreeEdge& f = report.freeEdges[k];
    x.field("patch", patchName(m, f.edge.patch));
    x.field("edge", edgeName(f.edge.edge));
    x.field("range", f.range);
    x.field("partial", f.partial);
  });
  o.objects("degenerate_edges", report.degenerateEdges.size(), [&](auto& x, size_t k) {
    const DegenerateEdge& d = report.degenerateEdges[k];
    x.field("patch", patchName(m, d.edge.patch));
    x.field("edge", edgeName(d.edge.edge));
    x.field("point", d.point);
  });
  o.objects("overlaps", report.overlaps.size(), [&](auto& x, size_t k) {
    const FaceOverlap& v = report.overlaps[k];
    x.field("a", patchName(m, v.a));
    x.field("b", patchName(m, v.b));
    x.field("fraction", v.fraction);
    x.field("max_distance", v.maxDistance);
    x.field("point", v.point);
  });
  o.objects("coincident_edges", report.coincidentEdges.size(), [&](auto& x, size_t k) {
    const CoincidentEdges& c = report.coincidentEdges[k];
    x.field("point", c.point);
    x.objects("edges", c.edges.size(), [&](auto& y, size_t e) {
      y.field("patch", patchName(m, c.edges[e].patch));
      y.field("edge", edgeName(c.edges[e].edge));
    });
  });
  OrderedJson summary = summaryJson(report, require);
  addVerdictSummary(summary, m, report, creaseAngleDeg);
  o.field("summary", summary);
}

/// withInputFile's "format": "json", "bpt", "step", "iges" or null.
OrderedJson inputFormat(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  OrderedJson format = nullptr;
  if (ext == ".json" || ext == ".bpt") format = ext.substr(1);
  if (ext == ".step" || ext == ".stp") format = "step";
  if (ext == ".iges" || ext == ".igs") format = "iges";
  return format;
}

}  // namespace

OrderedJson modelCheckJson(const Model& m, const ModelCheckReport& report, const std::vector<size_t>& order,
                           const std::optional<GeometricClass>& require, std::optional<double> pairing,
                           double creaseAngleDeg, const ModelUnits& units, DistanceSource distanceSource,
                           const std::vector<std::string>& warnings, AngleSource angleSource) {
  OrderedJson j = OrderedJson::object();
  DomObject o(j);
  modelCheckFields(o, m, report, order, require, pairing, creaseAngleDeg, units, distanceSource, warnings, angleSource);
  return j;
}

void writeModelCheckJson(std::ostream& out, const std::filesystem::path& file, const Model& m,
                         const ModelCheckReport& report, const std::vector<size_t>& order,
                         const std::optional<GeometricClass>& require, std::optional<double> pairing,
                         double creaseAngleDeg, const ModelUnits& units, DistanceSource distanceSource,
                         const std::vector<std::string>& warnings, AngleSource angleSource) {
  JsonTextWriter w(&out);
  TextObject o(w);
  w.beginObject();
  o.field("file", file.string());
  o.field("format", inputFormat(file));
  modelCheckFields(o, m, report, order, require, pairing, creaseAngleDeg, units, distanceSource, warnings, angleSource);
  w.endObject();
  w.flush();
  out << '\n';
  out.flush();
}

OrderedJson withInputFile(const std::filesystem::path& file, OrderedJson check) {
  OrderedJson out{{"file", file.string()}, {"format", inputFormat(file)}};
  // The reader's warnings third, on every output (an empty list when there are none).
  out["warnings"] = check.contains("warnings") ? std::move(check["warnings"]) : OrderedJson::array();
  for (auto& [key, value] : check.items())
    if (key != "file" && key != "warnings") out[key] = std::move(value);
  return out;
}

#ifdef SEAM_HAVE_OCCT
namespace {
/// "E<n>": a B-rep edge where a patch model names a patch edge (a_edge, b_edge, free edges).
std::string brepEdgeName(int edge) { return fmt::format("E{}", edge); }

/// The members of `seam check --json` of a STEP/IGES B-rep after "file" and "format" (brepCheckJson's keys).
template <class Out>
void brepCheckFields(Out& o, const occt::BRepCheckReport& r, const std::vector<size_t>& order,
                     const std::optional<GeometricClass>& require, double creaseAngleDeg) {
  int below = 0;
  for (const occt::BRepSeam& s : r.seams)
    if (require && s.report.geometric < *require) ++below;
  std::vector<const SeamReport*> reports;
  for (const occt::BRepSeam& s : r.seams) reports.push_back(&s.report);
  const Tolerances& tol = r.tolerances;
  // Each face by its entity in the file: "#1234" (STEP) or "D17" (IGES directory entry), and its name.
  auto orNull = [](const std::string& x) { return x.empty() ? OrderedJson(nullptr) : OrderedJson(x); };
  o.field("warnings", r.import.warnings);  // the reader's and the check's (entities lost, roots not transferred, ...)
  o.object("model", [&](auto& x) {
    x.field("patches", r.import.faces.size());
    x.field("faces", r.import.faces.size());
    x.field("sewn", r.sewn);
    x.objects("face_names", r.import.faces.size(), [&](auto& y, size_t k) {
      const occt::CadFace& f = r.import.faces[k];
      y.field("patch", f.patch);
      y.field("entity", orNull(f.entity));
      y.field("name", orNull(f.entityName));
    });
  });
  o.field("units", unitsJson(r.units));
  o.object("tolerances", [&](auto& x) {
    x.field("distance", tol.distance);
    x.field("distance_source", toString(r.distanceSource));
    x.field("angle_deg", tol.angleDeg);
    x.field("angle_source", toString(r.angleSource));
    x.field("curvature_rel", tol.curvatureRel);
    x.field("crease_angle_deg", creaseAngleDeg);
  });
  o.objects("seams", order.size(), [&](auto& x, size_t i) {
    const size_t k = order[i];
    const occt::BRepSeam& s = r.seams[k];
    const std::string edge = brepEdgeName(s.edge);  // the shared B-rep edge, the same on both faces
    seamFields(x, s.report, creaseAngleDeg, edge, edge);
    x.field("index", k);
    x.field("edge", s.edge);
    x.field("route", s.viaPatchEdges ? "patch edges (Bernstein form)" : "pcurves (sampled)");
    x.field("occt_continuity", s.occtContinuity);
  });
  o.field("corners", OrderedJson::array());  // not analysed for B-rep files (summary.corners is null)
  o.objects("free_edges", r.freeEdges.size(), [&](auto& x, size_t k) {
    const occt::BRepFreeEdge& f = r.freeEdges[k];
    x.field("patch", f.face);
    x.field("edge", brepEdgeName(f.edge));
    x.field("edge_index", f.edge);
    x.field("midpoint", f.midpoint);
  });
  o.objects("non_manifold_edges", r.nonManifoldEdges.size(), [&](auto& x, size_t k) {
    const occt::BRepNonManifoldEdge& e = r.nonManifoldEdges[k];
    x.field("edge", e.edge);
    x.field("faces", e.faces);
    x.field("midpoint", e.midpoint);
  });
  if (r.overlapsSearched)  // faces lying on each other inside their trims, as for a patch model
    o.objects("overlaps", r.overlaps.size(), [&](auto& x, size_t k) {
      const FaceOverlap& v = r.overlaps[k];
      x.field("a", fmt::format("F{}", v.a + 1));
      x.field("b", fmt::format("F{}", v.b + 1));
      x.field("fraction", v.fraction);
      x.field("max_distance", v.maxDistance);
      x.field("point", v.point);
      x.field("solids", std::vector<int>{r.overlapSolids[k].first, r.overlapSolids[k].second});
    });
  double g0Max = 0.0, g1MaxDeg = 0.0, g2Max = 0.0;
  for (const SeamReport* x : reports) {
    g0Max = std::max(g0Max, x->g0Max);
    g1MaxDeg = std::max(g1MaxDeg, x->g1MaxDeg);
    g2Max = std::max(g2Max, x->g2Max);
  }
  OrderedJson summary{{"seams", r.seams.size()},
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
                      {"overlaps", r.overlapsSearched ? OrderedJson(r.overlaps.size()) : OrderedJson(nullptr)},
                      {"overlap_faces_skipped",
                       r.overlapsSearched ? OrderedJson(r.overlapFacesSkipped) : OrderedJson(nullptr)},
                      {"agree_with_occt_g1", r.occtAgreement}};
  summary["require"] = require ? OrderedJson(std::string(toString(*require))) : OrderedJson(nullptr);
  summary["below_required"] = below;
  summary["verdicts"] = verdictCountsJson(countVerdicts(reports, creaseAngleDeg));
  const OrderedJson worst = worstJson(reports, creaseAngleDeg, [&](size_t k) {
    const occt::BRepSeam& s = r.seams[k];
    return OrderedJson{{"index", k}, {"a", s.a}, {"a_edge", brepEdgeName(s.edge)}, {"b", s.b},
                       {"b_edge", brepEdgeName(s.edge)}, {"edge", s.edge}};
  });
  for (const auto& [key, value] : worst.items()) summary[key] = value;
  o.field("summary", summary);
}
}  // namespace

OrderedJson brepCheckJson(const occt::BRepCheckReport& r, const std::vector<size_t>& order,
                          const std::optional<GeometricClass>& require, double creaseAngleDeg) {
  OrderedJson j = OrderedJson::object();
  DomObject o(j);
  brepCheckFields(o, r, order, require, creaseAngleDeg);
  return j;
}

void writeBRepCheckJson(std::ostream& out, const std::filesystem::path& file, const occt::BRepCheckReport& r,
                        const std::vector<size_t>& order, const std::optional<GeometricClass>& require,
                        double creaseAngleDeg) {
  JsonTextWriter w(&out);
  TextObject o(w);
  w.beginObject();
  o.field("file", file.string());
  o.field("format", inputFormat(file));
  brepCheckFields(o, r, order, require, creaseAngleDeg);
  w.endObject();
  w.flush();
  out << '\n';
  out.flush();
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
      bo.findOverlaps = true;  // as `seam check`: the same JSON from the CLI, batch and Python
      Result<occt::BRepCheckReport> r = occt::checkBRepFile(file, bo);
      if (!r) return r.status();
      occt::toShownUnits(*r);  // as `seam check`: the file's own unit, or --display-units
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
  ModelUnits units = declaredModelUnits(o.tol);
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
  checked->json["warnings"] = out.warnings;  // a STEP/IGES file read as patches: the reader's warnings
  checked->warnings = std::move(out.warnings);
  return checked;
}

}  // namespace

Status displayUnitsStatus(const std::string& name, const ModelUnits& units) {
  if (units.displaySource != UnitSource::kDisplayOption || units.length) return Status::ok();
  return Status(ErrorCode::kInvalidInput,
                fmt::format("{}: --display-units needs a model with a length unit; this one is unit-less (give its "
                            "unit with --units)",
                            name));
}

Result<FileCheck> checkModel(const Model& model, const std::string& name, const FileCheckOptions& o,
                             const ModelUnits& units) {
  FileCheck out;
  if (model.patches.empty()) {  // as `seam check`: only curves, or "patches": []
    out.json = withInputFile(name, noPatchesJson(name, units.shown()));
    return out;
  }
  if (Status st = displayUnitsStatus(name, units); !st) return st;
  ModelCheckOptions mo;
  const ResolvedTolerances resolved = resolveTolerances(o.tol, units, model.boundingBox().diagonal());
  mo.tolerances = resolved.tolerances;
  mo.require = o.require;
  mo.findOverlaps = true;  // as `seam check`: the same JSON from the CLI, batch and Python
  Result<ModelCheckReport> r = seam::checkModel(model, mo);
  if (!r) return r.status().withContext(name);
  // Every length in the shown unit (issue 38 §1), as `seam check` prints it.
  const double scale = units.displayScale();
  if (scale != 1.0) scaleLengths(*r, scale);
  out.belowRequired = o.require && r->summary.belowRequired > 0;
  out.json = withInputFile(name, modelCheckJson(model, *r, selectSeams(reportsOf(*r), o.selection), o.require,
                                               r->pairingTolerance, o.selection.creaseAngleDeg, units.shown(),
                                               resolved.distanceSource, {}, resolved.angleSource));
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
