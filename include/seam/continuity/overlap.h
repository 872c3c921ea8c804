#pragma once
// Overlapping faces (issue 38 §11, as CATIA's Connect Checker finds them): two patches that lie on each other over a
// part of their area, within the distance tolerance (a face copied twice, a patch laid over another, a split face
// whose pieces overlap). Seams (patches that meet along an edge) are not overlaps; nor are surfaces that cross or
// touch at a point.
#include <vector>

#include "seam/core/tolerances.h"
#include "seam/core/types.h"
#include "seam/model/model.h"

namespace seam {

struct OverlapOptions {
  /// Interior samples per direction of each patch: the points (i + 1/2) / n of its domain, i = 0..n-1 (none lies on
  /// a boundary, so a neighbour that only shares an edge never counts).
  int samplesPerDirection = 8;
  /// A pair overlaps when at least this fraction of one patch's samples lie within the distance tolerance of the
  /// other patch's interior (its closest point not on its boundary). 1/8: a strip one sample row wide is enough.
  double minFraction = 0.125;
  /// Threads (0: all hardware threads); the result is the same for every value.
  int threads = 0;
};

/// One overlapping pair: `fraction` of A's samples lie on B (or of B's on A, whichever is larger).
struct FaceOverlap {
  int a = 0, b = 0;         ///< indices into Model::patches, a < b
  double fraction = 0.0;    ///< of the samples of the patch that lies more on the other, in [minFraction, 1]
  double maxDistance = 0.0; ///< the largest distance of those samples to the other patch (achieved, <= tolerance)
  Vec3 point = Vec3::Zero();///< one of those samples (the first in sample order)
};

/// Every overlapping pair of `model`'s 3-D patches, sorted by (a, b). Candidate pairs are those whose control boxes
/// come within `distanceTolerance`; a sample is tested only when it lies within the tolerance of the other patch's
/// control box and of the slab of its control points around their mean plane (both contain the surface), then
/// projected onto it (Gauss-Newton from the nearest point of a 5 x 5 grid).
std::vector<FaceOverlap> findOverlaps(const Model& model, double distanceTolerance, const OverlapOptions& options = {});

}  // namespace seam
