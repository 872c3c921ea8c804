#pragma once
// Curvature continuity (G2) across a whole quad network (docs/algorithms/thesis-abstract.md, "G2 across
// networks"): every interior seam of a G0 (or G1) network of polynomial quad patches becomes G2, while free edges
// stay where they are.
//
// Every chosen patch is written exactly as a biquintic B-spline with its own interior knots, each of multiplicity 3
// (C2: the patch stays curvature continuous inside), 4 where the input is only C1 there or 5 where it is only C0 (a
// double or triple knot of a cubic: the thesis' Theorems 9-10); the middle 1/2 in a direction without interior knots.
// No patch takes another's knots, so uneven knots cost what a Bezier network costs (issue 36 goal 4). Along
// every seam, with the common edge parameter t and each side's cross-boundary parameter pointing into its patch,
// the two sides B (the pair's first patch) and C must satisfy, span by span of the edge (the merged breakpoints of
// both sides),
//     C_s  = -lambda B_s + kappa B_t                                                   (G1, lambda > 0)
//     C_ss = lambda^2 B_ss - 2 lambda kappa B_st + kappa^2 B_tt + mu B_s + nu B_t      (G2)
// (the chain rule of C(s, t) = B(u(s, t), v(s, t)), u_s = -lambda, v_s = kappa, u_ss = mu, v_ss = nu: the thesis'
// blending functions alpha, beta, gamma, delta, eta after division by beta). lambda is linear and kappa, mu, nu are
// quadratic per span; every identity is a polynomial of degree <= 7 per span, so it holds exactly when it holds at
// 8 distinct parameters of the span. The control points of all chosen patches and the blending coefficients are
// the unknowns of one system: the identities (and G0: equal boundary rows, one set of unknowns where both rows have
// the same knots, linear equations where they do not) at those parameters, solved by
// Gauss-Newton steps of least change of the control points, with a fairness term (G2NetworkOptions::fairness; a
// constrained least-squares step per iteration, sparse). At a vertex of valence 3 this solves the thesis' three "intertwining" systems (curvature points, then the
// F and G points) together, and at a 4-valent vertex it meets Johansson's Theorem 2 compatibility, because both are
// consequences of the identities above at the vertex. The result is not certified here: heal certifies every seam
// before and after (analyzeSeam) and keeps the input where anything is worse.
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "seam/continuity/seam.h"
#include "seam/core/types.h"
#include "seam/core/result.h"
#include "seam/core/tolerances.h"
#include "seam/model/model.h"

