// Benchmarks of the whole-model check (issue 3, section 8): an n x n model of bicubic Bezier patches cut from one
// C2 bicubic B-spline surface, with some seams perturbed (a gap or a kink).
//
//   BM_CheckModel/n/threads  full certified check of n x n patches (target for 100 x 100: < 1 s on one core)
//   BM_CheckModelPairingAndCorners/100/threads   the same without the seam analyses (pairing + vertices)
//   BM_AnalyzeSeam           one interior seam (per-seam cost)
//   BM_PairEdges/n           pairing alone for n x n patches, n = 32 (1k), 100 (10k), 200 (40k): O(N log N)
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "seam/continuity/model_check.h"
#include "seam/continuity/seam.h"
#include "seam/spline/bspline_surface.h"

#include "bench_models.h"

namespace {

using seam::BSplineSurface;
using seam::Matrix;
using seam::Model;

const Model& cachedModel(int n) {
  static std::vector<std::pair<int, Model>> cache;
  for (const auto& [k, m] : cache)
    if (k == n) return m;
  cache.emplace_back(n, seam::bench::gridModel(n));
  return cache.back().second;
}

void BM_CheckModel(benchmark::State& state) {
  const Model& m = cachedModel(static_cast<int>(state.range(0)));
  seam::ModelCheckOptions o;
  o.threads = static_cast<int>(state.range(1));
  size_t seams = 0, certified = 0;
  for (auto _ : state) {
    auto r = seam::checkModel(m, o);
    benchmark::DoNotOptimize(r);
    seams = r->seams.size();
    certified = static_cast<size_t>(r->summary.certifiedSeams);
  }
  state.counters["patches"] = static_cast<double>(m.patches.size());
  state.counters["seams"] = static_cast<double>(seams);
  state.counters["certified"] = static_cast<double>(certified);
  state.counters["per_seam"] = benchmark::Counter(static_cast<double>(seams),
                                                  benchmark::Counter::kIsIterationInvariantRate |
                                                      benchmark::Counter::kInvert);
}
// Args: n (n x n patches), threads (1 = one core, the target; 0 = all hardware threads).
BENCHMARK(BM_CheckModel)
    ->Args({32, 1})
    ->Args({100, 1})
    ->Args({100, 0})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->UseRealTime();

void BM_CheckModelPairingAndCorners(benchmark::State& state) {
  const Model& m = cachedModel(static_cast<int>(state.range(0)));
  seam::ModelCheckOptions o;
  o.analyzeSeams = false;
  o.threads = static_cast<int>(state.range(1));
  for (auto _ : state) {
    auto r = seam::checkModel(m, o);
    benchmark::DoNotOptimize(r);
  }
  state.counters["patches"] = static_cast<double>(m.patches.size());
}
// Args: n, threads (1 = one core, 0 = all).
BENCHMARK(BM_CheckModelPairingAndCorners)->Args({100, 1})->Args({100, 0})->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_AnalyzeSeam(benchmark::State& state) {
  const Model& m = cachedModel(100);
  // Patch 0 is span (0,0); patch 1 is span (0,1): they share patch 0's V1 edge and patch 1's V0 edge.
  seam::SeamOptions o;
  o.tol = seam::Tolerances::forModelSize(m.boundingBox().diagonal());
  for (auto _ : state) {
    auto r = seam::analyzeSeam(m.patches[0], seam::Edge::V1, m.patches[1], seam::Edge::V0, o);
    benchmark::DoNotOptimize(r);
  }
}
BENCHMARK(BM_AnalyzeSeam)->Unit(benchmark::kMicrosecond);

void BM_PairEdges(benchmark::State& state) {
  const Model& m = cachedModel(static_cast<int>(state.range(0)));
  size_t pairs = 0;
  for (auto _ : state) {
    auto r = seam::pairEdges(m);
    benchmark::DoNotOptimize(r);
    pairs = r->pairs.size();
  }
  state.counters["pairs"] = static_cast<double>(pairs);
  state.SetComplexityN(static_cast<int64_t>(m.patches.size()));
}
BENCHMARK(BM_PairEdges)->Arg(32)->Arg(100)->Arg(200)->Unit(benchmark::kMillisecond)->Complexity(benchmark::oNLogN);

}  // namespace

BENCHMARK_MAIN();
