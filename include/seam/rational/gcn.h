#pragma once
// GC^n of order n between two patches along a shared edge, for rational surfaces whose homogeneous surfaces need
// not be smooth (Zheng, Wang & Liang 1995). Two routes:
//  * exact (B-spline / NURBS patches with an affine edge correspondence): Theorem 5 in Bernstein form on every
//    Bezier piece of the seam, decided by polynomial identities (certified);
//  * sampled (any surfaces, e.g. expression patches): the recursion (3.8) at points along the edge, which also gives
//    the connecting functions, the reparametrisations psi1, psi2 of (3.3), (3.6) and the numerical check that they
//    make the pair C^n.
//
// Conventions (those of seam/continuity/seam.h): each side is seen from its edge; A's outward cross parameter is the
// paper's u (Q_u = A_out = -A'_u), B's inward cross parameter is ubar (the default transversal pbar_1 = 1 of
// Section 3.2), and the boundary parameter s is A's own edge parameter, with B's edge parameter an affine function
// of it. The connecting functions are therefore in the patches' own parameters.
#include <string>
#include <vector>

#include "seam/continuity/seam.h"
#include "seam/core/result.h"
#include "seam/model/model.h"
#include "seam/rational/connecting.h"
#include "seam/rational/exact_gcn.h"
#include "seam/rational/homogeneous_surface.h"

namespace seam::rational {

struct GcnOptions {
  int order = 3;             ///< n: orders 0..n are decided (at most kMaxGcnOrder)
  int samplesPerSpan = 16;   ///< sampled route on splines: points per Bezier span of A's edge (span midpoints)
  int surfaceSamples = 64;   ///< sampled route on other surfaces: points along the edge
  bool exactRoute = true;    ///< decide spline seams with Theorem 5 (certified) when the data allow it
  ConnectingOptions connecting;  ///< tolerances of the sampled route (its order and transversal are set here)
  ExactGcnOptions exact;         ///< tolerances of the exact route (its order is set here)
  SeamOptions seam;              ///< overlap and edge correspondence of spline seams (analyzeSeam)
};

/// One Bezier piece of the seam decided by Theorem 5.
struct GcnExactPiece {
  Interval t;              ///< range of A's edge parameter
  ExactGcnResult result;
};

struct GcnReport {
  std::string a, b;
  Edge aEdge = Edge::U0, bEdge = Edge::U0;
  Interval overlapA, overlapB;   ///< the shared part, in each patch's own edge parameter
  double slope = 1.0;            ///< B's edge parameter = slope * t + offset (negative: reversed)
  double offset = 0.0;
  int gcOrder = -1;              ///< highest GC^m, m <= n (-1: the patches do not even meet with GC^0)
  int cOrder = -1;               ///< highest rational C^k (Corollary, eq. 3.10) in the patches' own parameters
  bool certified = false;        ///< the verdict comes from the exact route on every piece
  GcnCase gcnCase = GcnCase::kGeneral;  ///< exact route: the case of the first piece
  /// Relative residual of each order up to the first failing one (exact identities when certified: the largest
  /// over the pieces; else the sampled maximum).
  std::vector<double> residuals;
  ConnectingReport sampled;            ///< connecting functions along s = A's edge parameter, C^n check
  std::vector<GcnExactPiece> exact;    ///< empty when the exact route was not used
  std::vector<std::string> notes;
};

/// Analyses edge `ea` of patch `a` against edge `eb` of patch `b`. Errors: kInvalidInput (order, non-3-D patches),
/// kNotFound (the edges do not overlap), kUnsupported (a non-affine edge correspondence), kDegenerate (a surface not
/// regular along the edge), with messages naming the seam.
Result<GcnReport> analyzeGcn(const Patch& a, Edge ea, const Patch& b, Edge eb, const GcnOptions& options = {});

/// The sampled route for any homogeneous surfaces (expression patches, callables, or splines): the whole edges are
/// matched end to end by an affine map (the orientation whose end points are closer). Never certified.
Result<GcnReport> analyzeGcn(const HomogeneousSurface& a, Edge ea, const HomogeneousSurface& b, Edge eb,
                             const GcnOptions& options = {});

}  // namespace seam::rational
