// OCC_CATCH_SIGNALS converts a signal raised inside OpenCASCADE into a Standard_Failure only when this macro is set
// (as in cad_io.cpp; see docs/reliability.md, "OpenCASCADE guards").
#ifndef OCC_CONVERT_SIGNALS
#define OCC_CONVERT_SIGNALS
#endif
#include "seam/occt/brep_heal.h"

#include <fmt/format.h>

#include <BRepCheck_Analyzer.hxx>
#include <BRepGProp.hxx>
#include <BRepLib.hxx>
#include <BRepTools.hxx>
#include <BRepAdaptor_Curve.hxx>
#include <BRepBuilderAPI_Copy.hxx>
#include <BRepBndLib.hxx>
#include <Bnd_Box.hxx>
#include <BndLib_Add2dCurve.hxx>
#include <Bnd_Box2d.hxx>
#include <Precision.hxx>
#include <BRepTopAdaptor_FClass2d.hxx>
#include <BRep_Builder.hxx>
#include <BRep_Tool.hxx>
#include <Adaptor3d_CurveOnSurface.hxx>
#include <BSplCLib.hxx>
#include <GeomLib.hxx>
#include <Geom_Curve.hxx>
#include <GProp_GProps.hxx>
#include <Geom2dAdaptor_Curve.hxx>
#include <Geom2d_Curve.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <Geom_BSplineSurface.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <OSD_Signal.hxx>
#include <ShapeAnalysis_Edge.hxx>
#include <ShapeAnalysis_Surface.hxx>
#include <ShapeBuild_Edge.hxx>
#include <ShapeFix_Edge.hxx>
#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <TopExp.hxx>
#include <TopExp_Explorer.hxx>
#include <TopTools_IndexedDataMapOfShapeListOfShape.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopoDS.hxx>
#include <XCAFDoc_DocumentTool.hxx>
#include <XCAFDoc_ShapeTool.hxx>
#include <TopoDS_Vertex.hxx>
#include <Geom_Curve.hxx>
#include <math_Matrix.hxx>

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <algorithm>
#include <cmath>
#include <exception>
#include <map>
#include <numbers>
#include <set>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "occt/brep_check_internal.h"
#include "occt/cad_internal.h"
#include "occt/face_mesh.h"
#include "seam/continuity/model_check.h"
#include "seam/io/file.h"
#include "seam/model/brep.h"
#include "seam/occt/cad_io.h"

namespace seam::occt {

namespace fs = std::filesystem;

namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;
/// Condition samples per healed edge at most (a long edge across many knot spans).
constexpr int kMaxEdgeSamples = 400;
/// Samples per knot span crossed (the conditions are exact at samples only; the check after certifies the rest).
constexpr int kSamplesPerSpan = 3;
/// Gauss-Newton steps (and relative step at which they stop) of the closest point on the partner's boundary.
constexpr int kPartnerIterations = 16;
constexpr double kPartnerStepRel = 1e-14;
/// Regularisation of the normal equations relative to their largest diagonal entry: the least-squares solution of
/// least norm to about this precision (the conditions are scaled to tolerances, so 1e-10 is far below them).
constexpr double kRidgeRel = 1e-10;
/// The largest normal matrix (entries, n x n) summed densely (normalMatrix): 32 MB, n up to 2 000.
constexpr double kDenseNormalMaxEntries = 4e6;
/// Weight of the fairness rows (second differences of the displacement over the net) against a position condition
/// (both per unit of displacement, in tolerances): small, so that the conditions come first.
constexpr double kFairnessRel = 0.03;
/// Weight of the conditions that hold a face's other seams, against 1 for those of the seams it heals: where the two
/// meet (a shared vertex of a kinked seam and a smooth one) the compromise keeps the smooth seam.
constexpr double kHeldWeight = 10.0;
/// Points of an edge's 3-D curve tested against a surface (is a gap one of the trims alone?).
constexpr int kCurveOnSurfaceSamples = 32;
/// Rounds of "revert the faces that made something worse, check again".
constexpr int kMaxRevertRounds = 3;
/// Local refinement before a face moves (knots inserted next to the edges it heals, so that only the control points
/// near them move, not the whole face): a pcurve whose (u, v) box is narrower than kIsoEdgeRel x the face's extent in
/// one direction runs along the other; kRefineStepRel x the face's extent is the spacing of the (degree) knots
/// inserted on the face's side of it, and an existing knot nearer than half a spacing counts as one of them.
constexpr double kIsoEdgeRel = 0.02;
constexpr double kRefineStepRel = 0.08;
/// Heals made from the input, each without the changes that the read-back of the one before found making a seam of
/// the written file worse (the last one writes the input unchanged if it still does).
constexpr int kMaxReadBackAttempts = 4;
/// A normal shorter than this fraction of |S_u| |S_v| (a pole) gives no G1 or fold condition there.
constexpr double kPoleNormalRel = 1e-8;
/// Samples of ShapeAnalysis_Edge::CheckSameParameter when an edge's tolerance is recomputed, and the margin put on
/// the deviation found (it samples).
constexpr int kToleranceSamples = 23;
constexpr double kToleranceMargin = 1.5;
/// A rebuilt 3-D edge curve is approximated within this fraction of the distance tolerance (readers that rebuild
/// pcurves from it then find the trims where they were); one that stays further than the tolerance is not used.
constexpr double kCurveRebuildRel = 1e-3;

using detail::isSignal;

/// The B-spline surface of a face that heal may edit (in its own frame: the face's location maps it to the model),
/// or why not.
struct Editable {
  Handle(Geom_BSplineSurface) surface;
  gp_Trsf toLocal;    ///< model -> the surface's frame
  gp_Trsf toModel;    ///< the surface's frame -> model
};

Result<Editable> editableSurface(const TopoDS_Face& face) {
  TopLoc_Location loc;
  Handle(Geom_Surface) g = BRep_Tool::Surface(face, loc);
  if (g.IsNull()) return invalidInput("the face has no surface");
  while (const auto t = Handle(Geom_RectangularTrimmedSurface)::DownCast(g)) {
    if (t.IsNull()) break;
    g = t->BasisSurface();
  }
  const auto bs = Handle(Geom_BSplineSurface)::DownCast(g);
  if (bs.IsNull())
    return invalidInput(fmt::format("its surface is a {}, not a B-spline surface (analytic surfaces are kept)",
                                    g->DynamicType()->Name()));
  Editable e;
  e.surface = bs;
  e.toModel = loc.Transformation();
  e.toLocal = e.toModel.Inverted();
  return e;
}

/// The rational basis functions R_ij of a B-spline surface at (u, v) and their u and v derivatives, for the
/// (p+1) x (q+1) functions that do not vanish there: S = sum R_ij P_ij exactly (weights fixed), so every condition
/// on S, S_u, S_v is linear in the control points.
struct BasisAt {
  int firstU = 1, firstV = 1;            ///< 1-based indices of the first non-zero functions
  int nu = 0, nv = 0;
  std::vector<double> r, ru, rv;         ///< row-major nu x nv
};

class SurfaceBasis {
 public:
  explicit SurfaceBasis(const Handle(Geom_BSplineSurface)& s)
      : s_(s),
        flatU_(1, flatLength(s->UMultiplicities(), s->UDegree(), s->IsUPeriodic())),
        flatV_(1, flatLength(s->VMultiplicities(), s->VDegree(), s->IsVPeriodic())) {
    s->UKnotSequence(flatU_);
    s->VKnotSequence(flatV_);
    s->Bounds(u0_, u1_, v0_, v1_);
  }
  /// The 1-based pole index of basis function k (periodic surfaces wrap around).
  [[nodiscard]] int poleU(int k) const { return wrap(k, s_->NbUPoles(), s_->IsUPeriodic()); }
  [[nodiscard]] int poleV(int k) const { return wrap(k, s_->NbVPoles(), s_->IsVPeriodic()); }
  [[nodiscard]] BasisAt at(double u, double v) const {
    u = std::clamp(u, u0_, u1_);
    v = std::clamp(v, v0_, v1_);
    const int p = s_->UDegree(), q = s_->VDegree();
    math_Matrix bu(1, 2, 1, p + 1), bv(1, 2, 1, q + 1);
    BasisAt b;
    BSplCLib::EvalBsplineBasis(1, p + 1, flatU_, u, b.firstU, bu, s_->IsUPeriodic());
    BSplCLib::EvalBsplineBasis(1, q + 1, flatV_, v, b.firstV, bv, s_->IsVPeriodic());
    b.nu = p + 1;
    b.nv = q + 1;
    const size_t n = static_cast<size_t>(b.nu * b.nv);
    b.r.resize(n);
    b.ru.resize(n);
    b.rv.resize(n);
    double W = 0, Wu = 0, Wv = 0;
    for (int i = 0; i < b.nu; ++i)
      for (int j = 0; j < b.nv; ++j) {
        const double w = s_->Weight(poleU(b.firstU + i), poleV(b.firstV + j));
        W += w * bu(1, i + 1) * bv(1, j + 1);
        Wu += w * bu(2, i + 1) * bv(1, j + 1);
        Wv += w * bu(1, i + 1) * bv(2, j + 1);
      }
    for (int i = 0; i < b.nu; ++i)
      for (int j = 0; j < b.nv; ++j) {
        const double w = s_->Weight(poleU(b.firstU + i), poleV(b.firstV + j));
        const double n0 = bu(1, i + 1) * bv(1, j + 1), nU = bu(2, i + 1) * bv(1, j + 1),
                     nV = bu(1, i + 1) * bv(2, j + 1);
        const size_t k = static_cast<size_t>(i * b.nv + j);
        b.r[k] = w * n0 / W;
        b.ru[k] = w * (nU * W - n0 * Wu) / (W * W);
        b.rv[k] = w * (nV * W - n0 * Wv) / (W * W);
      }
    return b;
  }

