#!/usr/bin/env bash
# Fuzzing (issue 15 §5; docs/reliability.md, "Fuzzing"): builds the libFuzzer harnesses of fuzz/ with clang-14 in
# build-fuzz/ and runs each for SECONDS (default 60) on a seed corpus made from the committed inputs
# (tests/data, tests/data/hostile, examples/models, fuzz/regressions). New inputs go to build-fuzz/corpus/<harness>/;
# a crash, a leak or a timeout stops that harness, leaves its input in build-fuzz/artifacts/ and fails the script.
# The STEP and IGES harnesses (fuzz_step, fuzz_iges: seam's reader over OpenCASCADE, about a hundred inputs a second)
# run a fixed number of inputs instead, CAD_RUNS (default 400), so that a CI run repeats exactly; CAD_RUNS=0 skips them.
# The writer harness (fuzz_export: JSON models written as STEP / IGES by seam's writer, issue 39 §6) runs EXPORT_RUNS
# inputs (default 1000, about 15 s; 0 skips it), as the readers do.
# The JSON, .bpt and expression harnesses run memory-capped (issue 39 §6): no single allocation above MALLOC_LIMIT_MB
# (default 64) and at most 512 MB resident; an input of at most 64 kB that asks for more is a blow-up (a size read
# from the input and trusted), which libFuzzer reports as a crash with the input.
# FUZZ_RUNS=N runs the JSON, .bpt and expression harnesses for N inputs each instead of SECONDS. With FUZZ_SEED fixed
# too, such a run repeats input for input on any machine, so CI's verdict does not depend on the machine's speed (a
# time limit let a slower CI machine's run explore other inputs than the local one).
#   bash scripts/fuzz.sh [SECONDS]          e.g. bash scripts/fuzz.sh 600
#   FUZZ_SEED=1 FUZZ_RUNS=100000 bash scripts/fuzz.sh   (CI)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-60}"
# FUZZ_SEED: libFuzzer's -seed (0, the default: a new random seed each run; CI fixes it so that a run repeats).
fuzz_seed="${FUZZ_SEED:-0}"
cad_runs="${CAD_RUNS:-400}"
export_runs="${EXPORT_RUNS:-1000}"
malloc_limit_mb="${MALLOC_LIMIT_MB:-64}"
fuzz_runs="${FUZZ_RUNS:-0}"

# The fuzzing tool chain (Debian 12): clang-14 and libFuzzer. Only here, not in scripts/setup.sh.
if ! command -v clang++-14 >/dev/null || ! ls /usr/lib/llvm-14/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a \
    >/dev/null 2>&1; then
  sudo_cmd=""
  [ "$(id -u)" -ne 0 ] && sudo_cmd="sudo"
  $sudo_cmd apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo_cmd apt-get install -y -qq clang-14 libfuzzer-14-dev
fi

cmake -S . -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" \
  -DCMAKE_CXX_COMPILER=clang++-14 -DSEAM_FUZZ=ON -DSEAM_WITH_OCCT=OFF -DSEAM_BUILD_CLI=OFF -DSEAM_BUILD_TESTS=OFF \
  -DSEAM_BUILD_BENCH=OFF -DSEAM_BUILD_EXAMPLES=OFF \
  $(command -v ccache >/dev/null && echo -DCMAKE_CXX_COMPILER_LAUNCHER=ccache) >/dev/null
harnesses=(json bpt gcn)
[ "$cad_runs" -gt 0 ] && harnesses+=(step iges)
[ "$export_runs" -gt 0 ] && harnesses+=(export)
cmake --build build-fuzz -j "$(nproc)" --target "${harnesses[@]/#/fuzz_}"

