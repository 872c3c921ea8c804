// seam and OpenCASCADE side by side, in one process, on the same surfaces (issue 16, goal 1).
//
//   evaluation  a 50 x 50 bicubic B-spline surface (polynomial and rational): point + first derivatives
//     (a) at 10^6 random parameters: seam `pointAndFirstDerivatives` vs `Geom_BSplineSurface::D1`
//     (b) on a 256 x 256 grid: seam `GridEvaluator` vs OpenCASCADE's fastest path, `GeomAdaptor_Surface::D1`
//         (a BSplSLib_Cache per span pair), fed span block by span block so that each cache is built once
//   model check  100 x 100 bicubic Bezier patches cut from one C2 surface, some seams perturbed:
//     seam `checkModel` (pairing, every seam certified G0/G1/G2, corners; one thread) vs OpenCASCADE's
//     `LocalAnalysis_SurfaceContinuity` (order G2) at 21 points per seam with the adjacency given for free.
//   network check  the closed 6 000-patch network of the local scheme's benchmarks (the frequency-10 geodesic
//     icosahedron split into quads on the unit sphere, tests/network_support.h): 12 000 seams, every one G0 with a
//     kink, and no two patches share control rows (issue 37 goal 1). The same two loops as for the grid model;
//     OpenCASCADE's side gets the network's adjacency (which side of which patch, which way round) for free.
//
// Before timing, both sides are evaluated at the same parameters and must agree (points and derivatives to 1e-11
// relative), and the model check's verdicts are compared (perturbed seams found by both). The benchmarks of each pair
// run one after the other (seam, then OpenCASCADE) and the program ends with a table of ratios.
// Built only when OpenCASCADE is found (SEAM_WITH_OCCT=ON). Run: build/bench/occt_side_by_side
#include <benchmark/benchmark.h>

#include <BSplCLib.hxx>
#include <GeomAbs_Shape.hxx>
#include <GeomAdaptor_Surface.hxx>
#include <Geom_BSplineSurface.hxx>
#include <LocalAnalysis_SurfaceContinuity.hxx>
#include <TColStd_Array1OfInteger.hxx>
#include <TColStd_Array1OfReal.hxx>
#include <TColStd_Array2OfReal.hxx>
#include <TColgp_Array2OfPnt.hxx>
#include <gp_Pnt.hxx>
#include <gp_Pnt2d.hxx>
#include <gp_Vec.hxx>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "seam/continuity/model_check.h"
#include "seam/spline/bspline_surface.h"

#include "../tests/network_support.h"
#include "bench_models.h"

