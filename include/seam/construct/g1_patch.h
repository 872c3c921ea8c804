#pragma once
// Exact G1 constructions with polynomial Bezier patches (Johansson, Section 4), the general engine.
//
// Conventions (the same as seam/continuity/seam.h, so that analyzeSeam reports the functions chosen here):
//  * A seam joins a KNOWN patch A (edge `neighbourEdge`) to the NEW patch N (edge `newEdge`). t is A's own
//    parameter along its edge, normalised to [0,1] and increasing with A's parameter.
//  * A_out(t) is the cross-boundary derivative of A pointing OUT of A (U0: -A_u, U1: +A_u, V0: -A_v,
//    V1: +A_v), A_t(t) the derivative along the edge, N_cross the cross-boundary derivative of N pointing
//    INTO N (U0: +N_u, U1: -N_u, V0: +N_v, V1: -N_v).
//  * G1 with polynomial connecting functions (Johansson 4.24, Lemma 1): N_cross(t) = lambda(t) A_out(t) +
//    kappa(t) A_t(t) as a polynomial identity, lambda > 0. In the paper's layout (r above, r-bar below:
//    r-bar_v(u,0) = lambda(u) r_v(u,1) + kappa(u) r_u(u,1)) this is exactly (4.24) with A = r, edge V1, N =
//    r-bar, edge V0, and the Bernstein coefficients of lambda and kappa are the paper's (lambda_0, alpha,
//    lambda_1) and (kappa_0, beta1, beta2, kappa_1) of (4.25).
//
// Every condition is linear in the unknowns (the control points of N and the Bernstein coefficients of every
// lambda and kappa), so the engine assembles ONE linear system C x = d from the kernel's Bernstein products
// and degree elevation (no coefficient tables), solves it in the least-squares sense with the constraints
// exact when they are consistent, and spends the remaining freedom on a fairness energy.
// docs/algorithms/johansson-constructions.md derives it and maps every equation of the paper (4.24)-(4.54)
// onto it.
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "seam/core/bernstein.h"
#include "seam/core/result.h"
#include "seam/core/types.h"
#include "seam/spline/bezier.h"
#include "seam/spline/bspline_surface.h"