# Seed corpora: every committed input of the harness's kind (copied, so that libFuzzer never writes into the tree).
seed() {  # seed HARNESS FILES...
  local dir="build-fuzz/seeds/$1"
  shift
  rm -rf "$dir"
  mkdir -p "$dir"
  for f in "$@"; do [ -f "$f" ] && cp "$f" "$dir/"; done
  return 0
}
shopt -s nullglob
seed json tests/data/*/*.json tests/data/hostile/*.json examples/models/*.json fuzz/regressions/json/*
seed bpt tests/data/hostile/*.bpt ../shared/data/bezier/*.bpt fuzz/regressions/bpt/*
seed gcn tests/data/gcn/*.json examples/models/zwl_example.json fuzz/regressions/gcn/*
# STEP/IGES: the hostile files of the OpenCASCADE guard tests and the smaller real files (up to 160 kB).
seed step tests/data/hostile_cad/*.stp ../shared/data/step/bug28366_fuselage.stp fuzz/regressions/step/*
seed iges tests/data/hostile_cad/*.igs ../shared/data/iges/BUC50025.igs ../shared/data/iges/occ22470.igs \
  fuzz/regressions/iges/*
# The writer: the small JSON models, each with a first byte that picks the format (even STEP, odd IGES).
seed export
for f in tests/data/*.json examples/models/*.json fuzz/regressions/export/*; do
  [ -f "$f" ] && [ "$(stat -c %s "$f")" -le 20000 ] || continue
  for fmt in 0 1; do
    { printf "%d" "$fmt"; cat "$f"; } >"build-fuzz/seeds/export/${fmt}_$(basename "$f")"
  done
done

mkdir -p build-fuzz/artifacts
# The harnesses run side by side, one per core, the longest first (in CI: json 49 s, iges 36 s, gcn 24 s, bpt 12 s,
# step 3 s on the 2-core VM); each writes its own log, so a run repeats input for input as when run one by one.
run_harness() {  # run_harness HARNESS: its log in build-fuzz/fuzz_HARNESS.log, "ok" or "failed" in .result
  local h="$1"
  mkdir -p "build-fuzz/corpus/$h"
  local limit=(-max_total_time="$seconds" -max_len=65536)
  [ "$fuzz_runs" -gt 0 ] && limit=(-runs="$fuzz_runs" -max_len=65536)
  local caps=(-rss_limit_mb=512 -malloc_limit_mb="$malloc_limit_mb")
  if [ "$h" = step ] || [ "$h" = iges ]; then
    limit=(-runs="$cad_runs" -max_len=262144)
    caps=(-rss_limit_mb=2048)
  fi
  if [ "$h" = export ]; then
    limit=(-runs="$export_runs" -max_len=65536)
    caps=(-rss_limit_mb=2048)
  fi
  echo "${limit[0]}" >"build-fuzz/fuzz_$h.limit"
  # caps: the text harnesses read at most -max_len bytes, so 512 MB (or one allocation above MALLOC_LIMIT_MB) is a
  # leak or a blow-up; OpenCASCADE's readers and writer keep 2 GB. -timeout: a single input taking 10 s is a hang
  # (the readers are linear).
  if ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
      "build-fuzz/fuzz/fuzz_$h" "${limit[@]}" -timeout=10 "${caps[@]}" \
      -print_final_stats=1 -seed="$fuzz_seed" -artifact_prefix="build-fuzz/artifacts/${h}-" \
      "build-fuzz/corpus/$h" "build-fuzz/seeds/$h" 2>"build-fuzz/fuzz_$h.log"; then
    echo ok >"build-fuzz/fuzz_$h.result"
  else
    echo failed >"build-fuzz/fuzz_$h.result"
  fi
}
order=()
for h in json iges export gcn bpt step; do
  [[ " ${harnesses[*]} " == *" $h "* ]] && order+=("$h")
done
slots="$(nproc)"
for h in "${order[@]}"; do
  rm -f "build-fuzz/fuzz_$h.result"
  run_harness "$h" &
  while [ "$(jobs -rp | wc -l)" -ge "$slots" ]; do wait -n || true; done
done
wait
status=0
for h in "${order[@]}"; do
  echo "== fuzz_$h: $(cat "build-fuzz/fuzz_$h.limit")"
  if [ "$(cat "build-fuzz/fuzz_$h.result" 2>/dev/null)" != ok ]; then
    status=1
    echo "fuzz_$h FAILED: see build-fuzz/fuzz_$h.log and build-fuzz/artifacts/"
    tail -n 40 "build-fuzz/fuzz_$h.log"
  fi
  grep -E '^stat::(number_of_executed_units|average_exec_per_sec|peak_rss_mb)' "build-fuzz/fuzz_$h.log" || true
done
exit "$status"