 private:
  static int flatLength(const TColStd_Array1OfInteger& mults, int degree, bool periodic) {
    return BSplCLib::KnotSequenceLength(mults, degree, periodic);
  }
  static int wrap(int k, int n, bool periodic) { return periodic ? ((k - 1) % n + n) % n + 1 : k; }
  Handle(Geom_BSplineSurface) s_;
  TColStd_Array1OfReal flatU_, flatV_;
  double u0_ = 0, u1_ = 0, v0_ = 0, v1_ = 0;
};

/// One face seen from an edge: surface and pcurve evaluators, the orientation's sign.
struct Side {
  TopoDS_Face face;
  Handle(Geom2d_Curve) pcurve;
  double first = 0, last = 0;
  GeomAdaptor_Surface surface;  ///< in model coordinates (BRep_Tool::Surface(face): location applied)
  Geom2dAdaptor_Curve curve;
};

std::optional<Side> sideOf(const TopoDS_Edge& edge, const TopoDS_Face& face) {
  Side s;
  s.face = face;
  s.pcurve = BRep_Tool::CurveOnSurface(edge, face, s.first, s.last);
  const Handle(Geom_Surface) surf = BRep_Tool::Surface(face);
  if (s.pcurve.IsNull() || surf.IsNull() || !(s.last > s.first)) return std::nullopt;
  s.surface.Load(surf);
  s.curve.Load(s.pcurve, s.first, s.last);
  return s;
}

/// The parameter of the point of G's boundary image closest to x, from `s` (Gauss-Newton on |S_G(c_G(s)) - x|^2).
double closestOnSide(const Side& G, const gp_Pnt& x, double s) {
  const double range = G.last - G.first;
  for (int it = 0; it < kPartnerIterations; ++it) {
    gp_Pnt2d uv;
    gp_Vec2d d;
    G.curve.D1(s, uv, d);
    gp_Pnt q;
    gp_Vec su, sv;
    G.surface.D1(uv.X(), uv.Y(), q, su, sv);
    const gp_Vec c1 = su * d.X() + sv * d.Y();
    const double c1n2 = c1.SquareMagnitude();
    if (!(c1n2 > 0.0)) break;
    const double next = std::clamp(s + gp_Vec(q, x).Dot(c1) / c1n2, G.first, G.last);
    if (!std::isfinite(next)) break;
    const bool done = std::abs(next - s) <= kPartnerStepRel * range;
    s = next;
    if (done) break;
  }
  return s;
}

/// J^T J, of which the LDL^T below reads the lower triangle. Up to kDenseNormalMaxEntries entries, only that
/// triangle, summed row by row into a dense array (each pair of a row's entries once) and then made sparse; every
/// larger system takes Eigen's sparse product. linkrods' eleven systems (n up to 1 701, 25-92 entries a row on
/// average), assembly included: 0.45 s with the sparse product, 0.27 s so. The sums are the same products added in
/// another order (the heal tables and written files of the real files are the same).
Eigen::SparseMatrix<double> normalMatrix(const Eigen::SparseMatrix<double, Eigen::RowMajor>& J) {
  const Eigen::Index n = J.cols();
  if (static_cast<double>(n) * static_cast<double>(n) > kDenseNormalMaxEntries) return J.transpose() * J;
  Eigen::MatrixXd lower = Eigen::MatrixXd::Zero(n, n);
  const int* outer = J.outerIndexPtr();  // J is compressed (setFromTriplets): row r is [outer[r], outer[r + 1])
  const int* inner = J.innerIndexPtr();
  const double* value = J.valuePtr();
  for (Eigen::Index r = 0; r < J.rows(); ++r) {
    const int end = outer[r + 1];
    // Columns ascend within a row: entry a pairs with the entries b <= a, all in column inner[a] of `lower`.
    for (int a = outer[r]; a < end; ++a) {
      double* column = lower.col(inner[a]).data();
      const double va = value[a];
      for (int k = a; k < end; ++k) column[inner[k]] += va * value[k];
    }
  }
  return lower.sparseView();
}

/// The linear least-squares system of one face's move: rows over the band's control points (3 unknowns each).
class MoveSystem {
 public:
  MoveSystem(const Editable& e, double sigmaPos, double sigmaAngle)
      : e_(e), basis_(e.surface), sigmaPos_(sigmaPos), sigmaAngle_(sigmaAngle) {}

  /// Adds the band's columns for the basis functions that do not vanish at (u, v).
  void addToBand(double u, double v) {
    const BasisAt b = basis_.at(u, v);
    for (int i = 0; i < b.nu; ++i)
      for (int j = 0; j < b.nv; ++j) {
        const std::pair<int, int> key{basis_.poleU(b.firstU + i), basis_.poleV(b.firstV + j)};
        if (!column_.count(key)) column_.emplace(key, static_cast<int>(column_.size()));
      }
  }
  /// The weight of the rows added from now on.
  void setWeight(double w) { weight_ = w; }
  /// S(u, v) = x (model coordinates).
  void position(double u, double v, const gp_Pnt& x) {
    const BasisAt b = basis_.at(u, v);
    gp_Pnt s = e_.surface->Value(u, v);
    const gp_XYZ target = x.Transformed(e_.toLocal).XYZ() - s.XYZ();
    for (int c = 0; c < 3; ++c) {
      Row row;
      for (size_t k = 0; k < b.r.size(); ++k) add(row, b, k, c, b.r[k] / sigmaPos_);
      row.rhs = target.Coord(c + 1) / sigmaPos_;
      push(std::move(row));
    }
  }
  /// n . S_u = n . S_v = `keep` ? their present values : 0 (n a unit normal in model coordinates): the tangent plane
  /// of the surface contains the plane normal to n (keep = false), or does not turn about it (keep = true).
  void tangentPlane(double u, double v, const gp_Dir& nModel, bool keep) {
    const BasisAt b = basis_.at(u, v);
    gp_Pnt p;
    gp_Vec su, sv;
    e_.surface->D1(u, v, p, su, sv);
    const gp_Dir n = nModel.Transformed(e_.toLocal);
    for (int d = 0; d < 2; ++d) {
      const gp_Vec& sd = d == 0 ? su : sv;
      const double len = sd.Magnitude();
      if (!(len > 0.0)) continue;
      const double scale = 1.0 / (len * sigmaAngle_);
      Row row;
      for (size_t k = 0; k < b.r.size(); ++k) {
        const double coef = (d == 0 ? b.ru[k] : b.rv[k]) * scale;
        for (int c = 0; c < 3; ++c) add(row, b, k, c, coef * n.Coord(c + 1));
      }
      row.rhs = keep ? 0.0 : -gp_Vec(n).Dot(sd) * scale;
      push(std::move(row));
    }
  }
  /// The displacement of every band control point (model-frame lengths), or nothing when the band is empty.
  [[nodiscard]] std::map<std::pair<int, int>, gp_Vec> solve() const {
    std::map<std::pair<int, int>, gp_Vec> out;
    const Eigen::Index n = 3 * static_cast<Eigen::Index>(column_.size());
    if (n == 0 || rows_.empty()) return out;
    // The least-squares system is sparse (a condition touches the (p+1)(q+1) poles around its point): the rows are
    // assembled as a sparse matrix J (one entry per condition and pole: the rows' own size), and the normal
    // equations J^T J x = J^T b formed by a sparse product and factored by a sparse LDL^T, so that a dense net's wide
    // band stays cheap. (Forming J^T J from one triplet per pair of a row's entries held 48^2 triplets per tangent
    // row: 1.46 GB and 42 s for linkrods.step.)
    size_t nnz = 0;
    for (const Row& r : rows_) nnz += r.cols.size();
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(nnz + 18 * column_.size());
    std::vector<double> b;
    b.reserve(rows_.size() + 6 * column_.size());
    for (const Row& r : rows_) {
      const auto row = static_cast<Eigen::Index>(b.size());
      for (size_t a = 0; a < r.cols.size(); ++a) entries.emplace_back(row, r.cols[a], r.vals[a]);
      b.push_back(r.rhs);
    }
    // Fairness: the second differences of the displacement over the net (a pole outside the band moves by 0), so
    // that between the condition samples the band moves smoothly and tapers to its border instead of the
    // least-norm solution's zigzag (which folds dense nets): one row per band pole, direction and coordinate.
    const double fair = kFairnessRel / sigmaPos_;
    const int nu = e_.surface->NbUPoles(), nv = e_.surface->NbVPoles();
    for (const auto& [key, col] : column_) {
      for (int dir = 0; dir < 2; ++dir) {
        const auto [i, j] = key;
        const std::pair<int, int> prev = dir == 0 ? std::pair{i - 1, j} : std::pair{i, j - 1};
        const std::pair<int, int> next = dir == 0 ? std::pair{i + 1, j} : std::pair{i, j + 1};
        if ((dir == 0 && (i == 1 || i == nu)) || (dir == 1 && (j == 1 || j == nv))) continue;
        std::vector<std::pair<Eigen::Index, double>> terms = {{col, -2.0 * fair}};
        for (const auto& nb : {prev, next})
          if (const auto it = column_.find(nb); it != column_.end()) terms.emplace_back(it->second, fair);
        for (int c = 0; c < 3; ++c) {
          const auto row = static_cast<Eigen::Index>(b.size());
          for (const auto& [ca, va] : terms) entries.emplace_back(row, 3 * ca + c, va);
          b.push_back(0.0);
        }
      }
    }
    Eigen::SparseMatrix<double, Eigen::RowMajor> J(static_cast<Eigen::Index>(b.size()), n);
    J.setFromTriplets(entries.begin(), entries.end());
    entries = {};
    const Eigen::VectorXd rhs =
        J.transpose() * Eigen::Map<const Eigen::VectorXd>(b.data(), static_cast<Eigen::Index>(b.size()));
    Eigen::SparseMatrix<double> M = normalMatrix(J);
    const double ridge = kRidgeRel * std::max(M.diagonal().maxCoeff(), std::numeric_limits<double>::min());
    for (Eigen::Index k = 0; k < n; ++k) M.coeffRef(k, k) += ridge;
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt(M);
    if (ldlt.info() != Eigen::Success) return out;  // no move (the seams say no condition could be set)
    const Eigen::VectorXd x = ldlt.solve(rhs);
    if (!x.allFinite()) return out;

    for (const auto& [key, col] : column_) {
      const gp_Vec d(x(3 * col), x(3 * col + 1), x(3 * col + 2));
      out.emplace(key, d);
    }
    return out;
  }

