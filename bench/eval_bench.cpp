// Evaluation throughput of the kernel (issue 2, section 6): points + first partial derivatives of a bicubic
// B-spline surface with 50 x 50 control points, (a) at 10^6 random parameters, (b) on a 256 x 256 grid.
#include <benchmark/benchmark.h>

#include <string>

#include "seam/spline/bspline_surface.h"

#include "bench_models.h"

namespace {

seam::BSplineSurface makeSurface(bool rational) { return seam::bench::jitteredSurface50(rational); }

void BM_RandomPointsFirstDerivatives(benchmark::State& state) {
  seam::bench::timeRandomEvaluation(state, makeSurface(state.range(0) != 0));
  state.SetLabel(state.range(0) ? "rational" : "polynomial");
}
BENCHMARK(BM_RandomPointsFirstDerivatives)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_GridPointsFirstDerivatives(benchmark::State& state) {
  seam::bench::timeGridEvaluation(state, makeSurface(state.range(0) != 0));
  state.SetLabel(state.range(0) ? "rational" : "polynomial");
}
BENCHMARK(BM_GridPointsFirstDerivatives)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

// Points alone at the same 10^6 random parameters: BSplineSurface::evaluate (Arg 0/1: polynomial/rational; the
// allocation-free loops since 2026-11-29) against the general route it took before, derivatives(u, v, 0)[0][0]
// (Arg 2/3), in one run.
void BM_RandomPoints(benchmark::State& state) {
  const bool rational = state.range(0) % 2 != 0, general = state.range(0) >= 2;
  const seam::BSplineSurface s = makeSurface(rational);
  const auto [us, vs] = seam::bench::randomParameterPairs();
  for (auto _ : state) {
    double acc = 0.0;
    for (size_t i = 0; i < us.size(); ++i)
      acc += general ? s.derivatives(us[i], vs[i], 0)[0][0][0] : s.evaluate(us[i], vs[i])[0];
    benchmark::DoNotOptimize(acc);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(us.size()));
  state.SetLabel(std::string(rational ? "rational" : "polynomial") + (general ? ", derivatives(u, v, 0)" : ", evaluate"));
}
BENCHMARK(BM_RandomPoints)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
