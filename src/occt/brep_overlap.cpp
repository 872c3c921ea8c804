// OCC_CATCH_SIGNALS converts a signal raised inside OpenCASCADE into a Standard_Failure only when this macro is set
// (as in cad_io.cpp; see docs/reliability.md, "OpenCASCADE guards").
#ifndef OCC_CONVERT_SIGNALS
#define OCC_CONVERT_SIGNALS
#endif
// Overlapping faces of a B-rep (issue 38 §11, the trimmed half): two faces that lie on each other, inside both
// faces' trims, within the distance tolerance. The patch-model search (src/continuity/overlap.cpp) samples whole
// patches; a B-rep face is a region of its surface, so here a face's samples are the points of a grid over its
// parameter box that lie inside its trims, and a sample lies on another face when its closest point on that face's
// surface is within the tolerance and inside that face's trims (strictly: not on its boundary). Faces trimmed from
// one surface side by side, and faces that share an edge, therefore never overlap. docs/check-output.md,
// "Overlapping faces", has the rule and its limits.
#include <BRepAdaptor_Surface.hxx>
#include <BRepBndLib.hxx>
#include <BRepGProp.hxx>
#include <GProp_GProps.hxx>
#include <BRepTools.hxx>
#include <BRepTopAdaptor_FClass2d.hxx>
#include <Bnd_Box.hxx>
#include <gp_Vec.hxx>
#include <Precision.hxx>
#include <Standard_ErrorHandler.hxx>
#include <Standard_Failure.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Face.hxx>
#include <gp_Pnt.hxx>
#include <gp_Pnt2d.hxx>

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "occt/brep_check_internal.h"

namespace seam::occt::detail {

namespace {

/// A face's samples: the points (i + 1/2) / n, (j + 1/2) / n of its parameter box (n = kOverlapGridFactor x
/// OverlapOptions::samplesPerDirection; a trimmed face keeps only those inside its trims, so its box gets more points
/// than a patch), their 3-D points, and the largest distance between neighbouring grid points (the surface lies
/// within about that of its nearest grid point).
constexpr int kOverlapGridFactor = 2;

struct FaceGrid {
  bool usable = false;             ///< the face has a finite parameter box and could be evaluated
  int n = 0;                       ///< grid points per direction
  std::vector<gp_Pnt2d> uv;        ///< n x n, row-major in u
  std::vector<gp_Pnt> xyz;
  double cell = 0.0;               ///< the largest 3-D distance between neighbouring grid points
  Bnd_Box box;                     ///< the face's box, enlarged by the tolerance
};

/// The face's classifier, made on the first thread that needs it, and used by one thread at a time: its Perform is
/// const but not safe to call from two threads at once (OpenCASCADE 7.6 reads the classifier's polygons from an
/// NCollection_Sequence, whose reads move a cursor cached in the sequence; two threads classifying on one face
/// crashed the search about once in 200 runs of `seam check linkrods.step`, issue 39). The lock is per face: the
/// threads still classify on different faces at once.
struct LazyClassifier {
  std::mutex lock;
  std::unique_ptr<BRepTopAdaptor_FClass2d> classifier;
};

/// `classifier` made on `face` where it is not yet, then its state of `uv`, under this frame's own signal handler: a
/// signal inside OpenCASCADE jumps back here (not to a caller's handler, past the caller's lock) and leaves as a
/// Standard_Failure that unwinds the caller's lock.
TopAbs_State classifyUnlocked(std::unique_ptr<BRepTopAdaptor_FClass2d>& classifier, const TopoDS_Face& face,
                              const gp_Pnt2d& uv) {
  OCC_CATCH_SIGNALS
  if (!classifier) classifier = std::make_unique<BRepTopAdaptor_FClass2d>(face, Precision::PConfusion());
  return classifier->Perform(uv);
}

FaceGrid faceGrid(const TopoDS_Face& face, int n, double tol) {
  FaceGrid g;
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
  BRepTools::UVBounds(face, u0, u1, v0, v1);
  if (!std::isfinite(u0) || !std::isfinite(u1) || !std::isfinite(v0) || !std::isfinite(v1) || !(u1 > u0) ||
      !(v1 > v0))
    return g;
  const BRepAdaptor_Surface surface(face, /*restriction=*/false);
  g.n = n;
  g.uv.reserve(static_cast<size_t>(n * n));
  g.xyz.reserve(static_cast<size_t>(n * n));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const gp_Pnt2d uv(u0 + (u1 - u0) * (i + 0.5) / n, v0 + (v1 - v0) * (j + 0.5) / n);
      g.uv.push_back(uv);
      g.xyz.push_back(surface.Value(uv.X(), uv.Y()));
    }
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const gp_Pnt& p = g.xyz[static_cast<size_t>(i * n + j)];
      if (i + 1 < n) g.cell = std::max(g.cell, p.Distance(g.xyz[static_cast<size_t>((i + 1) * n + j)]));
      if (j + 1 < n) g.cell = std::max(g.cell, p.Distance(g.xyz[static_cast<size_t>(i * n + j + 1)]));
    }
  BRepBndLib::Add(face, g.box);
  g.box.Enlarge(tol);
  g.usable = std::all_of(g.xyz.begin(), g.xyz.end(), [](const gp_Pnt& p) {
    return std::isfinite(p.X()) && std::isfinite(p.Y()) && std::isfinite(p.Z());
  });
  return g;
}

