#include "seam/report/report.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <string>
#include <vector>

#include "report/viewer_js.h"

namespace seam::report {

namespace {

std::string escape(std::string_view s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string num(double x) {
  if (!std::isfinite(x)) return "-";
  return fmt::format("{:.4g}", x);
}

/// Colours of the geometric classes (none, G0, G1, G2) and of free edges.
constexpr std::array<const char*, 4> kClassColour{"#d62728", "#ff7f0e", "#1f77b4", "#2ca02c"};
constexpr const char* kFreeColour = "#9a9a9a";
/// Free (naked) edges: a boundary no other face continues (web/viewer.js NAKED_COLOUR, the same colour).
constexpr const char* kNakedEdgeColour = "#e377c2";

const char* classColour(GeometricClass c) { return kClassColour[static_cast<size_t>(c)]; }

/// Colours of the verdicts gap, kink, crease, G1, G2, undetermined in the 3-D view (web/viewer.js has the same list).
constexpr std::array<const char*, kSeamVerdictCount> kVerdictColour{"#d62728", "#ff7f0e", "#9467bd",
                                                                  "#1f77b4", "#2ca02c", "#bcbd22"};

/// Axonometric projection: view direction (1, 1, 1) (z up in the drawing unless the model is flat in z).
struct View {
  Vec3 e1, e2;
  double x0 = 0, y0 = 0, scale = 1, padX = 10, padY = 10;  // padding centres the drawing
  int size = 720;
  [[nodiscard]] std::pair<double, double> map(const Vec3& p) const {
    return {(p.dot(e1) - x0) * scale + padX, size - padY - (p.dot(e2) - y0) * scale};
  }
};

View makeView(const std::vector<std::vector<Vec3>>& curves, int size) {
  View v;
  v.size = size;
  const Vec3 d = Vec3(1, 1, 1).normalized();
  v.e1 = Vec3(0, 0, 1).cross(d).normalized();
  v.e2 = d.cross(v.e1).normalized();
  double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
  for (const auto& c : curves)
    for (const Vec3& q : c) {
      xmin = std::min(xmin, q.dot(v.e1));
      xmax = std::max(xmax, q.dot(v.e1));
      ymin = std::min(ymin, q.dot(v.e2));
      ymax = std::max(ymax, q.dot(v.e2));
    }
  if (!(xmax >= xmin)) xmin = xmax = ymin = ymax = 0.0;
  const double ext = std::max({xmax - xmin, ymax - ymin, 1e-300});
  v.x0 = xmin;
  v.y0 = ymin;
  v.scale = (size - 20.0) / ext;
  v.padX = 10.0 + 0.5 * ((size - 20.0) - (xmax - xmin) * v.scale);
  v.padY = 10.0 + 0.5 * ((size - 20.0) - (ymax - ymin) * v.scale);
  return v;
}

/// Grid cells per direction for tessellating `s`: perSpan per Bezier span, at most `cap`.
std::pair<int, int> gridSize(const BSplineSurface& s, double perSpan, int cap, int atLeast) {
  const int su = static_cast<int>(s.knotsU().interiorBreakpoints(s.degreeU()).size()) + 1;
  const int sv = static_cast<int>(s.knotsV().interiorBreakpoints(s.degreeV()).size()) + 1;
  auto n = [&](int spans) {
    return std::clamp(static_cast<int>(std::lround(perSpan * spans)), std::min(atLeast, cap), cap);
  };
  return {n(su), n(sv)};
}

/// The point and unit normal of `s` at grid node (i, j) of an nu x nv grid over its domain (S_u x S_v; at a pole,
/// the normal of the nearest regular point inward).
void gridNode(const BSplineSurface& s, int i, int j, int nu, int nv, Vec3& pt, Vec3& n) {
  const Interval du = s.domainU(), dv = s.domainV();
  const double u = du.lo + du.length() * i / nu, v = dv.lo + dv.length() * j / nv;
  Vec3 su1, sv1;
  s.pointAndFirstDerivatives(u, v, pt, su1, sv1);
  n = su1.cross(sv1);
  // At a pole the normal vanishes: take it at points stepped inward (a pole's normal is their limit).
  for (double step = 1e-6; !(n.norm() > 0.0) && step < 0.5; step *= 10.0) {
    const double ui = u + (i == nu ? -1.0 : 1.0) * step * du.length();
    const double vi = v + (j == nv ? -1.0 : 1.0) * step * dv.length();
    Vec3 q, a, b;
    s.pointAndFirstDerivatives(ui, vi, q, a, b);
    n = a.cross(b);
  }
  n = n.norm() > 0.0 ? Vec3(n.normalized()) : Vec3(0, 0, 1);
}

/// A JSON string literal that is safe inside an HTML <script> ('<' as \u003c).
std::string jsonString(std::string_view s) {
  std::string out = "\"";
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += c;
    } else if (u < 0x20 || c == '<' || c == '>' || c == '&') {
      out += fmt::format("\\u{:04x}", u);
    } else {
      out += c;
    }
  }
  return out + "\"";
}

/// A number for the view's JSON (`digits` significant digits; null when not finite).
std::string jsonNum(double x, int digits = 6) { return std::isfinite(x) ? fmt::format("{:.{}g}", x, digits) : "null"; }

void appendPoints(std::string& out, const std::vector<Vec3>& pts) {
  out += '[';
  for (size_t i = 0; i < pts.size(); ++i)
    out += fmt::format("{}{},{},{}", i ? "," : "", jsonNum(pts[i].x()), jsonNum(pts[i].y()), jsonNum(pts[i].z()));
  out += ']';
}

std::vector<Vec3> sampleCurve(const BSplineCurve& c, Interval d, int n) {
  std::vector<Vec3> out;
  for (int i = 0; i <= n; ++i) out.push_back(c.evaluate(d.lo + d.length() * i / n).head<3>());
  return out;
}

/// The seam's table value for one measure and where its measured maximum lies (issue 38 goal 5: the plot and the
/// table show the same measure).
struct PlotPeak {
  double t = 0.0;      ///< parameter of the refined maximum on A's edge (SeamReport::g0Worst.t, ...)
  double value = 0.0;  ///< the refined maximum there (g0Sampled, ...): the plot's peak
  double table = 0.0;  ///< the table's value (g0Max, ...): a certified bound at or above it, or the same number
};

/// The samples with the seam's refined maximum added at its parameter, so that the plot peaks at the number the
/// sampled column of the table shows (the samples alone miss a maximum between them, or at an end overhang).
void addPeak(std::vector<double>& t, std::vector<double>& y, const PlotPeak& peak) {
  if (!std::isfinite(peak.t) || !std::isfinite(peak.value) || t.empty()) return;
  const auto at = std::lower_bound(t.begin(), t.end(), peak.t);
  const auto i = at - t.begin();
  if (at != t.end() && *at == peak.t) {
    y[static_cast<size_t>(i)] = std::max(y[static_cast<size_t>(i)], peak.value);
    return;
  }
  t.insert(at, peak.t);
  y.insert(y.begin() + i, peak.value);
}

/// One line plot (value against t) with a dashed tolerance line, a dot at the measured maximum and, where the
/// table shows a certified bound above it, a dotted line at the bound. data-peak / data-table carry the two
/// numbers for tests and scripts.
std::string plot(std::vector<double> t, std::vector<double> y, double tol, const std::string& label, int w, int h,
                 const PlotPeak& peak) {
  addPeak(t, y, peak);
  double ymax = std::isfinite(peak.table) ? std::max(tol, peak.table) : tol;
  double highest = -std::numeric_limits<double>::infinity();
  double highestT = t.front();
  for (size_t i = 0; i < y.size(); ++i)
    if (std::isfinite(y[i])) {
      ymax = std::max(ymax, y[i]);
      if (y[i] > highest) {
        highest = y[i];
        highestT = t[i];
      }
    }
  ymax = ymax > 0.0 ? 1.1 * ymax : 1.0;
  const double t0 = t.front(), t1 = t.back() > t.front() ? t.back() : t.front() + 1.0;
  const double left = 70, right = 10, top = 18, bottom = 22;
  auto X = [&](double x) { return left + (x - t0) / (t1 - t0) * (w - left - right); };
  auto Y = [&](double v) { return h - bottom - std::clamp(v / ymax, 0.0, 1.0) * (h - top - bottom); };
  std::string pts;
  for (size_t i = 0; i < t.size(); ++i)
    if (std::isfinite(y[i])) pts += fmt::format("{:.1f},{:.1f} ", X(t[i]), Y(y[i]));
  std::string s = fmt::format(
      "<svg class=\"plot\" width=\"{}\" height=\"{}\" viewBox=\"0 0 {} {}\" data-peak=\"{}\" data-table=\"{}\">", w, h, w,
      h, jsonNum(highest, 17), jsonNum(peak.table, 17));
  s += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"#fafafa\" stroke=\"#ccc\"/>", left, top,
                   w - left - right, h - top - bottom);
  s += fmt::format("<text x=\"{}\" y=\"12\" class=\"lbl\">{}</text>", left, escape(label));
  s += fmt::format("<text x=\"{}\" y=\"{:.1f}\" class=\"ax\" text-anchor=\"end\">{}</text>", left - 4, Y(ymax) + 4,
                   num(ymax));
  s += fmt::format("<text x=\"{}\" y=\"{:.1f}\" class=\"ax\" text-anchor=\"end\">0</text>", left - 4, Y(0.0) + 4);
  s += fmt::format("<text x=\"{}\" y=\"{}\" class=\"ax\">t = {}</text>", left, h - 6, num(t0));
  s += fmt::format("<text x=\"{}\" y=\"{}\" class=\"ax\" text-anchor=\"end\">{}</text>", w - right, h - 6, num(t1));
  s += fmt::format(
      "<line x1=\"{}\" x2=\"{}\" y1=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#d62728\" stroke-dasharray=\"5,4\"/>"
      "<text x=\"{}\" y=\"{:.1f}\" class=\"ax\" fill=\"#d62728\" text-anchor=\"end\">tol {}</text>",
      left, w - right, Y(tol), Y(tol), w - right - 2, Y(tol) - 3, num(tol));
  if (std::isfinite(peak.table) && std::isfinite(highest) && peak.table > highest * (1.0 + 1e-9) + 1e-300)
    s += fmt::format(
        "<line x1=\"{}\" x2=\"{}\" y1=\"{:.1f}\" y2=\"{:.1f}\" stroke=\"#555\" stroke-dasharray=\"1,3\"/>"
        "<text x=\"{}\" y=\"{:.1f}\" class=\"ax\" text-anchor=\"start\">bound {}</text>",
        left, w - right, Y(peak.table), Y(peak.table), left + 2, Y(peak.table) - 3, num(peak.table));
  s += fmt::format("<polyline fill=\"none\" stroke=\"#1f77b4\" stroke-width=\"1.5\" points=\"{}\"/>", pts);
  if (std::isfinite(highest))
    s += fmt::format("<circle cx=\"{:.1f}\" cy=\"{:.1f}\" r=\"3\" fill=\"#1f77b4\"><title>max {} at t = {}</title>"
                     "</circle>",
                     X(highestT), Y(highest), num(highest), num(highestT));
  s += "</svg>";
  return s;
}

