// Loads examples/models/two_patches.json, evaluates a point and its derivatives on a B-spline patch and on
// the rational quarter cylinder, and prints them. Run from the examples/ folder (the test does).
#include <cmath>
#include <cstdio>

#include "seam/core/tolerances.h"
#include "seam/io/file.h"
#include "seam/model/model.h"

int main() {
  const seam::Result<seam::Model> model = seam::io::readModel("models/two_patches.json");
  if (!model) {
    std::fprintf(stderr, "%s\n", model.status().message().c_str());
    return 1;
  }
  std::printf("patches: %zu, curves: %zu, bounding-box diagonal: %.6g\n", model->patches.size(),
              model->curves.size(), model->boundingBox().diagonal());

  // Point and derivatives up to order 2 of patch "A" at (u, v) = (0.25, 0.5): d[k][l] = d^{k+l} S / du^k
  // dv^l.
  const seam::Patch* a = model->findPatch("A");
  if (a == nullptr) return 1;
  const double u = 0.25;
  const double v = 0.5;
  const auto d = a->surface.derivatives(u, v, 2);
  for (int order = 0; order <= 2; ++order) {
    for (int k = order; k >= 0; --k) {
      const seam::VecX& x = d[static_cast<size_t>(k)][static_cast<size_t>(order - k)];
      std::printf("A  d^%d/du^%d dv^%d  = (%.10g, %.10g, %.10g)\n", order, k, order - k, x[0], x[1], x[2]);
    }
  }

  // The rational quarter cylinder has its axis on x = 0, y = 3 and radius 1: every point is at distance 1.
  const seam::Patch* q = model->findPatch("QuarterCylinder");
  if (q == nullptr) return 1;
  const seam::VecX p = q->surface.evaluate(0.3, 0.5);
  const double radius = std::hypot(p[0], p[1] - 3.0);
  std::printf("QuarterCylinder(0.3, 0.5) = (%.10g, %.10g, %.10g), distance from the axis %.17g\n", p[0], p[1],
              p[2], radius);
  constexpr double kRadiusTolerance = 64 * seam::kRoundoff;  // a few round-offs on a unit radius
  return std::abs(radius - 1.0) <= kRadiusTolerance ? 0 : 1;
}