namespace seam {

/// Default of G2NetworkOptions::maxFairFactorOperations.
inline constexpr double kDefaultMaxFairFactorOperations = 1e10;
/// Default weight of the fairness term of the G2 network solve (G2NetworkOptions::fairness).
inline constexpr double kDefaultG2Fairness = 10.0;

struct G2NetworkOptions {
  /// Patches to work on (indices into Model::patches); empty: every patch. Seams between a chosen patch and one
  /// that is not chosen are free edges (they stay where they are, G0 or better as in the input).
  std::vector<int> patches;
  /// Edges (model patch index, edge) kept as free edges (design creases, as LocalSchemeOptions::keepEdges).
  std::vector<std::pair<int, Edge>> keepEdges;
  /// Two edges closer than this pair (default kDefaultMaxGapRel x the model's bounding-box diagonal).
  std::optional<double> maxGap;
  /// Classification tolerances (default Tolerances::forModelSize(diagonal)).
  std::optional<Tolerances> tolerances;
  /// Gauss-Newton iterations at most (each one sparse constrained least-squares step).
  int maxIterations = 30;
  /// The solve stops when every identity's residual (a length: derivatives per unit of the normalised edge
  /// parameter) is below this fraction of the model's bounding-box diagonal, or when four steps gain less than a
  /// factor 2 (the last digits converge linearly: see the .cpp).
  double residualRel = 1e-12;
  /// The result is returned only when the residual is at or below this fraction of the diagonal (far below what
  /// the default tolerances can see: 0.01 degrees, 1 % curvature jump); whether every seam is G2 is then decided
  /// by the certified check, whose bounds are what heal reports.
  double acceptRel = 1e-7;
  /// Weight of the fairness term in every step (0: least change of the control points only): the squared second
  /// and mixed differences of the control-point changes of every patch, against their squared size. Least change
  /// alone lets the solve buy G2 with sharp bends (curvature 2.1 -> 10 on the fan of 3 of the tests, |k| = 90 on a
  /// model of size 2.3 with a C0 knot inside a patch); at 10 the curvature on the seams stays within 10 % of the
  /// input's on every test network and the displacement is smaller. The term is used while the residual is above
  /// 1e-4 of the model size (a KKT system per step instead of the m x m normal equations; the last, small steps are
  /// plain least change): ~1-2x the time of fairness 0. docs/algorithms/thesis-abstract.md, "Fairness".
  double fairness = kDefaultG2Fairness;
  /// Largest cost, in multiply-adds, of one factorisation of a step with the fairness term (the sum over the
  /// factor's columns of their squared nonzero counts, known from the symbolic analysis before it is paid). The term
  /// couples every control point of a patch with its neighbours, so on large patches the equations' Schur complement
  /// fills in: sunglasses_lens.igs (9 biquintic patches of 42 x 42 points, 4 095 equations) took 17 s per step with
  /// it against 0.01 s without, its G1 heal 53-61 s instead of 3 s. Above the limit the solve takes plain
  /// least-change steps (as fairness 0, the rows facing patches outside the solve kept stiff) and says so in a note.
  /// The default, 1e10, is 1-10 s per step on a 2-vCPU VM (the time per operation depends on the pattern); every
  /// network measured with the term stays under it (the 24-patch sphere's G2 solve 2.2e9, the open 6 x 6 grid's G1
  /// solve 8.7e9, where fairness 0 would move the surface 3x as far).
  double maxFairFactorOperations = kDefaultMaxFairFactorOperations;
  /// kG2 (default): the G1 and G2 identities. kG1: the G1 identities only (tangent-plane continuity of every seam,
  /// with lambda and kappa free per span): the network solve as a G1 scheme where the local scheme has no solution
  /// (issue 36 goal 1: a boundary vertex whose free edges are straight with unequal tangent lengths, which no
  /// symmetric fan fits; interior knots other than the middle). Any other value is invalid input.
  GeometricClass continuity = GeometricClass::kG2;
};

/// One interior vertex of the network (all its corners among the chosen patches, the seams around it closed) with
/// its curvature spread (CornerReport::curvatureSpreadRel: the largest normal-curvature difference between two of
/// its patches, relative) before and after the solve. 0 after means the vertex's curvature-point system is met:
/// one second fundamental form at the vertex (the thesis' first intertwining system at valence 3, the curvature
/// part of Johansson's Theorem 2 at valence 4; at valence 5 and more the literature's G2 constructions need more
/// pieces or higher degree, and this is the remaining mismatch the issue asks to report).
struct G2NetworkVertex {
  Vec3 point = Vec3::Zero();
  int valence = 0;
  std::optional<double> spreadBefore, spreadAfter;  ///< relative (empty where a corner is degenerate)
  /// Valence 4: the largest scaled residual of Johansson's Theorem 2 relations (eq. 3.17) after the solve
  /// (FourPatchVertex::g2Residual; empty where a seam is not G2 at the vertex).
  std::optional<double> theorem2After;
};

struct G2NetworkReport {
  int interiorSeams = 0;  ///< seams between chosen patches (both sides chosen, not kept)
  /// Of those, seams made G1 only: they end at a boundary vertex where the free boundary runs straight with
  /// different normal curvatures on its two sides, so G2 there would move the free edges (a note names the vertex).
  int g1OnlySeams = 0;
  int iterations = 0;     ///< Gauss-Newton steps taken
  /// Largest residual of the identities after the solve, relative to the bounding-box diagonal (the achieved value).
  double residualRel = 0.0;
  /// Smallest lambda over every seam (lambda is linear per span: its end values): > 0 means no fold.
  double minLambda = 0.0;
  /// Largest control-point displacement against the input written in the output's degrees and knots: for
  /// polynomial patches an upper bound on the displacement of the surface (partition of unity).
  double maxDisplacement = 0.0;
  double maxDisplacementRel = 0.0;  ///< divided by the bounding-box diagonal of the patch where it occurs
  std::vector<int> valences;        ///< distinct interior valences met, ascending
  std::vector<G2NetworkVertex> vertices;  ///< every interior vertex, in the order of the patches' corners
  std::optional<double> maxSpreadAfter;   ///< largest G2NetworkVertex::spreadAfter
  std::vector<std::string> patchesChanged;
  std::vector<std::string> notes;
};

struct G2NetworkResult {
  Model model;  ///< every chosen patch replaced by its biquintic form; every other patch bit-identical
  G2NetworkReport report;
};

/// Runs the solve. Errors (nothing is changed): kInvalidInput (no patches, non-3-D patches, bad indices),
/// kInvalidInput also for a negative or non-finite fairness weight or a negative or NaN maxFairFactorOperations; kUnsupported (rational patches, a degree above
/// 5, T-junctions, an edge shared by three patches, a collapsed edge among the chosen patches), kNoSolution (the iteration did not reach
/// the residual, or a seam would fold: lambda <= 0 somewhere).
Result<G2NetworkResult> g2NetworkScheme(const Model& model, const G2NetworkOptions& options = {});

}  // namespace seam