namespace {

using seam::BSplineSurface;
using seam::Matrix;
using seam::Model;

// ---- the same surface on both sides ---------------------------------------------------------------------------

BSplineSurface makeSurface(bool rational) { return seam::bench::jitteredSurface50(rational); }

// Distinct knots and multiplicities of a flat knot vector, as OpenCASCADE wants them.
void splitKnots(const std::vector<double>& flat, std::vector<double>& knots, std::vector<int>& mults) {
  for (double k : flat) {
    if (!knots.empty() && k == knots.back()) {
      ++mults.back();
    } else {
      knots.push_back(k);
      mults.push_back(1);
    }
  }
}

Handle(Geom_BSplineSurface) toOcct(const BSplineSurface& s) {
  TColgp_Array2OfPnt poles(1, s.numU(), 1, s.numV());
  TColStd_Array2OfReal weights(1, s.numU(), 1, s.numV());
  for (int i = 0; i < s.numU(); ++i)
    for (int j = 0; j < s.numV(); ++j) {
      const auto p = s.point(i, j);
      poles.SetValue(i + 1, j + 1, gp_Pnt(p[0], p[1], p[2]));
      weights.SetValue(i + 1, j + 1, s.weight(i, j));
    }
  std::vector<double> ku, kv;
  std::vector<int> mu, mv;
  splitKnots(s.knotsU().values(), ku, mu);
  splitKnots(s.knotsV().values(), kv, mv);
  TColStd_Array1OfReal KU(1, static_cast<int>(ku.size())), KV(1, static_cast<int>(kv.size()));
  TColStd_Array1OfInteger MU(1, static_cast<int>(mu.size())), MV(1, static_cast<int>(mv.size()));
  for (size_t i = 0; i < ku.size(); ++i) {
    KU.SetValue(static_cast<int>(i) + 1, ku[i]);
    MU.SetValue(static_cast<int>(i) + 1, mu[i]);
  }
  for (size_t i = 0; i < kv.size(); ++i) {
    KV.SetValue(static_cast<int>(i) + 1, kv[i]);
    MV.SetValue(static_cast<int>(i) + 1, mv[i]);
  }
  if (s.isRational()) return new Geom_BSplineSurface(poles, weights, KU, KV, MU, MV, s.degreeU(), s.degreeV());
  return new Geom_BSplineSurface(poles, KU, KV, MU, MV, s.degreeU(), s.degreeV());
}

struct SurfacePair {
  BSplineSurface seam;
  Handle(Geom_BSplineSurface) occt;
};

const SurfacePair& surfacePair(bool rational) {
  static std::map<bool, SurfacePair> cache;
  auto it = cache.find(rational);
  if (it == cache.end()) {
    BSplineSurface s = makeSurface(rational);
    Handle(Geom_BSplineSurface) o = toOcct(s);
    it = cache.emplace(rational, SurfacePair{std::move(s), o}).first;
  }
  return it->second;
}

double relDiff(const seam::Vec3& a, const gp_XYZ& b, double scale) {
  return std::sqrt((a[0] - b.X()) * (a[0] - b.X()) + (a[1] - b.Y()) * (a[1] - b.Y()) + (a[2] - b.Z()) * (a[2] - b.Z())) /
         scale;
}

// Both sides at 10 000 random parameters and on the grid: points and first derivatives must agree.
void verifyEvaluation(bool rational) {
  const SurfacePair& sp = surfacePair(rational);
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  double worst = 0.0;
  GeomAdaptor_Surface adaptor(sp.occt);
  for (int k = 0; k < 10000; ++k) {
    const double u = u01(rng), v = u01(rng);
    seam::Vec3 p, du, dv;
    sp.seam.pointAndFirstDerivatives(u, v, p, du, dv);
    gp_Pnt P;
    gp_Vec DU, DV;
    sp.occt->D1(u, v, P, DU, DV);
    const double scale = std::max({1.0, p.norm(), du.norm(), dv.norm()});
    worst = std::max({worst, relDiff(p, P.XYZ(), scale), relDiff(du, DU.XYZ(), scale), relDiff(dv, DV.XYZ(), scale)});
    adaptor.D1(u, v, P, DU, DV);
    worst = std::max({worst, relDiff(p, P.XYZ(), scale), relDiff(du, DU.XYZ(), scale), relDiff(dv, DV.XYZ(), scale)});
  }
  std::printf("verified: %s surface, seam vs OpenCASCADE (D1 and the cached adaptor), largest relative difference "
              "%.3g over 10 000 points\n",
              rational ? "rational" : "polynomial", worst);
  if (!(worst <= 1e-11)) {
    std::fprintf(stderr, "the two sides disagree (%.3g): no timing\n", worst);
    std::exit(1);
  }
}

// ---- (a) random parameters --------------------------------------------------------------------------------------

using seam::bench::kEvalGrid;
using seam::bench::kEvalRandomPoints;

void BM_Random_seam(benchmark::State& state) {
  seam::bench::timeRandomEvaluation(state, surfacePair(state.range(0) != 0).seam);
}

void BM_Random_occt(benchmark::State& state) {
  const SurfacePair& sp = surfacePair(state.range(0) != 0);
  const auto [us, vs] = seam::bench::randomParameterPairs();
  for (auto _ : state) {
    double acc = 0.0;
    for (size_t i = 0; i < us.size(); ++i) {
      gp_Pnt p;
      gp_Vec du, dv;
      sp.occt->D1(us[i], vs[i], p, du, dv);
      acc += p.X() + du.Y() + dv.Z();
    }
    benchmark::DoNotOptimize(acc);
  }
  state.SetItemsProcessed(state.iterations() * kEvalRandomPoints);
}

// ---- (b) grid --------------------------------------------------------------------------------------------------

void BM_Grid_seam(benchmark::State& state) {
  seam::bench::timeGridEvaluation(state, surfacePair(state.range(0) != 0).seam);
}

// OpenCASCADE's fastest path: GeomAdaptor_Surface keeps a BSplSLib_Cache (the span's polynomial in power form)
// and rebuilds it only when the parameter leaves the cached span pair. The grid is visited span block by span
// block so that each of the 47 x 47 caches is built exactly once; results go to arrays like seam's.
void BM_Grid_occt(benchmark::State& state) {
  const SurfacePair& sp = surfacePair(state.range(0) != 0);
  const std::vector<double> g = seam::bench::evenParameters(kEvalGrid);
  // Grid indices grouped by knot span (same span rule on both axes: the knot vectors are equal).
  const std::vector<double>& flat = sp.seam.knotsU().values();
  std::vector<std::vector<int>> blocks;
  int current = -1;
  for (int i = 0; i < kEvalGrid; ++i) {
    const double t = g[static_cast<size_t>(i)];
    int span = 3;
    while (span + 1 < static_cast<int>(flat.size()) - 4 && flat[static_cast<size_t>(span + 1)] <= t) ++span;
    if (span != current) {
      blocks.emplace_back();
      current = span;
    }
    blocks.back().push_back(i);
  }
  GeomAdaptor_Surface adaptor(sp.occt);
  std::vector<gp_Pnt> P(static_cast<size_t>(kEvalGrid * kEvalGrid));
  std::vector<gp_Vec> Du(P.size()), Dv(P.size());
  for (auto _ : state) {
    for (const auto& bu : blocks)
      for (const auto& bv : blocks)
        for (int i : bu)
          for (int j : bv) {
            const size_t k = static_cast<size_t>(i * kEvalGrid + j);
            adaptor.D1(g[static_cast<size_t>(i)], g[static_cast<size_t>(j)], P[k], Du[k], Dv[k]);
          }
    benchmark::DoNotOptimize(P.data());
    benchmark::DoNotOptimize(Du.data());
    benchmark::DoNotOptimize(Dv.data());
  }
  state.SetItemsProcessed(state.iterations() * kEvalGrid * kEvalGrid);
}

// ---- model check --------------------------------------------------------------------------------------------------

constexpr int kModelN = 100;
constexpr int kOcctSamplesPerSeam = 21;

struct GridModel {
  Model model;
  std::vector<Handle(Geom_BSplineSurface)> occt;
  std::vector<int> spanU, spanV;
  std::vector<seam::Interval> u, v;
  std::vector<std::array<int, 2>> seams;  // (a, b): b is a's neighbour at a's U1 (b's U0) or V1 (b's V0)
  std::vector<bool> alongU;               // true: the seam is a's U1 edge (runs along v)
};

const GridModel& gridModel() {
  static GridModel gm = [] {
    GridModel out;
    std::map<std::pair<int, int>, int> at;
    int index = 0;
    for (const seam::BezierPatchPiece& piece : seam::bench::gridPieces(kModelN)) {
      BSplineSurface b = piece.patch.toBSpline(piece.u, piece.v);
      out.occt.push_back(toOcct(b));
      out.spanU.push_back(piece.spanU);
      out.spanV.push_back(piece.spanV);
      out.u.push_back(piece.u);
      out.v.push_back(piece.v);
      at[{piece.spanU, piece.spanV}] = index;
      out.model.patches.push_back({"P" + std::to_string(index++), seam::PatchKind::kBezier, std::move(b)});
    }
    for (int k = 0; k < index; ++k) {
      const auto su = at.find({out.spanU[static_cast<size_t>(k)] + 1, out.spanV[static_cast<size_t>(k)]});
      if (su != at.end()) {
        out.seams.push_back({k, su->second});
        out.alongU.push_back(true);
      }
      const auto sv = at.find({out.spanU[static_cast<size_t>(k)], out.spanV[static_cast<size_t>(k)] + 1});
      if (sv != at.end()) {
        out.seams.push_back({k, sv->second});
        out.alongU.push_back(false);
      }
    }
    return out;
  }();
  return gm;
}

struct OcctCheckCounts {
  int seams = 0, g1 = 0, g2 = 0;
};

// OpenCASCADE's verdict of one seam, added to c: LocalAnalysis_SurfaceContinuity of order G2 with the seam's
// tolerances at kOcctSamplesPerSeam points (ends included), the worst verdict; uv(t, pa, pb) gives both surfaces'
// parameters at the normalised edge parameter t.
template <class Uv>
void occtSeam(const Handle(Geom_BSplineSurface)& a, const Handle(Geom_BSplineSurface)& b, const Uv& uv,
              double distanceTol, double angleRad, OcctCheckCounts& c) {
  bool g1 = true, g2 = true;
  for (int k = 0; k < kOcctSamplesPerSeam; ++k) {
    gp_Pnt2d pa, pb;
    uv(static_cast<double>(k) / (kOcctSamplesPerSeam - 1), pa, pb);
    LocalAnalysis_SurfaceContinuity lsc(a, pa.X(), pa.Y(), b, pb.X(), pb.Y(), GeomAbs_G2, 0.001, distanceTol, 0.001,
                                        0.001, angleRad, 0.01);
    if (!lsc.IsDone() || !lsc.IsG1()) g1 = false;
    if (!lsc.IsDone() || !lsc.IsG2()) g2 = false;
  }
  ++c.seams;
  c.g1 += g1 ? 1 : 0;
  c.g2 += g2 ? 1 : 0;
}

// OpenCASCADE's seam loop over the grid model.
OcctCheckCounts occtCheck(const GridModel& gm, double distanceTol, double angleRad) {
  OcctCheckCounts c;
  for (size_t s = 0; s < gm.seams.size(); ++s) {
    const size_t a = static_cast<size_t>(gm.seams[s][0]), b = static_cast<size_t>(gm.seams[s][1]);
    const bool alongU = gm.alongU[s];
    auto uv = [&](double t, gp_Pnt2d& pa, gp_Pnt2d& pb) {
      const seam::Interval &ua = gm.u[a], &va = gm.v[a], &ub = gm.u[b], &vb = gm.v[b];
      if (alongU) {  // a's U1 edge against b's U0 edge, both running along v
        pa.SetCoord(ua.hi, va.lo + t * va.length());
        pb.SetCoord(ub.lo, vb.lo + t * vb.length());
      } else {
        pa.SetCoord(ua.lo + t * ua.length(), va.hi);
        pb.SetCoord(ub.lo + t * ub.length(), vb.lo);
      }
    };
    occtSeam(gm.occt[a], gm.occt[b], uv, distanceTol, angleRad, c);
  }
  return c;
}

seam::Tolerances modelTolerances() {
  return seam::Tolerances::forModelSize(gridModel().model.boundingBox().diagonal());
}

// seam's check of `model` once (one thread) against OpenCASCADE's counts `c`: no timing when the two sides see
// different seams, or (sameG1) a different number of seams G1 or better.
void verifyAgainstOcct(const char* what, const Model& model, const OcctCheckCounts& c, bool sameG1) {
  seam::ModelCheckOptions o;
  o.threads = 1;
  const auto r = seam::checkModel(model, o);
  if (!r) {
    std::fprintf(stderr, "seam's check of the %s failed: %s\n", what, r.status().message().c_str());
    std::exit(1);
  }
  const int seamG1 = r->summary.geometric[2] + r->summary.geometric[3];
  std::printf("verified: %s of %zu patches; seam: %zu seams, %d G1 or better (%d G2; %d certified); OpenCASCADE at "
              "%d points per seam: %d seams, %d G1 (%d G2)\n",
              what, model.patches.size(), r->seams.size(), seamG1, r->summary.geometric[3],
              r->summary.certifiedSeams, kOcctSamplesPerSeam, c.seams, c.g1, c.g2);
  if (static_cast<int>(r->seams.size()) != c.seams || (sameG1 && seamG1 != c.g1)) {
    std::fprintf(stderr, "the two sides see different seams or classes: no timing\n");
    std::exit(1);
  }
}

void verifyModelCheck() {
  const seam::Tolerances tol = modelTolerances();
  verifyAgainstOcct("model", gridModel().model, occtCheck(gridModel(), tol.distance, tol.angleDeg * M_PI / 180.0),
                    false);
}

// seam's whole check of `model` on one thread (pairing, every seam certified, corners).
void runSeamCheck(benchmark::State& state, const Model& model, size_t seams) {
  seam::ModelCheckOptions o;
  o.threads = 1;
  for (auto _ : state) {
    auto r = seam::checkModel(model, o);
    benchmark::DoNotOptimize(r);
  }
  state.counters["seams"] = static_cast<double>(seams);
}

void BM_ModelCheck_seam(benchmark::State& state) {
  runSeamCheck(state, gridModel().model, gridModel().seams.size());
}

// OpenCASCADE's seam loop `check(model, distance, angle)` over `model` with the tolerances `tol`.
template <class M, class Check>
void runOcctCheck(benchmark::State& state, const M& model, const seam::Tolerances& tol, const Check& check) {
  for (auto _ : state) {
    auto c = check(model, tol.distance, tol.angleDeg * M_PI / 180.0);
    benchmark::DoNotOptimize(c);
  }
  state.counters["seams"] = static_cast<double>(model.seams.size());
}

void BM_ModelCheck_occt(benchmark::State& state) {
  runOcctCheck(state, gridModel(), modelTolerances(), occtCheck);
}

// ---- network check (issue 37 goal 1) ----------------------------------------------------------------------------

constexpr int kNetworkFrequency = 10;  // 60 m^2 = 6 000 patches

struct NetworkSeam {
  int a = 0, b = 0;
  seam::Edge ea = seam::Edge::U0, eb = seam::Edge::U0;
  bool reversed = false;  // b's edge runs the other way
};
struct NetworkModel {
  Model model;
  std::vector<Handle(Geom_BSplineSurface)> occt;
  std::vector<NetworkSeam> seams;
};

const NetworkModel& networkModel() {
  static NetworkModel nm = [] {
    namespace nt = seam::testing;
    NetworkModel out;
    nt::Network net = nt::buildNetwork(nt::geodesicIcosahedronMesh(kNetworkFrequency), nt::sphereShape());
    for (const auto& p : net.model.patches) out.occt.push_back(toOcct(p.surface));
    for (const nt::NetworkEdge& e : net.edges) {
      if (e.sides.size() != 2) continue;
      NetworkSeam ns{e.sides[0].first, e.sides[1].first, e.sides[0].second, e.sides[1].second, false};
      const auto& sa = net.model.patches[static_cast<size_t>(ns.a)].surface;
      const auto& sb = net.model.patches[static_cast<size_t>(ns.b)].surface;
      ns.reversed = (nt::edgePoint(sa, ns.ea, 0.0) - nt::edgePoint(sb, ns.eb, 0.0)).norm() >
                    (nt::edgePoint(sa, ns.ea, 0.0) - nt::edgePoint(sb, ns.eb, 1.0)).norm();
      out.seams.push_back(ns);
    }
    out.model = std::move(net.model);
    return out;
  }();
  return nm;
}

// (u, v) of the point of edge e at normalised edge parameter t of a patch with OpenCASCADE surface s.
gp_Pnt2d edgeUV(const Handle(Geom_BSplineSurface)& s, seam::Edge e, double t) {
  double u0, u1, v0, v1;
  s->Bounds(u0, u1, v0, v1);
  const seam::Vec2 ab = seam::testing::edgeParameters(e, t);
  return {u0 + ab.x() * (u1 - u0), v0 + ab.y() * (v1 - v0)};
}

OcctCheckCounts occtNetworkCheck(const NetworkModel& nm, double distanceTol, double angleRad) {
  OcctCheckCounts c;
  for (const NetworkSeam& ns : nm.seams) {
    const auto& sa = nm.occt[static_cast<size_t>(ns.a)];
    const auto& sb = nm.occt[static_cast<size_t>(ns.b)];
    auto uv = [&](double t, gp_Pnt2d& pa, gp_Pnt2d& pb) {
      pa = edgeUV(sa, ns.ea, t);
      pb = edgeUV(sb, ns.eb, ns.reversed ? 1.0 - t : t);
    };
    occtSeam(sa, sb, uv, distanceTol, angleRad, c);
  }
  return c;
}

seam::Tolerances networkTolerances() {
  return seam::Tolerances::forModelSize(networkModel().model.boundingBox().diagonal());
}

void verifyNetworkCheck() {
  const seam::Tolerances tol = networkTolerances();
  verifyAgainstOcct("network", networkModel().model,
                    occtNetworkCheck(networkModel(), tol.distance, tol.angleDeg * M_PI / 180.0), true);
}

void BM_NetworkCheck_seam(benchmark::State& state) {
  runSeamCheck(state, networkModel().model, networkModel().seams.size());
}

void BM_NetworkCheck_occt(benchmark::State& state) {
  runOcctCheck(state, networkModel(), networkTolerances(), occtNetworkCheck);
}

// ---- registration (interleaved: each seam benchmark followed by its OpenCASCADE twin) and the ratio table -------

class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs)
      if (r.run_type == Run::RT_Iteration && !r.error_occurred)
        times_[r.benchmark_name()] = {r.GetAdjustedRealTime(), r.GetAdjustedCPUTime()};  // ms
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    std::printf("\nOpenCASCADE time / seam time (> 1: seam faster):\n  %-28s %10s %10s\n", "benchmark", "wall",
                "CPU");
    for (const auto& [name, t] : times_) {
      const auto pos = name.find("_seam");
      if (pos == std::string::npos) continue;
      std::string twin = name;
      twin.replace(pos, 5, "_occt");
      const auto it = times_.find(twin);
      if (it != times_.end() && t.first > 0.0 && t.second > 0.0)
        std::printf("  %-28s %9.2fx %9.2fx\n", name.c_str(), it->second.first / t.first,
                    it->second.second / t.second);
    }
  }

 private:
  std::map<std::string, std::pair<double, double>> times_;  // (wall, CPU)
};

}  // namespace

