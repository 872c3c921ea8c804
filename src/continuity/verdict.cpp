// Seam verdicts for CAD users: gap, kink, crease, G1, G2, undetermined (continuity/verdict.h), and the listing order
// of a check.
#include "seam/continuity/verdict.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

namespace seam {

std::string_view toString(SeamVerdict v) {
  switch (v) {
    case SeamVerdict::kGap: return "gap";
    case SeamVerdict::kKink: return "kink";
    case SeamVerdict::kCrease: return "crease";
    case SeamVerdict::kG1: return "G1";
    case SeamVerdict::kG2: return "G2";
    case SeamVerdict::kUndetermined: return "undetermined";
  }
  return "?";
}

SeamVerdict seamVerdict(const SeamReport& r, double creaseAngleDeg) {
  switch (r.geometric) {
    case GeometricClass::kNone: return SeamVerdict::kGap;
    case GeometricClass::kG0:
      // NaN angles (nothing measurable) stay kinks: a defect to look at, never a silent crease.
      return r.g1MaxDeg >= creaseAngleDeg ? SeamVerdict::kCrease : SeamVerdict::kKink;
    case GeometricClass::kG1: return r.g1PoleT ? SeamVerdict::kUndetermined : SeamVerdict::kG1;
    case GeometricClass::kG2: return r.g1PoleT ? SeamVerdict::kUndetermined : SeamVerdict::kG2;
  }
  return SeamVerdict::kGap;
}

Result<SeamSortKey> parseSeamSortKey(std::string_view text) {
  if (text == "file") return SeamSortKey::kFile;
  if (text == "angle") return SeamSortKey::kAngle;
  if (text == "gap") return SeamSortKey::kGap;
  if (text == "curvature") return SeamSortKey::kCurvature;
  if (text == "verdict") return SeamSortKey::kVerdict;
  return invalidInput(fmt::format("unknown sort key \"{}\" (expected verdict, angle, gap, curvature or file)", text));
}

Result<SeamFilter> parseSeamFilter(std::string_view text) {
  for (SeamFilter f : {SeamFilter::kAll, SeamFilter::kProblems, SeamFilter::kGaps, SeamFilter::kKinks,
                       SeamFilter::kCreases})
    if (text == toString(f)) return f;
  return invalidInput(fmt::format("\"{}\" is not problems (gaps, kinks, undetermined seams and failed analyses), gaps, "
                                  "kinks, creases or all",
                                  text));
}

std::string_view toString(SeamFilter f) {
  switch (f) {
    case SeamFilter::kAll: return "all";
    case SeamFilter::kProblems: return "problems";
    case SeamFilter::kGaps: return "gaps";
    case SeamFilter::kKinks: return "kinks";
    case SeamFilter::kCreases: return "creases";
  }
  return "?";
}

bool passes(SeamFilter f, const SeamReport* seam, double creaseAngleDeg) {
  if (f == SeamFilter::kAll) return true;
  if (seam == nullptr) return f == SeamFilter::kProblems;
  const SeamVerdict v = seamVerdict(*seam, creaseAngleDeg);
  switch (f) {
    case SeamFilter::kProblems: return isProblem(v) || v == SeamVerdict::kUndetermined;
    case SeamFilter::kGaps: return v == SeamVerdict::kGap;
    case SeamFilter::kKinks: return v == SeamVerdict::kKink;
    case SeamFilter::kCreases: return v == SeamVerdict::kCrease;
    case SeamFilter::kAll: break;
  }
  return true;
}

namespace {

double sortValue(const SeamReport& r, SeamSortKey key) {
  double v = 0.0;
  switch (key) {
    case SeamSortKey::kFile:
    case SeamSortKey::kVerdict: return 0.0;
    case SeamSortKey::kAngle: v = r.g1MaxDeg; break;
    case SeamSortKey::kGap: v = r.g0Max; break;
    case SeamSortKey::kCurvature: v = r.g2RelMax; break;
  }
  return std::isnan(v) ? -1.0 : v;  // a measure that could not be computed sorts after every real value
}

}  // namespace

std::vector<std::size_t> selectSeams(std::span<const SeamReport* const> seams, const SeamSelection& sel) {
  std::vector<std::size_t> order;
  order.reserve(seams.size());
  for (std::size_t k = 0; k < seams.size(); ++k)
    if (passes(sel.only, seams[k], sel.creaseAngleDeg)) order.push_back(k);
  if (sel.sort == SeamSortKey::kVerdict) {
    // Kinks (largest angle first), gaps (largest first), undetermined seams and failed analyses, G1/G2 (file
    // order), creases (largest angle first). NaN measures sort last within their verdict.
    auto rank = [&](std::size_t k) -> std::pair<int, double> {
      const SeamReport* r = seams[k];
      if (r == nullptr) return {2, 0.0};
      switch (seamVerdict(*r, sel.creaseAngleDeg)) {
        case SeamVerdict::kKink: return {0, -sortValue(*r, SeamSortKey::kAngle)};
        case SeamVerdict::kGap: return {1, -sortValue(*r, SeamSortKey::kGap)};
        case SeamVerdict::kCrease: return {4, -sortValue(*r, SeamSortKey::kAngle)};
        case SeamVerdict::kUndetermined: return {2, 0.0};
        default: return {3, 0.0};
      }
    };
    std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) { return rank(x) < rank(y); });
  } else if (sel.sort != SeamSortKey::kFile) {
    std::stable_sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
      const SeamReport* a = seams[x];
      const SeamReport* b = seams[y];
      if (a == nullptr || b == nullptr) return a != nullptr && b == nullptr;  // failed analyses last
      return sortValue(*a, sel.sort) > sortValue(*b, sel.sort);
    });
  }
  if (sel.top && order.size() > *sel.top) order.resize(*sel.top);
  return order;
}

WorstDefects worstDefects(std::span<const SeamReport* const> seams, double creaseAngleDeg) {
  WorstDefects w;
  for (std::size_t k = 0; k < seams.size(); ++k) {
    const SeamReport* r = seams[k];
    if (r == nullptr) continue;
    const SeamVerdict v = seamVerdict(*r, creaseAngleDeg);
    if (v == SeamVerdict::kKink && (!w.kink || r->g1MaxDeg > seams[*w.kink]->g1MaxDeg)) w.kink = k;
    if (v == SeamVerdict::kGap && (!w.gap || r->g0Max > seams[*w.gap]->g0Max)) w.gap = k;
  }
  return w;
}

std::array<int, kSeamVerdictCount> countVerdicts(std::span<const SeamReport* const> seams, double creaseAngleDeg) {
  std::array<int, kSeamVerdictCount> n{};
  for (const SeamReport* r : seams)
    if (r != nullptr) ++n[static_cast<std::size_t>(seamVerdict(*r, creaseAngleDeg))];
  return n;
}

}  // namespace seam