 private:
  struct Row {
    std::vector<Eigen::Index> cols;
    std::vector<double> vals;
    double rhs = 0.0;
  };
  void add(Row& row, const BasisAt& b, size_t k, int c, double value) const {
    const int i = static_cast<int>(k) / b.nv, j = static_cast<int>(k) % b.nv;
    const auto it = column_.find({basis_.poleU(b.firstU + i), basis_.poleV(b.firstV + j)});
    if (it == column_.end() || value == 0.0) return;  // a control point outside the band does not move
    row.cols.push_back(3 * static_cast<Eigen::Index>(it->second) + c);
    row.vals.push_back(value);
  }
  void push(Row&& row) {
    if (row.cols.empty()) return;
    for (double& v : row.vals) v *= weight_;
    row.rhs *= weight_;
    rows_.push_back(std::move(row));
  }
  double weight_ = 1.0;
  const Editable& e_;
  SurfaceBasis basis_;
  double sigmaPos_, sigmaAngle_;
  std::map<std::pair<int, int>, int> column_;
  std::vector<Row> rows_;
};

/// The unit normal of a side at its pcurve parameter t, oriented as the face, or nothing at a pole.
std::optional<gp_Dir> normalAt(const Side& s, double t) {
  const gp_Pnt2d uv = s.curve.Value(t);
  gp_Pnt p;
  gp_Vec su, sv;
  s.surface.D1(uv.X(), uv.Y(), p, su, sv);
  const gp_Vec n = su.Crossed(sv);
  if (!(n.Magnitude() > kPoleNormalRel * su.Magnitude() * sv.Magnitude()) || !(n.Magnitude() > 0.0))
    return std::nullopt;
  const gp_Dir d(n);
  return s.face.Orientation() == TopAbs_REVERSED ? d.Reversed() : d;
}

/// Samples of an edge for the conditions: more where the face's knot spans are many.
int edgeSamples(const Editable& e, int perEdge) {
  return std::clamp(kSamplesPerSpan * (e.surface->NbUKnots() + e.surface->NbVKnots()), perEdge, kMaxEdgeSamples);
}

/// What to do with one seam.
struct Plan {
  enum Kind { kNothing, kHeal, kCreaseGap } kind = kNothing;
  int mover = 0;    ///< 1-based face index of the face that moves
  int partner = 0;  ///< the other face
};

/// A face's state before the heal (to put it back).
struct Saved {
  Handle(Geom_BSplineSurface) copy;
  /// The surface before the knots of the local refinement were inserted, and those knots (to put it back exactly:
  /// the knots removed, then every pole and weight of the original set again).
  Handle(Geom_BSplineSurface) original;
  std::vector<double> insertedU, insertedV;
};

/// Inserts knots next to the pcurves `edges` of `face` (its surface `e`) that run along a parameter direction, on the
/// face's side of them (kIsoEdgeRel, kRefineStepRel): the surface is the same, only its representation is finer.
/// The knots inserted are added to `saved`.
void refineNextTo(const Editable& e, const TopoDS_Face& face, const std::vector<Side>& edges, Saved& saved) {
  double fu0, fu1, fv0, fv1;
  BRepTools::UVBounds(face, fu0, fu1, fv0, fv1);
  const Handle(Geom_BSplineSurface)& bs = e.surface;
  double su0, su1, sv0, sv1;
  bs->Bounds(su0, su1, sv0, sv1);
  for (const Side& side : edges) {
    Bnd_Box2d box;
    BndLib_Add2dCurve::Add(side.curve, 0.0, box);
    if (box.IsVoid()) continue;
    double cu0, cv0, cu1, cv1;
    box.Get(cu0, cv0, cu1, cv1);
    for (int dir = 0; dir < 2; ++dir) {
      // dir 0: the pcurve runs along u (narrow in v): knots in v.
      const double lo = dir == 0 ? fv0 : fu0, hi = dir == 0 ? fv1 : fu1;
      const double c0 = dir == 0 ? cv0 : cu0, c1 = dir == 0 ? cv1 : cu1;
      const double s0 = dir == 0 ? sv0 : su0, s1 = dir == 0 ? sv1 : su1;
      const double extent = hi - lo;
      if (!(extent > 0.0) || c1 - c0 > kIsoEdgeRel * extent) continue;
      if ((dir == 0 ? bs->IsVPeriodic() : bs->IsUPeriodic())) continue;
      const double step = kRefineStepRel * extent, mid = 0.5 * (c0 + c1);
      const int degree = dir == 0 ? bs->VDegree() : bs->UDegree();
      // The face lies on the side of the pcurve where most of its (u, v) box is.
      const double sign = hi - mid >= mid - lo ? 1.0 : -1.0;
      for (int k = 1; k <= degree; ++k) {
        const double t = (sign > 0 ? c1 : c0) + sign * k * step;
        if (!(t > s0 && t < s1)) break;
        const int nk = dir == 0 ? bs->NbVKnots() : bs->NbUKnots();
        bool near = false;
        for (int i = 1; i <= nk && !near; ++i)
          near = std::abs((dir == 0 ? bs->VKnot(i) : bs->UKnot(i)) - t) < 0.5 * step;
        if (near) continue;
        if (saved.original.IsNull()) saved.original = Handle(Geom_BSplineSurface)::DownCast(bs->Copy());
        if (dir == 0) {
          bs->InsertVKnot(t, 1, 0.0, /*Add=*/true);
          saved.insertedV.push_back(t);
        } else {
          bs->InsertUKnot(t, 1, 0.0, /*Add=*/true);
          saved.insertedU.push_back(t);
        }
      }
    }
  }
}

/// Puts a face's surface back as it was before refineNextTo and the move: the inserted knots removed, then every pole
/// and weight of the original set again (bit for bit).
void unrefine(const Handle(Geom_BSplineSurface)& bs, const Saved& saved) {
  if (saved.original.IsNull()) return;
  auto removeKnot = [&](bool u, double t) {
    const int n = u ? bs->NbUKnots() : bs->NbVKnots();
    for (int i = 1; i <= n; ++i)
      if ((u ? bs->UKnot(i) : bs->VKnot(i)) == t) {
        const int m = u ? bs->UMultiplicity(i) : bs->VMultiplicity(i);
        if (u)
          bs->RemoveUKnot(i, m - 1, Precision::Infinite());
        else
          bs->RemoveVKnot(i, m - 1, Precision::Infinite());
        return;
      }
  };
  for (const double t : saved.insertedU) removeKnot(true, t);
  for (const double t : saved.insertedV) removeKnot(false, t);
  const Handle(Geom_BSplineSurface)& o = saved.original;
  if (bs->NbUPoles() != o->NbUPoles() || bs->NbVPoles() != o->NbVPoles()) return;  // cannot happen: knots restored
  for (int i = 1; i <= o->NbUPoles(); ++i)
    for (int j = 1; j <= o->NbVPoles(); ++j) {
      if (o->IsURational() || o->IsVRational())
        bs->SetPole(i, j, o->Pole(i, j), o->Weight(i, j));
      else
        bs->SetPole(i, j, o->Pole(i, j));
    }
}


/// What a move did to a face, on the kHealFoldGrid grid of its (u, v) box, points inside its trims: whether its
/// normal reverses anywhere (a fold), and its area against before, as the ratio of the sums of |S_u x S_v| (the
/// same grid weighs both: the ratio of the areas within the grid's quadrature error, far below kHealFaceAreaRel).
struct FaceChange {
  bool folds = false;
  double areaRatio = 1.0;
  double maxMove = 0.0;  ///< the largest |S_now - S_before| at the grid's points (in the surface's own frame)
};
/// The points of the kHealFoldGrid grid of a face's (u, v) box that lie inside its trims (classified once per face:
/// the trims do not move): by detail::gridInsideTrims' scan where the trims are closed polygons in (u, v), which
/// agrees with OpenCASCADE's classifier but within 1e-5 of the box's size of a trim
/// (OcctGridInsideTrims.AgreesWithOpenCascadesClassifierAwayFromTheTrimsOnEveryRealFace), else point by point by
/// that classifier.
std::vector<gp_Pnt2d> gridInside(const TopoDS_Face& face) {
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
  BRepTools::UVBounds(face, u0, u1, v0, v1);
  try {  // the scan first; where it cannot (open trims) or OpenCASCADE's sampling fails, point by point
    if (std::optional<std::vector<gp_Pnt2d>> scanned = detail::gridInsideTrims(face, kHealFoldGrid, u0, u1, v0, v1))
      return std::move(*scanned);
  } catch (const Standard_Failure&) {
  }
  BRepTopAdaptor_FClass2d inside(face, Precision::PConfusion());
  std::vector<gp_Pnt2d> out;
  for (int i = 0; i <= kHealFoldGrid; ++i)
    for (int j = 0; j <= kHealFoldGrid; ++j) {
      const gp_Pnt2d uv(u0 + (u1 - u0) * i / kHealFoldGrid, v0 + (v1 - v0) * j / kHealFoldGrid);
      if (inside.Perform(uv) != TopAbs_OUT) out.push_back(uv);
    }
  return out;
}

/// gridInside of the faces `which` (indices into `faceMap`), on `threads` threads (0: all hardware threads): each
/// face's classifier is its own and reads the face only; a failure is raised here in the order of `which`.
std::vector<std::vector<gp_Pnt2d>> gridsInside(const TopTools_IndexedMapOfShape& faceMap, const std::vector<int>& which,
                                               int threads) {
  std::vector<std::vector<gp_Pnt2d>> out(which.size());
  detail::forEachOnThreads(static_cast<int>(which.size()), threads, [&](int k) {
    out[static_cast<size_t>(k)] = gridInside(TopoDS::Face(faceMap(which[static_cast<size_t>(k)])));
  });
  return out;
}

FaceChange compareFace(const std::vector<gp_Pnt2d>& grid, const Handle(Geom_BSplineSurface)& now,
                       const Handle(Geom_BSplineSurface)& before) {
  FaceChange c;
  double areaNow = 0.0, areaBefore = 0.0;
  for (const gp_Pnt2d& uv : grid) {
    gp_Pnt p;
    gp_Vec au, av, bu, bv;
    gp_Pnt q;
    now->D1(uv.X(), uv.Y(), p, au, av);
    before->D1(uv.X(), uv.Y(), q, bu, bv);
    c.maxMove = std::max(c.maxMove, p.Distance(q));
    const gp_Vec na = au.Crossed(av), nb = bu.Crossed(bv);
    areaNow += na.Magnitude();
    areaBefore += nb.Magnitude();
    if (!(nb.Magnitude() > kPoleNormalRel * bu.Magnitude() * bv.Magnitude())) continue;  // a pole before
    if (!(na.Dot(nb) > 0.0)) c.folds = true;
  }
  if (areaBefore > 0.0) c.areaRatio = areaNow / areaBefore;
  return c;
}

/// The edge's 3-D curve rebuilt as the image of its pcurve on `face` (GeomLib::BuildCurve3d within `tolerance`),
/// and its tolerance set to what its pcurves now need (ShapeAnalysis_Edge::CheckSameParameter). An edge whose curve
/// cannot be built keeps its curve and gets the tolerance its deviation needs.
void rebuildEdgeCurve(const TopoDS_Edge& edge, const TopoDS_Face& face, double tolerance) {
  double first = 0, last = 0;
  const Handle(Geom2d_Curve) pc = BRep_Tool::CurveOnSurface(edge, face, first, last);
  const Handle(Geom_Surface) surface = BRep_Tool::Surface(face);
  BRep_Builder builder;
  if (!pc.IsNull() && !surface.IsNull() && last > first) {
    Adaptor3d_CurveOnSurface cos(new Geom2dAdaptor_Curve(pc, first, last), new GeomAdaptor_Surface(surface));
    Handle(Geom_Curve) curve;
    double maxDeviation = 0, averageDeviation = 0;
    GeomLib::BuildCurve3d(kCurveRebuildRel * tolerance, cos, first, last, curve, maxDeviation, averageDeviation);
    if (!curve.IsNull() && maxDeviation <= tolerance) {
      builder.UpdateEdge(edge, curve, TopLoc_Location(), BRep_Tool::Tolerance(edge));
      builder.Range(edge, first, last, /*Only3d=*/true);
    }
  }
  double deviation = 0.0;
  ShapeAnalysis_Edge().CheckSameParameter(edge, deviation, kToleranceSamples);
  builder.UpdateEdge(edge, std::max(deviation * kToleranceMargin, Precision::Confusion()));
}

/// Puts a vertex at the mean of its edges' curve ends that touch it, its tolerance covering them all.
void placeVertex(const TopoDS_Vertex& vertex, const TopTools_IndexedDataMapOfShapeListOfShape& vertexEdges) {
  const int k = vertexEdges.FindIndex(vertex);
  if (k == 0) return;
  std::vector<gp_Pnt> ends;
  for (TopTools_ListOfShape::Iterator it(vertexEdges.FindFromIndex(k)); it.More(); it.Next()) {
    const TopoDS_Edge edge = TopoDS::Edge(it.Value());
    if (BRep_Tool::Degenerated(edge)) continue;
    double first = 0, last = 0;
    const Handle(Geom_Curve) c = BRep_Tool::Curve(edge, first, last);
    if (c.IsNull()) continue;
    TopoDS_Vertex v0, v1;
    TopExp::Vertices(edge, v0, v1);
    if (v0.IsSame(vertex)) ends.push_back(c->Value(first));
    if (v1.IsSame(vertex)) ends.push_back(c->Value(last));
  }
  if (ends.empty()) return;
  gp_XYZ mean(0, 0, 0);
  for (const gp_Pnt& p : ends) mean += p.XYZ();
  mean /= static_cast<double>(ends.size());
  double reach = 0.0;
  for (const gp_Pnt& p : ends) reach = std::max(reach, p.Distance(gp_Pnt(mean)));
  BRep_Builder().UpdateVertex(vertex, gp_Pnt(mean), std::max(reach * kToleranceMargin, Precision::Confusion()));
}

/// True when the edge's 3-D curve lies on the face's surface within `tolerance` at kCurveOnSurfaceSamples points.
bool curveOnSurface(const TopoDS_Edge& edge, const TopoDS_Face& face, double tolerance) {
  double first = 0, last = 0;
  const Handle(Geom_Curve) c = BRep_Tool::Curve(edge, first, last);
  const Handle(Geom_Surface) surface = BRep_Tool::Surface(face);
  if (c.IsNull() || surface.IsNull()) return false;
  const Handle(ShapeAnalysis_Surface) sas = new ShapeAnalysis_Surface(surface);
  for (int i = 0; i <= kCurveOnSurfaceSamples; ++i) {
    sas->ValueOfUV(c->Value(first + (last - first) * i / kCurveOnSurfaceSamples), tolerance);
    if (!(sas->Gap() <= tolerance)) return false;
  }
  return true;
}

/// The pcurves of an edge on two faces before they were projected again, to put them back.
struct TrimFix {
  TopoDS_Edge edge;
  TopoDS_Face fa, fb;
  Handle(Geom2d_Curve) pa, pb;
  double tolerance = 0.0;
};

/// Puts a TrimFix's pcurves and tolerance back.
void restore(const TrimFix& fix) {
  BRep_Builder b;
  b.UpdateEdge(fix.edge, fix.pa, fix.fa, fix.tolerance);
  b.UpdateEdge(fix.edge, fix.pb, fix.fb, fix.tolerance);
  b.UpdateEdge(fix.edge, fix.tolerance);
}

/// Projects the edge's 3-D curve onto both faces as their new pcurves (ShapeFix_Edge), then makes the edge
/// same-parameter; nothing when a projection fails (and then nothing changes).
std::optional<TrimFix> reprojectPCurves(const TopoDS_Edge& edge, const TopoDS_Face& fa, const TopoDS_Face& fb,
                                        double tolerance) {
  TrimFix fix;
  fix.edge = edge;
  fix.fa = fa;
  fix.fb = fb;
  double f = 0, l = 0;
  fix.pa = BRep_Tool::CurveOnSurface(edge, fa, f, l);
  fix.pb = BRep_Tool::CurveOnSurface(edge, fb, f, l);
  fix.tolerance = BRep_Tool::Tolerance(edge);
  if (fix.pa.IsNull() || fix.pb.IsNull()) return std::nullopt;
  ShapeFix_Edge sfe;
  for (const TopoDS_Face& face : {fa, fb}) {
    ShapeBuild_Edge().RemovePCurve(edge, face);  // ShapeFix_Edge::FixRemovePCurve removes only mismatched ones
    if (!sfe.FixAddPCurve(edge, face, false, tolerance) || BRep_Tool::CurveOnSurface(edge, face, f, l).IsNull()) {
      restore(fix);  // FixAddPCurve returns true when it added the pcurve
      return std::nullopt;
    }
  }
  sfe.FixSameParameter(edge);
  return fix;
}

bool faceValid(const TopoDS_Face& face) { return BRepCheck_Analyzer(face).IsValid(); }

}  // namespace

