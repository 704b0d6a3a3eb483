#!/usr/bin/env bash
# Benchmark (not a test): scenarios/base_steel_elastic.toml (the paper's friction spring, steel
# leaves, elastic interfaces, 10 mm clamps, gravity, the supports moving 5 mm at 8 Hz), 1 s, in
# one invocation:
#   - mode cvode with the modal leaf inertia (auto's choice there), default cut and 1000 rad/s;
#   - the massless run of the same file (mode cvode, --beam-density 0);
#   - mode newmark at dt = 1e-4, 5e-5, 2.5e-5 s (the finest is the reference; the change between
#     the two finest shows it is converged).
# Prints each run's CPU time (user + sys), the modal runs' cost over the massless run, and every
# run's max |w - w_newmark(2.5e-5 s)| over the 1e-4 s outputs, as a fraction of newmark's peak
# |w| (w: R's deflection relative to the supports; R's absolute motion w + y_b deviates alike)
# and of the peak of its motion |w - w(0)|. docs/performance.md, "Leaf mass".
#   benchmarks/modal_base_excitation.sh [build dir (default build)] [work dir (default /tmp/modal_bench)] [t_end s (default 1)]
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."
cli=${1:-build}/apps/cli/stackbeam
work=${2:-/tmp/modal_bench}
t_end=${3:-1}
file=scenarios/base_steel_elastic.toml
mkdir -p "$work"
TIMEFORMAT='%U %S'
run() {  # run NAME ARGS...: prints "NAME cpu_s"
    local name=$1
    shift
    local t
    t=$( { time "$cli" simulate --scenario "$file" --t-end "$t_end" --quiet --out "$work/$name.csv" \
           --summary "$work/$name.json" "$@" >"$work/$name.txt" 2>&1; } 2>&1 )
    read -r user sys <<<"$t"
    echo "$name $(echo "$user + $sys" | bc -l)"
}
{
    run massless --mode cvode --beam-density 0 --dt 1e-4
    run modal --mode cvode --dt 1e-4
    run modal_cut1000 --mode cvode --dt 1e-4 --modal-cutoff 1000
    run newmark_1e-4 --mode newmark --dt 1e-4
    run newmark_5e-5 --mode newmark --dt 5e-5
    run newmark_2.5e-5 --mode newmark --dt 2.5e-5
} | tee "$work/cpu.txt"
/usr/bin/python3 - "$work" <<'PY'
import csv, sys
work = sys.argv[1]
def load(name):
    with open(f"{work}/{name}.csv") as fh:
        rows = list(csv.DictReader(fh))
    return {round(float(r["t"]) * 1e4): float(r["w"]) for r in rows}
cpu = dict(line.split() for line in open(f"{work}/cpu.txt"))
ref = load("newmark_2.5e-5")
peak = max(abs(v) for v in ref.values())
w0 = ref[0]
motion = max(abs(v - w0) for v in ref.values())
print(f"newmark(2.5e-5 s): peak |w| {peak:.6g} m, peak |w - w(0)| {motion:.6g} m")
print("run cpu_s x_massless max|w-w_ref|_m of_peak of_motion")
for name in cpu:
    if name == "newmark_2.5e-5":
        continue
    w = load(name)
    dev = max(abs(w[k] - ref[k]) for k in w if k in ref)
    print(f"{name} {float(cpu[name]):.3f} {float(cpu[name]) / float(cpu['massless']):.2f} {dev:.3g} "
          f"{dev / peak:.3%} {dev / motion:.3%}")
PY
