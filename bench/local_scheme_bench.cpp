// Benchmarks of the local G1 scheme (issue 13 §2): closed G0 networks on the unit sphere from the frequency-m
// geodesic icosahedron split into quads (60 m^2 bicubic Bezier patches; interior vertices of valence 3, 4, 5, 6).
//
//   BM_LocalScheme/m         localG1Scheme on the whole network, one thread (target: >= 6 000 patches, m = 10, < 2 s)
//   BM_HealLocal/m           seam heal --method local as a library call: pairing, every seam certified before and after,
//                            the scheme, the acceptance test, displacements (one thread)
//   BM_LocalSchemeCheck/m    checkModel of the scheme's output (every seam certified), one thread, for comparison
//   BM_HealCliProcess/m      the whole `seam heal FILE.json --method local -o OUT.json` process on the same network
//                            (written once to a temporary JSON file), pinned to one core: reading, the heal, writing
//                            (issue 37 goal 3: within 1.2x of BM_HealLocal)
//   BM_G2NetworkFan/k        g2NetworkScheme on the fan of 5 triangles (15 bicubic patches on a height field, the
//                            tests' network): k = 0 Bezier, k = 1 with 1-2 uneven interior knots per direction of
//                            every patch (insertUnevenKnots; issue 36 goal 4: no more than the Bezier network's cost)
// The network builder is the tests' (tests/network_support.h), so the benchmark runs on exactly the tested inputs.
#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "../tests/network_support.h"
#include "seam/continuity/model_check.h"
#include "seam/io/json.h"
#include "seam/repair/g2_network.h"
#include "seam/repair/heal.h"
#include "seam/repair/local_scheme.h"

namespace {

namespace nt = seam::testing;

const seam::Model& network(int m) {
  static std::map<int, seam::Model> cache;
  auto it = cache.find(m);
  if (it == cache.end())
    it = cache.emplace(m, nt::buildNetwork(nt::geodesicIcosahedronMesh(m), nt::sphereShape()).model).first;
  return it->second;
}

void BM_LocalScheme(benchmark::State& state) {
  const seam::Model& model = network(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    auto r = seam::localG1Scheme(model);
    if (!r) {
      state.SkipWithError(r.status().message().c_str());
      return;
    }
    benchmark::DoNotOptimize(r->model.patches.data());
  }
  state.counters["patches"] = static_cast<double>(model.patches.size());
}
BENCHMARK(BM_LocalScheme)->Arg(2)->Arg(5)->Arg(10)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_LocalSchemeCheck(benchmark::State& state) {
  const seam::Model& model = network(static_cast<int>(state.range(0)));
  auto r = seam::localG1Scheme(model);
  if (!r) {
    state.SkipWithError(r.status().message().c_str());
    return;
  }
  seam::ModelCheckOptions o;
  o.threads = 1;
  int g1 = 0;
  for (auto _ : state) {
    auto c = seam::checkModel(r->model, o);
    g1 = c->summary.geometric[2] + c->summary.geometric[3];
    benchmark::DoNotOptimize(c->seams.data());
  }
  state.counters["patches"] = static_cast<double>(model.patches.size());
  state.counters["seams_G1"] = g1;
}
BENCHMARK(BM_LocalSchemeCheck)->Arg(2)->Arg(10)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_HealLocal(benchmark::State& state) {
  const seam::Model& model = network(static_cast<int>(state.range(0)));
  seam::HealOptions o;
  o.method = seam::HealMethod::kLocal;
  int achieved = 0;
  for (auto _ : state) {
    auto r = seam::healModel(model, o);
    if (!r) {
      state.SkipWithError(r.status().message().c_str());
      return;
    }
    achieved = r->report.seamsAchieved;
    benchmark::DoNotOptimize(r->model.patches.data());
  }
  state.counters["patches"] = static_cast<double>(model.patches.size());
  state.counters["seams_achieved"] = achieved;
}
BENCHMARK(BM_HealLocal)->Arg(2)->Arg(10)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_G2NetworkFan(benchmark::State& state) {
  nt::Network net = nt::buildNetwork(nt::fanMesh(5), nt::heightFieldShape());
  if (state.range(0) == 1) nt::insertUnevenKnots(net.model, 20261130);
  int points = 0;
  for (auto _ : state) {
    auto r = seam::g2NetworkScheme(net.model);
    if (!r) {
      state.SkipWithError(r.status().message().c_str());
      return;
    }
    state.counters["steps"] = r->report.iterations;
    points = 0;
    for (const seam::Patch& p : r->model.patches) points += p.surface.numU() * p.surface.numV();
  }
  state.counters["points"] = points;
}
BENCHMARK(BM_G2NetworkFan)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

#ifdef SEAM_CLI_PATH
void BM_HealCliProcess(benchmark::State& state) {
  const seam::Model& model = network(static_cast<int>(state.range(0)));
  const std::filesystem::path dir = std::filesystem::temp_directory_path();
  const std::filesystem::path in = dir / fmt::format("seam_heal_cli_bench_{}.json", ::getpid());
  const std::filesystem::path out = dir / fmt::format("seam_heal_cli_bench_{}_out.json", ::getpid());
  if (!seam::io::writeModelJson(model, in)) {
    state.SkipWithError("cannot write the network");
    return;
  }
  // One core, as BM_HealLocal; the table goes to /dev/null (the user's terminal is not what is measured).
  const std::string command = fmt::format("taskset -c 0 '{}' heal '{}' --method local -o '{}' > /dev/null 2>&1",
                                          SEAM_CLI_PATH, in.string(), out.string());
  for (auto _ : state) {
    const int code = std::system(command.c_str());
    if (code != 0) {
      state.SkipWithError(fmt::format("seam heal exited with status {}", code).c_str());
      break;
    }
  }
  std::filesystem::remove(in);
  std::filesystem::remove(out);
  state.counters["patches"] = static_cast<double>(model.patches.size());
}
BENCHMARK(BM_HealCliProcess)->Arg(2)->Arg(10)->Unit(benchmark::kMillisecond)->UseRealTime();
#endif

}  // namespace

BENCHMARK_MAIN();