namespace {

/// Changes a heal must not make (a read-back of an earlier attempt found them making a seam of the file worse), by
/// the face's and the edge's index in the shape as read (the same file reads the same way every time), each with
/// the reason.
struct HealExclusions {
  std::map<int, std::string> faces;  ///< faces that must not move
  std::map<int, std::string> trims;  ///< edges whose pcurves must not be projected again
  [[nodiscard]] size_t size() const { return faces.size() + trims.size(); }
};

/// The heal of a shape in memory (healBRepFile between reading and writing). `report` is filled in; `reprojected`
/// receives the edges whose pcurves were projected again (the faces moved are report.facesChanged).
Status healShape(const TopoDS_Shape& shape, const fs::path& file, const detail::FaceLabels& labels,
                 const detail::FileUnits& units, const std::vector<std::string>& readWarnings,
                 const BRepHealOptions& options, const HealExclusions& excluded, BRepHealReport& report,
                 std::set<int>& reprojected, std::optional<BRepCheckReport>& checkedBefore) {
  BRepCheckOptions co;
  co.tolerances = options.tolerances;
  co.threads = options.threads;
  co.sewFreeEdges = false;  // the file's topology is what is written
  // The check of the input: the same for every attempt (the same file, read the same way), so made once.
  if (!checkedBefore) {
    Result<BRepCheckReport> first = detail::checkBRepShape(shape, file, labels, units, readWarnings, co);
    if (!first) return first.status();
    checkedBefore = std::move(first).value();
  }
  const Result<BRepCheckReport> before = *checkedBefore;
  const Tolerances tol = before->tolerances;
  report.tolerances = tol;
  report.units = before->units;
  report.warnings = before->import.warnings;
  report.freeEdges = static_cast<int>(before->freeEdges.size());
  std::map<std::string, std::string> entityOf;
  for (const CadFace& f : before->import.faces) entityOf[f.patch] = f.entity;

  TopTools_IndexedMapOfShape faceMap;
  TopExp::MapShapes(shape, TopAbs_FACE, faceMap);
  TopTools_IndexedDataMapOfShapeListOfShape edgeFaces;
  TopExp::MapShapesAndAncestors(shape, TopAbs_EDGE, TopAbs_FACE, edgeFaces);
  // Which faces can move, and which surfaces are shared (an in-place edit would move every face on it).
  std::map<const Standard_Transient*, int> surfaceUsers;
  std::vector<std::optional<Editable>> editable(static_cast<size_t>(faceMap.Extent()) + 1);
  std::vector<std::string> whyNot(editable.size());
  for (int i = 1; i <= faceMap.Extent(); ++i) {
    Result<Editable> e = editableSurface(TopoDS::Face(faceMap(i)));
    if (e) {
      ++surfaceUsers[e->surface.get()];
      editable[static_cast<size_t>(i)] = *e;
    } else {
      whyNot[static_cast<size_t>(i)] = e.status().message();
    }
  }
  for (int i = 1; i <= faceMap.Extent(); ++i)
    if (auto& e = editable[static_cast<size_t>(i)]; e && surfaceUsers[e->surface.get()] > 1) {
      e.reset();
      whyNot[static_cast<size_t>(i)] = "its surface is shared with another face";
    }
  // A face that OpenCASCADE finds invalid as read (trj3's F31: one open edge around a sliver) has no inside to test
  // a move against (the fold and area tests sample the face inside its trims): it does not move.
  for (int i = 1; i <= faceMap.Extent(); ++i)
    if (auto& e = editable[static_cast<size_t>(i)]; e && !faceValid(TopoDS::Face(faceMap(i)))) {
      e.reset();
      whyNot[static_cast<size_t>(i)] = "it is invalid as read (OpenCASCADE's BRepCheck_Analyzer): its inside, where a "
                                       "move is tested for folds, is not defined";
    }
  for (const auto& [fi, why] : excluded.faces)
    if (fi >= 1 && fi <= faceMap.Extent()) {
      editable[static_cast<size_t>(fi)].reset();
      whyNot[static_cast<size_t>(fi)] = why;
    }
  auto faceIndex = [](const std::string& name) { return std::stoi(name.substr(1)); };

  std::map<int, size_t> seamOfEdge;
  for (size_t k = 0; k < before->seams.size(); ++k) seamOfEdge[before->seams[k].edge] = k;
  // Stage 1: gaps of the trims alone. Where the 3-D edge lies on both surfaces (within the distance tolerance) but
  // the two pcurves' images are further apart, the surfaces meet and the trims are off: both pcurves are projected
  // again from the 3-D curve (ShapeFix_Edge), nothing moves. A seam that gets worse, or a face OpenCASCADE then
  // finds invalid where it was valid, gets its pcurves back.
  std::map<int, TrimFix> trimFixes;  // by edge index
  for (const BRepSeam& s : before->seams) {
    const int ia = faceIndex(s.a), ib = faceIndex(s.b);
    if (ia == ib || !(s.report.g0Max > tol.distance) || s.report.g0Max > report.maxGap) continue;
    if (excluded.trims.count(s.edge)) continue;
    const TopoDS_Edge edge = TopoDS::Edge(edgeFaces.FindKey(s.edge));
    const TopoDS_Face fa = TopoDS::Face(faceMap(ia)), fb = TopoDS::Face(faceMap(ib));
    if (!curveOnSurface(edge, fa, tol.distance) || !curveOnSurface(edge, fb, tol.distance)) continue;
    std::optional<TrimFix> fix = reprojectPCurves(edge, fa, fb, tol.distance);
    if (fix) trimFixes.emplace(s.edge, std::move(*fix));
  }
  // `base` with the seams of `edges` checked again (a change reaches no other seam: the trims of stage 1 change one
  // edge each; a moved face, its own edges).
  auto recheck = [&](const BRepCheckReport& base, const TopTools_IndexedMapOfShape& edges) -> Result<BRepCheckReport> {
    Result<BRepCheckReport> partial = detail::checkBRepShape(
        shape, file, labels, units, readWarnings, co, [&](const TopoDS_Edge& e) { return edges.Contains(e); });
    if (!partial) return partial.status();
    BRepCheckReport merged = base;
    std::map<int, size_t> at;
    for (size_t k = 0; k < merged.seams.size(); ++k) at[merged.seams[k].edge] = k;
    for (BRepSeam& s : partial->seams)
      if (const auto it = at.find(s.edge); it != at.end()) merged.seams[it->second] = std::move(s);
    return merged;
  };
  Result<BRepCheckReport> mid = before;
  if (!trimFixes.empty()) {
    TopTools_IndexedMapOfShape fixedEdges;
    for (const auto& [ei, fix] : trimFixes) fixedEdges.Add(fix.edge);
    mid = recheck(*before, fixedEdges);
    if (!mid) return mid.status();
    for (BRepSeam& s : mid->seams) {
      const auto fixed = trimFixes.find(s.edge);
      if (fixed == trimFixes.end()) continue;
      const BRepSeam& was = before->seams[seamOfEdge.at(s.edge)];
      const std::string why = detail::seamWorseThan(s.report, was.report, tol, options.creaseAngleDeg, report.units);
      const bool invalid = !faceValid(fixed->second.fa) || !faceValid(fixed->second.fb);
      if (why.empty() && !invalid && s.report.g0Max < was.report.g0Max) continue;
      restore(fixed->second);  // its pcurves back: the seam is the input's again
      trimFixes.erase(fixed);
      s = was;
    }
  }
  std::map<int, const SeamReport*> midOfEdge;
  for (const BRepSeam& s : mid->seams) midOfEdge[s.edge] = &s.report;

  // The plan of every seam.
  std::vector<Plan> plans(before->seams.size());
  for (size_t k = 0; k < before->seams.size(); ++k) {
    const BRepSeam& s = before->seams[k];
    const SeamReport& now = midOfEdge.count(s.edge) ? *midOfEdge.at(s.edge) : s.report;
    BRepHealSeam hs;
    hs.edge = s.edge;
    hs.a = s.a;
    hs.b = s.b;
    hs.entityA = entityOf[s.a];
    hs.entityB = entityOf[s.b];
    hs.before = s.report;
    if (!s.curve.empty()) hs.midpoint = s.curve[s.curve.size() / 2];
    const double gap = now.g0Max, angle = now.g1MaxDeg;
    const bool trimFixed = trimFixes.count(s.edge) > 0;
    const bool crease = angle > options.creaseAngleDeg;
    const bool needG0 = gap > tol.distance;
    const bool needG1 = options.continuity >= GeometricClass::kG1 && !crease && angle > tol.angleDeg;
    const int ia = faceIndex(s.a), ib = faceIndex(s.b);
    if (crease) ++report.creasesKept;
    if (!needG0 && !needG1 && trimFixed) {
      hs.action = "trims projected again: gap closed";
      ++report.seamsToHeal;
    } else if (!needG0 && !needG1) {
      hs.action = crease ? "crease kept" : options.continuity >= GeometricClass::kG1 ? "already G1" : "already G0";
    } else if (gap > report.maxGap) {
      hs.action = fmt::format("left: the gap is above --max-gap ({:.4g})", report.maxGap);
      ++report.seamsToHeal;
    } else if (ia == ib) {
      hs.action = "left: the seam of a closed face with itself";
      ++report.seamsToHeal;
    } else {
      ++report.seamsToHeal;
      const auto& ea = editable[static_cast<size_t>(ia)];
      const auto& eb = editable[static_cast<size_t>(ib)];
      if (!ea && !eb) {
        hs.action = fmt::format("left: neither face can move ({}: {}; {}: {}); the edge's tolerance covers the gap",
                                s.a, whyNot[static_cast<size_t>(ia)], s.b, whyNot[static_cast<size_t>(ib)]);
      } else {
        const bool moveA = ea && (!eb || ea->surface->NbUPoles() * ea->surface->NbVPoles() >=
                                             eb->surface->NbUPoles() * eb->surface->NbVPoles());
        plans[k] = {crease ? Plan::kCreaseGap : Plan::kHeal, moveA ? ia : ib, moveA ? ib : ia};
        hs.action = crease ? "crease: gap closed" : "healed";
        hs.moved = moveA ? s.a : s.b;
      }
    }
    report.seams.push_back(std::move(hs));
  }

  // Each moving face once, in face order; the seams of faces moved before it are held.
  std::map<int, std::vector<size_t>> byMover;
  for (size_t k = 0; k < plans.size(); ++k)
    if (plans[k].kind != Plan::kNothing) byMover[plans[k].mover].push_back(k);
  std::map<int, Saved> saved;
  std::map<int, double> displacement;  // by face: its largest control-point move (mm, a bound)
  std::map<int, double> moved;         // by face: its largest move at its fold grid's points (mm, measured)
  const double sigmaAngle = tol.angleDeg * kDegToRad;
  auto moveFaces = [&](const std::map<int, std::vector<size_t>>& movers) {
    for (const auto& [fi, seamIdx] : movers) {
      const TopoDS_Face face = TopoDS::Face(faceMap(fi));
      const Editable& e = *editable[static_cast<size_t>(fi)];
      Saved sv;
      {
        std::vector<Side> along;
        for (size_t k : seamIdx)
          if (auto a = sideOf(TopoDS::Edge(edgeFaces.FindKey(before->seams[k].edge)), face)) along.push_back(*a);
        refineNextTo(e, face, along, sv);
      }
      MoveSystem sys(e, tol.distance, sigmaAngle);
      const int n = edgeSamples(e, options.samplesPerEdge);
      std::set<int> targetEdges;
      // Targets: the band along each edge to heal, then its conditions.
      struct Target {
        Side self, other;
        bool crease;
      };
      std::vector<Target> targets;
      for (size_t k : seamIdx) {
        const int ei = before->seams[k].edge;
        const TopoDS_Edge edge = TopoDS::Edge(edgeFaces.FindKey(ei));
        TopoDS_Face other = TopoDS::Face(faceMap(plans[k].partner));
        // The face as it is bound to this edge (orientation of its occurrence in the ancestors' list).
        std::optional<Side> a = sideOf(edge, face), b = sideOf(edge, other);
        if (!a || !b) continue;
        targets.push_back({*a, *b, plans[k].kind == Plan::kCreaseGap});
        targetEdges.insert(ei);
        for (int i = 0; i <= n; ++i) {
          const gp_Pnt2d uv = a->curve.Value(a->first + (a->last - a->first) * i / n);
          sys.addToBand(uv.X(), uv.Y());
        }
      }
      for (const Target& t : targets) {
        for (int i = 0; i <= n; ++i) {
          const double ta = t.self.first + (t.self.last - t.self.first) * i / n;
          const gp_Pnt2d uv = t.self.curve.Value(ta);
          const gp_Pnt x = t.self.surface.Value(uv.X(), uv.Y());
          const double tb0 = t.other.first + (ta - t.self.first) / (t.self.last - t.self.first) *
                                                 (t.other.last - t.other.first);
          const double tb = closestOnSide(t.other, x, tb0);
          const gp_Pnt2d uvb = t.other.curve.Value(tb);
          const gp_Pnt target = t.other.surface.Value(uvb.X(), uvb.Y());
          // (u, v) in the editable surface's own parameters: the face's pcurve is in them (a trimmed wrapper keeps
          // its basis surface's parameters).
          sys.position(uv.X(), uv.Y(), target);
          if (t.crease) {
            if (const auto nf = normalAt(t.self, ta)) sys.tangentPlane(uv.X(), uv.Y(), *nf, true);
          } else if (options.continuity >= GeometricClass::kG1) {
            if (const auto ng = normalAt(t.other, tb)) sys.tangentPlane(uv.X(), uv.Y(), *ng, false);
          } else if (const auto nf = normalAt(t.self, ta)) {
            sys.tangentPlane(uv.X(), uv.Y(), *nf, true);  // G0 only: the gap closes, the angle is kept
          }
        }
      }
      // Held: every other edge of the face.
      TopTools_IndexedMapOfShape faceEdges;
      TopExp::MapShapes(face, TopAbs_EDGE, faceEdges);
      for (int k = 1; k <= faceEdges.Extent(); ++k) {
        const TopoDS_Edge edge = TopoDS::Edge(faceEdges(k));
        if (BRep_Tool::Degenerated(edge) || targetEdges.count(edgeFaces.FindIndex(edge))) continue;
        // A free edge (the model's own boundary) is not held: where a seam's kink reaches it, it turns with the face.
        if (edgeFaces.FindFromIndex(edgeFaces.FindIndex(edge)).Extent() < 2) continue;
        const std::optional<Side> s = sideOf(edge, face);
        if (!s) continue;
        sys.setWeight(kHeldWeight);
        for (int i = 0; i <= n; ++i) {
          const double t = s->first + (s->last - s->first) * i / n;
          const gp_Pnt2d uv = s->curve.Value(t);
          sys.position(uv.X(), uv.Y(), s->surface.Value(uv.X(), uv.Y()));
          if (const auto nf = normalAt(*s, t)) sys.tangentPlane(uv.X(), uv.Y(), *nf, true);
        }
        sys.setWeight(1.0);
      }
      const auto moves = sys.solve();
      if (moves.empty()) {
        unrefine(e.surface, sv);
        continue;
      }
      sv.copy = Handle(Geom_BSplineSurface)::DownCast(e.surface->Copy());
      double largest = 0.0;
      for (const auto& [key, d] : moves) {
        const gp_Pnt p = e.surface->Pole(key.first, key.second);
        e.surface->SetPole(key.first, key.second, gp_Pnt(p.XYZ() + d.XYZ()));
        largest = std::max(largest, d.Magnitude() * std::abs(e.toModel.ScaleFactor()));
      }
      saved.emplace(fi, sv);
      displacement[fi] = largest;
    }
  };
  moveFaces(byMover);

  // Check again; put back every face that made something worse, folded or changed its area too much.
  auto putBack = [&](int fi) {
    const Editable& e = *editable[static_cast<size_t>(fi)];
    const Saved& sv = saved.at(fi);
    for (int i = 1; i <= e.surface->NbUPoles(); ++i)
      for (int j = 1; j <= e.surface->NbVPoles(); ++j) e.surface->SetPole(i, j, sv.copy->Pole(i, j));
    unrefine(e.surface, sv);
    saved.erase(fi);
    displacement.erase(fi);
    moved.erase(fi);
  };
  std::map<int, std::string> reverted;
  Result<BRepCheckReport> after = mid;
  std::map<int, std::vector<gp_Pnt2d>> grids;  // by face: its fold grid's points inside its trims
  auto settle = [&]() -> Status {
    for (int round = 0; !saved.empty(); ++round) {
      // Only the edges of the moved faces can change: they are checked again, the others keep mid's report.
      TopTools_IndexedMapOfShape movedEdges;
      for (const auto& [fi, sv] : saved) TopExp::MapShapes(faceMap(fi), TopAbs_EDGE, movedEdges);
      after = recheck(*mid, movedEdges);
      if (!after) return after.status();
      std::map<int, std::string> bad;
      {
        std::vector<int> needGrid;
        for (const auto& [fi, sv] : saved)
          if (!grids.count(fi)) needGrid.push_back(fi);
        std::vector<std::vector<gp_Pnt2d>> made = gridsInside(faceMap, needGrid, options.threads);
        for (size_t k = 0; k < needGrid.size(); ++k) grids[needGrid[k]] = std::move(made[k]);
      }
      for (const auto& [fi, sv] : saved) {
        const auto& grid = grids.at(fi);
        const Editable& e = *editable[static_cast<size_t>(fi)];
        const FaceChange change = compareFace(grid, e.surface, sv.copy);
        moved[fi] = change.maxMove * std::abs(e.toModel.ScaleFactor());
        if (change.folds)
          bad[fi] = fmt::format("the face would fold (its normal reverses inside its trims; it moved by up to {:.3g} "
                                "mm there, its control points by up to {:.3g} mm)",
                                moved[fi], displacement[fi]);
        else if (std::abs(change.areaRatio - 1.0) > kHealFaceAreaRel)
          bad[fi] = fmt::format("the face's area would change by {:.3g} %", 100.0 * (change.areaRatio - 1.0));
      }
      for (const BRepSeam& s : after->seams) {
        const auto it = seamOfEdge.find(s.edge);
        if (it == seamOfEdge.end()) continue;
        const std::string why =
            detail::seamWorseThan(s.report, before->seams[it->second].report, tol, options.creaseAngleDeg,
                                  report.units);
        if (why.empty()) continue;
        for (const std::string& name : {s.a, s.b}) {
          const int fi = faceIndex(name);
          if (saved.count(fi) && !bad.count(fi)) bad[fi] = fmt::format("seam of edge {} got worse: {}", s.edge, why);
        }
      }
      if (bad.empty()) break;
      if (round + 1 >= kMaxRevertRounds)  // still not settled: every moved face goes back
        for (const auto& [fi, sv] : saved)
          if (!bad.count(fi)) bad[fi] = "the faces around it could not be healed without a seam getting worse";
      for (const auto& [fi, why] : bad) {
        putBack(fi);
        reverted[fi] = why;
      }
      if (saved.empty()) after = mid;
    }
    return Status::ok();
  };
  if (Status st = settle(); !st) return st;
  // The other side: a seam (kink or gap) whose moving face was put back is tried once more with its partner moving
  // instead, where the partner can move and did not move (or go back) in the first pass (linkrods' edge 100: F34,
  // the larger face, goes back; F31 moving alone makes the seam G1; trj3's edge 4: F4 goes back, F2 narrows the
  // gap from 0.00272 to 0.00257).
  std::map<int, std::vector<size_t>> byPartner;
  for (size_t k = 0; k < plans.size(); ++k) {
    Plan& pl = plans[k];
    if (pl.kind != Plan::kHeal || !reverted.count(pl.mover)) continue;
    const int other = pl.partner;
    if (!editable[static_cast<size_t>(other)] || saved.count(other) || reverted.count(other)) continue;
    std::swap(pl.mover, pl.partner);
    BRepHealSeam& hs = report.seams[k];
    hs.moved = faceIndex(hs.a) == other ? hs.a : hs.b;
    byPartner[other].push_back(k);
  }
  if (!byPartner.empty()) {
    moveFaces(byPartner);
    if (Status st = settle(); !st) return st;
  }

  // The 3-D curves of the moved faces' edges are built again on a face that did not move where there is one (the
  // partner of a healed seam), else on the moved face, so that a reader that rebuilds pcurves from them finds the
  // same trims; then each edge's tolerance is what its geometry needs, and the vertices' tolerances follow.
  std::set<int> movedFaces;
  for (const auto& [fi, sv] : saved) movedFaces.insert(fi);
  for (const int fi : movedFaces) {
    for (TopExp_Explorer ex(faceMap(fi), TopAbs_EDGE); ex.More(); ex.Next()) {
      const TopoDS_Edge edge = TopoDS::Edge(ex.Current());
      if (BRep_Tool::Degenerated(edge)) continue;
      TopoDS_Face anchor = TopoDS::Face(faceMap(fi));
      const int ei = edgeFaces.FindIndex(edge);
      for (TopTools_ListOfShape::Iterator it(edgeFaces.FindFromIndex(ei)); it.More(); it.Next())
        if (!movedFaces.count(faceMap.FindIndex(it.Value()))) anchor = TopoDS::Face(it.Value());
      rebuildEdgeCurve(edge, anchor, tol.distance);
    }
  }
  // Their vertices: at the mean of the ends of their edges' curves, with the tolerance that covers the ends (a
  // reader that trims edges at their vertices' projections, as OpenCASCADE's STEP reader does, finds the same ends).
  TopTools_IndexedMapOfShape vertices;
  for (const int fi : movedFaces) TopExp::MapShapes(faceMap(fi), TopAbs_VERTEX, vertices);
  TopTools_IndexedDataMapOfShapeListOfShape vertexEdges;
  TopExp::MapShapesAndAncestors(shape, TopAbs_VERTEX, TopAbs_EDGE, vertexEdges);
  for (int k = 1; k <= vertices.Extent(); ++k) placeVertex(TopoDS::Vertex(vertices(k)), vertexEdges);
  if (!saved.empty()) BRepLib::UpdateTolerances(shape, /*verifyFaceTolerance=*/false);

  // The report.
  std::map<int, const BRepSeam*> afterOfEdge;
  for (const BRepSeam& s : after->seams) afterOfEdge[s.edge] = &s;
  report.achieved = true;
  for (size_t k = 0; k < report.seams.size(); ++k) {
    BRepHealSeam& hs = report.seams[k];
    if (const auto it = afterOfEdge.find(hs.edge); it != afterOfEdge.end()) hs.after = it->second->report;
    const bool wasPlanned = plans[k].kind != Plan::kNothing;
    if (wasPlanned && reverted.count(plans[k].mover)) {
      hs.action = fmt::format("left: {} put back as it was: {}", hs.moved, reverted[plans[k].mover]);
      hs.moved.clear();
    } else if (wasPlanned && !saved.count(plans[k].mover)) {
      hs.action = "left: no condition could be set along the edge";
      hs.moved.clear();
    }
    if (hs.after) hs.worse = !detail::seamWorseThan(*hs.after, hs.before, tol, options.creaseAngleDeg).empty();
    report.seamsWorse += hs.worse ? 1 : 0;
    const bool target = hs.action != "crease kept" && hs.action.rfind("already", 0) != 0;
    if (!target) continue;
    const GeometricClass want = plans[k].kind == Plan::kCreaseGap || hs.before.g1MaxDeg > options.creaseAngleDeg
                                    ? GeometricClass::kG0
                                    : options.continuity;
    const bool reached = hs.after && meets(hs.after->geometric, want);
    report.seamsHealed += reached ? 1 : 0;
    // A face moved for it, but the seam did not reach the class: say so rather than "healed".
    if (!reached && hs.action == "healed")
      hs.action = fmt::format("moved, {} not reached", toString(want));
    // "Narrowed" only where the gap did narrow: a move can leave it a little wider within the never-worse slack.
    const bool narrowed = hs.after && hs.after->g0Max < hs.before.g0Max;
    if (!reached && hs.action == "crease: gap closed")
      hs.action = narrowed ? "crease: gap narrowed, not closed" : "crease: gap not narrowed";
    else if (!reached && hs.action == "trims projected again: gap closed")
      hs.action = narrowed ? "trims projected again: gap narrowed, not closed" : "trims projected again: gap not narrowed";
    report.achieved = report.achieved && reached;
  }
  for (const auto& [fi, d] : displacement) {
    report.facesChanged.push_back(fmt::format("F{}", fi));
    report.maxSurfaceDisplacement = std::max(report.maxSurfaceDisplacement, d);
    report.faceMoves.push_back({fmt::format("F{}", fi), moved.count(fi) ? moved.at(fi) : d, d});
  }
  for (BRepHealSeam& hs : report.seams)
    if (!hs.moved.empty())
      if (const auto it = moved.find(faceIndex(hs.moved)); it != moved.end()) hs.movedBy = it->second;
  for (const auto& [fi, why] : reverted) {
    report.facesReverted.push_back(fmt::format("F{}", fi));
    report.notes.push_back(fmt::format("F{} put back as it was: {}", fi, why));
  }
  report.trimsReprojected = static_cast<int>(trimFixes.size());
  for (const auto& [ei, fix] : trimFixes) reprojected.insert(ei);
  for (const auto& [fi, why] : excluded.faces)
    report.notes.push_back(fmt::format("F{} was not moved: {}", fi, why));
  for (const auto& [ei, why] : excluded.trims)
    report.notes.push_back(fmt::format("the pcurves of edge {} were left as they are: {}", ei, why));
  if (!trimFixes.empty())
    report.notes.push_back(fmt::format("{} edges had gaps of their trims alone (the 3-D edge lies on both surfaces): "
                                       "their pcurves were projected again from it; no surface moved for them",
                                       trimFixes.size()));
  if (report.freeEdges > 0)
    report.notes.push_back(fmt::format("{} free edges (bounding one face) are left as they are: the heal keeps the "
                                       "file's topology and heals the seams it has",
                                       report.freeEdges));
  return Status::ok();
}

}  // namespace

