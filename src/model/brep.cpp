#include "seam/model/brep.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "seam/core/tolerances.h"
#include "seam/model/model.h"

namespace seam {

namespace {

/// Samples per pcurve for the domain check.
constexpr int kDomainSamples = 9;

bool finite(double x) { return std::isfinite(x); }

/// The patch's point at (u, v), the parameters clamped into its domain.
Vec3 patchPoint(const BSplineSurface& s, double u, double v) {
  const Interval du = s.domainU(), dv = s.domainV();
  const VecX p = s.evaluate(std::clamp(u, du.lo, du.hi), std::clamp(v, dv.lo, dv.hi));
  return Vec3(p[0], p[1], p[2]);
}

/// Ok when [t0, t1] is finite, non-empty and inside `domain` (within kBRepDomainRelTol of its length).
std::string rangeProblem(double t0, double t1, Interval domain) {
  if (!finite(t0) || !finite(t1)) return fmt::format("range [{}, {}] is not finite", t0, t1);
  if (!(t1 > t0)) return fmt::format("range [{}, {}] is empty (a zero-length curve)", t0, t1);
  // OpenCASCADE's ranges may overshoot a converted curve's domain by its parametric confusion (1e-9).
  const double slack = kBRepDomainRelTol * domain.length() +
                       kKnotRelTol * std::max({std::abs(domain.lo), std::abs(domain.hi), 1.0});
  if (t0 < domain.lo - slack || t1 > domain.hi + slack)
    return fmt::format("range [{}, {}] is outside the curve's domain [{}, {}]", t0, t1, domain.lo, domain.hi);
  return "";
}

/// True when every control point of `c` is the same point (a curve of zero length).
bool allPointsEqual(const BSplineCurve& c) {
  for (int i = 1; i < c.numPoints(); ++i)
    if (c.points().row(i) != c.points().row(0)) return false;
  return true;
}

Vec2 pcurveAt(const BRepCoedge& c, double t) {
  const double lo = c.pcurve.domain().lo, hi = c.pcurve.domain().hi;
  const VecX p = c.pcurve.evaluate(std::clamp(t, lo, hi));
  return Vec2(p[0], p[1]);
}

}  // namespace

Status validateBRep(const Model& model, const BRepTopology& brep, const std::string& source) {
  auto fail = [&](const std::string& where, const std::string& problem) {
    return invalidInput(fmt::format("{}: brep {}: {}", source, where, problem));
  };
  const int nv = static_cast<int>(brep.vertices.size()), ne = static_cast<int>(brep.edges.size());
  const int nf = static_cast<int>(brep.faces.size()), ns = static_cast<int>(brep.shells.size());
  const int nsolid = static_cast<int>(brep.solids.size());
  const double diag = model.boundingBox().diagonal();
  for (int i = 0; i < nv; ++i) {
    const BRepVertex& v = brep.vertices[static_cast<size_t>(i)];
    if (!v.point.allFinite()) return fail(fmt::format("vertex {}", i), "point is not finite");
    if (!finite(v.tolerance) || v.tolerance < 0)
      return fail(fmt::format("vertex {}", i),
                  fmt::format("tolerance {} is not a finite number >= 0", v.tolerance));
  }
  for (int i = 0; i < ne; ++i) {
    const BRepEdge& e = brep.edges[static_cast<size_t>(i)];
    const std::string where = fmt::format("edge {}", i);
    for (int v : {e.v0, e.v1})
      if (v < 0 || v >= nv)
        return fail(where, fmt::format("vertex id {} does not exist (there are {} vertices)", v, nv));
    if (!finite(e.tolerance) || e.tolerance < 0)
      return fail(where, fmt::format("tolerance {} is not a finite number >= 0", e.tolerance));
    if (e.degenerate) {
      if (!finite(e.t0) || !finite(e.t1) || !(e.t1 > e.t0))
        return fail(where, fmt::format("range [{}, {}] is not a finite non-empty interval", e.t0, e.t1));
      continue;
    }
    if (e.curve.dim() != 3) return fail(where, fmt::format("the 3-D curve has {}-D points", e.curve.dim()));
    if (const std::string p = rangeProblem(e.t0, e.t1, e.curve.domain()); !p.empty()) return fail(where, p);
    if (allPointsEqual(e.curve))
      return fail(where, "the 3-D curve has zero length (all its points are equal)");
  }
  std::vector<int> faceOfPatch(model.patches.size(), -1);
  for (int f = 0; f < nf; ++f) {
    const BRepFace& face = brep.faces[static_cast<size_t>(f)];
    const std::string where = fmt::format("face {}", f);
    if (face.patch < 0 || face.patch >= static_cast<int>(model.patches.size()))
      return fail(where, fmt::format("patch {} does not exist", face.patch));
    int& owner = faceOfPatch[static_cast<size_t>(face.patch)];
    if (owner >= 0)
      return fail(where, fmt::format("patch \"{}\" is already the surface of face {} (one face per patch)",
                                     model.patches[static_cast<size_t>(face.patch)].name, owner));
    owner = f;
    const BSplineSurface& s = model.patches[static_cast<size_t>(face.patch)].surface;
    if (s.dim() != 3) return fail(where, "its patch is not 3-D");
    if (!finite(face.tolerance) || face.tolerance < 0)
      return fail(where, fmt::format("tolerance {} is not a finite number >= 0", face.tolerance));
    if (face.loops.empty()) return fail(where, "has no loop (a face needs its outer loop)");
    const Interval du = s.domainU(), dv = s.domainV();
    const double su = kBRepDomainRelTol * du.length(), sv = kBRepDomainRelTol * dv.length();
    for (size_t l = 0; l < face.loops.size(); ++l) {
      const std::vector<BRepCoedge>& loop = face.loops[l];
      const std::string lw = fmt::format("{}: loop {}", where, l);
      if (loop.empty()) return fail(lw, "is empty");
      for (size_t k = 0; k < loop.size(); ++k) {
        const BRepCoedge& c = loop[k];
        const std::string cw = fmt::format("{}: coedge {}", lw, k);
        if (c.edge < 0 || c.edge >= ne)
          return fail(cw, fmt::format("edge id {} does not exist (there are {} edges)", c.edge, ne));
        if (c.pcurve.dim() != 2)
          return fail(cw, fmt::format("the pcurve has {}-D points, expected 2-D (u, v)", c.pcurve.dim()));
        if (const std::string p = rangeProblem(c.t0, c.t1, c.pcurve.domain()); !p.empty())
          return fail(cw, "pcurve " + p);
        if (!brep.edges[static_cast<size_t>(c.edge)].degenerate && allPointsEqual(c.pcurve))
          return fail(
              cw, fmt::format("the pcurve of edge {} has zero length (all its points are equal) but the edge "
                              "is not degenerate",
                              c.edge));
        for (int i = 0; i < kDomainSamples; ++i) {
          const Vec2 q = pcurveAt(c, c.t0 + (c.t1 - c.t0) * i / (kDomainSamples - 1));
          if (q[0] < du.lo - su || q[0] > du.hi + su || q[1] < dv.lo - sv || q[1] > dv.hi + sv)
            return fail(
                cw, fmt::format("the pcurve leaves the patch's domain [{}, {}] x [{}, {}]: (u, v) = ({}, {})",
                                du.lo, du.hi, dv.lo, dv.hi, q[0], q[1]));
        }
      }
      // Closure: where each coedge ends, the next one starts (on the surface, within the tolerances). A face
      // that was open in its source file is kept as read (BRepFace::openAsRead).
      for (size_t k = 0; k < loop.size() && !face.openAsRead; ++k) {
        const BRepCoedge& a = loop[k];
        const BRepCoedge& b = loop[(k + 1) % loop.size()];
        const BRepEdge& ea = brep.edges[static_cast<size_t>(a.edge)];
        const BRepEdge& eb = brep.edges[static_cast<size_t>(b.edge)];
        const Vec2 qa = pcurveAt(a, a.reversed ? a.t0 : a.t1), qb = pcurveAt(b, b.reversed ? b.t1 : b.t0);
        const int va = a.reversed ? ea.v0 : ea.v1, vb = b.reversed ? eb.v1 : eb.v0;
        const double gap = (patchPoint(s, qa[0], qa[1]) - patchPoint(s, qb[0], qb[1])).norm();
        const double allowed = brep.vertices[static_cast<size_t>(va)].tolerance +
                               brep.vertices[static_cast<size_t>(vb)].tolerance + ea.tolerance +
                               eb.tolerance + face.tolerance + kBRepClosureRelTol * diag;
        if (!(gap <= allowed))
          return fail(
              fmt::format("{}: coedge {}", lw, k),
              fmt::format(
                  "the loop does not close: the pcurve of edge {} ends at (u, v) = ({}, {}), the next "
                  "coedge's (edge {}) starts at ({}, {}): {:.3g} apart on the surface, more than the "
                  "tolerance {:.3g}",
                  a.edge, qa[0], qa[1], b.edge, qb[0], qb[1], gap, allowed));
      }
    }
  }
  for (int i = 0; i < ns; ++i)
    for (const BRepUse& u : brep.shells[static_cast<size_t>(i)].faces)
      if (u.id < 0 || u.id >= nf)
        return fail(fmt::format("shell {}", i),
                    fmt::format("face id {} does not exist (there are {} faces)", u.id, nf));
  for (int i = 0; i < nsolid; ++i)
    for (const BRepUse& u : brep.solids[static_cast<size_t>(i)].shells)
      if (u.id < 0 || u.id >= ns)
        return fail(fmt::format("solid {}", i),
                    fmt::format("shell id {} does not exist (there are {} shells)", u.id, ns));
  for (size_t i = 0; i < brep.roots.size(); ++i) {
    const BRepRoot& r = brep.roots[i];
    const int n = r.kind == BRepRoot::Kind::kSolid ? nsolid : r.kind == BRepRoot::Kind::kShell ? ns : nf;
    const char* kind = r.kind == BRepRoot::Kind::kSolid   ? "solid"
                       : r.kind == BRepRoot::Kind::kShell ? "shell"
                                                          : "face";
    if (r.use.id < 0 || r.use.id >= n)
      return fail(fmt::format("root {}", i), fmt::format("{} id {} does not exist", kind, r.use.id));
  }
  return Status::ok();
}

int countTrimmedFaces(const Model& model, const BRepTopology& brep) {
  int trimmed = 0;
  for (const BRepFace& face : brep.faces) {
    if (face.patch < 0 || face.patch >= static_cast<int>(model.patches.size())) continue;
    const BSplineSurface& s = model.patches[static_cast<size_t>(face.patch)].surface;
    const Interval du = s.domainU(), dv = s.domainV();
    const double tu = kBRepIsoRelTol * du.length(), tv = kBRepIsoRelTol * dv.length();
    bool natural = face.loops.size() == 1;
    for (const BRepCoedge& c : natural ? face.loops[0] : std::vector<BRepCoedge>{}) {
      const Matrix& p = c.pcurve.points();
      auto along = [&](int axis, double value, double tol) {
        for (Eigen::Index r = 0; r < p.rows(); ++r)
          if (std::abs(p(r, axis) - value) > tol) return false;
        return true;
      };
      if (!along(0, du.lo, tu) && !along(0, du.hi, tu) && !along(1, dv.lo, tv) && !along(1, dv.hi, tv))
        natural = false;
    }
    if (!natural) ++trimmed;
  }
  return trimmed;
}

}  // namespace seam
