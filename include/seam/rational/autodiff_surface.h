#pragma once
// A homogeneous surface Q = (R, w) given as a C++ callable, differentiated by forward-mode automatic
// differentiation (Boost.Math autodiff, header-only: Debian libboost-dev). All mixed partial derivatives of total
// order <= kOrder come out of one evaluation, exact up to round-off.
//
//   auto q = seam::rational::autodiffSurface<4>("rbar", {0, 1}, {0, 1}, [](auto u, auto v) {
//     using std::sin;  // found by argument-dependent lookup for the autodiff type
//     return std::array{u, v, sin(u) * v, 1.0 + v};
//   });
//
// The callable receives u and v as the same autodiff scalar type T and returns four values convertible to T
// (x, y, z, w), e.g. std::array<T, 4>. Use the functions of <cmath> unqualified (with `using std::sin;` ...) so that
// the autodiff overloads are found.
#include <boost/math/differentiation/autodiff.hpp>
#include <string>
#include <utility>

#include "seam/rational/homogeneous_surface.h"

namespace seam::rational {

template <int kOrder, class F>
HomogeneousSurface autodiffSurface(std::string name, Interval domainU, Interval domainV, F f) {
  static_assert(kOrder >= 0 && kOrder <= 12, "autodiffSurface: derivative order must be in [0, 12]");
  namespace ad = boost::math::differentiation;
  HomogeneousSurface::Evaluator ev = [f, name](double u, double v, int order) -> Result<DerivativeTable> {
    const auto vars = ad::make_ftuple<double, kOrder, kOrder>(u, v);
    // fvar<fvar<double, N>, N>, the type of any expression in both variables; u and v are promoted to it.
    using T = std::decay_t<decltype(std::get<0>(vars) * std::get<1>(vars))>;
    const T uu = std::get<0>(vars);
    const T vv = std::get<1>(vars);
    const auto q = f(uu, vv);
    DerivativeTable d(static_cast<size_t>(order + 1));
    for (int a = 0; a <= order; ++a) {
      d[static_cast<size_t>(a)].resize(static_cast<size_t>(order - a + 1));
      for (int b = 0; a + b <= order; ++b) {
        Vec4 x;
        for (int k = 0; k < 4; ++k) {
          const T qk = q[static_cast<size_t>(k)];
          x[k] = static_cast<double>(qk.derivative(static_cast<size_t>(a), static_cast<size_t>(b)));
        }
        if (!x.allFinite())
          return Status(ErrorCode::kInvalidInput,
                        "surface \"" + name + "\": derivative (" + std::to_string(a) + ", " + std::to_string(b) +
                            ") is not finite at (" + std::to_string(u) + ", " + std::to_string(v) + ")");
        d[static_cast<size_t>(a)][static_cast<size_t>(b)] = x;
      }
    }
    return d;
  };
  return HomogeneousSurface(std::move(name), domainU, domainV, kOrder, std::move(ev));
}

}  // namespace seam::rational
