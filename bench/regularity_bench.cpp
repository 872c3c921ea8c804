// Throughput of the regularity certificates (issue 5): order-4 curve segments in R^3 per second (target >= 1e6/s)
// and 4 x 4 surface sub-nets per second, certificate only (no search, no ell), and the defect search for scale.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "seam/io/file.h"
#include "seam/regularity/regularity.h"

namespace {

using seam::BSplineCurve;
using seam::BSplineSurface;
using seam::Matrix;

std::vector<double> uniformKnots(int degree, int numPoints) {
  std::vector<double> t(static_cast<size_t>(numPoints + degree + 1));
  for (size_t i = 0; i < t.size(); ++i) t[i] = static_cast<double>(i);
  return t;
}

/// A wavy space curve with `n` control points; `noise` scales random perturbations (0: smooth, Lau holds
/// everywhere; 1: a random walk, most segments need Definition 1.1).
BSplineCurve curve(int n, double noise) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Matrix p(n, 3);
  for (int i = 0; i < n; ++i) {
    p.row(i) << std::cos(0.3 * i) + noise * u(rng), std::sin(0.3 * i) + noise * u(rng), 0.1 * i + noise * u(rng);
  }
  return BSplineCurve(3, seam::KnotVector(uniformKnots(3, n)), p);
}

/// A wavy ring of n control points (issue 16's scale benchmarks): most of a circle of radius 0.05 n with wiggles of
/// amplitude 0.5 in the radial direction and in z. No defect, but the derivative turns all the way round, so the
/// search cannot discard the whole curve at once: only regions of a few segments are injective by their cones, and
/// far-apart pieces must be told apart by their boxes.
BSplineCurve ring(int n) {
  Matrix p(n, 3);
  const double radius = 0.05 * n;
  for (int i = 0; i < n; ++i) {
    const double a = 1.9 * M_PI * i / n;
    const double r = radius + 0.5 * std::sin(1.3 * i);
    p.row(i) << r * std::cos(a), r * std::sin(a), 0.5 * std::cos(0.7 * i);
  }
  return BSplineCurve(3, seam::KnotVector(uniformKnots(3, n)), p);
}

BSplineSurface surface(int n, double noise) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Matrix p(n * n, 3);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      p.row(i * n + j) << i + noise * u(rng), j + noise * u(rng),
          std::sin(0.2 * i) * std::cos(0.2 * j) + noise * u(rng);
    }
  }
  return BSplineSurface(3, 3, seam::KnotVector(uniformKnots(3, n)), seam::KnotVector(uniformKnots(3, n)), n, n, p);
}

seam::regularity::RegularityOptions certificateOnly() {
  seam::regularity::RegularityOptions o;
  o.runSearch = false;
  o.maxEll = 0;
  return o;
}

void BM_CurveSegments(benchmark::State& state) {
  const double noise = static_cast<double>(state.range(0)) / 100.0;
  const BSplineCurve c = curve(20003, noise);
  const auto options = certificateOnly();
  long segments = 0;
  long certified = 0;
  for (auto _ : state) {
    auto r = seam::regularity::analyzeCurve(c, options);
    benchmark::DoNotOptimize(r);
    segments += static_cast<long>(r->segments.size());
    for (const auto& s : r->segments) certified += s.verdict == seam::regularity::Verdict::kCertified ? 1 : 0;
  }
  state.SetItemsProcessed(segments);
  state.counters["certified%"] = 100.0 * static_cast<double>(certified) / static_cast<double>(segments);
}
BENCHMARK(BM_CurveSegments)->Arg(0)->Arg(100)->Unit(benchmark::kMillisecond);

void BM_SurfaceSubnets(benchmark::State& state) {
  const double noise = static_cast<double>(state.range(0)) / 100.0;
  const BSplineSurface s = surface(103, noise);
  const auto options = certificateOnly();
  long subnets = 0;
  long certified = 0;
  for (auto _ : state) {
    auto r = seam::regularity::analyzeSurface(s, options);
    benchmark::DoNotOptimize(r);
    subnets += static_cast<long>(r->subnets.size());
    for (const auto& x : r->subnets) certified += x.verdict == seam::regularity::Verdict::kCertified ? 1 : 0;
  }
  state.SetItemsProcessed(subnets);
  state.counters["certified%"] = 100.0 * static_cast<double>(certified) / static_cast<double>(subnets);
}
BENCHMARK(BM_SurfaceSubnets)->Arg(0)->Arg(30)->Unit(benchmark::kMillisecond);

void BM_CurveSearch(benchmark::State& state) {
  const BSplineCurve c = curve(203, 0.0);
  long segments = 0;
  for (auto _ : state) {
    auto r = seam::regularity::searchCurveDefects(c);
    benchmark::DoNotOptimize(r);
    segments += 200;
  }
  state.SetItemsProcessed(segments);
}
BENCHMARK(BM_CurveSearch)->Unit(benchmark::kMillisecond);

void BM_SurfaceSearch(benchmark::State& state) {
  const BSplineSurface s = surface(13, 0.0);
  long patches = 0;
  for (auto _ : state) {
    auto r = seam::regularity::searchSurfaceDefects(s);
    benchmark::DoNotOptimize(r);
    patches += 100;
  }
  state.SetItemsProcessed(patches);
}
BENCHMARK(BM_SurfaceSearch)->Unit(benchmark::kMillisecond);

