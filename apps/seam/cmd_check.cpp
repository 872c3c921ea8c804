// seam check FILE [--seam A:ea B:eb] [--tol-distance D] [--tol-angle DEG] [--tol-curvature K]
//                  [--crease-angle DEG] [--sort angle|gap|curvature] [--top N] [--only problems]
//                  [--require G0|G1|G2] [--json]
// Continuity of every seam of a model (or of one pair of edges), its vertices and its free edges. Each seam gets a
// verdict a CAD user reads (continuity/verdict.h: gap, kink, crease, G1, G2); design creases (angle at or above
// --crease-angle) are listed apart from the other seams, and the summary names the worst kink and the worst gap.
// Exit codes: 0 ok, 1 --require given and some seam is below it, 2 bad usage or input.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "check_json.h"
#include "cli_util.h"
#include "command_registry.h"
#ifdef SEAM_HAVE_OCCT
#include "seam/occt/brep_check.h"
#include "seam/occt/brep_model.h"
#endif
#include "seam/continuity/model_check.h"
#include "seam/continuity/seam.h"
#include "seam/continuity/verdict.h"

namespace seam::cli {

namespace {

struct CheckOptions {
  std::string file;
  std::vector<std::string> seam;
  ToleranceOverrides tol;
  std::string require;
  bool json = false;
  bool patches = false;  // STEP/IGES: check the faces' patches instead of the B-rep edges
  std::optional<double> creaseAngle;
  std::string sort;  // "" = verdict for the tables, file for --json
  std::optional<size_t> top;
  std::string only;  // "" (all), problems, gaps, kinks, creases
  std::optional<int> threads;  // --threads: 0 = all hardware threads; unset = each check's own default
};

/// Largest --threads accepted (more than any machine seam runs on; a typo such as 1e9 is refused, not obeyed).
constexpr int kMaxCliThreads = 1024;

/// The listing choices (--crease-angle, --sort, --top, --only); nullopt (with the message on stderr) when one is
/// wrong.
std::optional<SeamSelection> parseSelection(const CheckOptions& o) {
  SeamSelection sel;
  if (o.creaseAngle) {
    if (!validCreaseAngle(*o.creaseAngle)) {
      printError("--crease-angle must be an angle in degrees in (0, 180]");
      return std::nullopt;
    }
    sel.creaseAngleDeg = *o.creaseAngle;
  }
  const Result<SeamSortKey> key = parseSeamSortKey(o.sort.empty() ? (o.json ? "file" : "verdict") : o.sort);
  if (!key) {
    printError("--sort: " + key.status().message());
    return std::nullopt;
  }
  sel.sort = *key;
  if (!o.only.empty()) {
    const Result<SeamFilter> only = parseSeamFilter(o.only);
    if (!only) {
      printError("--only: " + only.status().message());
      return std::nullopt;
    }
    sel.only = *only;
  }
  sel.top = o.top;
  return sel;
}

/// The listing of a check in text: the seams that are not design creases (gaps and kinks first when sorted), then
/// the creases apart. Each list is sorted, filtered (--only problems drops G1/G2 rows and the creases) and cut to
/// --top on its own. `reports[k]` is null for a seam whose analysis failed (listed with the others).
struct SeamListing {
  std::vector<size_t> main, creases;
  size_t mainAll = 0, creasesAll = 0;  ///< before --only / --top
};

SeamListing listSeams(const std::vector<const SeamReport*>& reports, const SeamSelection& sel) {
  SeamSelection order = sel;
  order.only = SeamFilter::kAll;
  order.top.reset();
  SeamListing l;
  for (size_t k : selectSeams(reports, order)) {
    const bool crease = reports[k] && seamVerdict(*reports[k], sel.creaseAngleDeg) == SeamVerdict::kCrease;
    if (crease) {
      ++l.creasesAll;
      if (passes(sel.only, reports[k], sel.creaseAngleDeg)) l.creases.push_back(k);
    } else {
      ++l.mainAll;
      if (passes(sel.only, reports[k], sel.creaseAngleDeg)) l.main.push_back(k);
    }
  }
  if (sel.top) {
    if (l.main.size() > *sel.top) l.main.resize(*sel.top);
    if (l.creases.size() > *sel.top) l.creases.resize(*sel.top);
  }
  return l;
}

/// "(showing 10 of 48, by angle; problems only)" when the listing is cut or filtered, else "".
std::string shownNote(size_t shown, size_t all, const SeamSelection& sel) {
  if (shown == all && sel.sort == SeamSortKey::kFile) return "";
  std::string note = shown == all ? "" : fmt::format("showing {} of {}", shown, all);
  if (sel.sort == SeamSortKey::kVerdict)
    note += fmt::format("{}kinks first, then gaps", note.empty() ? "" : ", ");
  else if (sel.sort != SeamSortKey::kFile)
    note += fmt::format("{}largest {} first", note.empty() ? "" : ", ",
                        sel.sort == SeamSortKey::kAngle ? "angle"
                        : sel.sort == SeamSortKey::kGap ? "gap"
                                                        : "relative curvature jump");
  if (sel.only != SeamFilter::kAll) note += fmt::format("{}only {}", note.empty() ? "" : ", ", toString(sel.only));
  return " (" + note + ")";
}

/// The heading note of the design creases' list: ": not listed (--only kinks)" when the filter leaves them out.
std::string creasesNote(const SeamListing& l, const SeamSelection& sel) {
  if (sel.only != SeamFilter::kAll && sel.only != SeamFilter::kCreases)
    return fmt::format(": not listed (--only {})", toString(sel.only));
  return shownNote(l.creases.size(), l.creasesAll, sel);
}

/// "verdicts: gap 1, kink 4, crease 160 (angle >= 20 deg, left as designed), G1 0, G2 43".
std::string verdictLine(const std::array<int, kSeamVerdictCount>& n, double creaseAngleDeg) {
  return fmt::format("verdicts: gap {}, kink {}, crease {} (angle >= {} deg, left as designed), G1 {}, G2 {}{}\n",
                     n[0], n[1], n[2], formatNumber(creaseAngleDeg), n[3], n[4],
                     n[5] ? fmt::format(", undetermined {} (a normal vanishes: G1 measured, not proved)", n[5]) : "");
}

std::optional<GeometricClass> parseClass(const std::string& s) {
  if (s == "G0") return GeometricClass::kG0;
  if (s == "G1") return GeometricClass::kG1;
  if (s == "G2") return GeometricClass::kG2;
  return std::nullopt;
}

const std::string& patchName(const Model& m, int index) { return m.patches[static_cast<size_t>(index)].name; }

std::string num(double x) { return formatNumber(x); }

std::string seamName(const Model& m, const ModelSeam& s) {
  return fmt::format("{}:{} / {}:{}", patchName(m, s.pair.a.patch), edgeName(s.pair.a.edge),
                     patchName(m, s.pair.b.patch), edgeName(s.pair.b.edge));
}

/// The worst kink and the worst gap with their location (issue 17: what a CAD user looks at first).
std::string worstLines(const std::vector<const SeamReport*>& reports, double creaseAngleDeg, const ModelUnits& units,
                       const std::function<std::string(size_t)>& name) {
  const WorstDefects w = worstDefects(reports, creaseAngleDeg);
  std::string out;
  if (w.kink) {
    const SeamReport& x = *reports[*w.kink];
    out += fmt::format("worst kink: {}, angle {} deg at {} (gap {})\n", name(*w.kink), formatNumber(x.g1MaxDeg),
                       formatVector(x.g1Worst.point.data(), 3), withUnit(formatNumber(x.g0Max), units));
  } else {
    out += "worst kink: none\n";
  }
  if (w.gap) {
    const SeamReport& x = *reports[*w.gap];
    out += fmt::format("worst gap: {}, gap {} at {} (angle {} deg)\n", name(*w.gap),
                       withUnit(formatNumber(x.g0Max), units), formatVector(x.g0Worst.point.data(), 3),
                       formatNumber(x.g1MaxDeg));
  } else {
    out += "worst gap: none\n";
  }
  return out;
}

/// The curvature jump as a CAD user reads it (Rhino's EdgeContinuity style, issue 17 §2): relative to the larger
/// curvature on the seam, in %, with the absolute jump (1 / model length unit) beside it. A seam whose angle reaches
/// the crease angle has no common tangent plane, where a curvature jump is not defined (the two shape operators
/// live in different planes): "n/a (crease angle)" instead of a number (issue 35 §2: a 180° fold printed a jump of
/// 1.36e6). The JSON keeps the number measured.
std::string formatCurvatureJump(const SeamReport& x, double creaseAngleDeg) {
  if (x.g1MaxDeg >= creaseAngleDeg) return "n/a (crease angle)";
  if (!std::isfinite(x.g2RelMax) || !std::isfinite(x.g2Max)) return formatNumber(x.g2Max);
  return fmt::format("{}% ({})", formatNumber(100.0 * x.g2RelMax), formatNumber(x.g2Max));
}

/// "G0 gap (mm)", or "G0 gap" for a unit-less model.
std::string gapHeader(const ModelUnits& units) {
  return units.length ? fmt::format("G0 gap ({})", units.name()) : "G0 gap";
}

/// "G2 jump % (abs, 1/mm)": the absolute jump is a curvature, in 1 / the model's unit (issue 38 goal 7).
std::string jumpHeader(const ModelUnits& units) {
  return units.length ? fmt::format("G2 jump % (abs, 1/{})", units.name()) : "G2 jump % (abs)";
}

std::string seamTable(const Model& m, const ModelCheckReport& r, const SeamSelection& sel, const ModelUnits& units) {
  const std::vector<const SeamReport*> reports = reportsOf(r);
  const SeamListing l = listSeams(reports, sel);
  auto rowOf = [&](size_t k) {
    const ModelSeam& s = r.seams[k];
    const EdgePair& p = s.pair;
    std::vector<std::string> row{patchName(m, p.a.patch), std::string(edgeName(p.a.edge)), patchName(m, p.b.patch),
                                 std::string(edgeName(p.b.edge))};
    if (s.report) {
      const SeamReport& x = *s.report;
      row.insert(row.end(), {std::string(toString(seamVerdict(x, sel.creaseAngleDeg))),
                             formatNumber(x.g0Max), formatNumber(x.g1MaxDeg),
                             formatCurvatureJump(x, sel.creaseAngleDeg), std::string(toString(x.geometric)),
                             std::string(toString(x.parametric)), x.certified ? "yes" : "no"});
    } else {
      row.insert(row.end(), {"error", "-", "-", "-", "error", "-", "-"});
    }
    if (!(p.fullA && p.fullB)) row.push_back(fmt::format("partial [{}, {}]", num(p.overlapA.lo), num(p.overlapA.hi)));
    else row.emplace_back("");
    return row;
  };
  const std::vector<std::string> header{"A",         "edge",      "B",         "edge",          "verdict",
                                        gapHeader(units), "G1 angle (deg)",   jumpHeader(units), "geometric",
                                        "parametric", "certified", "overlap"};
  const std::vector<bool> right{false, false, false, false, false, true, true, true, false, false, false, false};
  auto table = [&](const std::vector<size_t>& list) {
    std::vector<std::vector<std::string>> rows;
    for (size_t k : list) rows.push_back(rowOf(k));
    return rows.empty() ? std::string() : formatTable(header, rows, right);
  };
  std::string out = fmt::format("seams ({}){}\n", r.seams.size(),
                                l.creasesAll > 0 ? fmt::format(", design creases listed apart below") : "");
  if (l.mainAll != l.main.size() || sel.sort != SeamSortKey::kFile)
    out += fmt::format("other seams{}\n", shownNote(l.main.size(), l.mainAll, sel));
  out += table(l.main);
  if (l.creasesAll > 0) {
    out += fmt::format("\ndesign creases ({}, angle >= {} deg, left as designed){}\n", l.creasesAll,
                       num(sel.creaseAngleDeg),
                       creasesNote(l, sel));
    out += table(l.creases);
  }
  for (const ModelSeam& s : r.seams)
    if (!s.report) out += fmt::format("  {}: {}\n", seamName(m, s), s.error.message());
  return out;
}

std::string cornerTable(const Model& m, const ModelCheckReport& r) {
  std::vector<std::vector<std::string>> rows;
  for (const ModelCorner& c : r.corners) {
    const CornerReport& x = c.report;
    std::string names;
    for (const PatchCorner& k : x.corners) names += (names.empty() ? "" : " ") + patchName(m, k.patch);
    rows.push_back({formatVector(x.point.data(), 3), std::to_string(x.valence) + (x.closed ? "" : " (boundary)"),
                    names, x.normalSpreadDeg ? formatNumber(*x.normalSpreadDeg) : (x.degenerate ? "degenerate" : "-"),
                    x.curvatureSpreadRel ? num(100.0 * *x.curvatureSpreadRel) : "-",
                    x.fourPatch ? num(x.fourPatch->g1Residual) : "-",
                    x.fourPatch && x.fourPatch->g2Residual ? num(*x.fourPatch->g2Residual) : "-"});
  }
  std::string out = fmt::format("\ncorners ({})\n", r.corners.size());
  if (!rows.empty())
    out += formatTable({"point", "valence", "patches", "normal spread (deg)", "curvature spread (%)", "G1 residual",
                        "G2 residual"},
                       rows, {false, false, false, true, true, true, true});
  return out;
}

std::string edgeLists(const Model& m, const ModelCheckReport& r) {
  std::string out = fmt::format("\nfree edges ({})\n", r.freeEdges.size());
  for (const FreeEdge& f : r.freeEdges) {
    out += fmt::format("  {}:{}", patchName(m, f.edge.patch), edgeName(f.edge.edge));
    if (f.partial) out += fmt::format(" [{}, {}]", num(f.range.lo), num(f.range.hi));
    out += "\n";
  }
  out += fmt::format("\ndegenerate edges ({})\n", r.degenerateEdges.size());
  for (const DegenerateEdge& d : r.degenerateEdges)
    out += fmt::format("  {}:{} at {}\n", patchName(m, d.edge.patch), edgeName(d.edge.edge),
                       formatVector(d.point.data(), 3));
  if (!r.overlapsSearched && (m.trimmedFaces > 0 || m.brep))
    out += "\noverlapping faces: not searched (the trimmed faces are analysed as the patches of their parameter "
           "boxes, and faces trimmed from one surface would overlap as patches; without --patches the B-rep check "
           "searches them inside their trims)\n";
  if (!r.overlaps.empty()) {  // faces lying on each other: listed only when there are some
    out += fmt::format("\noverlapping faces ({} pair{}: the patches lie on each other within the distance tolerance; "
                       "share of the samples of one on the other, the largest distance among them, and one such "
                       "point)\n",
                       r.overlaps.size(), r.overlaps.size() == 1 ? "" : "s");
    for (const FaceOverlap& o : r.overlaps)
      out += fmt::format("  {} / {}: {} %, within {} at {}\n", patchName(m, o.a), patchName(m, o.b),
                         num(100.0 * o.fraction), num(o.maxDistance), formatVector(o.point.data(), 3));
  }
  if (!r.coincidentEdges.empty()) {  // duplicated faces: listed only when there are some
    constexpr size_t kNamesShown = 8;  // per group; a group can hold thousands of edges
    out += fmt::format("\ncoincident edges / duplicated faces ({} groups; only the first two edges of each are "
                       "paired)\n",
                       r.coincidentEdges.size());
    for (const CoincidentEdges& c : r.coincidentEdges) {
      out += fmt::format("  {} edges at {}:", c.edges.size(), formatVector(c.point.data(), 3));
      for (size_t k = 0; k < std::min(c.edges.size(), kNamesShown); ++k)
        out += fmt::format(" {}:{}", patchName(m, c.edges[k].patch), edgeName(c.edges[k].edge));
      if (c.edges.size() > kNamesShown) out += fmt::format(" ... and {} more", c.edges.size() - kNamesShown);
      out += "\n";
    }
  }
  return out;
}

std::string summaryLine(const Model& m, const ModelCheckReport& r, const std::optional<GeometricClass>& require,
                        double creaseAngleDeg, const ModelUnits& units) {
  const ModelCheckSummary& s = r.summary;
  std::string line = fmt::format(
      "\nsummary: {} seams (G2 {}, G1 {}, G0 {}, none {}; {} certified{}), worst {} / {}, max gap {}, max angle {} "
      "deg, max G2 jump {}; {} corners ({} 4-valent, {} degenerate), {} free edges, {} degenerate edges",
      s.seams, s.geometric[3], s.geometric[2], s.geometric[1], s.geometric[0], s.certifiedSeams,
      s.failedSeams > 0 ? fmt::format(", {} failed", s.failedSeams) : "", toString(s.worstGeometric),
      toString(s.worstParametric), withUnit(num(s.g0Max), units), num(s.g1MaxDeg), num(s.g2Max), s.corners,
      s.fourValentCorners,
      s.degenerateCorners, s.freeEdges, s.degenerateEdges);
  if (s.overlaps > 0) line += fmt::format(", {} overlapping face pair{}", s.overlaps, s.overlaps == 1 ? "" : "s");
  if (require)
    line += s.belowRequired > 0 ? fmt::format("; {} below {}", s.belowRequired, toString(*require))
                                : fmt::format("; all meet {}", toString(*require));
  const std::vector<const SeamReport*> reports = reportsOf(r);
  return line + "\n" + verdictLine(countVerdicts(reports, creaseAngleDeg), creaseAngleDeg) +
         worstLines(reports, creaseAngleDeg, units,
                    [&](size_t k) { return seamName(m, r.seams[k]); });
}

/// "NAME:edge" -> patch index and edge; prints the problem and returns nullopt when it is wrong.
std::optional<EdgeRef> parseSeamSide(const Model& m, const std::string& file, const std::string& text) {
  const size_t colon = text.rfind(':');
  if (colon == std::string::npos) {
    printError(fmt::format("--seam: \"{}\" is not NAME:EDGE (EDGE one of u0, u1, v0, v1)", text));
    return std::nullopt;
  }
  const std::string name = text.substr(0, colon);
  const Result<Edge> edge = parseEdge(text.substr(colon + 1));
  if (!edge) {
    printError(fmt::format("--seam: \"{}\": {}", text, edge.status().message()));
    return std::nullopt;
  }
  for (size_t k = 0; k < m.patches.size(); ++k)
    if (m.patches[k].name == name) return EdgeRef{static_cast<int>(k), *edge};
  printError(fmt::format("{}: no patch named \"{}\"", file, name));
  return std::nullopt;
}

/// The reader's warnings at the end of the table output (also on stderr as they happen): a partly read file must
/// not look complete. "" when there are none.
std::string warningLines(const std::vector<std::string>& warnings) {
  if (warnings.empty()) return "";
  std::string out = fmt::format("\nreader warnings ({}): the results are for what was read\n", warnings.size());
  for (const std::string& w : warnings) out += "  " + w + "\n";
  return out;
}

#ifdef SEAM_HAVE_OCCT
/// STEP/IGES: every edge shared by two faces of the (sewn) B-rep, with OpenCASCADE's verdict next to seam's.
/// `model`: a JSON model with its B-rep topology (Model::brep), checked as the shape made from it; else
/// o.file is read.
int runBRepCheck(const CheckOptions& o, const std::optional<GeometricClass>& require,
                 const SeamSelection& sel, const Model* model = nullptr) {
  occt::BRepCheckOptions bo;
  bo.tolerances = o.tol;
  if (o.threads) bo.threads = *o.threads;
  bo.findOverlaps = true;  // as for a patch model (faces lying on each other, inside their trims)
  bo.progress = brepProgressPrinter(o.file);
  Result<occt::BRepCheckReport> r = [&] {
    const CadTimeLimit limit(o.file, "reading and checking");
    return model != nullptr ? occt::checkBRepModel(*model, o.file, bo) : occt::checkBRepFile(o.file, bo);
  }();
  if (!r) {
    printError(r.status().message());
    return kExitBadInput;
  }
  occt::toShownUnits(*r);  // lengths in the file's own unit, or --display-units (issue 38 §1)
  for (const std::string& w : r->import.warnings) std::cerr << "seam: warning: " << w << "\n";
  int below = 0;
  for (const occt::BRepSeam& s : r->seams)
    if (require && s.report.geometric < *require) ++below;
  const Tolerances& tol = r->tolerances;
  std::vector<const SeamReport*> reports;
  for (const occt::BRepSeam& s : r->seams) reports.push_back(&s.report);
  const std::array<int, kSeamVerdictCount> verdicts = countVerdicts(reports, sel.creaseAngleDeg);
  if (o.json) {
    // Streamed (the same bytes as jsonText(withInputFile(file, brepCheckJson(...))), without the document).
    writeBRepCheckJson(std::cout, o.file, *r, selectSeams(reports, sel), require, sel.creaseAngleDeg);
  } else {
    fmt::print("{}: B-rep of {} faces{}; {}\n", o.file, r->import.faces.size(), r->sewn ? " (sewn)" : "",
               unitLine(r->units, {tol, r->distanceSource, r->angleSource, o.tol.preset}, sel.creaseAngleDeg));
    const SeamListing l = listSeams(reports, sel);
    // A face as "F12 #1283" where the file names its entity (docs/check-output.md).
    std::map<std::string, std::string> entityOf;
    for (const occt::CadFace& f : r->import.faces)
      if (!f.entity.empty()) entityOf[f.patch] = f.entity;
    auto face = [&](const std::string& patch) {
      const auto it = entityOf.find(patch);
      return it == entityOf.end() ? patch : patch + " " + it->second;
    };
    auto table = [&](const std::vector<size_t>& list) {
      std::vector<std::vector<std::string>> rows;
      for (size_t k : list) {
        const occt::BRepSeam& s = r->seams[k];
        rows.push_back({std::to_string(s.edge), face(s.a), face(s.b), std::string(toString(seamVerdict(s.report, sel.creaseAngleDeg))),
                        formatNumber(s.report.g0Max), formatNumber(s.report.g1MaxDeg),
                        formatCurvatureJump(s.report, sel.creaseAngleDeg),
                        std::string(toString(s.report.geometric)), s.report.certified ? "yes" : "no",
                        s.occtContinuity});
      }
      return rows.empty() ? std::string()
                          : formatTable({"edge", "A", "B", "verdict", gapHeader(r->units), "G1 angle (deg)",
                                         jumpHeader(r->units),
                                         "geometric", "certified", "OCCT"},
                                        rows, {false, false, false, false, true, true, true, false, false, false});
    };
    fmt::print("seams ({}){}\n", r->seams.size(), l.creasesAll > 0 ? ", design creases listed apart below" : "");
    if (l.mainAll != l.main.size() || sel.sort != SeamSortKey::kFile)
      fmt::print("other seams{}\n", shownNote(l.main.size(), l.mainAll, sel));
    fmt::print("{}", table(l.main));
    if (l.creasesAll > 0) {
      fmt::print("\ndesign creases ({}, angle >= {} deg, left as designed){}\n{}", l.creasesAll,
                 formatNumber(sel.creaseAngleDeg),
                 creasesNote(l, sel),
                 table(l.creases));
    }
    // One spelling of an edge everywhere (issue 38 §7): "edge N", its face beside it.
    fmt::print("\nfree edges ({}):", r->freeEdges.size());
    for (size_t k = 0; k < r->freeEdges.size(); ++k)
      fmt::print("{} edge {} ({})", k ? "," : "", r->freeEdges[k].edge, r->freeEdges[k].face);
    fmt::print("\nnon-manifold edges ({}):", r->nonManifoldEdges.size());
    for (size_t k = 0; k < r->nonManifoldEdges.size(); ++k)
      fmt::print("{} edge {}", k ? "," : "", r->nonManifoldEdges[k].edge);
    fmt::print("\n");
    if (!r->overlaps.empty()) {  // faces lying on each other: listed only when there are some
      fmt::print("\noverlapping faces ({} pair{}: the faces lie on each other within the distance tolerance, inside "
                 "both faces' trims; share of the samples of one on the other, the largest distance among them, and "
                 "one such point)\n",
                 r->overlaps.size(), r->overlaps.size() == 1 ? "" : "s");
      for (size_t k = 0; k < r->overlaps.size(); ++k) {
        const FaceOverlap& v = r->overlaps[k];
        const auto [sa, sb] = r->overlapSolids[k];
        fmt::print("  {} / {}: {} %, within {} at {}{}\n", face(fmt::format("F{}", v.a + 1)),
                   face(fmt::format("F{}", v.b + 1)), num(100.0 * v.fraction), num(v.maxDistance),
                   formatVector(v.point.data(), 3),
                   sa > 0 && sb > 0 && sa != sb ? fmt::format(" (solids {} and {} in contact)", sa, sb) : "");
      }
    }
    if (r->overlapFacesSkipped > 0)
      fmt::print("\noverlapping faces: {} face{} not searched (the trims enclose an area the samples cannot read: a "
                 "face of zero area or a sliver)\n",
                 r->overlapFacesSkipped, r->overlapFacesSkipped == 1 ? "" : "s");
    double maxGap = 0.0;
    for (const occt::BRepSeam& s : r->seams) maxGap = std::max(maxGap, s.report.g0Max);
    fmt::print("\nsummary: {} seams (G2 {}, G1 {}, G0 {}, none {}; {} certified), worst {}, max gap {}; {} free "
               "edges, {} non-manifold, {} degenerate, {} loose (bound no face){}; OpenCASCADE agrees on G1-or-not "
               "for {} of {}\n",
               r->seams.size(), r->geometric[3], r->geometric[2], r->geometric[1], r->geometric[0], r->certifiedSeams,
               toString(r->worstGeometric), withUnit(formatNumber(maxGap), r->units), r->freeEdges.size(), r->nonManifoldEdges.size(), r->degenerateEdges,
               r->looseEdges,
               r->overlaps.empty() ? std::string()
                                   : fmt::format(", {} overlapping face pair{}", r->overlaps.size(),
                                                 r->overlaps.size() == 1 ? "" : "s"),
               r->occtAgreement, r->seams.size());
    fmt::print("{}{}", verdictLine(verdicts, sel.creaseAngleDeg),
               worstLines(reports, sel.creaseAngleDeg, r->units, [&](size_t k) {
                 const occt::BRepSeam& s = r->seams[k];
                 return fmt::format("edge {} ({} / {})", s.edge, face(s.a), face(s.b));
               }));
    fmt::print("{}", warningLines(r->import.warnings));
  }
  return require && below > 0 ? kExitGeometryProblem : kExitOk;
}
#endif

int runCheck(const CheckOptions& o) {
  std::optional<GeometricClass> require;
  if (!o.require.empty()) {
    require = parseClass(o.require);
    if (!require) {
      printError(fmt::format("--require: \"{}\" is not G0, G1 or G2", o.require));
      return kExitBadInput;
    }
  }
  if (!validToleranceOptions(o.tol)) return kExitBadInput;
  if (o.threads && (*o.threads < 0 || *o.threads > kMaxCliThreads)) {
    printError(fmt::format("--threads must be 0 (all hardware threads) or a count from 1 to {}", kMaxCliThreads));
    return kExitBadInput;
  }
  const std::optional<SeamSelection> sel = parseSelection(o);
  if (!sel) return kExitBadInput;
#ifdef SEAM_HAVE_OCCT
  if (isCadFile(o.file) && !checkInputPath(o.file)) return kExitBadInput;  // a directory, FIFO, device: not OCCT's
  if (isCadFile(o.file) && !o.patches && o.seam.empty()) return runBRepCheck(o, require, *sel);
#endif
  ModelUnits units;
  std::vector<std::string> warnings;  // a STEP/IGES file read as patches: the reader's (also on stderr)
  const std::optional<Model> model = loadModel(o.file, o.tol, &units, &warnings);
  if (!model || !displayUnitsApply(o.file, units)) return kExitBadInput;
#ifdef SEAM_HAVE_OCCT
  // A JSON model with its trims (docs/format.md "brep"): checked as a B-rep, like the STEP/IGES it came from.
  if (model->brep && !o.patches && o.seam.empty()) return runBRepCheck(o, require, *sel, &*model);
#endif
  if (model->patches.empty()) {  // only curves, or "patches": []: as `report` and `heal` (issue 15)
    const std::string note = fmt::format("{}: the model has no patches: nothing to check", o.file);
    OrderedJson none = noPatchesJson(o.file, units.shown());
    none["warnings"] = warnings;
    if (o.json)
      printJson(withInputFile(o.file, std::move(none)));
    else
      fmt::print("{}\n", note);
    return kExitOk;
  }
  const ResolvedTolerances resolved = resolveTolerances(o.tol, units, model->boundingBox().diagonal());
  const Tolerances tol = resolved.tolerances;

  ModelCheckReport report;
  std::optional<double> pairing;
  if (!o.seam.empty()) {
    const std::optional<EdgeRef> a = parseSeamSide(*model, o.file, o.seam[0]);
    if (!a) return kExitBadInput;
    const std::optional<EdgeRef> b = parseSeamSide(*model, o.file, o.seam[1]);
    if (!b) return kExitBadInput;
    SeamOptions so;
    so.tol = tol;
    Result<SeamReport> r = analyzeSeam(model->patches[static_cast<size_t>(a->patch)], a->edge,
                                       model->patches[static_cast<size_t>(b->patch)], b->edge, so);
    if (!r) {
      printError(fmt::format("{}: seam {} - {}: {}", o.file, o.seam[0], o.seam[1], r.status().message()));
      return kExitBadInput;
    }
    report.tolerances = tol;
    ModelSeam ms;
    ms.pair.a = *a;
    ms.pair.b = *b;
    ms.pair.overlapA = r->overlapA;
    ms.pair.overlapB = r->overlapB;
    ms.pair.reversed = r->reversed;
    ms.report = std::move(r).value();
    report.seams.push_back(std::move(ms));
    ModelCheckSummary& s = report.summary;
    const SeamReport& x = *report.seams[0].report;
    s.seams = 1;
    ++s.geometric[static_cast<size_t>(x.geometric)];
    ++s.parametric[static_cast<size_t>(x.parametric)];
    s.certifiedSeams = x.certified ? 1 : 0;
    s.worstGeometric = x.geometric;
    s.worstParametric = x.parametric;
    s.g0Max = x.g0Max, s.g1MaxDeg = x.g1MaxDeg, s.g2Max = x.g2Max, s.g2RelMax = x.g2RelMax;
    s.g0Seam = s.g1Seam = s.g2Seam = 0;
    if (require && !meets(x.geometric, *require)) s.belowRequired = 1;
  } else {
    ModelCheckOptions mo;
    mo.tolerances = tol;
    if (o.threads) mo.threads = *o.threads;
    mo.require = require;
    mo.findOverlaps = true;
    if (model->patches.size() > kProgressPatches)
      std::cerr << fmt::format("seam: checking {} patches (pairing, seams in parallel, corners)...\n",
                               model->patches.size());
    Result<ModelCheckReport> r = checkModel(*model, mo);
    if (!r) {
      printError(fmt::format("{}: {}", o.file, r.status().message()));
      return kExitBadInput;
    }
    report = std::move(r).value();
    pairing = report.pairingTolerance;
  }
  // Every length in the shown unit (issue 38 §1: --display-units; the model's unit without it).
  const double scale = units.displayScale();
  ResolvedTolerances shownTol = resolved;
  if (scale != 1.0) {
    scaleLengths(report, scale);
    shownTol.tolerances.distance *= scale;
    if (pairing) *pairing *= scale;
  }
  units = units.shown();

  if (o.json) {
    // Streamed record by record (the DOM of a 10 000-patch check took ~300 MB and 3 s); the same bytes as
    // jsonText(withInputFile(file, modelCheckJson(...))), which the Python module returns as a dict.
    writeModelCheckJson(std::cout, o.file, *model, report, selectSeams(reportsOf(report), *sel), require, pairing,
                        sel->creaseAngleDeg, units, resolved.distanceSource, warnings, resolved.angleSource);
  } else {
    std::string out = fmt::format("{}: {}\n", o.file, unitLine(units, shownTol, sel->creaseAngleDeg, pairing));
    out += seamTable(*model, report, *sel, units);
    if (o.seam.empty()) out += cornerTable(*model, report) + edgeLists(*model, report);
    out += summaryLine(*model, report, require, sel->creaseAngleDeg, units);
    out += warningLines(warnings);
    fmt::print("{}", out);
  }
  return require && report.summary.belowRequired > 0 ? kExitGeometryProblem : kExitOk;
}

void addCheck(CLI::App& app, int& exit) {
  auto options = std::make_shared<CheckOptions>();
  CLI::App* cmd = app.add_subcommand("check", "Continuity of every seam, vertex and free edge of a model");
  cmd->add_option("FILE", options->file, modelFileHelp())->required();
  cmd->add_option("--seam", options->seam, "Analyse only this pair of edges, e.g. --seam S1:u1 S2:u0")
      ->expected(2)
      ->type_name("A:EDGE B:EDGE");
  addToleranceOptions(*cmd, options->tol);
  addDisplayUnitsOption(*cmd, options->tol);
  cmd->add_option("--crease-angle", options->creaseAngle,
                  "Seams whose angle is at or above this (degrees, in (0, 180]) are design creases, listed apart from "
                  "the gaps and kinks (default 20)");
  cmd->add_option("--sort", options->sort,
                  "Order of the seam lists: verdict (kinks, then gaps, then the rest; the default of the tables), angle, "
                  "gap or curvature (largest first), or file (the default of --json)");
  cmd->add_option("--top", options->top, "List at most N seams (per list)")->type_name("N");
  cmd->add_option("--only", options->only,
                  "List only: problems (gaps, kinks and failed analyses), gaps, kinks, creases, or all (the default)");
  cmd->add_option("--require", options->require, "Exit 1 when some seam is below this class (G0, G1 or G2)");
  cmd->add_flag("--json", options->json, "Print JSON instead of tables");
  cmd->add_option("--threads", options->threads,
                  "Threads for the check: 0 = all hardware threads (the default), 1 = one core; the report is the "
                  "same for every value")
      ->type_name("N");
  cmd->add_flag("--patches", options->patches,
                "STEP/IGES: check the faces as patches (natural boundaries, certified) instead of the B-rep edges");
  cmd->footer("Exit codes: 0 ok, 1 some seam is below --require, 2 bad usage or input.");
  cmd->callback([options, &exit]() { exit = runCheck(*options); });
}

}  // namespace

static CommandRegistrar registerCheck("check", addCheck);

}  // namespace seam::cli