namespace {

/// A seam of the written file, read back, that is worse than the input's.
struct WorseSeam {
  const BRepHealSeam* input = nullptr;  ///< the input's seam nearest to it (its edge's midpoint)
  std::string why;
};

/// The faces a heal changed (by index): those moved and those of the edges whose pcurves were projected again.
std::set<int> changedFaces(const BRepHealReport& report, const std::set<int>& reprojected) {
  std::set<int> changed;
  for (const std::string& f : report.facesChanged) changed.insert(std::stoi(f.substr(1)));
  for (const BRepHealSeam& h : report.seams)
    if (reprojected.count(h.edge)) {
      changed.insert(std::stoi(h.a.substr(1)));
      changed.insert(std::stoi(h.b.substr(1)));
    }
  return changed;
}

/// Boxes around what a heal changed: the faces moved and the faces of the edges whose pcurves were projected again,
/// with every face that shares a vertex with them (a moved vertex moves the ends of their edges too), each enlarged
/// by the distance tolerance. A seam of the written file whose edge's middle lies in none of them was not changed.
std::vector<Bnd_Box> changedRegion(const TopoDS_Shape& shape, const BRepHealReport& report,
                                   const std::set<int>& reprojected) {
  TopTools_IndexedMapOfShape faceMap;
  TopExp::MapShapes(shape, TopAbs_FACE, faceMap);
  TopTools_IndexedDataMapOfShapeListOfShape vertexFaces;
  TopExp::MapShapesAndAncestors(shape, TopAbs_VERTEX, TopAbs_FACE, vertexFaces);
  const std::set<int> changed = changedFaces(report, reprojected);
  std::set<int> near = changed;
  for (const int fi : changed)
    for (TopExp_Explorer ex(faceMap(fi), TopAbs_VERTEX); ex.More(); ex.Next())
      for (TopTools_ListOfShape::Iterator it(vertexFaces.FindFromKey(ex.Current())); it.More(); it.Next())
        near.insert(faceMap.FindIndex(it.Value()));
  std::vector<Bnd_Box> boxes;
  for (const int fi : near) {
    Bnd_Box box;
    BRepBndLib::Add(faceMap(fi), box);
    box.Enlarge(report.tolerances.distance);
    boxes.push_back(box);
  }
  return boxes;
}

/// The seams of a written STEP/IGES file as `seam check` finds them in what the writer's verification read back,
/// those whose edge's middle lies in `region` only (all when it is empty).
Result<std::vector<BRepSeam>> seamsReadBack(const fs::path& file, const detail::WrittenBack& back,
                                            const BRepHealOptions& options, const std::vector<Bnd_Box>& region) {
  BRepCheckOptions co;
  co.tolerances = options.tolerances;
  co.threads = options.threads;
  co.sewFreeEdges = false;
  detail::EdgeFilter inRegion;
  if (!region.empty())
    inRegion = [&](const TopoDS_Edge& e) {
      if (BRep_Tool::Degenerated(e)) return false;
      BRepAdaptor_Curve c(e);
      const gp_Pnt m = c.Value(0.5 * (c.FirstParameter() + c.LastParameter()));
      return std::any_of(region.begin(), region.end(), [&](const Bnd_Box& b) { return !b.IsOut(m); });
    };
  Result<BRepCheckReport> check =
      detail::checkBRepShape(back.shape, file, back.labels, back.units, back.warnings, co, inRegion);
  if (!check) return invalidInput("it could not be checked: " + check.status().message());
  return std::move(check->seams);
}

/// Every seam of the written file (`written`, read back) that is worse than the input's seam at its place (paired by
/// the edge's midpoint; worse only when worse than every input seam there), and, when `unhealed` (the seams of the
/// input written unchanged, read back) is given, also worse than that: a seam that OpenCASCADE's writer and reader
/// alone make worse is not the heal's doing (`seam convert` writes it the same).
std::vector<WorseSeam> worseSeams(const std::vector<BRepSeam>& written, const BRepHealReport& report,
                                  const BRepHealOptions& options, const std::vector<BRepSeam>* unhealed) {
  std::vector<WorseSeam> worse;
  const double slack = report.tolerances.distance;
  for (const BRepSeam& s : written) {
    if (s.curve.empty()) continue;
    const Vec3 mid = detail::seamMidpoint(s);
    WorseSeam w;
    for (const BRepHealSeam* h : detail::nearestSeams(report.seams, mid, slack, [](const BRepHealSeam& x) {
           return x.midpoint;
         })) {
      const std::string why =
          detail::seamWorseThan(s.report, h->before, report.tolerances, options.creaseAngleDeg, report.units);
      if (why.empty()) {
        w.input = nullptr;
        break;
      }
      if (w.input == nullptr) w = {h, why};
    }
    if (w.input != nullptr && unhealed != nullptr)
      for (const BRepSeam* u : detail::nearestSeams(*unhealed, mid, slack, detail::seamMidpoint))
        if (detail::seamWorseThan(s.report, u->report, report.tolerances, options.creaseAngleDeg).empty())
          w.input = nullptr;
    if (w.input != nullptr) worse.push_back(std::move(w));
  }
  return worse;
}

/// Adds to `excluded` the changes of the last attempt that are to blame for the worse seams of its written file:
/// the faces moved and the edges whose pcurves were projected again on the worse seam's own faces, else on the faces
/// next to them (sharing a seam). False when nothing could be blamed (the caller then gives the heal up).
bool blameReadBack(const std::vector<WorseSeam>& worse, const BRepHealReport& report,
                   const std::set<int>& reprojected, HealExclusions& excluded) {
  auto index = [](const std::string& name) { return std::stoi(name.substr(1)); };
  std::set<int> moved;
  for (const std::string& f : report.facesChanged) moved.insert(index(f));
  std::map<int, std::pair<int, int>> facesOfEdge;
  std::map<int, std::set<int>> neighbours;
  for (const BRepHealSeam& h : report.seams) {
    facesOfEdge[h.edge] = {index(h.a), index(h.b)};
    neighbours[index(h.a)].insert(index(h.b));
    neighbours[index(h.b)].insert(index(h.a));
  }
  const size_t had = excluded.size();
  for (const WorseSeam& w : worse) {
    if (w.input == nullptr) return false;
    const std::string reason = fmt::format("read back from the written file, the seam of {} and {} (edge {}) was "
                                           "worse: {}",
                                           w.input->a, w.input->b, w.input->edge, w.why);
    for (int ring = 0; ring < 2; ++ring) {
      std::set<int> near = {index(w.input->a), index(w.input->b)};
      if (ring == 1)
        for (const int f : std::set<int>(near)) near.insert(neighbours[f].begin(), neighbours[f].end());
      bool blamed = false;
      for (const int f : near)
        if (moved.count(f) && excluded.faces.emplace(f, reason).second) blamed = true;
      for (const int e : reprojected) {
        const auto [fa, fb] = facesOfEdge[e];
        if ((near.count(fa) || near.count(fb)) && excluded.trims.emplace(e, reason).second) blamed = true;
      }
      if (blamed) break;
    }
  }
  return excluded.size() > had;
}

}  // namespace

