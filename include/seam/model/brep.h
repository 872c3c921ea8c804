#pragma once
// The B-rep topology of a model with trimmed faces (issue 34 §1), as plain data: no OpenCASCADE type. The
// faces' surfaces are the model's patches; everything else (vertices, edges with their 3-D curves, the loops
// of pcurves that bound each face in its patch's (u, v) parameters, shells, solids) is held here. The JSON
// model format stores it as the top-level "brep" object (docs/format.md); src/occt/brep_model.* makes it from
// and into OpenCASCADE shapes. Ids are 0-based indices into the arrays of BRepTopology.
#include <string>
#include <vector>

#include "seam/core/result.h"
#include "seam/core/types.h"
#include "seam/spline/bspline_curve.h"

namespace seam {

struct Model;

struct BRepVertex {
  Vec3 point = Vec3::Zero();
  double tolerance = 0.0;  ///< model units; >= 0
};

/// An edge: a 3-D curve over [t0, t1] from vertex v0 (at t0) to vertex v1 (at t1). A degenerate edge (a
/// face's side collapsed to a point, the pole of a sphere) has no 3-D curve, only its pcurves and its one
/// vertex (v0 == v1).
struct BRepEdge {
  int v0 = 0, v1 = 0;
  double t0 = 0.0, t1 = 1.0;
  double tolerance = 0.0;
  bool degenerate = false;
  BSplineCurve curve;  ///< 3-D (rational allowed); unused when degenerate
};

/// An edge's use in a loop of a face: its orientation in the loop (reversed: the loop runs from t1 to t0) and
/// its pcurve, a 2-D curve in the face patch's (u, v) parameters over [t0, t1] (the edge's own parameters:
/// the pcurve at t lies where the 3-D curve is at t). A periodic face's seam edge appears twice in a loop,
/// once in each orientation, each use with its own pcurve.
struct BRepCoedge {
  int edge = 0;
  bool reversed = false;
  double t0 = 0.0, t1 = 1.0;
  BSplineCurve pcurve;
};

/// A face on patch `patch` (index into Model::patches), bounded by `loops` (the first the outer loop, the
/// others holes; each loop is closed: every coedge ends where the next one starts, the last where the first
/// starts). `reversed`: the face's normal is the patch's S_u x S_v reversed.
struct BRepFace {
  int patch = 0;
  bool reversed = false;
  double tolerance = 0.0;
  std::vector<std::vector<BRepCoedge>> loops;
  /// True for a face whose loops do not close in the file it was read from (its wire's edges do not connect and
  /// OpenCASCADE's BRepCheck_Analyzer finds it invalid as read). Such a face is kept as it was read, so that a
  /// conversion loses nothing: validateBRep does not require its loops to close, and the writers write it as it
  /// is (invalid, as the input was). JSON: `"open_as_read": "yes"`.
  bool openAsRead = false;
};

/// A face in a shell, a shell in a solid, or a top-level shape, with its orientation there.
struct BRepUse {
  int id = 0;
  bool reversed = false;
};

struct BRepShell {
  std::vector<BRepUse> faces;
};

struct BRepSolid {
  std::vector<BRepUse> shells;
};

/// A top-level shape of the model: a solid, a shell or a face (in this order of the source shape's traversal,
/// so that a shape made again from the topology lists its faces in the same order as the source).
struct BRepRoot {
  enum class Kind { kSolid, kShell, kFace };
  Kind kind = Kind::kFace;
  BRepUse use;
};

struct BRepTopology {
  std::vector<BRepVertex> vertices;
  std::vector<BRepEdge> edges;
  std::vector<BRepFace> faces;
  std::vector<BRepShell> shells;
  std::vector<BRepSolid> solids;
  std::vector<BRepRoot> roots;
};

/// Checks `brep` against `model`'s patches: every id in range; tolerances finite and >= 0; ranges finite,
/// non-empty and inside their curves' domains (within kBRepDomainRelTol of the domain's length); 3-D curves
/// 3-D, pcurves 2-D; no pcurve of a non-degenerate edge of zero length (all its control points equal); every
/// pcurve inside its patch's domain (within kBRepDomainRelTol of the domain's size, sampled); every loop
/// closed: where a coedge ends and the next starts, the patch's two points are at most the two vertices' and
/// two edges' tolerances + kBRepClosureRelTol x the model diagonal apart; each face on a distinct patch.
/// kInvalidInput naming `source` and the object (`brep face 3: loop 0: coedge 2: ...`).
Status validateBRep(const Model& model, const BRepTopology& brep, const std::string& source);

/// Loops may close with this gap beyond the tolerances of their vertices and edges, relative to the model
/// diagonal.
inline constexpr double kBRepClosureRelTol = 1e-9;
/// A pcurve may leave its patch's domain by this fraction of the domain's size: OpenCASCADE's pcurves
/// overshoot a bounded surface by up to their edge's tolerance (trj3_s1-al-214.stp); the patch is evaluated
/// there by extending its end spans (as OpenCASCADE does).
inline constexpr double kBRepDomainRelTol = 1e-3;
/// A pcurve that runs along a side of its patch's domain within this fraction of the domain's size is an
/// iso-parameter edge (as kIsoEdgeRelTol of the STEP/IGES reader).
inline constexpr double kBRepIsoRelTol = 1e-7;

/// The faces of `brep` that are trimmed: all but those bounded by one loop whose every pcurve runs along a
/// side of the patch's domain (control points within kBRepIsoRelTol of the side) and which together cover the
/// whole box.
int countTrimmedFaces(const Model& model, const BRepTopology& brep);

}  // namespace seam