constexpr const char* kStyle = R"(
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;margin:24px;color:#222}
h1{font-size:1.4em} h2{font-size:1.15em;margin-top:1.6em;border-bottom:1px solid #ddd}
table{border-collapse:collapse;font-size:.85em} td,th{border:1px solid #ddd;padding:3px 7px;text-align:right}
th{background:#f2f2f2;cursor:pointer;user-select:none} td.l,th.l{text-align:left}
.c0{color:#d62728;font-weight:600}.c1{color:#ff7f0e;font-weight:600}.c2{color:#1f77b4}.c3{color:#2ca02c}
.plot{margin:2px 8px 2px 0}.lbl{font-size:11px;fill:#333}.ax{font-size:10px;fill:#555}
.seam{margin:10px 0 18px 0}.legend span{display:inline-block;margin-right:14px}
.sw{display:inline-block;width:18px;height:4px;vertical-align:middle;margin-right:5px}
#view3d-ui{margin:6px 0;font-size:.9em}#view3d-ui label{margin-right:14px}
.v3row{display:flex;flex-wrap:wrap;gap:12px;align-items:flex-start}
#view3d-canvas{width:720px;height:540px;border:1px solid #ddd;cursor:grab}
#view3d-panel{max-width:600px;font-size:.9em;color:#444}
.vlabel{font-size:11px;fill:#222;paint-order:stroke;stroke:#fff;stroke-width:3px}
#view3d-canvas{position:relative}.v3label{position:absolute;font:11px sans-serif;color:#222;background:#fffc;
border:1px solid #999;border-radius:3px;padding:0 3px;white-space:nowrap;pointer-events:none;transform:translate(6px,-50%)}
)";

constexpr const char* kScript = R"(
document.querySelectorAll('table.sortable th').forEach(function(th, col){
  th.addEventListener('click', function(){
    var table = th.closest('table'), body = table.tBodies[0];
    var rows = Array.prototype.slice.call(body.rows);
    var asc = th.getAttribute('data-dir') !== 'asc';
    table.querySelectorAll('th').forEach(function(h){ h.removeAttribute('data-dir'); });
    th.setAttribute('data-dir', asc ? 'asc' : 'desc');
    rows.sort(function(a, b){
      var x = a.cells[col].getAttribute('data-v') || a.cells[col].textContent;
      var y = b.cells[col].getAttribute('data-v') || b.cells[col].textContent;
      var fx = parseFloat(x), fy = parseFloat(y);
      var r = (!isNaN(fx) && !isNaN(fy)) ? fx - fy : x.localeCompare(y);
      return asc ? r : -r;
    });
    rows.forEach(function(r){ body.appendChild(r); });
  });
});
)";

/// Where a seam's dot and label go: the worst gap of a gap, the largest angle of a kink or crease, else the largest
/// curvature jump.
const Vec3& worstPointOf(const SeamReport& r, SeamVerdict v) {
  if (v == SeamVerdict::kGap) return r.g0Worst.point;
  if (v == SeamVerdict::kKink || v == SeamVerdict::kCrease || v == SeamVerdict::kUndetermined) return r.g1Worst.point;
  return r.g2Worst.point;
}

/// A seam's value label (HtmlReportOptions::maxValueLabels): its text and its rank in the seam table.
struct ValueLabel {
  std::string text;
  int rank = 0;
  [[nodiscard]] bool empty() const { return text.empty(); }
};

/// The JSON read by the 3-D view (web/viewer.js documents the fields).
std::string viewData(const ReportData& data, const std::vector<const SeamReport*>& reports,
                     const std::vector<bool>& hasPlots, const std::vector<ValueLabel>& labels,
                     double creaseAngleDeg, int maxSpikeSamples) {
  std::string j = "{\"meshes\":[";
  for (size_t m = 0; m < data.meshes.size(); ++m) {
    const ReportMesh& mesh = data.meshes[m];
    j += fmt::format("{}{{\"name\":{},\"p\":", m ? "," : "", jsonString(mesh.name));
    appendPoints(j, mesh.points);
    j += ",\"n\":[";
    for (size_t i = 0; i < mesh.normals.size(); ++i) {
      const Vec3& n = mesh.normals[i];
      j += fmt::format("{}{:.3f},{:.3f},{:.3f}", i ? "," : "", n.x(), n.y(), n.z());
    }
    j += "],\"i\":[";
    for (size_t i = 0; i < mesh.triangles.size(); ++i) j += fmt::format("{}{}", i ? "," : "", mesh.triangles[i]);
    j += "]}";
  }
  size_t totalSamples = 0;
  for (const SeamReport* r : reports) totalSamples += r ? r->samples.size() : 0;
  const double keep = totalSamples > static_cast<size_t>(std::max(maxSpikeSamples, 0))
                          ? static_cast<double>(std::max(maxSpikeSamples, 0)) / static_cast<double>(totalSamples)
                          : 1.0;
  j += "],\"seams\":[";
  for (size_t k = 0; k < data.seams.size(); ++k) {
    const ReportSeam& s = data.seams[k];
    const SeamReport* r = reports[k];
    const int v = r ? static_cast<int>(seamVerdict(*r, creaseAngleDeg)) : -1;
    j += fmt::format("{}{{\"k\":{},\"v\":{},\"a\":{},\"b\":{},\"plot\":{},\"c\":", k ? "," : "", k, v,
                     jsonString(s.a), jsonString(s.b), hasPlots[k] ? "true" : "false");
    appendPoints(j, s.curve);
    j += ",\"w\":";
    if (r) {
      const Vec3& w = worstPointOf(*r, static_cast<SeamVerdict>(v));
      j += fmt::format("[{},{},{}]", jsonNum(w.x()), jsonNum(w.y()), jsonNum(w.z()));
    } else {
      j += "null";
    }
    if (!labels[k].empty()) j += fmt::format(",\"l\":{},\"lr\":{}", jsonString(labels[k].text), labels[k].rank);
    j += ",\"s\":";
    if (r && r->samples.size() >= 2 && keep > 0.0) {
      // Thin the samples evenly (first and last kept) to this seam's share of maxSpikeSamples.
      const size_t n = r->samples.size();
      constexpr size_t kMaxSpikesPerSeam = 64;  // denser combs are not readable
      const size_t want = std::clamp<size_t>(static_cast<size_t>(std::ceil(keep * static_cast<double>(n))), 2,
                                             std::min(n, kMaxSpikesPerSeam));
      std::string t = "[", g1 = "[", g2 = "[";
      for (size_t i = 0; i < want; ++i) {
        const SeamSample& x = r->samples[want == 1 ? 0 : i * (n - 1) / (want - 1)];
        const char* sep = i ? "," : "";
        t += sep + jsonNum(x.t, 5);  // enough for a place along the seam and a spike's length
        g1 += sep + jsonNum(x.g1Deg, 3);
        g2 += sep + jsonNum(x.g2Rel, 3);
      }
      j += fmt::format("{{\"t\":{}],\"g1\":{}],\"g2\":{}]}}", t, g1, g2);
    } else {
      j += "null";
    }
    j += "}";
  }
  j += "],\"outline\":[";
  for (size_t i = 0; i < data.outline.size(); ++i) {
    if (i) j += ",";
    appendPoints(j, data.outline[i]);
  }
  j += "],\"free\":[";
  for (size_t i = 0; i < data.freeEdgeCurves.size(); ++i) {
    if (i) j += ",";
    appendPoints(j, data.freeEdgeCurves[i]);
  }
  // The spikes' noise floor: values below the tolerances are not drawn (issue 38 §9: the teapot's 5e-13 deg of
  // round-off drawn as full-length spikes looked like kinks).
  return j + fmt::format("],\"tol\":{{\"g1\":{},\"g2\":{}}}}}", jsonNum(data.tolerances.angleDeg),
                         jsonNum(data.tolerances.curvatureRel));
}

}  // namespace

std::string overlapsFact(const std::vector<FaceOverlap>& overlaps, const std::function<std::string(int)>& name,
                         const std::function<std::string(double)>& number,
                         const std::function<std::string(double)>& distance) {
  std::string text = overlaps.empty()       ? "none"
                     : overlaps.size() == 1 ? std::string("1 pair:")
                                            : fmt::format("{} pairs:", overlaps.size());
  for (size_t k = 0; k < std::min(overlaps.size(), kOverlapsListed); ++k) {
    const FaceOverlap& o = overlaps[k];
    text += fmt::format("{} {} / {} ({} %, within {})", k ? "," : "", name(o.a), name(o.b), number(100.0 * o.fraction),
                        distance(o.maxDistance));
  }
  if (overlaps.size() > kOverlapsListed) text += fmt::format(" and {} more", overlaps.size() - kOverlapsListed);
  return text;
}

ReportData reportData(const Model& model, const ModelCheckReport& report, int samplesPerEdge) {
  ReportData d;
  d.tolerances = report.tolerances;
  const ModelCheckSummary& S = report.summary;
  auto name = [&](int p) { return model.patches[static_cast<size_t>(p)].name; };
  d.facts.emplace_back("patches", std::to_string(model.patches.size()));
  d.facts.emplace_back("corners", fmt::format("{} ({} 4-valent, {} degenerate)", S.corners, S.fourValentCorners,
                                              S.degenerateCorners));
  if (report.overlapsSearched)  // faces lying on each other (issue 38 §11), as `seam check` lists them
    d.facts.emplace_back("overlapping faces", overlapsFact(report.overlaps, name, num, num));
  for (const Patch& p : model.patches)
    for (Edge e : {Edge::U0, Edge::U1, Edge::V0, Edge::V1}) {
      const BSplineCurve c = p.surface.boundaryCurve(e);
      d.outline.push_back(sampleCurve(c, c.domain(), samplesPerEdge));
    }
  for (const ModelSeam& s : report.seams) {
    ReportSeam r;
    r.a = name(s.pair.a.patch);
    r.b = name(s.pair.b.patch);
    r.aEdge = std::string(edgeName(s.pair.a.edge));
    r.bEdge = std::string(edgeName(s.pair.b.edge));
    r.report = s.report;
    r.error = s.error.message();
    const BSplineCurve c = model.patches[static_cast<size_t>(s.pair.a.patch)].surface.boundaryCurve(s.pair.a.edge);
    r.curve = sampleCurve(c, s.pair.overlapA, samplesPerEdge);
    d.seams.push_back(std::move(r));
  }
  for (const FreeEdge& f : report.freeEdges) {
    d.freeEdges.push_back(fmt::format("{}:{}{}", name(f.edge.patch), edgeName(f.edge.edge),
                                      f.partial ? fmt::format(" [{}, {}]", num(f.range.lo), num(f.range.hi)) : ""));
    const BSplineCurve c = model.patches[static_cast<size_t>(f.edge.patch)].surface.boundaryCurve(f.edge.edge);
    d.freeEdgeCurves.push_back(sampleCurve(c, f.range, samplesPerEdge));
  }
  for (const DegenerateEdge& g : report.degenerateEdges)
    d.degenerateEdges.push_back(fmt::format("{}:{}", name(g.edge.patch), edgeName(g.edge.edge)));
  for (const ModelCorner& c : report.corners) {
    d.corners.push_back(&c.report);
    std::string names;
    for (const PatchCorner& pc : c.report.corners) names += name(pc.patch) + " ";
    d.cornerPatchNames.push_back(names);
  }
  d.meshes = reportMeshes(model);
  return d;
}

bool hasViewer3d() { return detail::kViewerJs[0] != '\0'; }

std::vector<ReportMesh> reportMeshes(const Model& model, const std::vector<bool>& shade, int vertexBudget) {
  constexpr double kPerSpan = 8.0;
  constexpr int kMin = 2, kMax = 64;
  std::vector<size_t> which;
  for (size_t i = 0; i < model.patches.size(); ++i)
    if ((shade.empty() || (i < shade.size() && shade[i])) && model.patches[i].surface.dim() == 3) which.push_back(i);
  // Coarsen every patch by the same factor until the total fits the budget (never below kMin cells).
  double perSpan = kPerSpan;
  for (int round = 0; round < 8; ++round) {
    double total = 0.0;
    for (size_t i : which) {
      const auto [nu, nv] = gridSize(model.patches[i].surface, perSpan, kMax, kMin);
      total += static_cast<double>(nu + 1) * (nv + 1);
    }
    if (total <= vertexBudget || perSpan <= 0.5) break;
    perSpan = std::max(0.5, perSpan * std::sqrt(vertexBudget / total) * 0.95);
  }
  std::vector<ReportMesh> out;
  for (size_t i : which) {
    const BSplineSurface& s = model.patches[i].surface;
    const auto [nu, nv] = gridSize(s, perSpan, kMax, kMin);
    ReportMesh m;
    m.name = model.patches[i].name;
    for (int a = 0; a <= nu; ++a)
      for (int b = 0; b <= nv; ++b) {
        Vec3 pt, n;
        gridNode(s, a, b, nu, nv, pt, n);
        m.points.push_back(pt);
        m.normals.push_back(n);
      }
    auto id = [rowLength = nv + 1](int a, int b) { return a * rowLength + b; };
    for (int a = 0; a < nu; ++a)
      for (int b = 0; b < nv; ++b)
        m.triangles.insert(m.triangles.end(),
                           {id(a, b), id(a + 1, b), id(a + 1, b + 1), id(a, b), id(a + 1, b + 1), id(a, b + 1)});
    out.push_back(std::move(m));
  }
  return out;
}

std::string htmlReport(const Model& model, const ModelCheckReport& report, const HtmlReportOptions& options) {
  return htmlReport(reportData(model, report, options.samplesPerEdge), options);
}

std::string htmlReport(const ReportData& data, const HtmlReportOptions& options) {
  const Tolerances& tol = data.tolerances;
  const SeamSelection& sel = options.selection;
  std::vector<const SeamReport*> reports;
  for (const ReportSeam& s : data.seams) reports.push_back(s.report ? &*s.report : nullptr);
  auto verdictOf = [&](size_t k) { return seamVerdict(*reports[k], sel.creaseAngleDeg); };
  std::array<int, 4> classes{};
  int certified = 0, failed = 0;
  GeometricClass worst = GeometricClass::kG2;
  double g0 = 0, g1 = 0, g2 = 0, g2rel = 0;
  for (const ReportSeam& s : data.seams) {
    if (!s.report) {
      ++failed;
      worst = GeometricClass::kNone;
      continue;
    }
    ++classes[static_cast<size_t>(s.report->geometric)];
    certified += s.report->certified ? 1 : 0;
    worst = std::min(worst, s.report->geometric);
    g0 = std::max(g0, s.report->g0Max);
    g1 = std::max(g1, s.report->g1MaxDeg);
    g2 = std::max(g2, s.report->g2Max);
    g2rel = std::max(g2rel, s.report->g2RelMax);
  }
  std::string h;
  h += "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">";
  h += fmt::format("<title>{}</title><style>{}</style></head><body>\n", escape(options.title), kStyle);
  h += fmt::format("<h1>{}</h1>\n", escape(options.title));

  // ---- the reader's warnings first: a partly read file must not look complete (issue 39 goal 3)
  if (!data.warnings.empty()) {
    h += fmt::format("<h2 id=\"warnings\">Warnings ({})</h2>\n<p>The file was not read in full or not exactly; the "
                     "results below are for what was read.</p>\n<ul class=\"warnings\">",
                     data.warnings.size());
    for (const std::string& w : data.warnings) h += "<li>" + escape(w) + "</li>";
    h += "</ul>\n";
  }

  // ---- summary
  h += "<h2 id=\"summary\">Summary</h2>\n<table>";
  auto row = [&](const std::string& k, const std::string& v) {
    h += fmt::format("<tr><th class=\"l\">{}</th><td class=\"l\">{}</td></tr>", escape(k), v);
  };
  row("seams", fmt::format("{} ({} certified, {} failed)", data.seams.size(), certified, failed));
  const std::array<int, kSeamVerdictCount> verdicts = countVerdicts(reports, sel.creaseAngleDeg);
  row("by verdict", fmt::format("gap {}, kink {}, crease {} (angle &ge; {}&deg;, left as designed), G1 {}, G2 {}{}",
                                verdicts[0], verdicts[1], verdicts[2], num(sel.creaseAngleDeg), verdicts[3],
                                verdicts[4],
                                verdicts[5] ? fmt::format(", undetermined {} (a normal vanishes)", verdicts[5]) : ""));
  const WorstDefects worstDefect = worstDefects(reports, sel.creaseAngleDeg);
  auto where = [&](size_t k, const Vec3& p) {
    const ReportSeam& s = data.seams[k];
    return fmt::format("<a href=\"#seam-{}\">#{}</a> {}{} / {}{} at [{}, {}, {}]", k, k, escape(s.a),
                       s.aEdge.empty() ? "" : ":" + escape(s.aEdge), escape(s.b),
                       s.bEdge.empty() ? "" : ":" + escape(s.bEdge), num(p.x()), num(p.y()), num(p.z()));
  };
  row("worst kink", worstDefect.kink ? fmt::format("{}&deg;, {}", num(reports[*worstDefect.kink]->g1MaxDeg),
                                                   where(*worstDefect.kink, reports[*worstDefect.kink]->g1Worst.point))
                                     : "none");
  // A length with the model's unit ("0.0012 mm"; the number alone for a unit-less model).
  auto len = [&](double x) { return data.lengthUnit.empty() ? num(x) : num(x) + " " + escape(data.lengthUnit); };
  row("worst gap", worstDefect.gap ? fmt::format("{}, {}", len(reports[*worstDefect.gap]->g0Max),
                                                 where(*worstDefect.gap, reports[*worstDefect.gap]->g0Worst.point))
                                   : "none");
  row("by class", fmt::format("G2 {}, G1 {}, G0 {}, none {}", classes[3], classes[2], classes[1], classes[0]));
  row("worst", fmt::format("<span class=\"c{}\">{}</span>", static_cast<int>(worst), toString(worst)));
  row("largest gap (G0)", len(g0));
  row("largest angle (G1, degrees)", num(g1));
  row("largest curvature jump (G2)", fmt::format("{} (relative {})", num(g2), num(g2rel)));
  row("free edges / degenerate edges", fmt::format("{} / {}", data.freeEdges.size(), data.degenerateEdges.size()));
  if (!data.warnings.empty()) row("reader warnings", fmt::format("<a href=\"#warnings\">{}</a>", data.warnings.size()));
  for (const auto& [k, v] : data.facts) row(k, escape(v));
  if (!data.unitNote.empty()) row("length unit", escape(data.unitNote));
  row("tolerances", fmt::format("distance {}{}, angle {}&deg;{}, curvature {} relative", len(tol.distance),
                                data.distanceSource.empty() ? "" : " (" + escape(data.distanceSource) + ")",
                                num(tol.angleDeg), data.angleSource.empty() ? "" : " (" + escape(data.angleSource) + ")",
                                num(tol.curvatureRel)));
  h += "</table>\n";

  // ---- value labels: the worst gaps and kinks, in the seam table's order (issue 38 §11)
  std::vector<ValueLabel> labels(data.seams.size());
  {
    SeamSelection byVerdict = sel;
    byVerdict.only = SeamFilter::kAll;
    byVerdict.top.reset();
    byVerdict.sort = SeamSortKey::kVerdict;
    int given = 0;
    for (size_t k : selectSeams(reports, byVerdict)) {
      if (given >= options.maxValueLabels) break;
      if (!reports[k] || !passes(sel.only, reports[k], sel.creaseAngleDeg)) continue;
      const SeamVerdict v = verdictOf(k);
      if (v == SeamVerdict::kKink)
        labels[k].text = fmt::format("#{} kink {}\u00b0", k, num(reports[k]->g1MaxDeg));
      else if (v == SeamVerdict::kGap)
        labels[k].text = fmt::format("#{} gap {}{}", k, num(reports[k]->g0Max),
                                     data.lengthUnit.empty() ? "" : " " + data.lengthUnit);
      else
        continue;
      labels[k].rank = given++;
    }
  }
  // ---- overview drawing
  h += "<h2 id=\"overview\">Model</h2>\n";
  const bool view3d = options.view3d && hasViewer3d();
  if (view3d) {
    h += "<div id=\"view3d\"><p id=\"view3d-note\">3-D view: drag to rotate, right-drag to pan, wheel to zoom; "
         "click a seam for its plots. Shaded patches, seams coloured by verdict, worst points of gaps, kinks and "
         "creases as dots.</p>\n<div id=\"view3d-ui\" style=\"display:none\"><div class=\"legend\">";
    for (int v = 0; v < static_cast<int>(kSeamVerdictCount); ++v)
      h += fmt::format("<span><span class=\"sw\" style=\"background:{}\"></span>{}</span>", kVerdictColour[v],
                       toString(static_cast<SeamVerdict>(v)));
    h += fmt::format("<span><span class=\"sw\" style=\"background:#000\"></span>analysis failed</span>"
                     "<span><span class=\"sw\" style=\"background:{}\"></span>free (naked) edge</span></div>",
                     kNakedEdgeColour);
    h += "<label><input type=\"checkbox\" id=\"view3d-zebra\"> zebra stripes</label>"
         "<label>spikes along the seams <select id=\"view3d-spikes\"><option value=\"none\">none</option>"
         "<option value=\"g1\">G1 angle</option><option value=\"g2\">G2 jump (relative)</option></select></label>"
         "<span id=\"view3d-spike-scale\"></span> "
         "<label><input type=\"checkbox\" id=\"view3d-outline\" checked> other boundaries</label>"
         "<label><input type=\"checkbox\" id=\"view3d-labels\" checked> value labels</label>"
         "<button id=\"view3d-home\" type=\"button\">reset view</button></div>\n"
         "<div class=\"v3row\"><div id=\"view3d-canvas\"></div><div id=\"view3d-panel\">Click a seam in the view "
         "to see its G0/G1/G2 plots here.</div></div></div>\n"
         "<details id=\"view2d\" open><summary>2-D drawing (axonometric, coloured by geometric class)</summary>\n";
  }
  h += "<div class=\"legend\">";
  for (int c = 3; c >= 0; --c)
    h += fmt::format("<span><span class=\"sw\" style=\"background:{}\"></span>{}</span>", kClassColour[c],
                     toString(static_cast<GeometricClass>(c)));
  h += fmt::format("<span><span class=\"sw\" style=\"background:{}\"></span>other boundary</span>"
                   "<span><span class=\"sw\" style=\"background:{}\"></span>free (naked) edge</span></div>\n",
                   kFreeColour, kNakedEdgeColour);
  {
    std::vector<std::vector<Vec3>> all = data.outline;
    for (const ReportSeam& s : data.seams) all.push_back(s.curve);
    const View view = makeView(all, options.overviewSize);
    auto polyline = [&](const std::vector<Vec3>& c, const char* colour, double width, const std::string& title) {
      std::string pts;
      for (const Vec3& p : c) {
        const auto [x, y] = view.map(p);
        pts += fmt::format("{:.1f},{:.1f} ", x, y);
      }
      h += fmt::format("<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" points=\"{}\"><title>{}</title>"
                       "</polyline>",
                       colour, width, pts, escape(title));
    };
    h += fmt::format("<svg width=\"{0}\" height=\"{0}\" viewBox=\"0 0 {0} {0}\" style=\"border:1px solid #ddd\">",
                     options.overviewSize);
    for (const auto& c : data.outline) polyline(c, kFreeColour, 0.8, "boundary");
    for (const auto& c : data.freeEdgeCurves) polyline(c, kNakedEdgeColour, 1.4, "free (naked) edge");
    for (size_t k = 0; k < data.seams.size(); ++k) {
      const ReportSeam& s = data.seams[k];
      const GeometricClass c = s.report ? s.report->geometric : GeometricClass::kNone;
      polyline(s.curve, classColour(c), 1.8, fmt::format("#{} {} / {}: {}", k, s.a, s.b, toString(c)));
    }
    for (size_t k = 0; k < data.seams.size(); ++k) {
      if (labels[k].empty()) continue;
      const auto [x, y] = view.map(worstPointOf(*reports[k], verdictOf(k)));
      h += fmt::format("<circle cx=\"{0:.1f}\" cy=\"{1:.1f}\" r=\"2.5\" fill=\"{2}\"/><text x=\"{3:.1f}\" "
                       "y=\"{4:.1f}\" class=\"vlabel\" data-seam=\"{5}\">{6}</text>",
                       x, y, kVerdictColour[static_cast<int>(verdictOf(k))], x + 4.0, y - 4.0, k,
                       escape(labels[k].text));
    }
    h += "</svg>\n";
  }
  if (view3d) h += "</details>\n";

  // ---- seam tables: the seams that are not design creases (kinks first), then the creases apart
  // Default order: kinks (largest angle first), gaps (largest first), failed analyses, G1/G2 in file order, then the
  // creases (largest angle first); a --sort measure replaces it within each table.
  SeamSelection all = sel;
  all.only = SeamFilter::kAll;
  all.top.reset();
  if (all.sort == SeamSortKey::kFile) all.sort = SeamSortKey::kVerdict;
  std::vector<size_t> order = selectSeams(reports, all);
  std::vector<size_t> mainRows, creaseRows;
  size_t creasesAll = 0;
  for (size_t k : order) {
    const bool crease = reports[k] && verdictOf(k) == SeamVerdict::kCrease;
    creasesAll += crease ? 1 : 0;
    if (!passes(sel.only, reports[k], sel.creaseAngleDeg)) continue;
    (crease ? creaseRows : mainRows).push_back(k);
  }
  if (sel.top) {
    if (mainRows.size() > *sel.top) mainRows.resize(*sel.top);
    if (creaseRows.size() > *sel.top) creaseRows.resize(*sel.top);
  }
  const bool extra = !data.extraHeader.empty();
  auto seamTable = [&](const std::vector<size_t>& rows) {
    std::string t = "<table class=\"sortable\"><thead><tr><th>#</th><th class=\"l\">A</th><th class=\"l\">edge</th>"
                    "<th class=\"l\">B</th><th class=\"l\">edge</th><th class=\"l\">verdict</th>" +
                    (data.lengthUnit.empty() ? std::string("<th>G0 gap</th>")
                                             : "<th>G0 gap (" + escape(data.lengthUnit) + ")</th>") +
                    "<th>G1 angle (&deg;)</th><th>G2 jump</th><th>G2 relative</th><th class=\"l\">geometric</th>"
                    "<th class=\"l\">parametric</th><th class=\"l\">certified</th>";
    if (extra) t += fmt::format("<th class=\"l\">{}</th>", escape(data.extraHeader));
    t += "</tr></thead><tbody>\n";
    for (size_t k : rows) {
      const ReportSeam& s = data.seams[k];
      t += fmt::format("<tr><td><a href=\"#seam-{0}\">{0}</a></td><td class=\"l\">{1}</td><td class=\"l\">{2}</td>"
                       "<td class=\"l\">{3}</td><td class=\"l\">{4}</td>",
                       k, escape(s.a), escape(s.aEdge), escape(s.b), escape(s.bEdge));
      if (!s.report) {
        t += fmt::format("<td colspan=\"{}\" class=\"l c0\">analysis failed: {}</td></tr>\n", extra ? 9 : 8,
                         escape(s.error));
        continue;
      }
      const SeamReport& r = *s.report;
      const int gc = static_cast<int>(r.geometric);
      const SeamVerdict v = verdictOf(k);
      t += fmt::format("<td class=\"l{}\" data-v=\"{}\">{}</td>", isProblem(v) ? fmt::format(" c{}", gc) : "",
                       static_cast<int>(v), toString(v));
      t += fmt::format("<td data-v=\"{:.17g}\">{}</td><td data-v=\"{:.17g}\">{}</td><td data-v=\"{:.17g}\">{}</td>"
                       "<td data-v=\"{:.17g}\">{}</td><td class=\"l c{}\" data-v=\"{}\">{}</td><td class=\"l\">{}</td>"
                       "<td class=\"l\">{}</td>",
                       r.g0Max, num(r.g0Max), r.g1MaxDeg, num(r.g1MaxDeg), r.g2Max, num(r.g2Max), r.g2RelMax,
                       num(r.g2RelMax), gc, gc, toString(r.geometric), toString(r.parametric),
                       r.certified ? "yes" : "no");
      if (extra) t += fmt::format("<td class=\"l\">{}</td>", escape(s.extra));
      t += "</tr>\n";
    }
    return t + "</tbody></table>\n";
  };
  const size_t mainAll = data.seams.size() - creasesAll;
  h += "<h2 id=\"seams\">Seams</h2>\n<p>Kinks (near-tangent seams) first, then gaps, then the rest; design creases "
       "are listed apart below. Click a column header to sort. Values of certified seams are upper bounds that hold "
       "over the whole seam; the others are refined sampled maxima.";
  if (mainRows.size() != mainAll) h += fmt::format(" Showing {} of {}.", mainRows.size(), mainAll);
  h += "</p>\n" + seamTable(mainRows);
  h += fmt::format("<h2 id=\"creases\">Design creases</h2>\n<p>{} seams whose angle is at or above the crease angle "
                   "({}&deg;): intended sharp edges, left as designed.",
                   creasesAll, num(sel.creaseAngleDeg));
  if (creaseRows.size() != creasesAll) h += fmt::format(" Showing {} of {}.", creaseRows.size(), creasesAll);
  h += "</p>\n";
  if (!creaseRows.empty()) h += seamTable(creaseRows);

  // ---- per-seam plots, in the order of the tables (kinks and gaps first, creases last)
  order.clear();
  order.insert(order.end(), mainRows.begin(), mainRows.end());
  order.insert(order.end(), creaseRows.begin(), creaseRows.end());
  h += "<h2 id=\"plots\">Along each seam</h2>\n";
  if (static_cast<int>(order.size()) > options.maxPlottedSeams)
    h += fmt::format("<p>The {} worst of {} seams are plotted.</p>\n", options.maxPlottedSeams, order.size());
  int plotted = 0;
  std::vector<bool> hasPlots(data.seams.size(), false);
  for (size_t k : order) {
    if (plotted >= options.maxPlottedSeams) break;
    const ReportSeam& s = data.seams[k];
    if (!s.report || s.report->samples.size() < 2) continue;
    ++plotted;
    hasPlots[k] = true;
    const SeamReport& r = *s.report;
    std::vector<double> t, y0, y1, y2;
    for (const SeamSample& x : r.samples) {
      t.push_back(x.t);
      y0.push_back(x.g0);
      y1.push_back(x.g1Deg);
      y2.push_back(x.g2Rel);
    }
    h += fmt::format("<div class=\"seam\" id=\"seam-{}\"><b>#{} {}{} / {}{}</b> &mdash; <span class=\"c{}\">{}</span>, "
                     "{}{}<br>",
                     k, k, escape(s.a), s.aEdge.empty() ? "" : ":" + escape(s.aEdge), escape(s.b),
                     s.bEdge.empty() ? "" : ":" + escape(s.bEdge), static_cast<int>(r.geometric),
                     toString(r.geometric), toString(r.parametric), r.certified ? ", certified" : ", sampled");
    h += plot(t, y0, tol.distance, "G0 gap", options.plotWidth, options.plotHeight,
              {r.g0Worst.t, r.g0Sampled, r.g0Max});
    h += plot(t, y1, tol.angleDeg, "G1 angle (degrees)", options.plotWidth, options.plotHeight,
              {r.g1Worst.t, r.g1SampledDeg, r.g1MaxDeg});
    h += plot(t, y2, tol.curvatureRel, "G2 jump (relative)", options.plotWidth, options.plotHeight,
              {r.g2Worst.t, r.g2RelSampled, r.g2RelMax});
    h += "</div>\n";
  }

  // ---- corners, free and degenerate edges
  h += fmt::format("<h2 id=\"corners\">Corners ({})</h2>\n", data.corners.size());
  h += "<table class=\"sortable\"><thead><tr><th class=\"l\">point</th><th>valence</th><th class=\"l\">patches</th>"
       "<th>normal spread (&deg;)</th><th>curvature spread (%)</th><th>G1 residual</th><th>G2 residual</th></tr>"
       "</thead><tbody>\n";
  for (size_t k = 0; k < data.corners.size(); ++k) {
    const CornerReport& r = *data.corners[k];
    h += fmt::format("<tr><td class=\"l\">[{}, {}, {}]</td><td>{}</td><td class=\"l\">{}</td><td>{}</td><td>{}</td>"
                     "<td>{}</td><td>{}</td></tr>\n",
                     num(r.point.x()), num(r.point.y()), num(r.point.z()), r.valence,
                     escape(k < data.cornerPatchNames.size() ? data.cornerPatchNames[k] : ""),
                     r.normalSpreadDeg ? num(*r.normalSpreadDeg) : (r.degenerate ? "degenerate" : "-"),
                     r.curvatureSpreadRel ? num(100.0 * *r.curvatureSpreadRel) : "-",
                     r.fourPatch ? num(r.fourPatch->g1Residual) : "-",
                     r.fourPatch && r.fourPatch->g2Residual ? num(*r.fourPatch->g2Residual) : "-");
  }
  h += "</tbody></table>\n";
  h += fmt::format("<h2 id=\"free\">Free edges ({})</h2>\n<p>", data.freeEdges.size());
  for (const std::string& f : data.freeEdges) h += escape(f) + " &nbsp; ";
  h += "</p>\n";
  h += fmt::format("<h2 id=\"degenerate\">Degenerate edges ({})</h2>\n<p>", data.degenerateEdges.size());
  for (const std::string& f : data.degenerateEdges) h += escape(f) + " &nbsp; ";
  h += "</p>\n";
  h += fmt::format("<script>{}</script>\n", kScript);
  if (view3d) {
    h += "<script id=\"seam-view-data\" type=\"application/json\">";
    h += viewData(data, reports, hasPlots, labels, sel.creaseAngleDeg, options.maxSpikeSamples);
    h += "</script>\n<script>";
    h += detail::kViewerJs;
    h += "</script>\n";
  }
  h += "</body></html>\n";
  return h;
}

Result<std::string> objMesh(const Model& model, const MeshOptions& options) {
  if (options.samplesPerSpan < 1 || options.maxSamplesPerPatch < 1)
    return invalidInput("mesh: samplesPerSpan and maxSamplesPerPatch must be at least 1");
  std::string out = "# seam mesh: one object per patch, per-vertex unit normals\n";
  long base = 1;
  for (const Patch& p : model.patches) {
    const BSplineSurface& s = p.surface;
    if (s.dim() != 3) return invalidInput(fmt::format("mesh: patch \"{}\" is not 3-D", p.name));
    const auto [nu, nv] = gridSize(s, options.samplesPerSpan, options.maxSamplesPerPatch, 1);
    out += fmt::format("o {}\n", p.name);
    std::string normals;
    for (int i = 0; i <= nu; ++i)
      for (int j = 0; j <= nv; ++j) {
        Vec3 pt, n;
        gridNode(s, i, j, nu, nv, pt, n);
        out += fmt::format("v {:.17g} {:.17g} {:.17g}\n", pt.x(), pt.y(), pt.z());
        normals += fmt::format("vn {:.9g} {:.9g} {:.9g}\n", n.x(), n.y(), n.z());
      }
    out += normals;
    auto id = [&, rowLength = nv + 1](int i, int j) { return base + static_cast<long>(i) * rowLength + j; };
    for (int i = 0; i < nu; ++i)
      for (int j = 0; j < nv; ++j) {
        const long a = id(i, j), b = id(i + 1, j), c = id(i + 1, j + 1), d = id(i, j + 1);
        out += fmt::format("f {0}//{0} {1}//{1} {2}//{2}\nf {0}//{0} {2}//{2} {3}//{3}\n", a, b, c, d);
      }
    base += static_cast<long>(nu + 1) * (nv + 1);
  }
  return out;
}

void scaleGeometry(ReportData& d, double scale) {
  for (ReportSeam& s : d.seams)
    for (Vec3& p : s.curve) p *= scale;
  for (std::vector<std::vector<Vec3>>* curves : {&d.outline, &d.freeEdgeCurves})
    for (std::vector<Vec3>& c : *curves)
      for (Vec3& p : c) p *= scale;
  for (ReportMesh& m : d.meshes)
    for (Vec3& p : m.points) p *= scale;
}

void scaleLengths(ReportData& d, double scale) {
  scaleGeometry(d, scale);
  d.tolerances.distance *= scale;
  for (ReportSeam& s : d.seams)
    if (s.report) scaleLengths(*s.report, scale);
  std::vector<CornerReport> owned;
  owned.reserve(d.corners.size());
  for (const CornerReport* c : d.corners) {
    owned.push_back(*c);
    scaleLengths(owned.back(), scale);
  }
  d.ownedCorners = std::move(owned);
  for (size_t k = 0; k < d.corners.size(); ++k) d.corners[k] = &d.ownedCorners[k];
}

}  // namespace seam::report