namespace {

/// The report of a heal whose written file, read back, stayed worse than the input: the input is written unchanged
/// (as `seam convert` writes it) and every seam says why.
Result<BRepHealReport> unchangedAfterReadBack(const fs::path& in, const fs::path& out, const std::string& worse,
                                              BRepHealReport report) {
  CadConvertOptions plain;
  plain.compareSeams = false;  // the heal has compared the seams of this round trip already (roundTripNotes)
  Result<CadConvertReport> unchanged = convertCadFile(in, out, {}, plain);
  if (!unchanged) return unchanged.status();
  for (BRepHealSeam& s : report.seams) {
    if (s.moved.empty() && s.action.rfind("trims projected", 0) != 0) continue;
    s.action = "left: the healed file, read back, had a seam worse than the input (" + worse + ")";
    s.moved.clear();
    s.movedBy = 0.0;
    s.after = s.before;
  }
  report.notes.push_back(fmt::format("nothing of the heal was written: read back from the written file, {}; the "
                                     "output is the input, unchanged",
                                     worse));
  std::erase_if(report.notes, [](const std::string& n) { return n.find("projected again") != std::string::npos; });
  report.facesReverted.insert(report.facesReverted.end(), report.facesChanged.begin(), report.facesChanged.end());
  report.facesChanged.clear();
  report.faceMoves.clear();
  report.maxSurfaceDisplacement = 0.0;
  report.trimsReprojected = 0;
  report.seamsHealed = 0;
  report.achieved = report.seamsToHeal == 0;
  report.after = report.before;
  return report;
}

BRepCounts countsOf(const TopoDS_Shape& shape, const detail::ShapeCounts& c) {
  return {c.faces, c.trimmedFaces, c.edges, c.solids, c.area, BRepCheck_Analyzer(shape).IsValid()};
}

/// Writes `pristine` (a copy of the input made before the heal touched it) to `file` in `format`, through a document
/// as the heal writes (names and colours aside, which do not change the geometry read back), and reads it back into
/// `back`. `counts` are the input's, `threads` as in detail::AreaOptions. A STEP file is not counted again: it only
/// serves as the baseline of the seams, and the healed file written before it was.
Status writeUnchanged(const fs::path& in, const TopoDS_Shape& pristine, const fs::path& file, CadFormat format,
                      const std::string& unit, const detail::ShapeCounts& counts, int threads,
                      detail::WrittenBack& back) {
  std::vector<std::string> notes;
  detail::OcctSignalGuard guard;
  try {
    OCC_CATCH_SIGNALS
    const Handle(TDocStd_Document) doc = detail::newCadDocument();
    XCAFDoc_DocumentTool::ShapeTool(doc->Main())->AddShape(pristine, false);
    return detail::writeCadDocument(doc, file, format, unit, counts, &notes, 0.0, 0.0, &back, threads,
                                    /*countReadBack=*/false);
  } catch (const Standard_Failure& f) {
    return invalidInput(fmt::format("{}: OpenCASCADE failed writing it unchanged: {}", in.string(),
                                    f.GetMessageString()));
  }
}

}  // namespace

