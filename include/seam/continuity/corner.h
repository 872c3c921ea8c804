#pragma once
// Vertices where patch corners meet: valence, the spread of the patch normals, and for 4-valent vertices the
// connecting functions of the four seams and the compatibility relations of Johansson's Theorem 1 (G1, eqs. 2.6,
// 2.7) and Theorem 2 (G2, eq. 3.17). docs/algorithms/johansson.md ("Corners (Theorems 1, 2)") derives every formula
// used here, documents how the actual patches are mapped onto the paper's numbering (Figure 2), and says what the
// relations can and cannot detect.
#include <array>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "seam/core/result.h"
#include "seam/core/tolerances.h"
#include "seam/core/types.h"
#include "seam/model/model.h"
#include "seam/spline/bspline_surface.h"

namespace seam {

/// One corner of a patch: the patch (an index into the patch list of the call) and which end of each parameter range.
struct PatchCorner {
  int patch = 0;
  bool uMax = false;  ///< the corner is at u = u_max (else u = u_min)
  bool vMax = false;  ///< the corner is at v = v_max (else v = v_min)
  /// The edge u = const through the corner (it runs along v).
  [[nodiscard]] Edge uEdge() const { return uMax ? Edge::U1 : Edge::U0; }
  /// The edge v = const through the corner (it runs along u).
  [[nodiscard]] Edge vEdge() const { return vMax ? Edge::V1 : Edge::V0; }
  friend bool operator==(const PatchCorner&, const PatchCorner&) = default;
};

/// Two corner edges that are one seam: edge `aEdge` of corner `a` and edge `bEdge` of corner `b` (indices into the
/// corner list of the call). Each edge must be one of the two edges through its corner.
struct CornerLink {
  int a = 0;
  Edge aEdge = Edge::U0;
  int b = 0;
  Edge bEdge = Edge::U0;
};

/// How an actual patch is reoriented onto the paper's layout (Figure 2):
/// oriented = (swapUV ? S.swappedUV() : S), then .reversedU() if reverseU, then .reversedV() if reverseV.
struct PatchLayout {
  bool swapUV = false;
  bool reverseU = false;
  bool reverseV = false;
  friend bool operator==(const PatchLayout&, const PatchLayout&) = default;
};

/// One of the four seams at a 4-valent vertex, in the common parametrisation of the paper (Section 2: the patches
/// are reparametrised so that the boundary curves of neighbours agree; see johansson.md for the exact choice).
/// The seam joins patch `from` (side A, eq. 2.1's r^(1)) to patch `to` (side B): B_cross = lambda A_cross + kappa A_along.
struct VertexSeam {
  int from = 0;  ///< paper numbering 1..4
  int to = 0;
  double lambda = 0.0;     ///< eq. 2.1 at V (least squares)
  double kappa = 0.0;
  double dLambda = 0.0;    ///< d lambda / d(common parameter along the seam) at V, exact derivative of the LS solution
  double dKappa = 0.0;
  /// |B_cross - lambda A_cross - kappa A_along| / |B_cross|: sine of the angle between B_cross and A's tangent plane.
  double g1Residual = 0.0;
  /// Normal component of d/ds (B_cross - lambda A_cross - kappa A_along) relative to |B_cross'| + |B_cross| / L
  /// (L = CornerOptions::lengthScale): how fast the tangent planes separate along the seam away from V. Zero when
  /// the seam is G1 in a neighbourhood of V (then eq. 3.11 / 3.12 holds).
  double g1SlopeResidual = 0.0;
  /// Jump of the normal curvature in the direction B_cross at V (1/length): the normal component of the Lemma 2
  /// residual (eq. 3.10) divided by |B_cross|^2.
  double g2Jump = 0.0;
  /// g2Jump relative to max(|k_A|, |k_B|, 1/L) (k = the two normal curvatures in that direction).
  double g2JumpRel = 0.0;
  bool g1 = false;         ///< g1Residual and g1SlopeResidual within the angle tolerance (as sines)
  bool g2 = false;         ///< g1 and g2JumpRel within the curvature tolerance
  std::optional<double> mu, nu;  ///< eq. 3.10 (tangential least squares), only where the seam is G2 at V
};

/// Compatibility at a 4-valent vertex (Theorems 1 and 2). Residuals are scaled to be dimensionless and invariant
/// under reparametrisation (johansson.md): each relation is a component of a vector identity, multiplied by the
/// length of the tangent vector it multiplies and divided by the size of that vector identity's terms.
struct FourPatchVertex {
  std::array<int, 4> corner{};        ///< index into the corner list of the paper's patches 1, 2, 3, 4
  std::array<PatchLayout, 4> layout;  ///< reorientation of each of them onto Figure 2
  /// Seams in the order (1,2), (2,3), (4,3), (1,4), as in eqs. 2.2 and 2.3.
  std::array<VertexSeam, 4> seams;
  /// Scaled residuals of kappa12 = lambda14 kappa43, kappa14 = lambda12 kappa23 (2.6) and
  /// lambda12 - lambda43 = kappa14 kappa43, lambda14 - lambda23 = kappa12 kappa23 (2.7), in this order (signed).
  std::array<double, 4> g1Relations{};
  double g1Residual = 0.0;  ///< max |g1Relations|
  /// Scaled residuals of the six relations of eq. 3.17 in the paper's order (signed); only when all four seams are G2
  /// at V (otherwise mu, nu are not defined).
  std::optional<std::array<double, 6>> g2Relations;
  std::optional<double> g2Residual;  ///< max |g2Relations|
};

struct CornerOptions {
  Tolerances tol;  ///< classification thresholds (scale them to the model: Tolerances::forModelSize)
  /// Length used to make curvatures and second derivatives dimensionless (1/L is "no curvature"). Default: the
  /// largest control-box diagonal of the patches at the vertex.
  std::optional<double> lengthScale;
  /// Only for the overload without links: two corner edges are one seam when the points at a quarter of each edge
  /// (from the vertex) lie within this distance of the other edge. Default: 100 x tol.distance.
  std::optional<double> linkTolerance;
};

struct CornerReport {
  Vec3 point = Vec3::Zero();           ///< mean of the corner points
  double cornerGap = 0.0;              ///< largest distance of a corner point from `point`
  std::vector<PatchCorner> corners;    ///< as given
  /// Sectors around the vertex in order (a patch whose edge collapses at the vertex contributes one sector made of
  /// its two corners); each entry lists its corner indices (one, or two for a collapsed edge).
  std::vector<std::vector<int>> sectors;
  /// +1/-1 per corner: the orientation (of u x v) that makes the normals consistent across the seams around the vertex.
  std::vector<int> orientation;
  int valence = 0;       ///< number of sectors
  bool closed = false;   ///< the sectors close around the vertex (interior vertex), else it is on the boundary
  bool degenerate = false;              ///< some corner has a vanishing normal (S_u x S_v = 0, e.g. a pole)
  std::vector<int> degenerateCorners;   ///< their indices
  /// Largest angle (degrees) between the consistently oriented unit normals of the non-degenerate corners of one fan
  /// (maximum over the fans); empty when no fan has two corners with a normal.
  std::optional<double> normalSpreadDeg;
  /// Largest difference of normal curvature (1/length), over every tangent direction, between two non-degenerate
  /// corners of one fan (their second fundamental forms compared in the fan's mean tangent plane; johansson.md, "The
  /// curvature spread at a vertex"). 0 when every seam at the vertex is G2 there; for a vertex of valence n it is
  /// the residual of the thesis' curvature-point system (one common form from 3n corner values). Only for fans whose
  /// normals lie within 10 degrees of their mean (else there is no common tangent plane to compare in); empty when no
  /// fan has two such corners.
  std::optional<double> curvatureSpread;
  /// curvatureSpread relative to max(largest |normal curvature| at the vertex, 1 / lengthScale).
  std::optional<double> curvatureSpreadRel;
  std::optional<FourPatchVertex> fourPatch;  ///< closed, valence 4, no degenerate corner, every seam linked
  std::vector<std::string> notes;            ///< why a part was not computed, orientation conflicts, ...
};

/// Analyses the vertex where `corners` of `patches` meet, with the seams between their edges given by `links`.
/// Errors: kInvalidInput for an empty corner list, an index out of range, a link whose edge does not pass through
/// its corner, or a non-3-D patch.
Result<CornerReport> analyzeCorner(std::span<const Patch> patches, std::span<const PatchCorner> corners,
                                   std::span<const CornerLink> links, const CornerOptions& options = {});

/// Same, finding the links by geometry (CornerOptions::linkTolerance).
Result<CornerReport> analyzeCorner(std::span<const Patch> patches, std::span<const PatchCorner> corners,
                                   const CornerOptions& options = {});

/// Converts the lengths of `report` (the point, the corner gap; the curvature spread as 1/length) to another unit,
/// as scaleLengths(SeamReport&) does.
void scaleLengths(CornerReport& report, double scale);

/// The links between the edges of `corners` found by geometry: two edges through the vertex are one seam when the
/// point at a quarter of each (measured from the vertex) lies within `tolerance` of the other edge curve.
std::vector<CornerLink> findCornerLinks(std::span<const Patch> patches, std::span<const PatchCorner> corners,
                                        double tolerance);

/// Reorients `s` by `layout` (the definition in PatchLayout), for tests and tools.
BSplineSurface applyLayout(const BSplineSurface& s, const PatchLayout& layout);

}  // namespace seam
