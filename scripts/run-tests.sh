#!/usr/bin/env bash
# The tests: installs what is missing (Debian), builds, and runs every test with CTest,
# twice: the Release build in build/, then a second build in build-asan/ under
# AddressSanitizer and UndefinedBehaviorSanitizer (any report fails the test that
# made it). STACKBEAM_SANITIZERS=0 skips the second (for a quick local run; CI runs both).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
export DEBIAN_FRONTEND=noninteractive
source scripts/common.sh

install_packages "${STACKBEAM_BUILD_PACKAGES[@]}" gnuplot-nox  # gnuplot: the CLI test of --plot
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
fi
