#pragma once
// A seam model: named patches (surfaces) and curves, as read from a JSON/.bpt file (and later STEP/IGES).
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "seam/core/result.h"
#include "seam/core/types.h"
#include "seam/spline/bspline_curve.h"
#include "seam/spline/bspline_surface.h"

namespace seam {

/// How a patch was given in the file (the geometry is always held as a B-spline surface).
enum class PatchKind { kBSpline, kBezier };

struct Patch {
  std::string name;
  PatchKind kind = PatchKind::kBSpline;
  BSplineSurface surface;
};

struct Curve {
  std::string name;
  BSplineCurve curve;
};

/// Axis-aligned box; empty() until a point is added.
struct BoundingBox {
  Vec3 min = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 max = Vec3::Constant(-std::numeric_limits<double>::infinity());
  [[nodiscard]] bool empty() const { return !(min.array() <= max.array()).all(); }
  void add(const Vec3& p) {
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  void add(const BoundingBox& b) {
    if (!b.empty()) { add(b.min); add(b.max); }
  }
  [[nodiscard]] double diagonal() const { return empty() ? 0.0 : (max - min).norm(); }
};

/// Bounding box of the control points (contains the surface: convex-hull property, positive weights).
BoundingBox controlBox(const BSplineSurface& s);
BoundingBox controlBox(const BSplineCurve& c);

/// The trimmed-face topology of a model (vertices, edges, faces with their loops of pcurves, shells, solids):
/// include/seam/model/brep.h.
struct BRepTopology;

struct Model {
  std::vector<Patch> patches;
  std::vector<Curve> curves;
  /// Faces of the source B-rep (STEP/IGES) that are trimmed: each of them is held here as the patch of its
  /// parameter box, without its trim loops. A writer that holds only patches (JSON, the patch route to STEP/IGES)
  /// would write those faces untrimmed, so it refuses such a model (issue 34 §1: never a lossy output); the B-rep
  /// routes of src/occt (convertCadFile, healBRepFile) keep the trims. 0 for JSON and .bpt models.
  int trimmedFaces = 0;
  /// The B-rep topology of the faces (issue 34 §1): every face lies on one patch and is bounded by loops of
  /// pcurves in that patch's (u, v) parameters, edges shared between faces. Read from STEP/IGES (when every
  /// face's pcurves fit its patch) and from JSON ("brep", docs/format.md); written to JSON and, through
  /// OpenCASCADE, to STEP/IGES. Null for patch-only models. Immutable once made (copies of the model share
  /// it): the repairs (heal, join, corner) drop it from the model they return, and a trimmed model without it
  /// is refused by the patch-only writers.
  std::shared_ptr<const BRepTopology> brep;

  [[nodiscard]] const Patch* findPatch(const std::string& name) const;
  [[nodiscard]] const Curve* findCurve(const std::string& name) const;
  /// Box of every control point of every patch and curve.
  [[nodiscard]] BoundingBox boundingBox() const;
};

/// Ok when `model` holds no trimmed B-rep faces, or holds them with their topology (Model::brep) and `output`
/// is a writer that keeps it (`keepsBRep`: JSON); else kInvalidInput naming `output` and the number of
/// trimmed faces that a patch-only output would write untrimmed (issue 34 §1). Every patch writer calls it
/// first.
Status checkNoTrimsLost(const Model& model, const std::string& output, bool keepsBRep = false);

}  // namespace seam
