#pragma once
// What a seam means to a CAD user (issue 17 §1): design creases apart from defects, the way CAD connection checkers
// (CATIA Connect Checker, Rhino EdgeContinuity) separate them. The paper-based GeometricClass (none/G0/G1/G2) stays
// the detail; the verdict is what a surface designer reads:
//   gap     G0 fails (the gap is above the distance tolerance), whatever the angle;
//   kink    G0 holds, the angle is above the G1 tolerance and below the crease angle (a near-tangent seam: a defect);
//   crease  G0 holds and the angle is at or above the crease angle (an intended sharp edge, left as designed);
//   G1, G2  tangent / curvature continuous within the tolerances;
//   undetermined  G0 holds and the angle measured wherever both normals are defined is within the G1 tolerance,
//           but a normal vanishes on the seam (a pole) where G1 was neither bounded nor proved as an identity
//           (SeamReport::g1PoleT): tangent everywhere it can be measured, undecided at that point (issue 35 §2).
// The angle used is SeamReport::g1MaxDeg (the certified bound, or the refined sampled maximum when the seam is not
// certified): the same number the tables print and heal compares with its crease angle.
#include <array>
#include <cstddef>
#include <optional>
#include <span>
#include <string_view>
#include <vector>

#include "seam/continuity/seam.h"
#include "seam/core/result.h"

namespace seam {

/// Default crease angle (degrees): a seam whose tangent planes meet at this angle or more is a design crease, not a
/// near-tangent defect. Kinks from tolerance problems (translation losses, perturbed control points) are a few
/// degrees; CAD checkers' G1 thresholds are 0.5-1 degree (docs/tolerances.md). `seam check --crease-angle`,
/// `seam heal --crease-angle` (heal leaves creases alone), `seam join --crease-angle`.
inline constexpr double kDefaultCreaseAngleDeg = 20.0;

enum class SeamVerdict { kGap, kKink, kCrease, kG1, kG2, kUndetermined };
/// Number of verdicts (countVerdicts' entries).
inline constexpr std::size_t kSeamVerdictCount = 6;
/// "gap", "kink", "crease", "G1", "G2", "undetermined".
std::string_view toString(SeamVerdict v);

/// The verdict of an analysed seam (its geometric class was computed with the tolerances in force; see above).
SeamVerdict seamVerdict(const SeamReport& report, double creaseAngleDeg = kDefaultCreaseAngleDeg);

/// Gaps and kinks are defects; creases, G1 and G2 seams are not, nor are undetermined ones (listed with the
/// problems all the same: see SeamFilter::kProblems).
inline bool isProblem(SeamVerdict v) { return v == SeamVerdict::kGap || v == SeamVerdict::kKink; }

/// True when `creaseAngleDeg` is an angle in (0, 180] degrees.
inline bool validCreaseAngle(double creaseAngleDeg) { return creaseAngleDeg > 0.0 && creaseAngleDeg <= 180.0; }

/// Order of a seam listing: as found (the file's / pairing order), by a measure, largest first, or by verdict: kinks
/// (largest angle first), gaps (largest first), undetermined seams and failed analyses, G1 and G2 seams (file order),
/// creases (largest angle first), the order of `seam report`'s tables and the default of `seam check`'s text tables
/// (issue 38 goal 3).
enum class SeamSortKey { kFile, kAngle, kGap, kCurvature, kVerdict };
/// Parses "file", "angle", "gap", "curvature" or "verdict". Errors: kInvalidInput naming the accepted values.
Result<SeamSortKey> parseSeamSortKey(std::string_view text);

/// Which verdicts a listing shows: all, problems (gaps, kinks, undetermined seams and failed analyses), or one
/// verdict.
enum class SeamFilter { kAll, kProblems, kGaps, kKinks, kCreases };
/// Parses "all", "problems", "gaps", "kinks" or "creases". Errors: kInvalidInput naming the accepted values.
Result<SeamFilter> parseSeamFilter(std::string_view text);
/// "all", "problems", "gaps", "kinks", "creases".
std::string_view toString(SeamFilter f);
/// Whether a seam passes the filter (null: a seam whose analysis failed, shown with the problems).
bool passes(SeamFilter f, const SeamReport* seam, double creaseAngleDeg);

/// Which seams a listing shows.
struct SeamSelection {
  SeamSortKey sort = SeamSortKey::kFile;
  SeamFilter only = SeamFilter::kAll;  ///< --only
  std::optional<std::size_t> top;      ///< at most this many (after sorting)
  double creaseAngleDeg = kDefaultCreaseAngleDeg;
};

/// Indices into `seams` in listing order. A null entry is a seam whose analysis failed: it counts as a problem and
/// comes last in a sorted listing. Sorting is stable: equal values keep the file order. The measures: angle
/// g1MaxDeg, gap g0Max, curvature g2RelMax (relative jump), each largest first.
std::vector<std::size_t> selectSeams(std::span<const SeamReport* const> seams, const SeamSelection& selection);

/// The worst defects of a set of seams, for a summary: the kink with the largest angle and the gap with the largest
/// distance (indices into `seams`, empty when there is none). Null entries are skipped.
struct WorstDefects {
  std::optional<std::size_t> kink, gap;
};
WorstDefects worstDefects(std::span<const SeamReport* const> seams, double creaseAngleDeg = kDefaultCreaseAngleDeg);

/// Counts per verdict, indexed by SeamVerdict (gap, kink, crease, G1, G2, undetermined). Null entries are not
/// counted.
std::array<int, kSeamVerdictCount> countVerdicts(std::span<const SeamReport* const> seams,
                                 double creaseAngleDeg = kDefaultCreaseAngleDeg);

}  // namespace seam