/// A cone apex + u C(v) over a wavy closed-ish cubic C of n control points: its side u = 0 is a pole (every face of
/// revolution has one), and C's last knot span is a sliver of 1.5e-5 of the others, as trj3_s1-al-214.stp's F6 has
/// (issue 39 goal 1): the search used to refine along the pole and across the sliver down to its resolution.
BSplineSurface poleCone(int n) {
  std::vector<double> kv = uniformKnots(3, n);
  for (int k = 0; k <= 3; ++k) kv[kv.size() - 1 - k] = kv[kv.size() - 5] + 1.5e-5;
  Matrix p(4 * n, 3);
  const double greville[4] = {0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0};  // Bezier in u: S is linear in u
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < n; ++j) {
      const double th = 5.5 * j / n;
      const double r = 1.0 + 0.1 * std::sin(3.0 * th);
      p.row(i * n + j) << greville[i] * r * std::cos(th), greville[i] * r * std::sin(th), greville[i] * 0.7;
    }
  return BSplineSurface(3, 3, seam::KnotVector({0, 0, 0, 0, 1, 1, 1, 1}), seam::KnotVector(kv), 4, n, p);
}

void BM_SurfaceSearchPole(benchmark::State& state) {
  const BSplineSurface s = poleCone(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    auto r = seam::regularity::searchSurfaceDefects(s);
    if (!r.isOk() || r->criticalPoints.size() != 1 || !r->summary.complete) {
      state.SkipWithError(("not one pole: " + std::to_string(r->criticalPoints.size()) + " critical, " + std::to_string(r->selfIntersections.size()) + " self, unresolved " + std::to_string(r->summary.unresolved) + ", complete " + std::to_string(r->summary.complete)).c_str());
      break;
    }
    benchmark::DoNotOptimize(r);
  }
  state.SetItemsProcessed(state.iterations() * (state.range(0) - 3));
}
BENCHMARK(BM_SurfaceSearchPole)->Arg(12)->Arg(100)->Unit(benchmark::kMillisecond);

/// A real face with a near-fold: linkrods.step's F27 (../shared/data/step, a rational B-spline of degrees (6, 8) and
/// 65 spans in v), whose S_u x S_v vanishes at points of a curve and nearly vanishes along it. The search cannot
/// settle the curve at its resolution and spends its whole work budget there (300 000 region visits): this
/// measures the cost of one visit on a face that cannot be certified (issue 39 goal 1; `seam regularity` on
/// linkrods took 68 s, 53 of them on F26 and F27).
void BM_SurfaceSearchNearFold(benchmark::State& state) {
  const seam::Result<seam::Model> model =
      seam::io::readModel(std::string(SEAM_SOURCE_DIR) + "/tests/data/regularity/near_fold_linkrods_F27.json");
  if (!model.isOk() || model->patches.size() != 1) {
    state.SkipWithError("tests/data/regularity/near_fold_linkrods_F27.json does not read as one patch");
    return;
  }
  for (auto _ : state) {
    auto r = seam::regularity::searchSurfaceDefects(model->patches[0].surface);
    if (!r.isOk() || r->criticalPoints.empty()) {
      state.SkipWithError("no critical point found on the near-fold face");
      break;
    }
    benchmark::DoNotOptimize(r);
    state.counters["visits"] = static_cast<double>(r->summary.work);
  }
}
BENCHMARK(BM_SurfaceSearchNearFold)->Unit(benchmark::kMillisecond)->Iterations(1);

/// The whole analysis as `seam regularity` runs it (certificates, Theorem 2.7 up to ell = 2, the search) on
/// curves of n segments (issue 16 goal 5: 200 000 in well under 2 s).
void BM_AnalyzeCurveScale(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const BSplineCurve c = ring(n + 3);
  for (auto _ : state) {
    auto r = seam::regularity::analyzeCurve(c);
    benchmark::DoNotOptimize(r);
    if (!r || !r->search->summary.provedClean(r->search->defectFound())) state.SkipWithError("not proved clean");
  }
  state.SetItemsProcessed(state.iterations() * n);
}
BENCHMARK(BM_AnalyzeCurveScale)->Arg(2000)->Arg(8000)->Arg(200000)->Unit(benchmark::kMillisecond);

/// The search alone on the same curves.
void BM_CurveSearchScale(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const BSplineCurve c = ring(n + 3);
  long work = 0;
  for (auto _ : state) {
    auto r = seam::regularity::searchCurveDefects(c);
    benchmark::DoNotOptimize(r);
    work = r->summary.work;
  }
  state.SetItemsProcessed(state.iterations() * n);
  state.counters["work"] = static_cast<double>(work);
}
BENCHMARK(BM_CurveSearchScale)->Arg(2000)->Arg(8000)->Arg(200000)->Unit(benchmark::kMillisecond);

/// The whole analysis of a bicubic net of n x n Bezier sub-nets (issue 16 goal 5: 200 x 200 in well under 2 s).
void BM_AnalyzeSurfaceScale(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const BSplineSurface s = surface(n + 3, 0.0);
  for (auto _ : state) {
    auto r = seam::regularity::analyzeSurface(s);
    benchmark::DoNotOptimize(r);
    if (!r || !r->search->summary.provedClean(r->search->defectFound())) state.SkipWithError("not proved clean");
  }
  state.SetItemsProcessed(state.iterations() * n * n);
}
BENCHMARK(BM_AnalyzeSurfaceScale)->Arg(50)->Arg(200)->Unit(benchmark::kMillisecond);

void BM_SurfaceSearchScale(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const BSplineSurface s = surface(n + 3, 0.0);
  long work = 0;
  for (auto _ : state) {
    auto r = seam::regularity::searchSurfaceDefects(s);
    benchmark::DoNotOptimize(r);
    work = r->summary.work;
  }
  state.SetItemsProcessed(state.iterations() * n * n);
  state.counters["work"] = static_cast<double>(work);
}
BENCHMARK(BM_SurfaceSearchScale)->Arg(50)->Arg(200)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
