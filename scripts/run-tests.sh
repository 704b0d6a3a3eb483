#!/usr/bin/env bash
# The tests: installs what is missing (Debian), builds, and runs every test with CTest,
# twice: the Release build in build/, then a second build in build-asan/ under
# AddressSanitizer and UndefinedBehaviorSanitizer (any report fails the test that
# made it); then a third, small one in build-tsan/: the sweep's threads under
# ThreadSanitizer (the library and test_sweep only). STACKBEAM_SANITIZERS=0 skips the
# second and third (for a quick local run; CI runs all three).
# Then the readers under libFuzzer for 20 s each (scripts/fuzz.sh, Clang, from build-asan/;
# a crash, hang or sanitizer report fails the run; docs/fuzzing.md); STACKBEAM_FUZZ=0 skips it.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
export DEBIAN_FRONTEND=noninteractive
source scripts/common.sh

# gnuplot: the CLI test of --plot; MPI: the sweep's; Python: the module's tests
pkgs=("${STACKBEAM_BUILD_PACKAGES[@]}" "${STACKBEAM_MPI_PACKAGES[@]}" "${STACKBEAM_PYTHON_PACKAGES[@]}" gnuplot-nox)
if [ "${STACKBEAM_SANITIZERS:-1}" != 0 ] || [ "${STACKBEAM_FUZZ:-1}" != 0 ]; then
  pkgs+=("${STACKBEAM_SANITIZER_PACKAGES[@]}")
fi
install_packages "${pkgs[@]}"
build
# --timeout: a test that hangs (a sanitizer's abort_on_error was seen to hang a binary for
# over 16 min instead of failing) fails after 15 min instead of stalling the run.
# -j2: the tests are independent (each writes its own files). The tests labelled `slow`
# (the long convergence studies, tests/CMakeLists.txt) run in the Release build only; the
# sanitizer build runs every other test, each at most about 3 min there.
ctest --test-dir build --output-on-failure --timeout 900 -j2

if [ "${STACKBEAM_SANITIZERS:-1}" != 0 ]; then
  start=$(date +%s)
  build_sanitized
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:strict_string_checks=1:detect_stack_use_after_return=1 \
  UBSAN_OPTIONS=halt_on_error=1:print_stacktrace=1 \
    ctest --test-dir build-asan --output-on-failure --timeout 900 -j2 -LE slow
  echo "sanitizer build and tests: $(( $(date +%s) - start )) s"
  start=$(date +%s)
  build_tsan
  TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 ctest --test-dir build-tsan --output-on-failure --timeout 900 -R '^test_sweep$'
  echo "thread sanitizer build and test: $(( $(date +%s) - start )) s"
fi

if [ "${STACKBEAM_FUZZ:-1}" != 0 ]; then
  # a fixed seed: the same inputs on every CI run (a longer run: docs/fuzzing.md)
  # the targets are in the sanitizer build when it ran (build_sanitized), else in build-fuzz/
  if [ "${STACKBEAM_SANITIZERS:-1}" != 0 ]; then export STACKBEAM_FUZZ_BUILD=build-asan; fi
  STACKBEAM_FUZZ_SEED=1 scripts/fuzz.sh 20
fi