namespace seam {

// ---------------------------------------------------------------------------------------------------------------
// Section 4 intro: G1 across one edge, (4.24)-(4.27) for any degrees.

/// The two rows of a neighbour patch that G1 across one edge fixes.
struct G1EdgeRows {
  int degreeAlong = 0;  ///< degree of the neighbour along the edge: max(p, deg lambda + p, deg kappa + p - 1)
  Matrix boundary;  ///< (degreeAlong+1) x dim: the neighbour's boundary row (the edge of r, elevated; 4.27)
  Matrix inner;     ///< the first inner row (4.26): boundary + (lambda r_out + kappa r_t) / crossDegree
};

/// The boundary row and first inner row of the neighbour r-bar of `r` across edge `edge` for connecting
/// functions `lambda`, `kappa` (scalar polynomials in r's edge parameter t, conventions above; an empty
/// `kappa` is zero) and r-bar's degree `crossDegree` across the edge. Rows are ordered by increasing t.
/// `alongDegree`, when given, must be at least the minimum degree above (the rows are then elevated to it).
/// Errors: kInvalidInput for a rational `r`, a vector-valued lambda/kappa, crossDegree < 1 or a too small
/// alongDegree.
Result<G1EdgeRows> g1NeighbourRows(const BezierPatch& r, Edge edge, const BernsteinPoly& lambda,
                                   const BernsteinPoly& kappa, int crossDegree,
                                   std::optional<int> alongDegree = std::nullopt);

// ---------------------------------------------------------------------------------------------------------------
// The general engine: one new patch N against any number of known neighbours.

/// One seam of the new patch with a known neighbour.
struct G1SeamSpec {
  BezierPatch neighbour;          ///< A: polynomial (non-rational) Bezier patch, 3-D
  Edge neighbourEdge = Edge::V1;  ///< A's edge on the seam
  Edge newEdge = Edge::V0;        ///< N's edge on the seam
  bool reversed = false;          ///< N's parameter along its edge runs against A's
  /// Degrees of lambda and kappa. Default: lambda deg = d - p and kappa deg = d - p + 1, where d is N's
  /// degree along the edge and p A's (the paper's 2 and 3 for (5,5) against bicubics; 1 and 2 for
  /// (4,4), 4.37).
  std::optional<int> lambdaDegree;
  std::optional<int> kappaDegree;
  bool kappaZero = false;  ///< kappa == 0 on this seam (Sarraga's setting; no kappa unknowns)
  /// Bernstein coefficients of lambda / kappa fixed to given values: (index, value).
  std::vector<std::pair<int, double>> fixedLambda;
  std::vector<std::pair<int, double>> fixedKappa;
};

/// How the control points that no G1 condition fixes (and the remaining free lambda/kappa coefficients) are
/// chosen.
enum class InteriorRule {
  kFairness,   ///< minimise the thin-plate energy of N (plus the small parameter regularisation below)
  kTwistRule,  ///< Johansson (4.54): q22 = q21 + q12 - q11 at every corner between two seams (degree >= 5),
               ///< the rest by fairness
};

struct G1PatchOptions {
  int degreeU =
      5;  ///< bi-degree of N to try first (Johansson: 5; 4 is (4.37); 6 with kappa = 0 is Sarraga's)
  int degreeV = 5;
  /// Raise both degrees by one while the constraints are inconsistent, up to this bi-degree (never below the
  /// start).
  int maxDegree = 8;
  bool kappaZero = false;  ///< kappa == 0 on every seam (overrides the per-seam flag)
  InteriorRule interior = InteriorRule::kFairness;
  /// Weight of the regularisation integral (lambda')^2 + kappa^2 of every seam relative to the thin-plate
  /// energy (both scaled to the patch size): keeps lambda near constant and kappa near zero where the energy
  /// alone is flat.
  double parameterWeight = 1e-2;
};

/// The connecting functions of one seam (in A's edge parameter t).
struct ConnectingFunctions {
  BernsteinPoly lambda;  ///< scalar
  BernsteinPoly kappa;   ///< scalar (the zero polynomial of degree 0 when kappa == 0)
};

/// Johansson's compatibility at one corner of N where two seams meet, in its general form (Theorem 1 and the
/// twist relation behind (4.36)). Residuals are dimensionless (relative to |N_u| + |N_v| at the corner).
struct CornerCompatibility {
  int corner = 0;  ///< 0: (u,v) = (0,0), 1: (1,0), 2: (0,1), 3: (1,1)
  int seamU = 0;   ///< the seam on N's U-edge through the corner (it fixes N_u there)
  int seamV = 0;   ///< the seam on N's V-edge through the corner
  /// (4.30) in general form: N_u and N_v at the corner as given by one seam's lambda, kappa and by the other
  /// seam's boundary curve agree (max of the two relative differences).
  double tangentResidual = 0.0;
  /// (4.36) in general form: the twist N_uv as given by the two seams' d/dt (lambda A_out + kappa A_t)
  /// agrees.
  double twistResidual = 0.0;
  /// The normal component of that twist difference; it depends only on the neighbours (lambda, kappa at the
  /// corner are fixed by Theorem 1), so no choice of the free parameters and no degree can remove it.
  double twistNormalResidual = 0.0;
};

/// One attempt of the engine at one bi-degree.
struct G1Attempt {
  int degreeU = 0, degreeV = 0;
  int unknowns = 0;     ///< control-point coordinates + lambda/kappa coefficients
  int constraints = 0;  ///< rows of the linear system
  int rank = 0;
  double residual =
      0.0;             ///< max scaled residual of the constraints (angles in radians, distances / patch size)
  bool exact = false;  ///< residual <= kIdentityRelTol: every constraint holds to round-off
};

struct G1PatchResult {
  BezierPatch patch;                           ///< N, polynomial, bi-degree (degreeU, degreeV)
  std::vector<ConnectingFunctions> functions;  ///< one per seam, in the order of the specs
  std::vector<CornerCompatibility> corners;    ///< corners of N between two seams
  std::vector<G1Attempt> attempts;             ///< every bi-degree tried, in order; the last one is `patch`
  int freeParameters = 0;          ///< dimension of the solution space of the constraints at the final degree
  double energy = 0.0;             ///< thin-plate energy of N (in the patch's own coordinates)
  bool exact = false;              ///< the final attempt satisfies every constraint to round-off
  std::vector<std::string> notes;  ///< degree raised, twist rule skipped, lambda not positive, ...
};

/// Builds N of the first bi-degree >= (degreeU, degreeV) for which the G0 and G1 constraints of every seam
/// (and the fixed coefficients) are consistent; when none up to maxDegree is, returns the attempt with the
/// smallest residual (exact == false; its notes say so). Seams must be given with N's corners in common: two
/// seams on adjacent edges of N must meet at the corner (the engine does not check geometry, it solves in
/// least squares). Errors: kInvalidInput for no seam, a rational/non-3-D neighbour, two seams on the same
/// edge of N, a fixed coefficient index out of range or degrees < 1; kUnsupported when N's degree along an
/// edge can never reach the neighbour's (maxDegree too small).
Result<G1PatchResult> buildG1Patch(std::span<const G1SeamSpec> seams, const G1PatchOptions& options = {});

/// The thin-plate energy  integral over [0,1]^2 of |S_uu|^2 + 2 |S_uv|^2 + |S_vv|^2  of a polynomial patch,
/// exactly.
double thinPlateEnergy(const BezierPatch& patch);

}  // namespace seam
