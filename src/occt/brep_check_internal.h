#pragma once
// The B-rep check of a shape already in memory: checkBRepFile's work after reading (the B-rep heal checks the
// shape it is about to write, before and after each change).
#include <filesystem>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Shape.hxx>

#include "occt/cad_internal.h"
#include "seam/occt/brep_check.h"

namespace seam::occt::detail {

/// Checks `shape` as checkBRepFile checks the shape it reads from `file` (which names the model in messages and
/// warnings): `labels` give the faces' entities, `units` the file's unit, `readWarnings` come first in the
/// report's warnings. Faces are named "F<n>" in TopExp::MapShapes order, edges numbered in the edge map's order.
/// `onlyEdges`, when given, selects the edges analysed (the others are left out of the report: the heal checks again
/// only the edges its changes can reach).
using EdgeFilter = std::function<bool(const TopoDS_Edge&)>;
Result<BRepCheckReport> checkBRepShape(const TopoDS_Shape& shape, const std::filesystem::path& file,
                                       FaceLabels labels, const FileUnits& units,
                                       const std::vector<std::string>& readWarnings,
                                       const BRepCheckOptions& options, const EdgeFilter& onlyEdges = {});

/// The pairs of `faces` (TopExp::MapShapes order; FaceOverlap::a and ::b are 0-based indices into it) that lie on
/// each other within `tol`, inside both faces' trims (src/occt/brep_overlap.cpp; docs/check-output.md, "Overlapping
/// faces"), sorted by (a, b); `skippedFaces` faces had samples on another face but trims the samples do not read
/// right (a face of zero area, a sliver) and were left out.
struct BRepOverlapSearch {
  std::vector<FaceOverlap> overlaps;
  int skippedFaces = 0;
};
BRepOverlapSearch findBRepOverlaps(const TopTools_IndexedMapOfShape& faces, double tol, const OverlapOptions& options);

/// A seam is worse after a change (a heal, a write and read back) when its gap (angle) grows by more than this
/// fraction of the tolerance beyond max(before, tolerance): a tenth of a tolerance is below what the tolerance says
/// about the geometry. Angles use seam's strict scale, min(tolerance, kStrictAngleDeg), not the verdict's tolerance.
inline constexpr double kWorseSlackRel = 0.1;

/// Why the seam `after` is worse than `before`, "" when it is not. A crease (angle above `creaseDeg`) is worse when
/// its angle changes by more than the angle tolerance either way (its angle is the design's); any other seam when its
/// angle grows beyond max(before, tolerance); any seam when its gap grows beyond max(before, tolerance). The gaps
/// of the reason are shown in `units`' shown unit, named (the heal's table shows a cm file's gaps in cm; this text
/// gave them in mm, unnamed, beside it); the default shows model units, unnamed for a unit-less model.
std::string seamWorseThan(const SeamReport& after, const SeamReport& before, const Tolerances& tol, double creaseDeg,
                          const ModelUnits& units = {});

/// The middle point of a seam's 3-D edge (its drawing polyline), where seams of two checks of the same model are
/// paired: the edge numbers of a file read back need not be those of the input.
inline Vec3 seamMidpoint(const BRepSeam& s) { return s.curve.empty() ? Vec3::Zero() : s.curve[s.curve.size() / 2]; }

/// The seams of `seams` whose midpoint (`midOf`) is nearest to `mid`, with every other one within `slack` of that
/// distance (coincident edges of touching solids share a midpoint).
template <typename SeamT, typename MidOf>
std::vector<const SeamT*> nearestSeams(const std::vector<SeamT>& seams, const Vec3& mid, double slack, MidOf midOf) {
  double best = std::numeric_limits<double>::infinity();
  for (const SeamT& h : seams) best = std::min(best, (midOf(h) - mid).norm());
  std::vector<const SeamT*> out;
  for (const SeamT& h : seams)
    if ((midOf(h) - mid).norm() <= best + slack) out.push_back(&h);
  return out;
}

/// A seam of a second check of the same model (the file written and read back) that is worse than every seam of the
/// first at its place.
struct SeamWorse {
  const BRepSeam* before = nullptr;  ///< the first check's seam nearest to it
  const BRepSeam* after = nullptr;
  std::string why;
};
/// Every seam of `after` worse than the seams of `before` at its place (paired by midpoint within `tol.distance`).
std::vector<SeamWorse> seamsWorse(const std::vector<BRepSeam>& before, const std::vector<BRepSeam>& after,
                                  const Tolerances& tol, double creaseDeg, const ModelUnits& units = {});

}  // namespace seam::occt::detail