int main(int argc, char** argv) {
  verifyEvaluation(false);
  verifyEvaluation(true);
  verifyModelCheck();
  verifyNetworkCheck();
  for (int rational = 0; rational <= 1; ++rational) {
    const std::string tag = rational ? "/rational" : "/polynomial";
    benchmark::RegisterBenchmark(("Random_seam" + tag).c_str(), BM_Random_seam)
        ->Arg(rational)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("Random_occt" + tag).c_str(), BM_Random_occt)
        ->Arg(rational)
        ->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("Grid_seam" + tag).c_str(), BM_Grid_seam)->Arg(rational)->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(("Grid_occt" + tag).c_str(), BM_Grid_occt)->Arg(rational)->Unit(benchmark::kMillisecond);
  }
  benchmark::RegisterBenchmark("ModelCheck_seam", BM_ModelCheck_seam)->Unit(benchmark::kMillisecond)->Iterations(3);
  benchmark::RegisterBenchmark("ModelCheck_occt", BM_ModelCheck_occt)->Unit(benchmark::kMillisecond)->Iterations(3);
  benchmark::RegisterBenchmark("NetworkCheck_seam", BM_NetworkCheck_seam)->Unit(benchmark::kMillisecond)->Iterations(3);
  benchmark::RegisterBenchmark("NetworkCheck_occt", BM_NetworkCheck_occt)->Unit(benchmark::kMillisecond)->Iterations(3);
  benchmark::Initialize(&argc, argv);
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
