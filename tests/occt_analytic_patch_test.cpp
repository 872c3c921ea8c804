// The polynomial patches of analytic surfaces in their own parameters (src/occt/analytic_patch.h), against
// OpenCASCADE's own evaluation of the same surfaces (Geom_Surface::D1: another implementation of the closed forms).
#include <gtest/gtest.h>

#include <Geom_ConicalSurface.hxx>
#include <Geom_CylindricalSurface.hxx>
#include <Geom_Plane.hxx>
#include <Geom_RectangularTrimmedSurface.hxx>
#include <Geom_SphericalSurface.hxx>
#include <Geom_ToroidalSurface.hxx>
#include <gp_Ax3.hxx>
#include <gp_Pnt.hxx>
#include <gp_Vec.hxx>
#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "occt/analytic_patch.h"
#include "test_helpers.h"

namespace seam {
namespace {

constexpr double kPi = std::numbers::pi;

Vec3 vec(const gp_XYZ& x) { return {x.X(), x.Y(), x.Z()}; }

struct Case {
  std::string name;
  Handle(Geom_Surface) surface;
  double u0, u1, v0, v1, size;
};

/// An oblique frame (not the world axes) so that every coordinate of the patch carries both cos and sin terms.
gp_Ax3 frame(double scale, bool leftHanded) {
  gp_Ax3 a(gp_Pnt(0.3 * scale, -0.7 * scale, 1.1 * scale), gp_Dir(0.2, -0.3, 0.93), gp_Dir(0.8, 0.5, 0.0));
  if (leftHanded) a.YReverse();
  return a;
}

std::vector<Case> cases(double scale) {
  std::vector<Case> out;
  for (const bool left : {false, true}) {
    const std::string hand = left ? " (left-handed)" : "";
    out.push_back({"cylinder" + hand, new Geom_CylindricalSurface(frame(scale, left), 2.0 * scale), -0.4,
                   2.0 * kPi - 0.4, -3.0 * scale, 5.0 * scale, 5.0 * scale});
    out.push_back({"cone" + hand, new Geom_ConicalSurface(frame(scale, left), 0.35, 1.5 * scale), 1.0, 4.0,
                   -1.0 * scale, 2.0 * scale, 3.0 * scale});
    out.push_back({"sphere" + hand, new Geom_SphericalSurface(frame(scale, left), 3.0 * scale), 0.0, 2.0 * kPi,
                   -kPi / 2, kPi / 2, 3.0 * scale});
    out.push_back({"torus" + hand, new Geom_ToroidalSurface(frame(scale, left), 4.0 * scale, 1.0 * scale), 0.5, 3.0,
                   -2.0, 2.5, 5.0 * scale});
  }
  return out;
}

TEST(AnalyticPatch, ReproducesCylindersConesSpheresAndToriInTheirOwnParameters) {
  // At 400 random points of each box, at three scales: the patch's point within its own error bound (plus round-off
  // of the evaluation, 1e-14 of the size) of OpenCASCADE's, and its first partials within 1e-12 of the size (the
  // Taylor remainder of a derivative is 2.3e-15 of the radius; the rest is round-off). The error bound itself is
  // at the round-off of the model's size (2.3e-16 of a sphere's radius: both directions are circles).
  std::mt19937 rng(20261203);
  for (const double scale : {1e-3, 1.0, 1e4})
    for (const Case& c : cases(scale)) {
      SCOPED_TRACE(c.name + " at scale " + std::to_string(scale));
      const Result<occt::detail::AnalyticPatch> p = occt::detail::analyticPatch(c.surface, c.u0, c.u1, c.v0, c.v1);
      ASSERT_TRUE(p.isOk()) << p.status().message();
      EXPECT_LE(p->positionError, 1e-15 * c.size);
      EXPECT_EQ(p->surface.domainU().lo, c.u0);
      EXPECT_EQ(p->surface.domainU().hi, c.u1);
      std::uniform_real_distribution<double> du(c.u0, c.u1), dv(c.v0, c.v1);
      for (int i = 0; i < 400; ++i) {
        const double u = du(rng);
        const double v = dv(rng);
        gp_Pnt q;
        gp_Vec qu, qv;
        c.surface->D1(u, v, q, qu, qv);
        Vec3 x, xu, xv;
        p->surface.pointAndFirstDerivatives(u, v, x, xu, xv);
        EXPECT_LE((x - vec(q.XYZ())).norm(), p->positionError + 1e-14 * c.size) << "u " << u << " v " << v;
        EXPECT_LE((xu - vec(qu.XYZ())).norm(), 1e-12 * c.size) << "u " << u << " v " << v;
        EXPECT_LE((xv - vec(qv.XYZ())).norm(), 1e-12 * c.size) << "u " << u << " v " << v;
      }
    }
}

TEST(AnalyticPatch, SpansEndOnTheSurfaceBitForBitAndStayShort) {
  // A whole cylinder: the span breaks at most kTrigSpanMax apart, and at each break the patch's point is the
  // closed form's value computed from cos / sin at the break (the pinned ends), as on the neighbouring span.
  const Handle(Geom_CylindricalSurface) cyl = new Geom_CylindricalSurface(gp_Ax3(gp::XOY()), 7.0);
  const Result<occt::detail::AnalyticPatch> p = occt::detail::analyticPatch(cyl, 0.0, 2.0 * kPi, 0.0, 1.0);
  ASSERT_TRUE(p.isOk()) << p.status().message();
  EXPECT_EQ(p->kind, "cylinder");
  EXPECT_EQ(p->surface.degreeU(), occt::detail::kTrigDegree);
  EXPECT_EQ(p->surface.degreeV(), 1);
  std::vector<double> breaks;
  for (const double k : p->surface.knotsU().values())
    if (breaks.empty() || k > breaks.back()) breaks.push_back(k);
  ASSERT_GE(breaks.size(), 2u);
  EXPECT_EQ(static_cast<int>(breaks.size()) - 1, static_cast<int>(std::ceil(2.0 * kPi / occt::detail::kTrigSpanMax)));
  for (size_t k = 0; k + 1 < breaks.size(); ++k)
    EXPECT_LE(breaks[k + 1] - breaks[k], occt::detail::kTrigSpanMax * (1.0 + 1e-12));
  for (const double b : breaks) {
    const Vec3 x = p->surface.evaluate(b, 0.5).head<3>();
    EXPECT_NEAR(x.x(), 7.0 * std::cos(b), 1e-14 * 7.0) << b;
    EXPECT_NEAR(x.y(), 7.0 * std::sin(b), 1e-14 * 7.0) << b;
  }
}

TEST(AnalyticPatch, OtherSurfacesAndEmptyBoxesAreRefused) {
  const Handle(Geom_Plane) plane = new Geom_Plane(gp_Ax3(gp::XOY()));
  const Result<occt::detail::AnalyticPatch> p = occt::detail::analyticPatch(plane, 0.0, 1.0, 0.0, 1.0);
  ASSERT_FALSE(p.isOk());
  EXPECT_EQ(p.status().code(), ErrorCode::kUnsupported);
  EXPECT_NE(p.status().message().find("Geom_Plane"), std::string::npos) << p.status().message();
  const Handle(Geom_CylindricalSurface) cyl = new Geom_CylindricalSurface(gp_Ax3(gp::XOY()), 1.0);
  for (const auto& box : std::vector<std::array<double, 4>>{
           {1.0, 1.0, 0.0, 1.0}, {0.0, 1.0, 2.0, 1.0}, {0.0, std::nan(""), 0.0, 1.0}, {0.0, 1.0, 0.0, HUGE_VAL}}) {
    const Result<occt::detail::AnalyticPatch> q = occt::detail::analyticPatch(cyl, box[0], box[1], box[2], box[3]);
    ASSERT_FALSE(q.isOk());
    EXPECT_EQ(q.status().code(), ErrorCode::kInvalidInput);
  }
  const Result<occt::detail::AnalyticPatch> none = occt::detail::analyticPatch(Handle(Geom_Surface)(), 0, 1, 0, 1);
  ASSERT_FALSE(none.isOk());
  EXPECT_EQ(none.status().code(), ErrorCode::kInvalidInput);
  EXPECT_FALSE(occt::detail::hasAnalyticPatch(Handle(Geom_Surface)()));
  EXPECT_FALSE(occt::detail::hasAnalyticPatch(plane));
  EXPECT_TRUE(occt::detail::hasAnalyticPatch(cyl));
  // Under a trimmed surface the basis surface is taken.
  const Handle(Geom_RectangularTrimmedSurface) trimmed = new Geom_RectangularTrimmedSurface(cyl, 0.0, 1.0, 0.0, 2.0);
  const Result<occt::detail::AnalyticPatch> t = occt::detail::analyticPatch(trimmed, 0.0, 1.0, 0.0, 2.0);
  ASSERT_TRUE(t.isOk()) << t.status().message();
  EXPECT_EQ(t->kind, "cylinder");
}

}  // namespace
}  // namespace seam
