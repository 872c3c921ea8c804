#pragma once
// Private (continuity/seam*.cpp): the exact data of a seam piece (everything as rational polynomials of a local
// parameter in [0, 1]) and the certified bounds on it: G0 / G1 / G2 bounds, their subdivision to a relative gap
// (certifyMax), and the ranges of the Lemma 1 connecting functions. docs/algorithms/seam-measures.md.
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <optional>
#include <vector>

#include "continuity/rational_poly.h"
#include "core/bernstein_internal.h"
#include "seam/continuity/seam.h"
#include "seam/core/bernstein.h"

namespace seam::detail {

/// Normal curvatures below kFlatCurvatureRatio / (patch size) are treated as flat when forming relative jumps:
/// a radius of curvature a thousand times the patch size is indistinguishable from a plane.
constexpr double kFlatCurvatureRatio = 1e-3;
/// Absolute slack (radians) of the certified angle bound: far below any angle tolerance, above the round-off of
/// normal directions.
constexpr double kAngleBoundFloor = 1e-9;
/// A closed certified bound within this factor of its round-off floor (kAngleBoundFloor for angles,
/// kIdentityRelTol x curvature for G2) makes the condition an identity, as the coefficient tests do.
constexpr double kIdentityBoundFactor = 2.0;
/// Largest error (radians) of a sampled angle taken as a measurement (g1ValueIfDefined): next to a vanishing normal
/// the angle is round-off over a vanishing length (89 degrees where the limit is 0.002, issue 35 §2). 1e-5 rad is
/// 0.0006 degrees, far below every angle tolerance (0.01 degrees and more).
constexpr double kG1ValueNoise = 1e-5;

constexpr double kRadToDeg = 180.0 / std::numbers::pi;

// ------------------------------------------------------------------------------------------------------------
// Exact piece data along the seam: everything as (rational) polynomials of a local parameter tau in [0,1].
struct CartesianSide {
  RationalPoly S, Su, Sv, Suu, Suv, Svv;
};

// Cartesian derivatives of S = x / w from homogeneous cross-derivative polynomials X0, X1, X2 (k-th u-derivative
// along the edge, as functions of tau). `slot` selects which weight exponent (A = 0, B = 1) the result carries.
CartesianSide cartesian(const BernsteinPoly& X0, const BernsteinPoly& X1, const BernsteinPoly& X2, bool rational,
                        int slot);

struct Piece {
  BernsteinPoly tOf, sOf;  // A's and B's edge parameters as functions of tau
  BernsteinPoly wa, wb;
  RationalPoly g0;          // a - b
  BernsteinPoly P, Q, R;    // G1: NA.NB, |NA x NB|^2, |NA|^2 |NB|^2 (normal numerators, end roots stripped)
  BernsteinPoly cross;      // NA x NB
  double crossScale = 0.0;  // |NA| |NB| scale for the identity test
  bool g2Available = false;
  RationalPoly rho, T2, nA2, BcT2, O2;  // O2 = |O|^2 (chart conditioning next to poles)
  double rhoScale = 0.0;
  RationalPoly c1, c2, O, Aoo;
  RationalPoly L, K, D;     // Lemma 1: lambda = L / D, kappa = K / D (kappa per unit of the piece parameter)
  // A's and B's position and normal numerators (x / w; end roots divided out): the closest-point excess of a seam
  // with a gap (continuity/closest_excess.h). Patch seams only (PieceData::kAll).
  BernsteinPoly xa, xb, na, nb;
};

/// Degree of the Lemma 2 residual buildPiece forms from these sides: 2 deg D + deg B_cc + deg n_A + 2 (deg w_A +
/// deg w_B), with n_A = A_t x A_o and D = -|n_A|^2. Known before any product is formed.
int lemma2Degree(const CartesianSide& A, const CartesianSide& B, int waDegree, int wbDegree);

/// What buildPiece forms: everything (patch seams), or only what the G2 bound and samples read (the pcurve route's
/// G2 pieces: wa, wb, rho, T2, nA2, BcT2, O2, tOf; its G1 comes from the composed normals, ComposedSide).
enum class PieceData { kAll, kG2Only };

/// The piece from both sides' Cartesian forms (cartesian) and weights (1 for a polynomial side).
Piece buildPiece(const CartesianSide& A, const CartesianSide& B, BernsteinPoly wa, BernsteinPoly wb,
                 BernsteinPoly tOf, BernsteinPoly sOf, int maxDegree, PieceData data);
/// The piece from both sides' homogeneous rows X0, X1, X2 (all the data, PieceData::kAll).
Piece buildPiece(const std::array<BernsteinPoly, 3>& XA, const std::array<BernsteinPoly, 3>& XB, bool ratA,
                 bool ratB, BernsteinPoly tOf, BernsteinPoly sOf, int maxDegree);

/// The weights of a piece restricted to [x0, x1]: lower and upper bounds of the denominators there.
struct SubPiece {
  double waLo, waHi, wbLo, wbHi;  // coefficient bounds of the weights restricted to [x0, x1]
  SubPiece(const Piece& p, double x0, double x1);
  // As detail::denominatorLower / denominatorUpper of the restricted weights.
  [[nodiscard]] double denLower(const RationalPoly& r) const { return std::pow(waLo, r.ea) * std::pow(wbLo, r.eb); }
  [[nodiscard]] double denUpper(const RationalPoly& r) const { return std::pow(waHi, r.ea) * std::pow(wbHi, r.eb); }
};

/// |r| at x of the piece (r's numerator over the weights' powers); `vec`: the value itself.
double evalRational(const RationalPoly& r, const Piece& pc, double x, VecX* vec = nullptr);

/// The measures' bounds on [x0, x1] of a piece and their values at x: the gap, the normal angle (radians) and the
/// G2 quotient (shape-operator jump of a G1 seam).
double g0Bound(const Piece& pc, double x0, double x1);
double g0Value(const Piece& pc, double x);
double g1Bound(const Piece& pc, double x0, double x1);
/// g1Bound with sin^2 bounded by the largest ratio Q_i / R_i of the restricted coefficients where that is smaller than
/// Q_hi / R_lo: it exceeds the angle by O(h^2) on an interval of width h, not O(h), so the subdivision closes in
/// about a sixth of the steps (the patch route; issue 37 goal 1). The pcurve route keeps g1Bound: its pairing of
/// the two boundaries is certified only to within the 1 % slack of the looser bound (docs/algorithms/seam-measures.md).
double g1BoundByRatios(const Piece& pc, double x0, double x1);
/// The angle between the normals at x, or nullopt where its evaluation error may exceed kG1ValueNoise (a normal
/// vanishing at or next to x). g1Value: the same, 0 where undefined (a sample that raises no maximum).
std::optional<double> g1ValueIfDefined(const Piece& pc, double x);
double g1Value(const Piece& pc, double x);
/// The fold test of a G1 identity: N_A . N_B takes a value below -tolerance somewhere (certifiedMinimum). A negative
/// coefficient alone is not a fold: a normal with a double zero inside the edge has P = (x - x0)^2 (...), whose
/// middle coefficients are negative.
inline bool folds(const Piece& pc, double tolerance) {
  return lowerBound(pc.P) < 0.0 && certifiedMinimum(pc.P, tolerance).attained < -tolerance;
}
/// G1 as an identity on composed pieces: N_A x N_B vanishes coefficient-wise (to kIdentityRelTol) and no piece
/// folds (`foldSeen`: a fold the caller found otherwise), or the angle bound closed (`boundClosed`) at the
/// round-off floor of the subdivision (`boundDeg` within kIdentityBoundFactor of kAngleBoundFloor). Both seam routes.
bool g1IdentityOf(const std::vector<Piece>& pieces, bool boundClosed, double boundDeg, bool foldSeen = false);
double g2Bound(const Piece& pc, double x0, double x1);
// The G2 quotient at x, or nullopt where it has no value: a vanishing normal or tangent, or a chart too
// ill-conditioned for curvature (next to a pole the quotient is round-off over a vanishing normal, as in measureAt).
std::optional<double> g2ValueIfDefined(const Piece& pc, double x);
double g2Value(const Piece& pc, double x);

// Ranges of lambda and kappa over all pieces: kLemma1Samples per piece, the extreme sample of each refined by golden
// section between its neighbours (cheap rational polynomials here, unlike the pointwise measures).
void lemma1Ranges(const std::vector<Piece>& pieces, Interval& lambda, Interval& kappa);
/// The largest |n_A . (B_cc - lambda^2 A_oo - 2 lambda kappa A_ot - kappa^2 A_tt)| (unit n_A) over all pieces, refined
/// the same way, where the curvature is defined; nullopt when some piece's Lemma 2 polynomials were not formed.
std::optional<double> lemma2ResidualMax(const std::vector<Piece>& pieces);

// Certified maximum over all pieces: subdivides each piece until its bound is within the relative gap of the best
// value seen (`best`, raised by the values found at midpoints). Returns the bound; `ok` false when some interval
// could not be bounded (infinite bound at the depth limit); `unclosed` (if given) then receives the piece and the
// midpoint of the first such interval. `threshold` (the verdict's tolerance in the value's unit; none by default):
// an interval whose bound lies above it while the best value does not is subdivided further even when its bound is
// within the relative gap, so that a certificate whose maximum lies within boundRelGap of the tolerance still
// decides which side the maximum is on (linkrods.step edge 75: bound 0.5016 deg, samples 0.4967 deg, tolerance 0.5)
// unless the depth or work limit ends the subdivision first.
double certifyMax(const std::vector<Piece>& pieces, const std::function<double(const Piece&, double, double)>& bound,
                  const std::function<double(const Piece&, double)>& value, double& best, double& bestX,
                  int& bestPiece, double floor, const SeamOptions& opt, bool& ok, const bool* stop = nullptr,
                  std::pair<int, double>* unclosed = nullptr,
                  double threshold = std::numeric_limits<double>::infinity());

}  // namespace seam::detail