Result<BRepHealReport> healBRepFile(const fs::path& in, const fs::path& out, const BRepHealOptions& options) {
  const std::optional<CadFormat> inFormat = cadFormatOf(in), outFormat = cadFormatOf(out);
  if (!inFormat || !outFormat)
    return invalidInput(fmt::format("{} -> {}: the B-rep heal reads and writes STEP/IGES", in.string(),
                                    out.string()));
  if (options.continuity != GeometricClass::kG0 && options.continuity != GeometricClass::kG1)
    return invalidInput(fmt::format("{}: the heal of a trimmed B-rep reaches G0 or G1 (G2 works on untrimmed patch "
                                    "models: JSON or .bpt)",
                                    in.string()));
  if (options.tolerances.units)
    return invalidInput(fmt::format("{}: --units rescales the model; the B-rep heal keeps the file's own "
                                    "coordinates and unit, so it takes no --units",
                                    in.string()));
  // What was written is read back and checked again: a STEP or IGES reader rebuilds the trims from the written 3-D
  // edge curves and vertices, so the seams of the file can differ from those of the model in memory. Every seam of
  // the file (paired with the input's by the midpoint of its edge) must be no worse than in the input. Where one is,
  // the changes next to it (faces moved, pcurves projected again) are excluded and the heal is made again from the
  // input, at most kMaxReadBackAttempts times; when nothing more can be blamed, nothing of the heal is written: the
  // input is written unchanged (as `seam convert` writes it) and every seam says why.
  HealExclusions excluded;
  std::string lastWorse;
  std::optional<std::vector<BRepSeam>> unhealed;  // the seams of the input written unchanged, read back
  std::optional<BRepCheckReport> checkedBefore;   // the input's check, the same for every attempt
  std::optional<BRepCounts> countsBefore;          // its counts, too
  std::optional<detail::ShapeCounts> shapeCounts;  // and OpenCASCADE's counts of it, with its faces' areas
  std::vector<std::string> roundTripNotes;         // seams the plain round trip makes worse
  TopoDS_Shape pristine;  // a copy of the input as read, made before the first heal: the round trip's baseline
  for (int attempt = 0;; ++attempt) {  // each attempt ends in a return or excludes something more
    BRepHealReport report;
    report.requested = options.continuity;
    report.creaseAngleDeg = options.creaseAngleDeg;
    std::vector<std::string> readWarnings;
    detail::FaceLabels labels;
    detail::FileUnits units;
    const Handle(TDocStd_Document) doc = detail::newCadDocument();
    Result<TopoDS_Shape> read =
        detail::readShape(in, *inFormat, &readWarnings, detail::kTransferTimeLimit, &labels, &units, &doc);
    if (!read) return read.status();
    const TopoDS_Shape shape = *read;
    report.unit = detail::cadUnitName(units.units.millimetresPerFileUnit, *outFormat);
    // The model is in millimetres; --max-gap is in the shown unit (the file's own, or --display-units).
    const std::optional<LengthUnit> shown = detail::shownCadUnit(options.tolerances, units.units.fileUnit).first;
    report.maxGap = options.maxGap ? *options.maxGap * (shown ? lengthUnitInfo(*shown).millimetres : 1.0)
                                   : kDefaultBRepMaxGapMm;
    detail::ShapeCounts countsAfter;
    std::set<int> reprojected;
    {
      detail::OcctSignalGuard guard;
      try {
        OCC_CATCH_SIGNALS
        if (!countsBefore) {  // the same every attempt
          shapeCounts = detail::countShape(shape, detail::AreaOptions{0.0, options.threads});
          countsBefore = countsOf(shape, *shapeCounts);
          // The heal edits the surfaces, pcurves, edges and vertices in place: the copy (geometry too) keeps the
          // input for the round trip's baseline without reading the file again.
          pristine = BRepBuilderAPI_Copy(shape, /*copyGeom=*/true, /*copyMesh=*/false).Shape();
        }
        report.before = *countsBefore;
        if (Status st = healShape(shape, in, labels, units, readWarnings, options, excluded, report, reprojected,
                                  checkedBefore);
            !st)
          return st;
        // Only the faces moved and those whose pcurves were projected again can have another area.
        const std::set<int> changed = changedFaces(report, reprojected);
        countsAfter = detail::countShape(shape, detail::AreaOptions{0.0, options.threads, &*shapeCounts, &changed});
        report.after = countsOf(shape, countsAfter);
      } catch (const Standard_Failure& f) {
        return invalidInput(fmt::format("{}: OpenCASCADE {} during the heal: {}", in.string(),
                                        isSignal(f) ? detail::kCrashedOnTheModel : "failed",
                                        f.GetMessageString()));
      }
    }
    if (report.before.valid && !report.after.valid)
      return invalidInput(fmt::format("{}: not written: the healed model fails OpenCASCADE's BRepCheck_Analyzer, "
                                      "which the input passes",
                                      out.string()));
    if (report.facesChanged.empty() && report.trimsReprojected == 0) {
      if (Status st = detail::writeCadDocument(doc, out, *outFormat, report.unit, countsAfter, &report.notes); !st)
        return st;
      return report;
    }
    const fs::path temp = io::temporaryPathFor(out);
    io::RemoveOnExit removeTemporary{temp};
    detail::WrittenBack back;
    if (Status st = detail::writeCadDocument(doc, temp, *outFormat, report.unit, countsAfter, &report.notes,
                                             kHealWrittenAreaRelTol, 0.0, &back, options.threads);
        !st) {
      std::string message = st.message();  // it names the temporary file: name the output instead
      for (size_t at = message.find(temp.string()); at != std::string::npos; at = message.find(temp.string()))
        message.replace(at, temp.string().size(), out.string());
      return Status(st.code(), message);
    }
    const std::vector<Bnd_Box> region = changedRegion(shape, report, reprojected);
    Result<std::vector<BRepSeam>> written = seamsReadBack(temp, back, options, region);
    if (!written) return unchangedAfterReadBack(in, out, written.status().message(), std::move(report));
    std::vector<WorseSeam> worse = worseSeams(*written, report, options, unhealed ? &*unhealed : nullptr);
    if (!worse.empty() && !unhealed) {
      // Is it the writer's and reader's own doing? The input written unchanged, read back, is the baseline.
      const fs::path plain = io::temporaryPathFor(out);
      io::RemoveOnExit removePlain{plain};
      detail::WrittenBack plainBack;
      if (Status st = writeUnchanged(in, pristine, plain, *outFormat, report.unit, *shapeCounts, options.threads,
                                     plainBack);
          !st)
        return st;
      Result<std::vector<BRepSeam>> plainSeams = seamsReadBack(plain, plainBack, options, region);
      if (!plainSeams) return unchangedAfterReadBack(in, out, plainSeams.status().message(), std::move(report));
      unhealed = std::move(*plainSeams);
      worse = worseSeams(*written, report, options, &*unhealed);
      const std::vector<WorseSeam> roundTrip = worseSeams(*unhealed, report, options, nullptr);
      for (const WorseSeam& w : roundTrip)
        roundTripNotes.push_back(fmt::format(
            "the seam of {} and {} (edge {}) is worse in the input written unchanged and read back ({}): "
            "OpenCASCADE's writer and reader do that (`seam convert` writes the same); the heal is held to it there",
            w.input->a, w.input->b, w.input->edge, w.why));

    }
    report.notes.insert(report.notes.end(), roundTripNotes.begin(), roundTripNotes.end());
    if (worse.empty()) {
      std::error_code ec;
      fs::rename(temp, out, ec);
      if (ec) return invalidInput(fmt::format("{}: cannot replace file: {}", out.string(), ec.message()));
      if (attempt > 0)
        report.notes.push_back(fmt::format("healed in {} attempts: the written file of each earlier one, read back, "
                                           "had a seam worse than the input; the changes next to it were not made "
                                           "again ({} faces not moved, {} edges' pcurves kept)",
                                           attempt + 1, excluded.faces.size(), excluded.trims.size()));
      return report;
    }
    lastWorse = worse.front().input == nullptr
                    ? worse.front().why
                    : fmt::format("the seam of {} and {} (edge {} of the input): {}", worse.front().input->a,
                                  worse.front().input->b, worse.front().input->edge, worse.front().why);
    if (attempt + 1 < kMaxReadBackAttempts && blameReadBack(worse, report, reprojected, excluded)) continue;
    return unchangedAfterReadBack(in, out, lastWorse, std::move(report));
  }
}

