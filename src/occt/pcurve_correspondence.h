#pragma once
// Two faces of a B-rep edge whose parameter curves do not share a parameter (issue 18): a circle's pcurve whose
// rational B-spline form has another parameter than the angle, a converted cylinder, cone, sphere or torus whose
// patch parameter along a circle is not the angle. The certified pcurve route (certifyPCurveSeam) needs both sides
// as exact curves of one parameter; this re-expresses B's side in A's parameter r by a correspondence q = phi(r)
// that is piecewise cubic, strictly monotone (checked on its Bernstein coefficients) and maps A's range onto B's
// end to end, composed with B's pcurve exactly in Bernstein form. B's points are then exactly those of B's edge
// (only their pairing with A's points is approximate), so the certified bounds remain upper bounds: the distance
// from every point of either edge to the other is at most the G0 bound, whatever phi's accuracy. phi interpolates
// the closest-point correspondence, refined until it matches it within a small fraction of the distance tolerance
// at check points, so that the bounds stay tight. Details: docs/algorithms/seam-measures.md ("Edges without a
// common parameter").
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>

#include "seam/continuity/seam.h"
#include "seam/core/result.h"

namespace seam::occt::detail {

/// A fraction of the distance tolerance: phi must pair points within this of the closest-point correspondence.
inline constexpr double kCorrespondenceTolFraction = 1e-3;
/// Finer pairing accuracies (fractions of the distance tolerance) tried in turn where the angle bound of the pairing
/// at kCorrespondenceTolFraction lies below a sample between closest points.
inline constexpr std::array<double, 2> kFinerPairingFractions = {1e-5, 1e-7};
/// Halvings of a piece of phi before the correspondence is given up (2^10 pieces per piece of the breakpoints).
inline constexpr int kCorrespondenceMaxDepth = 10;

/// The bound work (SeamOptions::maxBoundWork) of a seam certified through a correspondence: its polynomials have
/// three times the degree of the pcurve it composes, and with the default budget the G2 subdivision of a few such
/// seams took most of a file's check (linkrods: 4.5 s against 2.2 s with this budget, the same verdicts and
/// certified seams on every file of ../shared/data). An interval left open keeps its valid, looser bound.
inline constexpr int kCorrespondenceBoundWork = 4000;

struct Correspondence {
  PCurveSide b;               ///< B's side with pcurve c_B(phi(r)) over A's range
  int pieces = 0;             ///< cubic pieces of phi
  double pairingError = 0.0;  ///< largest |S_B(c_B(phi(r))) - S_B(c_B(phi*(r)))| at the check points (phi* closest)
};

/// A side's edge point S(c(t)) and its derivative along the edge (chain rule; the pcurve clamped to the domain).
struct EdgeJet {
  Vec3 point, tangent;
};
EdgeJet edgeJet(const PCurveSide& s, double t);

/// How many of a side's latest jets EdgeJetMemo keeps.
inline constexpr size_t kEdgeJetMemoSize = 8;

/// edgeJet of one side, the last kEdgeJetMemoSize evaluations kept by parameter (bit pattern): a check point's jet
/// at phi(s) is where the closest-point search starts, and its jet at phi*(s) often the one the search's last step
/// evaluated. edgeJet is a pure function of (side, t): a kept jet is the one a new call would return, bit for bit.
class EdgeJetMemo {
 public:
  explicit EdgeJetMemo(const PCurveSide& s) : side_(s) {}
  [[nodiscard]] const PCurveSide& side() const { return side_; }
  /// edgeJet(side(), t), from the kept ones when t was among the latest.
  EdgeJet at(double t);

 private:
  const PCurveSide& side_;
  std::array<std::uint64_t, kEdgeJetMemoSize> keys_{};
  std::array<EdgeJet, kEdgeJetMemoSize> jets_{};
  size_t count_ = 0, next_ = 0;
};

/// B's side in A's parameter, as above. `distanceTol` is the model's G0 tolerance (it sets how close phi must pair
/// points). kUnsupported (with the reason) when phi cannot be made monotone and accurate, or when the composed
/// pcurve is not a valid (positive-weight) B-spline.
/// `pairFraction` (of distanceTol) is the pairing accuracy asked for; kCorrespondenceTolFraction unless a finer pairing
/// is retried (kFinerPairingFractions).
Result<Correspondence> correspondInParameterOf(const PCurveSide& a, const PCurveSide& b, double distanceTol,
                                               double pairFraction = kCorrespondenceTolFraction);

}  // namespace seam::occt::detail
