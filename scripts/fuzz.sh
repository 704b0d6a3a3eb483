#!/usr/bin/env bash
# Fuzzing of the readers (docs/fuzzing.md): builds the libFuzzer targets of fuzz/ with
# Debian's clang-14 in build-fuzz/ (only the targets and the library they link: tests,
# demos and the CLI off) and runs each for a while.
#
#   scripts/fuzz.sh [SECONDS [TARGET...]]    default: 20 s for every target (the CI's run)
#
# Each target fuzz_<name> runs with its growing corpus in build-fuzz/corpus/<name>/
# (kept between runs), the seeds of fuzz/CMakeLists.txt, fuzz/<name>.dict if present,
# a 10 s per-input time limit (a hang) and 2 GB of memory (an input that needs more is
# a bug too). A crash, hang, out-of-memory or sanitizer report leaves its input in
# build-fuzz/artifacts/<name>/ and fails the script; make it a regression test by
# copying it into fuzz/regressions/<name>/ (and a bad-input test, docs/fuzzing.md).
# STACKBEAM_FUZZ_JOBS=N runs N fuzzing processes per target (default 1: a shared machine);
# STACKBEAM_FUZZ_SEED=S fixes libFuzzer's random seed (the CI's run: 1; default: random).
# STACKBEAM_FUZZ_BUILD=DIR builds and runs the targets in DIR, a build already configured
# with -DSTACKBEAM_BUILD_FUZZERS=ON (the CI's run: build-asan/, the sanitizer build of
# scripts/common.sh, which has them), instead of configuring build-fuzz/.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
export DEBIAN_FRONTEND=noninteractive
source scripts/common.sh

seconds=${1:-20}
shift || true
install_packages "${STACKBEAM_BUILD_PACKAGES[@]}" "${STACKBEAM_SANITIZER_PACKAGES[@]}"
start=$(date +%s)
dir=${STACKBEAM_FUZZ_BUILD:-build-fuzz}
if [ -n "${STACKBEAM_FUZZ_BUILD:-}" ]; then
  if ! grep -q '^STACKBEAM_BUILD_FUZZERS:BOOL=ON' "$dir/CMakeCache.txt" 2>/dev/null; then
    echo "STACKBEAM_FUZZ_BUILD=$dir: not a build configured with -DSTACKBEAM_BUILD_FUZZERS=ON" >&2
    exit 2
  fi
else
  # -O1 -g1: as the sanitizer build (common.sh), a third of the compile time of -O2 -g
  cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g1" -DCMAKE_CXX_COMPILER=clang++-14 \
    -DSTACKBEAM_BUILD_FUZZERS=ON -DSTACKBEAM_BUILD_TESTS=OFF -DSTACKBEAM_BUILD_DEMOS=OFF
fi
targets=("$@")
if [ "${#targets[@]}" -eq 0 ]; then
  for src in fuzz/fuzz_*.cpp; do
    name=$(basename "$src" .cpp)
    targets+=("${name#fuzz_}")
  done
fi
cmake --build "$dir" -j"$(nproc)" --target "${targets[@]/#/fuzz_}"
echo "fuzz build: $(( $(date +%s) - start )) s"

jobs=${STACKBEAM_FUZZ_JOBS:-1}
status=0
for name in "${targets[@]}"; do
  corpus=$dir/corpus/$name
  artifacts=$dir/artifacts/$name
  mkdir -p "$corpus" "$artifacts"
  mapfile -t seeds < "$dir/fuzz/fuzz_$name.seeds"
  dict=()
  [ -f "fuzz/$name.dict" ] && dict=(-dict="fuzz/$name.dict")
  echo "fuzz_$name: ${seconds} s, ${jobs} job(s), corpus $corpus, seeds ${seeds[*]}"
  fuzz_start=$(date +%s)
  # -jobs/-workers: N independent processes (fuzz-N.log each); with 1, run in the foreground
  seed=()
  [ -n "${STACKBEAM_FUZZ_SEED:-}" ] && seed=(-seed="$STACKBEAM_FUZZ_SEED")
  parallel=()
  [ "$jobs" -gt 1 ] && parallel=(-jobs="$jobs" -workers="$jobs")
  if ! ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
      "$dir/fuzz/fuzz_$name" "${parallel[@]}" "${seed[@]}" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
      -print_final_stats=1 -artifact_prefix="$artifacts/" "${dict[@]}" "$corpus" "${seeds[@]}"; then
    echo "fuzz_$name: FAILED: the input is in $artifacts/ (docs/fuzzing.md: what to do with it)" >&2
    status=1
  fi
  echo "fuzz_$name: $(( $(date +%s) - fuzz_start )) s"
done
echo "fuzz build and runs: $(( $(date +%s) - start )) s"
exit "$status"
