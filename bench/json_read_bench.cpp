// Reading JSON models with long rows (issue 39 goal 2): a B-spline patch of 2 rows of n points and a curve of n
// points, n up to 10^5, on both routes of the reader (src/io/json.cpp). The time per point must stay flat as n
// grows: before issue 39 the fast route walked each row from its start for every point (2 x 30 000: 38 s).
//
//   BM_ReadLongRowPatch/n         io::parseModelJson (the fast route, simdjson) of a 2 x n patch
//   BM_ReadLongRowPatchNlohmann/n the nlohmann route (SAX into a compact document) of the same text
//   BM_ReadLongCurve/n            io::parseModelJson of a curve of n points
//
// Reading a model file of n bicubic B-spline patches (issue 37 goal 4; peak memory is measured on the whole CLI with
// /usr/bin/time, docs/performance.md):
//   BM_ReadModelFileStreamed/n    io::readModelJson: the streamed route, one element at a time from 1 MB chunks
//   BM_ReadModelFileWhole/n       io::readFile, then io::parseModelJson of the whole text (the route before)
#include <benchmark/benchmark.h>
#include <fmt/format.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <random>
#include <string>

#include "io/json_read.h"
#include "seam/io/file.h"
#include "seam/io/json.h"

namespace {

/// Text of a uniform cubic B-spline patch of 2 x n points (degree [1, 3]) or of a curve of n points.
std::string longRowText(int n, bool curve) {
  std::string knots = "[0, 0, 0, 0";
  for (int k = 1; k < n - 3; ++k) knots += fmt::format(", {}", k);
  knots += fmt::format(", {0}, {0}, {0}, {0}]", n - 3);
  auto row = [&](int i) {
    std::string r = "[";
    for (int j = 0; j < n; ++j)
      r += fmt::format("{}[{}, {}, {}]", j == 0 ? "" : ", ", i * 0.5 + 0.25, j * 0.0009765625, (i + j) % 7 * 0.125);
    return r + "]";
  };
  if (curve)
    return fmt::format(R"({{"curves": [{{"name": "c", "type": "bspline", "degree": 3, "knots": {}, "points": {}}}]}})",
                       knots, row(0));
  return fmt::format(R"({{"patches": [{{"name": "p", "type": "bspline", "degree": [1, 3], "knots": [[0, 0, 1, 1], {}], )"
                     R"("points": [{}, {}]}}]}})",
                     knots, row(0), row(1));
}

// Reads `text` with `parse` per iteration; `points` control points per read.
template <typename Parse>
void readLoop(benchmark::State& state, const std::string& text, Parse parse, int64_t points) {
  for (auto _ : state) {
    auto m = parse(text, "bench.json");
    if (!m) state.SkipWithError(m.status().message().c_str());
    benchmark::DoNotOptimize(m);
  }
  state.SetItemsProcessed(state.iterations() * points);
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(text.size()));
}

void BM_ReadLongRowPatch(benchmark::State& state) {
  readLoop(state, longRowText(static_cast<int>(state.range(0)), false), seam::io::parseModelJson, 2 * state.range(0));
}
BENCHMARK(BM_ReadLongRowPatch)->Arg(1000)->Arg(10000)->Arg(30000)->Arg(100000)->Unit(benchmark::kMillisecond);

void BM_ReadLongRowPatchNlohmann(benchmark::State& state) {
  readLoop(state, longRowText(static_cast<int>(state.range(0)), false), seam::io::detail::parseModelJsonNlohmann,
           2 * state.range(0));
}
BENCHMARK(BM_ReadLongRowPatchNlohmann)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);

void BM_ReadLongCurve(benchmark::State& state) {
  readLoop(state, longRowText(static_cast<int>(state.range(0)), true), seam::io::parseModelJson, state.range(0));
}
BENCHMARK(BM_ReadLongCurve)->Arg(1000)->Arg(100000)->Unit(benchmark::kMillisecond);

/// A file of n bicubic B-spline patches (one interior knot in v) written as seam writes models, in the temporary
/// folder; removed when the benchmark ends.
struct ModelFile {
  std::filesystem::path path;
  std::uintmax_t bytes = 0;
  explicit ModelFile(int n) {
    path = std::filesystem::temp_directory_path() / fmt::format("seam_json_read_bench_{}_{}.json", ::getpid(), n);
    std::mt19937 rng(static_cast<unsigned>(n));
    std::uniform_real_distribution<double> coord(-500.0, 500.0);
    std::ofstream os(path, std::ios::binary);
    os << "{\n  \"patches\": [";
    for (int k = 0; k < n; ++k) {
      os << (k == 0 ? "\n" : ",\n") << fmt::format("    {{\n      \"name\": \"P{}\",\n      \"type\": \"bspline\",\n      "
                                                "\"degree\": [3, 3],\n      \"knots\": [[0, 0, 0, 0, 1, 1, 1, 1], "
                                                "[0, 0, 0, 0, 0.5, 1, 1, 1, 1]],\n      \"points\": [\n",
                                                k);
      for (int i = 0; i < 4; ++i) {
        os << "        [";
        for (int j = 0; j < 5; ++j)
          os << fmt::format("{}[{:.17g}, {:.17g}, {:.17g}]", j == 0 ? "" : ", ", coord(rng), coord(rng), coord(rng));
        os << (i < 3 ? "],\n" : "]\n");
      }
      os << "      ]\n    }";
    }
    os << "\n  ]\n}\n";
    os.close();
    bytes = std::filesystem::file_size(path);
  }
  ~ModelFile() { std::filesystem::remove(path); }
};

void BM_ReadModelFileStreamed(benchmark::State& state) {
  const ModelFile file(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    auto m = seam::io::readModelJson(file.path);
    if (!m) state.SkipWithError(m.status().message().c_str());
    benchmark::DoNotOptimize(m);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(file.bytes));
}
BENCHMARK(BM_ReadModelFileStreamed)->Arg(1000)->Arg(30000)->Unit(benchmark::kMillisecond);

void BM_ReadModelFileWhole(benchmark::State& state) {
  const ModelFile file(static_cast<int>(state.range(0)));
  for (auto _ : state) {
    auto text = seam::io::readFile(file.path);
    if (!text) state.SkipWithError(text.status().message().c_str());
    auto m = seam::io::parseModelJson(*text, file.path.string());
    if (!m) state.SkipWithError(m.status().message().c_str());
    benchmark::DoNotOptimize(m);
  }
  state.SetItemsProcessed(state.iterations() * state.range(0));
  state.SetBytesProcessed(state.iterations() * static_cast<int64_t>(file.bytes));
}
BENCHMARK(BM_ReadModelFileWhole)->Arg(1000)->Arg(30000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
