#!/usr/bin/env bash
# The main job: installs what is missing (Debian), builds, and runs the paper's
# section 5 example in all three cases. Table on stdout; CSV files and PNG
# figures in out/ (extra arguments go to paper_demo, e.g. --out-dir DIR).
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
export DEBIAN_FRONTEND=noninteractive
source scripts/common.sh

install_packages "${STACKBEAM_BUILD_PACKAGES[@]}" "${STACKBEAM_MPI_PACKAGES[@]}" "${STACKBEAM_PYTHON_PACKAGES[@]}" gnuplot-nox
build
if [ "$#" -eq 0 ]; then set -- --out-dir out; fi
./build/demos/paper_demo "$@"