namespace {

/// `text` with every occurrence of `from` replaced by `to`.
std::string replacedAll(std::string text, const std::string& from, const std::string& to) {
  if (from.empty()) return text;
  for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
    text.replace(at, from.size(), to);
  return text;
}

}  // namespace

Result<BRepModelHeal> healBRepModel(const Model& model, const std::string& source, CadFormat format,
                                    const BRepHealOptions& options) {
  if (!model.brep)
    return invalidInput(fmt::format("{}: the model holds no B-rep (no \"brep\"): heal its patches instead",
                                    source));
  const fs::path folder = fs::temp_directory_path();
  const char* ext = format == CadFormat::kStep ? ".step" : ".igs";
  fs::path in = io::temporaryPathFor(folder / "in"), out = io::temporaryPathFor(folder / "out");
  in += ext;
  out += ext;
  const io::RemoveOnExit removeIn{in}, removeOut{out};
  // The temporary files never appear in what the user reads: the model is `source`, the heal's output its healed
  // form (full paths first, then the bare names some messages use).
  const std::string healedName = source + " (healed)";
  const auto named = [&](std::string text) {
    text = replacedAll(std::move(text), in.string(), source);
    text = replacedAll(std::move(text), out.string(), healedName);
    text = replacedAll(std::move(text), in.filename().string(), source);
    return replacedAll(std::move(text), out.filename().string(), healedName);
  };
  const auto renamed = [&](const Status& st) { return Status(st.code(), named(st.message())); };
  if (Status st = writeCadFile(model, in, format); !st) return renamed(st);
  Result<BRepHealReport> healed = healBRepFile(in, out, options);
  if (!healed) return renamed(healed.status());
  Result<CadImport> back = readCadFile(out);
  if (!back) return renamed(back.status());
  BRepModelHeal result{std::move(healed).value(), std::move(back->model)};
  BRepHealReport& r = result.report;
  for (std::string& w : r.warnings) w = named(std::move(w));
  for (std::string& n : r.notes) n = named(std::move(n));
  // Face names: the files name faces F<n> in face order; the model's own names come back when every face read back
  // is the patch of the model's face at its place (the same degrees and control-point counts).
  const BRepTopology& topo = *model.brep;
  bool sameFaces = result.model.patches.size() == topo.faces.size();
  for (size_t i = 0; sameFaces && i < topo.faces.size(); ++i) {
    const BSplineSurface& a = model.patches[static_cast<size_t>(topo.faces[i].patch)].surface;
    const BSplineSurface& b = result.model.patches[i].surface;
    sameFaces = a.degreeU() == b.degreeU() && a.degreeV() == b.degreeV() && a.numU() == b.numU() &&
                a.numV() == b.numV();
  }
  std::map<std::string, std::string> nameOf;
  if (sameFaces) {
    for (size_t i = 0; i < topo.faces.size(); ++i) {
      const std::string& own = model.patches[static_cast<size_t>(topo.faces[i].patch)].name;
      nameOf[result.model.patches[i].name] = own;
      result.model.patches[i].name = own;
    }
  } else {
    r.warnings.push_back(fmt::format("{}: the faces read back do not match the model's one to one: they are named "
                                     "F<n> in face order, not by the model's patch names",
                                     source));
  }
  const auto faceName = [&](const std::string& f) {
    const auto it = nameOf.find(f);
    return it == nameOf.end() ? f : it->second;
  };
  for (BRepHealSeam& seam : r.seams) {
    seam.a = faceName(seam.a);
    seam.b = faceName(seam.b);
    if (!seam.moved.empty()) seam.moved = faceName(seam.moved);
    seam.entityA.clear();  // entities of the temporary file: nothing the user's model has
    seam.entityB.clear();
  }
  for (std::string& f : r.facesChanged) f = faceName(f);
  for (std::string& f : r.facesReverted) f = faceName(f);
  for (BRepFaceMove& m : r.faceMoves) m.face = faceName(m.face);
  return result;
}

}  // namespace seam::occt
