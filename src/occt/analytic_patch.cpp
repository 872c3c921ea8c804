// Polynomial patches of analytic surfaces in their own parameters (analytic_patch.h).
#include "occt/analytic_patch.h"

#include <fmt/format.h>

#include <Geom_ConicalSurface.hxx>
#include <Geom_CylindricalSurface.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Geom_SphericalSurface.hxx>
#include <Geom_ToroidalSurface.hxx>
#include <Standard_Failure.hxx>
#include <gp_Ax3.hxx>
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "seam/core/bernstein.h"

namespace seam::occt::detail {

namespace {

/// The functions of one parameter the analytic surfaces are sums of products of: 1, the parameter itself, its cosine
/// and its sine.
enum Basis { kOne = 0, kLinear = 1, kCos = 2, kSin = 3 };

/// S(u, v) = sum of f_i(u) g_j(v) C_ij over the terms.
struct Term {
  Basis u, v;
  Vec3 c;
};

Vec3 vec(const gp_XYZ& x) { return {x.X(), x.Y(), x.Z()}; }

/// The n-th derivative of cos (sine: of sin) at m.
double trigDerivative(bool sine, int n, double m) {
  const int k = (n + (sine ? 3 : 0)) % 4;  // sin = cos^(3): sin^(n) = cos^(n + 3)
  switch (k) {
    case 0: return std::cos(m);
    case 1: return -std::sin(m);
    case 2: return -std::cos(m);
    default: return std::sin(m);
  }
}

/// The Bernstein coefficients (degree `degree`, local parameter x in [0, 1] over [a, b]) of f = 1, the parameter, cos
/// or sin: exact for 1 and the parameter; for cos and sin the Taylor polynomial about the middle, its ends then moved
/// onto the values f(a), f(b) by a linear correction (no larger than the remainder), so that neighbouring spans share
/// their end values bit for bit.
VecX basisCoefficients(Basis f, double a, double b, int degree) {
  VecX out(degree + 1);
  switch (f) {
    case kOne:
      out.setOnes();
      return out;
    case kLinear:
      for (int i = 0; i <= degree; ++i) out[i] = a + (b - a) * static_cast<double>(i) / degree;
      return out;
    case kCos:
    case kSin: break;
  }
  const bool sine = f == kSin;
  const double m = 0.5 * (a + b), h = 0.5 * (b - a);
  // sum_n d_n h^n y^n / n! with y = 2 x - 1, written in powers of x.
  VecX power = VecX::Zero(degree + 1);
  double scale = 1.0;  // h^n / n!
  for (int n = 0; n <= degree; ++n) {
    if (n > 0) scale *= h / n;
    const double dn = trigDerivative(sine, n, m) * scale;
    // (2 x - 1)^n = sum_j C(n, j) 2^j x^j (-1)^(n - j)
    double binom = 1.0;
    for (int j = 0; j <= n; ++j) {
      if (j > 0) binom = binom * (n - j + 1) / j;
      power[j] += dn * binom * std::ldexp(1.0, j) * (((n - j) % 2) ? -1.0 : 1.0);
    }
  }
  out = BernsteinPoly::fromPowerBasis(power).coeffs().col(0);
  const double fa = sine ? std::sin(a) : std::cos(a), fb = sine ? std::sin(b) : std::cos(b);
  const double e0 = fa - out[0], e1 = fb - out[degree];
  for (int i = 1; i < degree; ++i) {
    const double x = static_cast<double>(i) / degree;
    out[i] += (1.0 - x) * e0 + x * e1;
  }
  out[0] = fa;
  out[degree] = fb;
  return out;
}

/// The Taylor remainder bound of cos / sin (values) on a span of `length` radians at degree kTrigDegree, and twice
/// that for the pinned ends' linear correction.
double trigError(double length) {
  double r = 1.0;
  for (int n = 1; n <= kTrigDegree + 1; ++n) r *= 0.5 * length / n;
  return 2.0 * r;
}

/// One direction of the patch: its span breaks and degree.
struct Direction {
  std::vector<double> breaks;
  int degree = 1;
  bool trig = false;
};

Direction direction(double lo, double hi, bool trig) {
  Direction d;
  d.trig = trig;
  d.degree = trig ? kTrigDegree : 1;
  const int spans = trig ? std::max(1, static_cast<int>(std::ceil((hi - lo) / kTrigSpanMax))) : 1;
  for (int k = 0; k <= spans; ++k) d.breaks.push_back(k == spans ? hi : lo + (hi - lo) * k / spans);
  return d;
}

std::vector<double> knots(const Direction& d) {
  std::vector<double> k(static_cast<size_t>(d.degree + 1), d.breaks.front());
  for (size_t s = 1; s + 1 < d.breaks.size(); ++s) k.insert(k.end(), static_cast<size_t>(d.degree), d.breaks[s]);
  k.insert(k.end(), static_cast<size_t>(d.degree + 1), d.breaks.back());
  return k;
}

}  // namespace

bool hasAnalyticPatch(const Handle(Geom_Surface) & surface) {
  try {
    Handle(Geom_Surface) base = surface;
    while (const auto t = Handle(Geom_RectangularTrimmedSurface)::DownCast(base)) base = t->BasisSurface();
    return !base.IsNull() && (base->IsKind(STANDARD_TYPE(Geom_CylindricalSurface)) ||
                              base->IsKind(STANDARD_TYPE(Geom_ConicalSurface)) ||
                              base->IsKind(STANDARD_TYPE(Geom_SphericalSurface)) ||
                              base->IsKind(STANDARD_TYPE(Geom_ToroidalSurface)));
  } catch (const Standard_Failure&) {
    return false;
  }
}

Result<AnalyticPatch> analyticPatch(const Handle(Geom_Surface) & surface, double u0, double u1, double v0, double v1) {
  if (!(std::isfinite(u0) && std::isfinite(u1) && std::isfinite(v0) && std::isfinite(v1) && u1 > u0 && v1 > v0))
    return invalidInput(fmt::format("analytic patch: the parameter box [{}, {}] x [{}, {}] is empty or not finite",
                                    u0, u1, v0, v1));
  if (surface.IsNull()) return invalidInput("analytic patch: no surface");
  Handle(Geom_Surface) base = surface;
  std::vector<Term> terms;
  AnalyticPatch out;
  try {
    while (const auto t = Handle(Geom_RectangularTrimmedSurface)::DownCast(base)) base = t->BasisSurface();
    const auto frame = [](const gp_Ax3& p) {
      return std::array<Vec3, 4>{vec(p.Location().XYZ()), vec(p.XDirection().XYZ()), vec(p.YDirection().XYZ()),
                                 vec(p.Direction().XYZ())};
    };
    if (const auto cyl = Handle(Geom_CylindricalSurface)::DownCast(base)) {
      // C + R (cos u X + sin u Y) + v Z (ElSLib::CylinderValue)
      const auto [c, x, y, z] = frame(cyl->Position());
      const double r = cyl->Radius();
      terms = {{kOne, kOne, c}, {kCos, kOne, r * x}, {kSin, kOne, r * y}, {kOne, kLinear, z}};
      out.kind = "cylinder";
    } else if (const auto cone = Handle(Geom_ConicalSurface)::DownCast(base)) {
      // C + (R + v sin a)(cos u X + sin u Y) + v cos a Z (ElSLib::ConeValue)
      const auto [c, x, y, z] = frame(cone->Position());
      const double r = cone->RefRadius(), sa = std::sin(cone->SemiAngle()), ca = std::cos(cone->SemiAngle());
      terms = {{kOne, kOne, c},       {kCos, kOne, r * x},     {kSin, kOne, r * y},
               {kCos, kLinear, sa * x}, {kSin, kLinear, sa * y}, {kOne, kLinear, ca * z}};
      out.kind = "cone";
    } else if (const auto sph = Handle(Geom_SphericalSurface)::DownCast(base)) {
      // C + R cos v (cos u X + sin u Y) + R sin v Z (ElSLib::SphereValue)
      const auto [c, x, y, z] = frame(sph->Position());
      const double r = sph->Radius();
      terms = {{kOne, kOne, c}, {kCos, kCos, r * x}, {kSin, kCos, r * y}, {kOne, kSin, r * z}};
      out.kind = "sphere";
    } else if (const auto tor = Handle(Geom_ToroidalSurface)::DownCast(base)) {
      // C + (R + r cos v)(cos u X + sin u Y) + r sin v Z (ElSLib::TorusValue)
      const auto [c, x, y, z] = frame(tor->Position());
      const double R = tor->MajorRadius(), r = tor->MinorRadius();
      terms = {{kOne, kOne, c},      {kCos, kOne, R * x},    {kSin, kOne, R * y},
               {kCos, kCos, r * x},  {kSin, kCos, r * y},    {kOne, kSin, r * z}};
      out.kind = "torus";
    } else {
      return Status(ErrorCode::kUnsupported,
                    fmt::format("no polynomial patch for a {} in its own parameters", base->DynamicType()->Name()));
    }
  } catch (const Standard_Failure& f) {
    return Status(ErrorCode::kUnsupported, std::string("OpenCASCADE failed on the surface: ") + f.GetMessageString());
  }
  for (const Term& t : terms)
    if (!t.c.allFinite()) return invalidInput("analytic patch: the surface's frame or radii are not finite");
  bool trigU = false, trigV = false;
  for (const Term& t : terms) {
    trigU = trigU || t.u == kCos || t.u == kSin;
    trigV = trigV || t.v == kCos || t.v == kSin;
  }
  const Direction du = direction(u0, u1, trigU), dv = direction(v0, v1, trigV);
  const int numU = static_cast<int>(du.breaks.size() - 1) * du.degree + 1;
  const int numV = static_cast<int>(dv.breaks.size() - 1) * dv.degree + 1;
  Matrix points = Matrix::Zero(static_cast<Eigen::Index>(numU) * numV, 3);
  // The bound of |patch - surface|: per term, |f g - f~ g~| <= ef |g| + |f~| eg with |f~| <= |f| + ef, where |f| <= 1
  // (1, cos, sin) or the largest |parameter| of the box (the parameter itself, which is exact).
  const double maxU = std::max(std::abs(u0), std::abs(u1)), maxV = std::max(std::abs(v0), std::abs(v1));
  const auto bound = [](Basis f, double maxAbs) { return f == kLinear ? maxAbs : 1.0; };
  for (size_t su = 0; su + 1 < du.breaks.size(); ++su) {
    const double a = du.breaks[su], b = du.breaks[su + 1];
    std::array<VecX, 4> fu;
    for (int f = 0; f < 4; ++f) fu[static_cast<size_t>(f)] = basisCoefficients(static_cast<Basis>(f), a, b, du.degree);
    const double eu = du.trig ? trigError(b - a) : 0.0;
    for (size_t sv = 0; sv + 1 < dv.breaks.size(); ++sv) {
      const double c = dv.breaks[sv], d = dv.breaks[sv + 1];
      std::array<VecX, 4> gv;
      for (int g = 0; g < 4; ++g)
        gv[static_cast<size_t>(g)] = basisCoefficients(static_cast<Basis>(g), c, d, dv.degree);
      const double ev = dv.trig ? trigError(d - c) : 0.0;
      double err = 0.0;
      for (const Term& t : terms) {
        const double ef = (t.u == kCos || t.u == kSin) ? eu : 0.0, eg = (t.v == kCos || t.v == kSin) ? ev : 0.0;
        err += (ef * bound(t.v, maxV) + (bound(t.u, maxU) + ef) * eg) * t.c.norm();
      }
      out.positionError = std::max(out.positionError, err);
      for (int k = 0; k <= du.degree; ++k)
        for (int l = 0; l <= dv.degree; ++l) {
          Vec3 p = Vec3::Zero();
          for (const Term& t : terms)
            p += fu[static_cast<size_t>(t.u)][k] * gv[static_cast<size_t>(t.v)][l] * t.c;
          const Eigen::Index row = static_cast<Eigen::Index>(static_cast<int>(su) * du.degree + k) * numV +
                                   static_cast<int>(sv) * dv.degree + l;
          points.row(row) = p.transpose();
        }
    }
  }
  Result<BSplineSurface> s =
      BSplineSurface::create(du.degree, dv.degree, knots(du), knots(dv), numU, numV, std::move(points));
  if (!s) return Status(ErrorCode::kInvalidInput, "analytic patch: " + s.status().message());
  out.surface = std::move(s).value();
  return out;
}

}  // namespace seam::occt::detail
