#!/usr/bin/env bash
# Benchmark (not a test): issue 27's friction-at-scale targets in one invocation, whole processes,
# CPU time (`cpu_s_per_sim_s`: CPU s per simulated second). The graduated 10-leaf spring at 100,
# 200 and 400 elements per half leaf and the identical 10 x 400, 100 ms, elastic interfaces,
# every default (TransitionStudy way 61, path 48, repair -1), each run once per repetition as its
# own process, interleaved with the same runs of a second build (the code before a change, or
# the same build again), and the same meshes bonded (stacks 3 and 4: the targets' reference).
# docs/performance.md, "Decisions 040-043 together".
#   benchmarks/transition_targets.sh NEW_BENCH [OLD_BENCH] [REPETITIONS (default 5)]
# NEW_BENCH / OLD_BENCH: bench_stackbeam binaries (OLD_BENCH built before the `repair` argument
# existed, where the filter with it matches nothing, is run with the filter without it). Prints
# one line per run: rep, run, CPU s per sim. s.
set -euo pipefail
new=$1
old=${2:-}
reps=${3:-5}
cpu() {  # cpu BINARY FILTER: the run's CPU s per simulated second
    "$1" --benchmark_filter="$2" 2>/dev/null | grep -o 'cpu_s_per_sim_s=[0-9.e+-]*' | cut -d= -f2
}
flt() {  # flt EL STACK PATH [repair]: one TransitionStudy registration
    echo "TransitionStudy/el:$1/stack:$2/ms:100/way:61/trace:0/schur:0/fixed:-1/path:$3/hits:-1/${4:-}"
}
echo "# rep run cpu_s_per_sim_s"
for rep in $(seq 1 "$reps"); do
    for run in "400 1" "400 2" "200 1" "100 1"; do
        read -r el st <<<"$run"
        if [ -n "$old" ]; then  # (an old build with the repair argument takes the new filter)
            v=$(cpu "$old" "$(flt "$el" "$st" 48 repair:-1/)")
            [ -n "$v" ] || v=$(cpu "$old" "$(flt "$el" "$st" 48)iter")
            echo "$rep old_el${el}_stack$st $v"
        fi
        echo "$rep new_el${el}_stack$st $(cpu "$new" "$(flt "$el" "$st" 48 repair:-1/)")"
    done
    for run in "400 3" "400 4" "200 3" "100 3"; do
        read -r el st <<<"$run"
        echo "$rep bonded_el${el}_stack$st $(cpu "$new" "$(flt "$el" "$st" 0 repair:-1/)")"
    done
done