/// Gauss-Newton iterations of the closest point on a surface from a grid point: from the nearest grid point the
/// foot is found in 3-5 (quadratic convergence where the point lies on the surface); more is a point far from it.
constexpr int kFootIterations = 8;

/// The foot of `p` on `surface` by Gauss-Newton from (u, v) (minimising |S(u, v) - p|^2 with the first derivatives):
/// the parameters reached. The distance to the point found is measured by the caller, so a foot that is not the
/// nearest point is still a point of the surface (a witness), never a false distance.
gp_Pnt2d footNear(const BRepAdaptor_Surface& surface, const gp_Pnt& p, double u, double v) {
  for (int it = 0; it < kFootIterations; ++it) {
    gp_Pnt s;
    gp_Vec su, sv;
    surface.D1(u, v, s, su, sv);
    const gp_Vec r(s, p);
    const double a = su.Dot(su), b = su.Dot(sv), c = sv.Dot(sv), det = a * c - b * b;
    if (!(det > 0.0) || !std::isfinite(det)) break;  // a pole or a degenerate point: stop where it is
    const double ru = su.Dot(r), rv = sv.Dot(r);
    const double du = (c * ru - b * rv) / det, dv = (a * rv - b * ru) / det;
    u += du;
    v += dv;
    if (std::abs(du) <= Precision::PConfusion() && std::abs(dv) <= Precision::PConfusion()) break;
  }
  return {u, v};
}

/// A face's inside samples stand for its area only when the classifier reads its trims right: a face of zero area
/// (trj3_s1-al-214.stp's F14, 7e-13 mm^2, whose parameter box is 10 mm across) or a sliver classifies all of its
/// box inside. A face whose inside samples cover more than this many times its area (BRepGProp), or less than its
/// inverse, is left out of the search (BRepCheckReport::overlapFacesSkipped): its trims cannot be sampled.
constexpr double kOverlapAreaAgreement = 4.0;

/// The area the inside samples of `g` stand for: each sample's |S_u x S_v| times its cell of the parameter box.
double sampledArea(const TopoDS_Face& face, const FaceGrid& g, const std::vector<signed char>& in) {
  double u0 = 0, u1 = 0, v0 = 0, v1 = 0;
  BRepTools::UVBounds(face, u0, u1, v0, v1);
  const double cell = (u1 - u0) * (v1 - v0) / (static_cast<double>(g.n) * g.n);
  const BRepAdaptor_Surface surface(face, /*restriction=*/false);
  double area = 0.0;
  for (size_t k = 0; k < g.uv.size(); ++k) {
    if (in[k] != 1) continue;
    gp_Pnt p;
    gp_Vec su, sv;
    surface.D1(g.uv[k].X(), g.uv[k].Y(), p, su, sv);
    area += su.Crossed(sv).Magnitude() * cell;
  }
  return area;
}

/// A's samples that lie on B: their indices into A's grid, and the distance of each.
struct Hits {
  std::vector<int> samples;
  std::vector<double> distances;
};

/// The search over one shape's faces: the grids, the classifiers (made on first use), the candidate pairs and what
/// each face's samples found on its partners. Every failure inside OpenCASCADE (a face it cannot evaluate or
/// classify) leaves that face or that pair out: the search reports what it finds; the seams' check reports the
/// faces' problems. A signal (a crash inside OpenCASCADE) is raised to the caller instead, which ends the check with
/// an error, as a signal on an edge does: a crash is never turned into a silently missing pair.
class Search {
 public:
  Search(const TopTools_IndexedMapOfShape& faces, double tol, const OverlapOptions& options)
      : faces_(faces),
        tol_(tol),
        options_(options),
        n_(faces.Extent()),
        grids_(static_cast<size_t>(n_)),
        classifiers_(static_cast<size_t>(n_)),
        partners_(static_cast<size_t>(n_)),
        hits_(static_cast<size_t>(n_)),
        inside_(static_cast<size_t>(n_), 0),
        skipped_(static_cast<size_t>(n_), 0),
        arena_(options.threads > 0 ? options.threads : tbb::task_arena::automatic) {}

