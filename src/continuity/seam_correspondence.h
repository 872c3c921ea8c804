#pragma once
// Private (continuity/seam*.cpp): how the points of two edges are matched. The overlap of the edges, then the
// correspondence s = phi(t): shared control rows, affine, polynomial, else closest-point projection; the exact
// pieces along the seam for the certified routes. docs/algorithms/seam-measures.md, "Correspondence".
#include <limits>
#include <optional>
#include <vector>

#include "continuity/seam_piece.h"
#include "continuity/seam_side.h"
#include "seam/continuity/seam.h"

namespace seam::detail {

// Seams that share their control rows (C^k splits: two patches cut from one surface at a knot line, issue 16 goal
// 2). docs/algorithms/seam-measures.md, "Seams that share their control rows", derives the bounds.

struct SharedRowBounds {
  double g0 = 0.0;  // certified gap bound (the largest control-point difference of the boundary rows)
  double g1 = 0.0;  // certified angle bound, radians
  double g2 = 0.0;  // certified bound of the G2 quotient (as g2Bound)
  double c1 = 0.0, c2 = 0.0;  // largest coefficient of B'_u - A_out and B'_uu - A'_uu (parametric identities)
  double lambda = 1.0;        // the constant of B_1 = lambda A_out (least squares over the first rows)
};

/// Bounds of a seam whose two sides are polynomial, share their Bezier spans along the edge (same degree, same
/// normalised breakpoints, the overlap being both whole edges) and whose rows satisfy, up to rounding,
/// B_0 = A_0, B_1 = lambda A_out (one constant lambda > 0) and B_2 = lambda^2 A_oo (the C2 relation for the
/// cross-derivative scale lambda). nullopt when any of that fails or the bounds are not at round-off level: the
/// caller then takes the general route. No allocation.
std::optional<SharedRowBounds> sharedRowBounds(const Side& A, const Side& B, bool reversed);

// Correspondence: a master side parametrises the seam; per master span a polynomial map m(sigma) (sigma local in
// the span) gives the other side's global edge parameter.
struct MapSpan {
  int span;             // master span index
  double sig0, sig1;    // local interval inside the span that belongs to the overlap
  BernsteinPoly m;      // slave global parameter as a function of sigma in [0,1] (whole span)
};

/// The exact pieces of the seam along the maps (the master's spans, cut where the map crosses a slave breakpoint).
/// B's edge parameter s = sOf(x) at A's edge parameter t = tOf(x), through the piece whose t range holds t (tOf is
/// monotone on each piece): x in closed form where tOf is affine, else by the bisection that cuts the pieces
/// (solveMonotone). nullopt when no piece holds t.
std::optional<double> partnerThroughPieces(const std::vector<Piece>& pieces, double t);

std::vector<Piece> buildPieces(const Side& master, const Side& slave, bool masterIsA,
                               const std::vector<MapSpan>& maps, const SeamOptions& opt);
// Affine map from A's overlap onto B's overlap.
std::vector<MapSpan> affineMaps(const Side& A, Interval oa, Interval ob, bool reversed);
// Polynomial map of degree r from the master's parameter to the slave's, fitted per master span by least squares
// on closest-point projections (it is verified afterwards by the exact distance bound).
std::vector<MapSpan> fittedMaps(const Side& master, const Side& slave, Interval om, int r);

/// A's range and its end points, and the end mismatch of the seam (issue 15 §4).
struct SeamOverlap {
  Interval da;                 ///< A's range (its edge's domain restricted to aRange)
  Vec3 a0, a1;                 ///< A's points at the ends of that range
  /// Largest distance between an end of A and the end of B matched to it both ways, where (A's t) and A's point.
  double endMismatch = 0.0, endMismatchT = 0.0;
  Vec3 endMismatchPoint = Vec3::Zero();
};
/// The overlap of the edges: each edge's end points projected onto the other edge (an end point is snapped to the
/// partner's end when that end is about as close as the partner curve). Sets rep.reversed, rep.overlapA and
/// rep.overlapB; false when the edges do not overlap.
bool findOverlap(const Side& A, const Side& B, std::optional<Interval> aRange, double diagA, double diagB,
                 SeamReport& rep, SeamOverlap& out);

/// The correspondence chosen for a seam and, when certified, its exact pieces.
struct SeamCorrespondence {
  std::vector<Piece> pieces;
  bool certified = false;
  double corrBound = std::numeric_limits<double>::infinity();  ///< certified bound of |a - b o phi| when certified
  std::optional<SharedRowBounds> shared;  ///< the shared-row route's bounds (no pieces then)
};
/// The certified gap bound below which a correspondence is exact (round-off), for edges of this size.
double exactCorrespondenceFloor(double edgeScale);
/// Shared control rows, affine, then polynomial, else closest-point projection (rep.correspondence, its degree and
/// a note when the measures are sampled). `exactFloor`: the bound below which a correspondence is exact.
SeamCorrespondence findCorrespondence(const Side& A, const Side& B, const SeamOptions& opt, double exactFloor,
                                      SeamReport& rep);

}  // namespace seam::detail
