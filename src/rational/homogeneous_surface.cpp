// Homogeneous surfaces for the rational GC^n analysis; see include/seam/rational/homogeneous_surface.h.
#include "seam/rational/homogeneous_surface.h"

#include <fmt/format.h>

#include <cmath>
#include <memory>

#include "seam/core/knot_vector.h"
#include "seam/core/tolerances.h"

namespace seam::rational {

HomogeneousSurface::HomogeneousSurface(std::string name, Interval domainU, Interval domainV, int maxOrder,
                                       Evaluator evaluator)
    : name_(std::move(name)), u_(domainU), v_(domainV), maxOrder_(maxOrder), eval_(std::move(evaluator)) {}

Result<DerivativeTable> HomogeneousSurface::derivatives(double u, double v, int order) const {
  if (!eval_) return invalidInput("empty homogeneous surface");
  if (order < 0 || order > maxOrder_)
    return invalidInput(fmt::format("surface \"{}\": derivatives of order {} requested, at most {} available", name_,
                                    order, maxOrder_));
  return eval_(u, v, order);
}

Result<Vec3> HomogeneousSurface::point(double u, double v) const {
  auto d = derivatives(u, v, 0);
  if (!d) return d.status();
  const Vec4& q = (*d)[0][0];
  if (!(std::abs(q[3]) > 0.0) || !q.allFinite())
    return Status(ErrorCode::kDegenerate,
                  fmt::format("surface \"{}\": weight is zero or not finite at ({}, {})", name_, u, v));
  return Vec3(q.head<3>() / q[3]);
}

HomogeneousSurface HomogeneousSurface::edgeFrame(Edge e, bool outward) const {
  // (u, v) = origin + a * da * axisA + b * axisB; swapped when the edge runs along u (V0/V1).
  const bool swap = !isUEdge(e);
  const Interval across = swap ? v_ : u_;
  const Interval along = swap ? u_ : v_;
  const bool atLow = (e == Edge::U0 || e == Edge::V0);
  const double origin = atLow ? across.lo : across.hi;
  // Moving into the patch from the edge: +1 at the low end, -1 at the high end.
  const double inward = atLow ? 1.0 : -1.0;
  const double sa = outward ? -inward : inward;
  const Interval aDomain = outward ? Interval{-across.length(), 0.0} : Interval{0.0, across.length()};
  auto base = eval_;
  Evaluator ev = [base, swap, origin, sa](double a, double b, int order) -> Result<DerivativeTable> {
    const double x = origin + sa * a;
    auto r = swap ? base(b, x, order) : base(x, b, order);
    if (!r) return r;
    const DerivativeTable& d = *r;
    DerivativeTable out(static_cast<size_t>(order + 1));
    for (int i = 0; i <= order; ++i) {
      out[static_cast<size_t>(i)].resize(static_cast<size_t>(order - i + 1));
      const double f = (i % 2 == 1 && sa < 0.0) ? -1.0 : 1.0;
      for (int j = 0; i + j <= order; ++j)
        out[static_cast<size_t>(i)][static_cast<size_t>(j)] =
            f * (swap ? d[static_cast<size_t>(j)][static_cast<size_t>(i)] : d[static_cast<size_t>(i)][static_cast<size_t>(j)]);
    }
    return out;
  };
  return HomogeneousSurface(name_, aDomain, along, maxOrder_, std::move(ev));
}

HomogeneousSurface HomogeneousSurface::normalized(const Vec3& center, double scale) const {
  auto base = eval_;
  Evaluator ev = [base, center, scale](double u, double v, int order) -> Result<DerivativeTable> {
    auto r = base(u, v, order);
    if (!r) return r;
    DerivativeTable d = std::move(*r);
    for (auto& row : d)
      for (Vec4& q : row) q.head<3>() = (q.head<3>() - center * q[3]) / scale;
    return d;
  };
  return HomogeneousSurface(name_, u_, v_, maxOrder_, std::move(ev));
}

HomogeneousSurface homogeneousSurface(const BSplineSurface& surface, std::string name) {
  // Homogeneous control points as 4-vectors (w P, w), shared by every copy of the evaluator.
  auto s = std::make_shared<const BSplineSurface>(surface);
  auto pw = std::make_shared<Matrix>(surface.numU() * surface.numV(), 4);
  for (int i = 0; i < surface.numU(); ++i)
    for (int j = 0; j < surface.numV(); ++j) {
      const int row = i * surface.numV() + j;
      const double w = surface.weight(i, j);
      pw->row(row).head(3) = w * surface.point(i, j).head(3);
      (*pw)(row, 3) = w;
    }
  const std::string label = name;
  HomogeneousSurface::Evaluator ev = [s, pw](double u, double v, int order) -> Result<DerivativeTable> {
    const int pu = s->degreeU(), pv = s->degreeV();
    const int su = s->knotsU().findSpan(pu, u), sv = s->knotsV().findSpan(pv, v);
    const Matrix Nu = basisFunctionDerivatives(s->knotsU(), pu, su, u, std::min(order, pu));
    const Matrix Nv = basisFunctionDerivatives(s->knotsV(), pv, sv, v, std::min(order, pv));
    DerivativeTable d(static_cast<size_t>(order + 1));
    for (int a = 0; a <= order; ++a) {
      d[static_cast<size_t>(a)].assign(static_cast<size_t>(order - a + 1), Vec4::Zero());
      if (a > pu) continue;
      for (int b = 0; a + b <= order && b <= pv; ++b) {
        Vec4 acc = Vec4::Zero();
        for (int r = 0; r <= pu; ++r) {
          Vec4 row = Vec4::Zero();
          for (int c = 0; c <= pv; ++c)
            row += Nv(b, c) * pw->row((su - pu + r) * s->numV() + (sv - pv + c)).transpose();
          acc += Nu(a, r) * row;
        }
        d[static_cast<size_t>(a)][static_cast<size_t>(b)] = acc;
      }
    }
    return d;
  };
  return HomogeneousSurface(label, surface.domainU(), surface.domainV(), std::numeric_limits<int>::max() / 4,
                            std::move(ev));
}

}  // namespace seam::rational
