#pragma once
// Named tolerances. Every comparison against a threshold in seam goes through one of these; see
// docs/tolerances.md for what each means, its default and how it scales with the model.
#include <algorithm>
#include <cmath>
#include <optional>

namespace seam {

/// Relative round-off level of double arithmetic on well-scaled data (about 2^-40). A quantity whose magnitude is
/// below kRoundoff * scale (scale = the magnitude of the data it was computed from) is "zero up to round-off".
inline constexpr double kRoundoff = 1e-12;

/// Two knots closer than kKnotRelTol * (knot-vector length) are the same knot (multiplicity counting, span search).
inline constexpr double kKnotRelTol = 1e-12;

/// A polynomial identity (e.g. "the normals of two patches are parallel along the whole seam") is taken to hold when
/// every Bernstein coefficient of the difference is below kIdentityRelTol x the scale of the data it was computed
/// from. Products of several factors of degree up to ~30 lose a few digits more than kRoundoff; 1e-10 leaves two
/// orders of margin while any real defect of a CAD model (>= 1e-8 relative) stays far above it.
inline constexpr double kIdentityRelTol = 1e-10;

/// Model-dependent tolerances used to classify geometry. Defaults follow `seam check` (issue 3):
/// distance = 1e-6 x bounding-box diagonal, angle = 0.01 degrees, curvature = 1 % relative.
struct Tolerances {
  double distance = 1e-6;       ///< absolute length; G0 gaps at or below it count as closed
  double angleDeg = 0.01;       ///< degrees; tangent-plane angles at or below it count as G1
  double curvatureRel = 0.01;   ///< relative; normal-curvature jumps at or below it (relative) count as G2
  double parametric = 1e-9;     ///< relative; parametric derivative mismatch (C1/C2) relative to the derivative size

  /// Defaults scaled to a model whose bounding-box diagonal is `diagonal` (a zero or non-finite diagonal -> 1).
  static Tolerances forModelSize(double diagonal) {
    Tolerances t;
    const double d = (std::isfinite(diagonal) && diagonal > 0.0) ? diagonal : 1.0;
    t.distance = 1e-6 * d;
    return t;
  }
};

/// User choices (e.g. the CLI's --tol-* options) that replace single fields of the model-size defaults.
struct ToleranceOverrides {
  std::optional<double> distance, angleDeg, curvatureRel;
  [[nodiscard]] Tolerances appliedTo(Tolerances t) const {
    if (distance) t.distance = *distance;
    if (angleDeg) t.angleDeg = *angleDeg;
    if (curvatureRel) t.curvatureRel = *curvatureRel;
    return t;
  }
};

}  // namespace seam
