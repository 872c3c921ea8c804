// Evaluation throughput of the kernel (issue 2, section 6): points + first partial derivatives of a bicubic
// B-spline surface with 50 x 50 control points, (a) at 10^6 random parameters, (b) on a 256 x 256 grid.
#include <benchmark/benchmark.h>

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

}  // namespace

BENCHMARK_MAIN();
