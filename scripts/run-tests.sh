#!/usr/bin/env bash
# The tests: installs what is missing (Debian), builds, and runs every test with CTest.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
export DEBIAN_FRONTEND=noninteractive
source scripts/common.sh

install_packages "${STACKBEAM_BUILD_PACKAGES[@]}"
build
ctest --test-dir build --output-on-failure