  BRepOverlapSearch run() {
    const int n = std::max(1, kOverlapGridFactor * options_.samplesPerDirection);
    arena_.execute([&] {
      tbb::parallel_for(0, n_, [&](int k) {
        try {
          OCC_CATCH_SIGNALS  // the thread that runs the task: its own handler (inside the try, which catches it)
          grids_[static_cast<size_t>(k)] = faceGrid(face(k), n, tol_);
        } catch (const Standard_Failure& f) {
          if (isSignal(f)) throw;  // a crash inside OpenCASCADE ends the check (exit 2), as on an edge
          grids_[static_cast<size_t>(k)] = FaceGrid{};
        }
      });
    });
    // Candidates: pairs whose boxes, each enlarged by the tolerance, meet (each face lists the other).
    for (int a = 0; a < n_; ++a)
      for (int b = a + 1; b < n_; ++b) {
        const FaceGrid &ga = grid(a), &gb = grid(b);
        if (!ga.usable || !gb.usable || ga.box.IsOut(gb.box)) continue;
        partners_[static_cast<size_t>(a)].push_back(b);
        partners_[static_cast<size_t>(b)].push_back(a);
      }
    arena_.execute([&] { tbb::parallel_for(0, n_, [&](int a) { searchFrom(a); }); });
    return pairs();
  }

 private:
  [[nodiscard]] TopoDS_Face face(int k) const { return TopoDS::Face(faces_(k + 1)); }
  [[nodiscard]] const FaceGrid& grid(int k) const { return grids_[static_cast<size_t>(k)]; }

  /// The state of `uv` on face k by the face's classifier (LazyClassifier: one thread at a time per face).
  TopAbs_State classify(int k, const gp_Pnt2d& uv) {
    LazyClassifier& c = classifiers_[static_cast<size_t>(k)];
    const std::lock_guard<std::mutex> hold(c.lock);  // outside classifyUnlocked's signal frame: always unlocked
    return classifyUnlocked(c.classifier, face(k), uv);
  }

  /// Face a's samples on each of its partners (hits_[a]); for a face with a hit, how many of its samples lie inside
  /// its trims (inside_[a]) and whether they stand for its area (skipped_[a] when not: kOverlapAreaAgreement). Most
  /// faces have no hit, and their own samples are never classified.
  void searchFrom(int a) {
    const FaceGrid& ga = grid(a);
    const std::vector<int>& mine = partners_[static_cast<size_t>(a)];
    std::vector<Hits>& out = hits_[static_cast<size_t>(a)];
    out.resize(mine.size());
    std::vector<signed char> in(ga.xyz.size(), -1);  // a's own classification of its samples, when asked
    auto insideA = [&](int s) {
      if (in[static_cast<size_t>(s)] < 0)
        in[static_cast<size_t>(s)] = classify(a, ga.uv[static_cast<size_t>(s)]) == TopAbs_IN ? 1 : 0;
      return in[static_cast<size_t>(s)] == 1;
    };
    bool any = false;
    for (size_t m = 0; m < mine.size(); ++m) {
      try {
        OCC_CATCH_SIGNALS  // the thread that runs the task: its own handler (inside the try, which catches it)
        out[m] = samplesOn(ga, mine[m], insideA);
        any = any || !out[m].samples.empty();
      } catch (const Standard_Failure& f) {
        if (isSignal(f)) throw;  // a crash inside OpenCASCADE ends the check (exit 2), as on an edge
        out[m] = Hits{};
      }
    }
    if (!any) return;
    try {
      OCC_CATCH_SIGNALS
      int count = 0;
      for (int s = 0; s < static_cast<int>(ga.xyz.size()); ++s) count += insideA(s) ? 1 : 0;
      inside_[static_cast<size_t>(a)] = count;
      GProp_GProps props;
      BRepGProp::SurfaceProperties(face(a), props);
      const double area = std::abs(props.Mass()), sampled = sampledArea(face(a), ga, in);
      if (!(sampled <= kOverlapAreaAgreement * area && area <= kOverlapAreaAgreement * sampled))
        skipped_[static_cast<size_t>(a)] = 1;
    } catch (const Standard_Failure& f) {
      if (isSignal(f)) throw;  // a crash inside OpenCASCADE ends the check (exit 2), as on an edge
      inside_[static_cast<size_t>(a)] = 0;
      skipped_[static_cast<size_t>(a)] = 1;
    }
  }

