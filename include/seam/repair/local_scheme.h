#pragma once
// The local G1 scheme for whole quad networks (docs/algorithms/thesis-abstract.md, "The local scheme"): every
// interior seam of a G0 network of quad patches becomes G1, at interior vertices of any valence n >= 3 and at
// boundary vertices, while free edges stay where they are. The work for a vertex depends only on its one-ring.
//
// Stages (after the thesis' Algorithm 2, re-derived; blending alpha = beta = 1, gamma piecewise cubic per edge):
//  1. every patch is written exactly as a biquintic B-spline whose knot 1/2 has multiplicity 4 in both directions
//     (four C1-joined quintic Bezier pieces; a bicubic or biquartic Bezier patch, or a B-spline with the single
//     interior knot 1/2, is raised and refined exactly);
//  2. per vertex: the tangent vectors of its edges are fitted (least squares) by an affine image of the regular
//     n-gon, t_i = a cos(2 pi i / n) + b sin(2 pi i / n), so t_{i-1} + t_{i+1} = 2 cos(2 pi / n) t_i (the tangent
//     points become coplanar with the vertex: the thesis' eq. 14); at a boundary vertex the free edges' tangents are
//     kept and the interior ones are fitted by a regular fan between them;
//  3. per edge: each half of the edge becomes a cubic (vertex, tangent point, curvature point, midpoint), C1 at
//     the midpoint, fitted to the old edge;
//  4. per vertex: the twist points and gamma'(0) of every edge solve the cyclic corner system (the thesis' eq.
//     15-16: unique for odd n; for even n >= 6 the curvature points are moved, minimally, onto the restriction
//     sum_i (-1)^i gamma_i(0) N.Phi_i''(0) = 0);
//  5. per edge: the rows beside the edge solve B_u + C_s = gamma Phi' coefficient by coefficient on both halves
//     (gamma(1/2) = 0, gamma C1 at the middle), with the smallest change of the cross-boundary vectors.
// The output patches are biquintic B-splines (C1 inside at the knot 1/2); the report says so.
#include <optional>
#include <utility>
#include <string>
#include <vector>

#include "seam/continuity/seam.h"
#include "seam/core/result.h"
#include "seam/core/tolerances.h"
#include "seam/model/model.h"

namespace seam {

struct EdgePairing;  // seam/continuity/model_check.h

struct LocalSchemeOptions {
  /// Patches to work on (indices into Model::patches); empty: every patch. Seams between a chosen patch and one
  /// that is not chosen are treated as free edges (they stay where they are).
  std::vector<int> patches;
  /// Edges (model patch index, edge) kept as free edges even where they pair with a chosen neighbour: design creases
  /// that must not be smoothed (heal passes the seams whose kink is above its crease angle). Both sides of such a
  /// seam keep their boundary curve, so the seam stays G0 and keeps its crease. A kept crease must end where it meets
  /// another kept edge or a free edge: where it ends alone at a vertex, G1 on the other seams there would flatten it
  /// at that vertex, and the scheme refuses (kUnsupported).
  std::vector<std::pair<int, Edge>> keepEdges;
  /// Two corners closer than this are one vertex, edges closer than this pair (default kDefaultMaxGapRel x the
  /// model's bounding-box diagonal, as heal).
  std::optional<double> maxGap;
  /// Classification tolerances (default Tolerances::forModelSize(diagonal)).
  std::optional<Tolerances> tolerances;
  /// Weight of the curvature points against the twist points in the even-valence correction (1: equal).
  double curvatureWeight = 1.0;
  /// The model's edge pairing, when the caller has it already (heal): it must be pairEdgesWithin(model, tol, maxGap,
  /// diagonal) with the tolerances, gap limit and bounding-box diagonal the scheme uses. nullptr: paired here.
  const EdgePairing* pairing = nullptr;
};

/// One vertex of the network as the scheme saw it.
struct LocalSchemeVertex {
  Vec3 point = Vec3::Zero();
  int valence = 0;        ///< patches meeting at the vertex
  bool boundary = false;  ///< on a free edge (the fan is open)
  /// Largest move of a tangent point by the n-gon fit, relative to the length of the longest tangent vector.
  double tangentFitRel = 0.0;
  /// Largest normal correction of a curvature point (even n >= 6 only), absolute.
  double curvatureCorrection = 0.0;
  /// Largest residual of the corner systems after the solve (relative to the data), ~1e-15 when exact.
  double cornerResidual = 0.0;
};

struct LocalSchemeReport {
  std::vector<LocalSchemeVertex> vertices;
  std::vector<std::string> patchesChanged;
  /// Largest control-point displacement against the input expressed in the output's knots and degrees: for
  /// polynomial patches an upper bound on the displacement of the surface (partition of unity).
  double maxDisplacement = 0.0;
  /// maxDisplacement divided by the bounding-box diagonal of the patch where it occurs.
  double maxDisplacementRel = 0.0;
  int interiorSeams = 0;  ///< seams the scheme made G1 (both sides chosen)
  std::vector<int> valences;  ///< distinct interior valences met, ascending
  std::vector<std::string> notes;  ///< degree raised, knots refined, even-valence corrections, ...
};

struct LocalSchemeResult {
  Model model;  ///< every chosen patch replaced by its biquintic form; every other patch bit-identical
  LocalSchemeReport report;
};

/// Runs the scheme. Errors (nothing is changed): kInvalidInput (no patches, non-3-D or rational patches, bad
/// indices), kUnsupported (a patch whose knots are not {1/2} after exact refinement, a degree above 5, a T-junction
/// or partial seam, a vertex whose fan is not a disc or a half disc, a collapsed edge (pole) among the chosen
/// patches), kNoSolution (a fan whose tangent fit would fold). The result is not verified here: heal certifies every
/// seam before and after and keeps the input where anything got worse.
Result<LocalSchemeResult> localG1Scheme(const Model& model, const LocalSchemeOptions& options = {});

}  // namespace seam
