#pragma once
// Pointwise curvature comparison and 1-D maximum refinement shared by the seam analysis (continuity/seam.cpp) and
// the B-rep edge check (occt/brep_check.cpp).
#include <Eigen/Dense>
#include <functional>
#include <utility>
#include <vector>

#include "seam/core/types.h"

namespace seam::detail {

/// Local maxima of a sampled measure that are refined by golden-section search, and the iterations per maximum
/// (0.618^40 ~ 4e-9 of the bracketing interval).
inline constexpr int kRefinedMaxima = 3;
inline constexpr int kGoldenIterations = 40;

/// The shape operator (second fundamental form with respect to unit normal n) of a surface with first partials
/// su, sv and second partials suu, suv, svv, expressed in the orthonormal tangent frame (e1, e2).
Eigen::Matrix2d shapeInFrame(const Vec3& su, const Vec3& sv, const Vec3& suu, const Vec3& suv, const Vec3& svv,
                             const Vec3& n, const Vec3& e1, const Vec3& e2);

/// Spectral norm of the symmetric part of m (largest |normal curvature| difference over all directions).
double spectralNorm(const Eigen::Matrix2d& m);

/// Golden-section refinement of a local maximum of f on [lo, hi]: (x, f(x)).
std::pair<double, double> refineMax(const std::function<double(double)>& f, double lo, double hi,
                                    int iterations = kGoldenIterations);

/// Refines the kRefinedMaxima largest local maxima of values[i] (sampled at xs[i], increasing) between their
/// neighbouring samples and returns the best (x, value), never below the best sample.
std::pair<double, double> refinedMaximum(const std::vector<double>& xs, const std::vector<double>& values,
                                         const std::function<double(double)>& f);

}  // namespace seam::detail
