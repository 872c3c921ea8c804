#pragma once
// Basic value types shared by every module.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace seam {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using VecX = Eigen::VectorXd;
/// A list of points or coefficients: one ROW per point, one column per coordinate.
using Matrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

/// A closed parameter interval [lo, hi].
struct Interval {
  double lo = 0.0;
  double hi = 1.0;
  [[nodiscard]] double length() const { return hi - lo; }
  [[nodiscard]] bool contains(double t) const { return t >= lo && t <= hi; }
  friend bool operator==(const Interval&, const Interval&) = default;
};

}  // namespace seam
