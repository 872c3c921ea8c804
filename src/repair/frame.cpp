#include <algorithm>
#include <cmath>

#include "repair/frame_internal.h"
#include "seam/core/tolerances.h"

namespace seam::detail {

KnotVector negatedKnots(const KnotVector& k) {
  std::vector<double> t(k.values().rbegin(), k.values().rend());
  for (double& x : t) x = -x;
  return KnotVector(std::move(t));
}

namespace {

// Frame sizes and the map (a, b) -> (i, j) of the original grid.
struct FrameMap {
  int nu = 0, nv = 0;  // original grid
  int na = 0, nb = 0;  // frame grid (a along, b across)
  Edge e = Edge::V0;
  bool flip = false;
  [[nodiscard]] std::pair<int, int> ij(int a, int b) const {
    const int aa = flip ? na - 1 - a : a;
    switch (e) {
      case Edge::V0: return {aa, b};
      case Edge::V1: return {aa, nv - 1 - b};
      case Edge::U0: return {b, aa};
      case Edge::U1: return {nu - 1 - b, aa};
    }
    return {aa, b};
  }
};

FrameMap mapFor(int nu, int nv, Edge e, bool flip) {
  FrameMap m;
  m.nu = nu;
  m.nv = nv;
  m.e = e;
  m.flip = flip;
  if (isUEdge(e)) {
    m.na = nv;
    m.nb = nu;
  } else {
    m.na = nu;
    m.nb = nv;
  }
  return m;
}

}  // namespace

int originalIndex(const BSplineSurface& s, Edge e, bool flipAlong, int a, int b) {
  const FrameMap m = mapFor(s.numU(), s.numV(), e, flipAlong);
  const auto [i, j] = m.ij(a, b);
  return i * s.numV() + j;
}

BSplineSurface toEdgeFrame(const BSplineSurface& s, Edge e, bool flipAlong) {
  const FrameMap m = mapFor(s.numU(), s.numV(), e, flipAlong);
  KnotVector along = isUEdge(e) ? s.knotsV() : s.knotsU();
  KnotVector across = isUEdge(e) ? s.knotsU() : s.knotsV();
  if (flipAlong) along = negatedKnots(along);
  if (e == Edge::U1 || e == Edge::V1) across = negatedKnots(across);
  const int pa = isUEdge(e) ? s.degreeV() : s.degreeU();
  const int pb = isUEdge(e) ? s.degreeU() : s.degreeV();
  Matrix pts(s.points().rows(), s.points().cols());
  VecX w(s.weights().size());
  for (int a = 0; a < m.na; ++a)
    for (int b = 0; b < m.nb; ++b) {
      const auto [i, j] = m.ij(a, b);
      pts.row(a * m.nb + b) = s.points().row(i * s.numV() + j);
      if (w.size()) w[a * m.nb + b] = s.weights()[i * s.numV() + j];
    }
  return BSplineSurface(pa, pb, std::move(along), std::move(across), m.na, m.nb, std::move(pts), std::move(w));
}

BSplineSurface fromEdgeFrame(const BSplineSurface& f, Edge e, bool flipAlong) {
  // The original grid sizes follow from the frame's.
  const int nu = isUEdge(e) ? f.numV() : f.numU();
  const int nv = isUEdge(e) ? f.numU() : f.numV();
  const FrameMap m = mapFor(nu, nv, e, flipAlong);
  KnotVector along = flipAlong ? negatedKnots(f.knotsU()) : f.knotsU();
  KnotVector across = (e == Edge::U1 || e == Edge::V1) ? negatedKnots(f.knotsV()) : f.knotsV();
  Matrix pts(f.points().rows(), f.points().cols());
  VecX w(f.weights().size());
  for (int a = 0; a < m.na; ++a)
    for (int b = 0; b < m.nb; ++b) {
      const auto [i, j] = m.ij(a, b);
      pts.row(i * nv + j) = f.points().row(a * m.nb + b);
      if (w.size()) w[i * nv + j] = f.weights()[a * m.nb + b];
    }
  if (isUEdge(e))
    return BSplineSurface(f.degreeV(), f.degreeU(), std::move(across), std::move(along), nu, nv, std::move(pts),
                          std::move(w));
  return BSplineSurface(f.degreeU(), f.degreeV(), std::move(along), std::move(across), nu, nv, std::move(pts),
                        std::move(w));
}

double snapToKnot(const KnotVector& k, double t) {
  const std::vector<double>& v = k.values();
  const double tol = kKnotRelTol * (v.back() - v.front());
  for (double b : v)
    if (std::abs(b - t) <= tol) return b;
  return t;
}

}  // namespace seam::detail
