#!/usr/bin/env bash
# Benchmark (not a test): `stackbeam sweep` of the 100-point rig map (benchmarks/sweep/rig_map.toml)
# with --jobs 1, --jobs 2 and mpirun -n 2; prints each run's wall and CPU time (user + sys of
# the command and its children) and the speed-up over --jobs 1. docs/performance.md, "Sweeps".
#   benchmarks/sweep_speedup.sh [build dir (default build)] [work dir (default /tmp/sweep_bench)]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
cli=${1:-build}/apps/cli/stackbeam
work=${2:-/tmp/sweep_bench}
spec=benchmarks/sweep/rig_map.toml
mkdir -p "$work"
TIMEFORMAT='%R %U %S'
run() {  # run NAME COMMAND...: prints "NAME wall cpu"
    local name=$1
    shift
    rm -rf "$work/$name"
    local t
    t=$( { time "$@" --out-dir "$work/$name" --no-plot >/dev/null 2>&1; } 2>&1 )
    read -r wall user sys <<<"$t"
    # busy: the points' wall time summed over the threads / (threads x the run's wall time): the
    # share of the run in which each thread was running a point (not waiting for work or a lock)
    local points jobs
    points=$(grep '"points_wall_time_s"' "$work/$name/sweep.json" | sed 's/.*: *//; s/,$//')
    jobs=$(( $(grep '"jobs"' "$work/$name/sweep.json" | sed 's/[^0-9]//g') * $(grep '"processes"' "$work/$name/sweep.json" | sed 's/[^0-9]//g') ))
    echo "$name $wall $(echo "$user + $sys" | bc -l) $(echo "$points / ($jobs * $wall)" | bc -l | cut -c1-4) $(uptime | sed 's/.*load average: //')"
}
echo "run wall_s cpu_s busy load(1,5,15 min)"
r1=$(run jobs1 "$cli" sweep "$spec" --jobs 1); echo "$r1"
r2=$(run jobs2 "$cli" sweep "$spec" --jobs 2); echo "$r2"
if command -v mpirun >/dev/null; then
    r3=$(OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl_vader_single_copy_mechanism=none run mpi2 mpirun -n 2 "$cli" sweep "$spec"); echo "$r3"
fi
w1=$(echo "$r1" | cut -d' ' -f2)
for r in "$r2" ${r3:+"$r3"}; do
    echo "speed-up $(echo "$r" | cut -d' ' -f1): $(echo "$w1 / $(echo "$r" | cut -d' ' -f2)" | bc -l | cut -c1-5)"
done
# on a loaded machine the wall times are the scheduler's shares; the CPU times say whether the
# parallel runs did more work: with equal CPU and busy threads, an idle 2-core machine gives
# 2 x cpu(jobs1) / cpu(run) (the tail of one last point aside)
c1=$(echo "$r1" | cut -d' ' -f3)
for r in "$r2" ${r3:+"$r3"}; do
    echo "idle-machine estimate $(echo "$r" | cut -d' ' -f1): $(echo "2 * $c1 / $(echo "$r" | cut -d' ' -f3)" | bc -l | cut -c1-4)"
done
for d in jobs2 mpi2; do
    [ -d "$work/$d" ] && { diff <(sed 's/,[^,]*$//' "$work/jobs1/points.csv") <(sed 's/,[^,]*$//' "$work/$d/points.csv") >/dev/null &&
        echo "$d: the same table as jobs1" || echo "$d: TABLE DIFFERS from jobs1"; }
done
