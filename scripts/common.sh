# Shared by run-demo.sh and run-tests.sh (sourced, not run): installs the Debian
# packages the project needs, if missing, and configures and builds it in build/.

# The packages every build needs (pkgconf: the test of the installed stackbeam.pc; ninja-build:
# the builds' generator, generator_args below; libceres-dev: stackbeam fit's bounded least squares,
# docs/decisions/059-calibration.md; libzip-dev: the FMU archive, fmu/ and docs/fmu.md).
STACKBEAM_BUILD_PACKAGES=(build-essential cmake ninja-build pkgconf libsundials-dev libeigen3-dev libsuitesparse-dev libboost-test-dev libcli11-dev libtoml11-dev nlohmann-json3-dev libceres-dev libzip-dev)
# OpenMPI: `mpirun -n N stackbeam sweep` (optional: without it the sweep runs on threads only;
# the tests then skip the MPI comparison).
STACKBEAM_MPI_PACKAGES=(libopenmpi-dev openmpi-bin)
# The Python module (python/, docs/python.md) and its tests and figures, for Debian's /usr/bin/python3
# (python3-pil: the GIF writer of stackbeam.plot.animate_stack).
STACKBEAM_PYTHON_PACKAGES=(python3-dev pybind11-dev python3-numpy python3-pytest python3-matplotlib python3-pil)
# Clang and its sanitizer runtimes: the sanitizer builds (build_sanitized, build_tsan) and the
# fuzzing of the readers (scripts/fuzz.sh).
STACKBEAM_SANITIZER_PACKAGES=(clang-14 libclang-rt-14-dev)

# install_packages PKG...: apt-get installs the packages that are not installed yet.
# Skips apt entirely (fast) when all of them are installed already.
install_packages() {
  local missing=() pkg
  if ! command -v dpkg-query >/dev/null 2>&1; then
    echo "note: dpkg-query not found (not a Debian system?); not installing: $*" >&2
    return 0
  fi
  for pkg in "$@"; do
    if ! dpkg-query -W -f='${Status}' "$pkg" 2>/dev/null | grep -q 'install ok installed'; then
      missing+=("$pkg")
    fi
  done
  if [ "${#missing[@]}" -eq 0 ]; then
    echo "packages: all installed ($*)"
    return 0
  fi
  local sudo=()
  if [ "$(id -u)" -ne 0 ]; then
    if ! command -v sudo >/dev/null 2>&1; then
      echo "error: need root or sudo to install: ${missing[*]}" >&2
      return 1
    fi
    sudo=(sudo)
  fi
  echo "packages: installing ${missing[*]}"
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get update
  "${sudo[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
}

# generator_args DIR: `-G Ninja` for a build directory not configured yet (or already
# configured with Ninja), when ninja is installed; nothing for one configured with another
# generator (CMake refuses to change it), which keeps that one. Ninja compiles the objects of
# a target while the libraries it links are still being built (the Makefile generator waits
# for the whole library first): both cores stay busy past each library's longest source
# (docs/decisions/048-ci-build-time.md).
generator_args() {
  if command -v ninja >/dev/null 2>&1 && \
     { [ ! -f "$1/CMakeCache.txt" ] || grep -q '^CMAKE_GENERATOR:INTERNAL=Ninja$' "$1/CMakeCache.txt"; }; then
    echo "-G Ninja"
  fi
}

# build: configures and builds the project in build/ (Release).
build() {
  # shellcheck disable=SC2046
  cmake -S . -B build $(generator_args build) -DCMAKE_BUILD_TYPE=Release
  cmake --build build -j"$(nproc)"
}

# build_sanitized: a second build in build-asan/ with AddressSanitizer and
# UndefinedBehaviorSanitizer (every UB report fatal), assertions on (Eigen's index
# checks too), -O1 -g1 (a third of the compile time of -O2 -g with both
# sanitizers, line numbers in the reports kept), compiled by Clang (Debian's clang-14,
# STACKBEAM_SANITIZER_PACKAGES: 0.6x GCC's compile time with both sanitizers, measured
# on a test file, the build's largest cost; the Release build stays GCC's), the library shared (the Release
# build's is static, so the tests cover both kinds of installed package). Without the
# Python module: an instrumented extension cannot load into the uninstrumented python3
# (the sanitizer runtime must come first); the Release build tests it. With the libFuzzer
# targets of the readers (fuzz/): the sources they run get the fuzzer's coverage too, and
# scripts/fuzz.sh runs them from this build (STACKBEAM_FUZZ_BUILD=build-asan), so the
# library is compiled under the sanitizers once for both (decision 032). The readers,
# writers and the CLI at -O0 (half their compile time; they read and dispatch, the work the
# tests run is the library's solvers and steppers, -O1). Without studies/ (no test runs them).
build_sanitized() {
  # shellcheck disable=SC2046
  cmake -S . -B build-asan $(generator_args build-asan) -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" -DBUILD_SHARED_LIBS=ON \
    -DSTACKBEAM_BUILD_PYTHON=OFF -DSTACKBEAM_BUILD_FUZZERS=ON -DSTACKBEAM_FUZZ_PLAIN_REST=OFF \
    -DSTACKBEAM_COLD_COMPILE_OPTIONS=-O0 -DSTACKBEAM_BUILD_STUDIES=OFF \
    -DCMAKE_CXX_FLAGS="-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
  cmake --build build-asan -j"$(nproc)"
}

# build_tsan: a third, small build in build-tsan/ under ThreadSanitizer: the library and
# the one test that runs its points on threads (tests/test_sweep.cpp, `stackbeam sweep
# --jobs N`'s scheduler), not the whole project (a few minutes on 2 cores). Proves the
# library keeps no mutable state shared between runs: a data race fails the test.
build_tsan() {
  # shellcheck disable=SC2046
  cmake -S . -B build-tsan $(generator_args build-tsan) -DCMAKE_CXX_COMPILER=clang++-14 -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-O1 -g1" \
    -DCMAKE_CXX_FLAGS="-fsanitize=thread -fno-omit-frame-pointer" -DSTACKBEAM_BUILD_DEMOS=OFF \
    -DSTACKBEAM_COLD_COMPILE_OPTIONS=-O0
  cmake --build build-tsan -j"$(nproc)" --target test_sweep
}
