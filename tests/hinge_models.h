#pragma once
// Models whose seam verdicts are known by construction (issue 17): pairs of planar bilinear patches meeting along a
// straight edge at a given angle, optionally with a gap. Used by verdict_test, cli_check_test, heal_test, join_test.
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "seam/model/model.h"
#include "seam/spline/bspline_surface.h"

namespace seam::test {

/// A bilinear (degree 1 x 1) patch with corners P(u, v) = o + u du + v dv, u, v in [0, 1].
inline Patch planarPatch(const std::string& name, const Vec3& o, const Vec3& du, const Vec3& dv) {
  Matrix pts(4, 3);
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) pts.row(i * 2 + j) = (o + i * du + j * dv).transpose();
  return Patch{name, PatchKind::kBezier, BSplineSurface(1, 1, KnotVector::bezier(1), KnotVector::bezier(1), 2, 2, pts)};
}

/// One hinge: A in the plane z = 0 (x in [-1, 0], y in [y0, y0 + 1]), B leaving A's edge x = 0 (A:u1 = B:u0) in the
/// direction (cos phi, 0, sin phi), so that the oriented normals of A and B differ by exactly `angleDeg` degrees
/// along the whole seam. B is lifted by `gap` in z (a seam with a gap of exactly `gap`, measured perpendicular to A).
inline void addHinge(Model& m, const std::string& a, const std::string& b, double angleDeg, double y0,
                     double gap = 0.0) {
  const double phi = angleDeg * std::numbers::pi / 180.0;
  m.patches.push_back(planarPatch(a, Vec3(-1.0, y0, 0.0), Vec3(1.0, 0.0, 0.0), Vec3(0.0, 1.0, 0.0)));
  m.patches.push_back(
      planarPatch(b, Vec3(0.0, y0, gap), Vec3(std::cos(phi), 0.0, std::sin(phi)), Vec3(0.0, 1.0, 0.0)));
}

/// Hinges side by side (2 apart in y, so that no two hinges pair), named A<k> / B<k>.
inline Model hingeModel(const std::vector<double>& anglesDeg, const std::vector<double>& gaps = {}) {
  Model m;
  for (size_t k = 0; k < anglesDeg.size(); ++k)
    addHinge(m, "A" + std::to_string(k), "B" + std::to_string(k), anglesDeg[k], 2.0 * static_cast<double>(k),
             k < gaps.size() ? gaps[k] : 0.0);
  return m;
}

/// `m` with every control point multiplied by `s` (knots and weights as they are): the same model in another unit.
inline Model scaledModel(const Model& m, double s) {
  Model out = m;
  for (Patch& p : out.patches) {
    const BSplineSurface& f = p.surface;
    p.surface = BSplineSurface(f.degreeU(), f.degreeV(), f.knotsU(), f.knotsV(), f.numU(), f.numV(), f.points() * s,
                               f.weights());
  }
  return out;
}

}  // namespace seam::test