  /// The samples of `ga` (inside its own trims, by `insideA`) that lie on face b inside its trims.
  template <typename InsideA>
  Hits samplesOn(const FaceGrid& ga, int b, InsideA& insideA) {
    const FaceGrid& gb = grid(b);
    std::optional<BRepAdaptor_Surface> surfaceB;  // this task's own (an adaptor caches its evaluations)
    // The foot of a point within the tolerance of B's surface lies in a grid cell, within about a cell of its nearest
    // grid point (half a diagonal where the cell is flat): a point farther than that is off B's surface.
    const double reach = tol_ + gb.cell;
    Hits out;
    for (int s = 0; s < static_cast<int>(ga.xyz.size()); ++s) {
      const gp_Pnt& p = ga.xyz[static_cast<size_t>(s)];
      if (gb.box.IsOut(p)) continue;
      size_t nearest = 0;
      double best = p.SquareDistance(gb.xyz[0]);
      for (size_t q = 1; q < gb.xyz.size(); ++q)
        if (const double d = p.SquareDistance(gb.xyz[q]); d < best) {
          best = d;
          nearest = q;
        }
      if (std::sqrt(best) > reach) continue;
      if (!surfaceB) surfaceB.emplace(face(b), /*restriction=*/false);
      const gp_Pnt2d foot = footNear(*surfaceB, p, gb.uv[nearest].X(), gb.uv[nearest].Y());
      const double d = p.Distance(surfaceB->Value(foot.X(), foot.Y()));  // the foot found is the witness
      if (!(d <= tol_)) continue;
      if (classify(b, foot) != TopAbs_IN) continue;
      if (!insideA(s)) continue;
      out.samples.push_back(s);
      out.distances.push_back(d);
    }
    return out;
  }

  /// Each unordered pair: the larger share of the two directions; none with a face whose trims were not read right.
  BRepOverlapSearch pairs() const {
    BRepOverlapSearch result;
    result.skippedFaces = static_cast<int>(std::count(skipped_.begin(), skipped_.end(), 1));
    auto share = [&](const Hits& h, int f) {
      const int all = inside_[static_cast<size_t>(f)];
      return all > 0 ? static_cast<double>(h.samples.size()) / all : 0.0;
    };
    for (int a = 0; a < n_; ++a) {
      if (skipped_[static_cast<size_t>(a)]) continue;
      const std::vector<int>& mine = partners_[static_cast<size_t>(a)];
      for (size_t m = 0; m < mine.size(); ++m) {
        const int b = mine[m];
        if (b < a || skipped_[static_cast<size_t>(b)]) continue;
        const std::vector<int>& theirs = partners_[static_cast<size_t>(b)];
        const size_t back = static_cast<size_t>(std::find(theirs.begin(), theirs.end(), a) - theirs.begin());
        const Hits& ab = hits_[static_cast<size_t>(a)][m];
        const Hits& ba = hits_[static_cast<size_t>(b)][back];
        const double sa = share(ab, a), sb = share(ba, b);
        const bool fromA = sa >= sb;
        const double fraction = fromA ? sa : sb;
        if (!(fraction >= options_.minFraction)) continue;
        const Hits& h = fromA ? ab : ba;
        const gp_Pnt& first = grid(fromA ? a : b).xyz[static_cast<size_t>(h.samples.front())];
        FaceOverlap o;
        o.a = a;
        o.b = b;
        o.fraction = fraction;
        o.maxDistance = *std::max_element(h.distances.begin(), h.distances.end());
        o.point = Vec3(first.X(), first.Y(), first.Z());
        result.overlaps.push_back(o);
      }
    }
    return result;
  }

  const TopTools_IndexedMapOfShape& faces_;
  const double tol_;
  const OverlapOptions options_;
  const int n_;
  std::vector<FaceGrid> grids_;
  std::vector<LazyClassifier> classifiers_;
  std::vector<std::vector<int>> partners_;  ///< each face's candidates (boxes within the tolerance)
  std::vector<std::vector<Hits>> hits_;     ///< hits_[a][m]: a's samples on its m-th partner
  std::vector<int> inside_;                 ///< a's samples inside its trims (faces with a hit only)
  std::vector<char> skipped_;               ///< a's trims not read right by its samples
  tbb::task_arena arena_;
};

}  // namespace

BRepOverlapSearch findBRepOverlaps(const TopTools_IndexedMapOfShape& faces, double tol, const OverlapOptions& options) {
  return Search(faces, tol, options).run();
}

}  // namespace seam::occt::detail
