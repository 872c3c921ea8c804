// Evaluation throughput of the kernel (issue 2, section 6): points + first partial derivatives of a bicubic
// B-spline surface with 50 x 50 control points, (a) at 10^6 random parameters, (b) on a 256 x 256 grid.
#include <benchmark/benchmark.h>

#include <random>

#include "seam/spline/bspline_surface.h"

#include "bench_models.h"

namespace {

seam::BSplineSurface makeSurface(bool rational) { return seam::bench::jitteredSurface50(rational); }

void BM_RandomPointsFirstDerivatives(benchmark::State& state) {
  const seam::BSplineSurface s = makeSurface(state.range(0) != 0);
  constexpr int kPoints = 1'000'000;
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::vector<double> us(kPoints), vs(kPoints);
  for (int i = 0; i < kPoints; ++i) {
    us[static_cast<size_t>(i)] = u01(rng);
    vs[static_cast<size_t>(i)] = u01(rng);
  }
  for (auto _ : state) {
    double acc = 0.0;
    for (int i = 0; i < kPoints; ++i) {
      seam::Vec3 p, du, dv;
      s.pointAndFirstDerivatives(us[static_cast<size_t>(i)], vs[static_cast<size_t>(i)], p, du, dv);
      acc += p[0] + du[1] + dv[2];
    }
    benchmark::DoNotOptimize(acc);
  }
  state.SetItemsProcessed(state.iterations() * kPoints);
  state.SetLabel(state.range(0) ? "rational" : "polynomial");
}
BENCHMARK(BM_RandomPointsFirstDerivatives)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_GridPointsFirstDerivatives(benchmark::State& state) {
  const seam::BSplineSurface s = makeSurface(state.range(0) != 0);
  constexpr int kGrid = 256;
  std::vector<double> g(kGrid);
  for (int i = 0; i < kGrid; ++i) g[static_cast<size_t>(i)] = static_cast<double>(i) / (kGrid - 1);
  const seam::GridEvaluator eval(s, g, g);
  seam::Matrix P, Du, Dv;
  for (auto _ : state) {
    eval.evaluate(&P, &Du, &Dv);
    benchmark::DoNotOptimize(P.data());
    benchmark::DoNotOptimize(Du.data());
    benchmark::DoNotOptimize(Dv.data());
  }
  state.SetItemsProcessed(state.iterations() * kGrid * kGrid);
  state.SetLabel(state.range(0) ? "rational" : "polynomial");
}
BENCHMARK(BM_GridPointsFirstDerivatives)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
