#!/usr/bin/env bash
# `stackbeam fit` (docs/calibration.md) on benchmarks/fit/two_parameters.toml (mu and E of the
# rig spring, one loop, ~15 runs of 0.1 s):
#   fit_cli_test.sh <stackbeam> <work dir> exit     exit status 0 and the outputs for a good spec;
#                                                  2 naming the key for a bad spec, a bad option, a
#                                                  missing spec file
#   fit_cli_test.sh <stackbeam> <work dir> resume   stopped after 2 iterations (--stop-after, as SIGINT):
#                                                  130, history.csv kept; the same command resumes
#                                                  from its last accepted values and reaches the
#                                                  uninterrupted fit's values; --restart starts over
# No wall-clock threshold anywhere.
set -u
cli=$1 dir=$2 what=$3
src=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
spec=$src/benchmarks/fit/two_parameters.toml
mkdir -p "$dir"
fail() { echo "FAIL: $*"; exit 1; }
# value N FILE: the fitted value of parameter N (0-based) in fit.json
value() { python3 -c "import json,sys; print(json.load(open(sys.argv[2]))['parameters'][int(sys.argv[1])]['value'])" "$1" "$2"; }
# close A B: |A/B - 1| < 1e-4 (both fits stop on the same tolerances, 1e-5 of the bound width
# in the values' steps and 1e-6 relative in the misfit: 1e-4 is well above both)
close() { python3 -c "import sys; a, b = map(float, sys.argv[1:]); sys.exit(0 if abs(a / b - 1) < 1e-4 else 1)" "$1" "$2"; }

case $what in
exit)
    out=$dir/exit_good
    rm -rf "$out"
    "$cli" fit "$spec" --out-dir "$out" --jobs 2 --no-plot > "$dir/good.out" || fail "good spec: exit status $?"
    for f in fitted.toml fit.json history.csv loops.csv; do [ -s "$out/$f" ] || fail "$f not written"; done
    grep -q '"converged": true' "$out/fit.json" || fail "not converged: $(cat "$out/fit.json")"
    # refused NAME SED PATTERN...: the spec edited by SED (its relative paths made absolute) is
    # refused with exit status 2 and a message matching every PATTERN
    refused() {
        local name=$1 edit=$2
        shift 2
        sed "$edit"'; s|"\.\./\.\./|"'"$src"'/|' "$spec" > "$dir/$name.toml"
        "$cli" fit "$dir/$name.toml" --out-dir "$dir/exit_bad" --no-plot 2> "$dir/$name.err"
        local rc=$?
        [ $rc = 2 ] || fail "$name: exit status $rc, expected 2"
        for pattern in "$@"; do grep -q "$pattern" "$dir/$name.err" || fail "$name: no '$pattern' in: $(cat "$dir/$name.err")"; done
    }
    # a column the CSV does not have: the key and the value named
    refused bad_column 's/force_column = "load_cell_n"/force_column = "load_n"/' "loops\[0\].force_column" "'load_n' is not a column"
    # bounds the scenario refuses (a negative friction coefficient): the parameter named
    refused bad_bound 's/lower = 0.05/lower = -0.05/' "parameters\[0\].*refuses the bound -0.05"
    # a bad option -> 2 naming it; a missing spec file -> 2 naming it
    "$cli" fit "$spec" --jobs -1 --no-plot > "$dir/jobs.out" 2>&1
    rc=$?
    [ $rc = 2 ] || fail "--jobs -1: exit status $rc, expected 2"
    grep -q -- "--jobs" "$dir/jobs.out" || fail "--jobs is not named: $(cat "$dir/jobs.out")"
    "$cli" fit "$dir/no_such_spec.toml" --no-plot 2> "$dir/missing.err"
    rc=$?
    [ $rc = 2 ] || fail "a missing spec file: exit status $rc, expected 2"
    grep -q "no_such_spec.toml" "$dir/missing.err" || fail "the file is not named: $(cat "$dir/missing.err")"
    echo "exit statuses as documented"
    ;;
resume)
    ref=$dir/resume_ref out=$dir/resume
    rm -rf "$ref" "$out"
    "$cli" fit "$spec" --out-dir "$ref" --jobs 2 --no-plot >/dev/null || fail "reference fit: exit status $?"
    "$cli" fit "$spec" --out-dir "$out" --jobs 2 --no-plot --stop-after 2 > "$dir/stop.out"
    rc=$?
    [ $rc = 130 ] || fail "--stop-after 2: exit status $rc, expected 130 (as SIGINT)"
    grep -q "run the same command again to resume" "$dir/stop.out" || fail "no resume advice"
    [ ! -e "$out/fit.json" ] || fail "a stopped fit wrote fit.json"
    [ "$(($(wc -l < "$out/history.csv") - 1))" -ge 1 ] || fail "history.csv has no iteration after the stop"
    last=$(awk -F, '$4 == 1' "$out/history.csv" | tail -1 | cut -d, -f6-)
    "$cli" fit "$spec" --out-dir "$out" --jobs 2 --no-plot > "$dir/resume.out" || fail "resume: exit status $?"
    grep -q "resuming from .*history.csv's last accepted values: $(echo "$last" | tr ',' ' ')" "$dir/resume.out" ||
        fail "the resume does not start from the last accepted values ($last): $(head -3 "$dir/resume.out")"
    for j in 0 1; do
        close "$(value $j "$out/fit.json")" "$(value $j "$ref/fit.json")" ||
            fail "parameter $j: resumed $(value $j "$out/fit.json"), uninterrupted $(value $j "$ref/fit.json")"
    done
    # --restart: from the spec's starts, history.csv started over (its first row the spec's start)
    "$cli" fit "$spec" --out-dir "$out" --jobs 2 --no-plot --restart > "$dir/restart.out" || fail "--restart: exit status $?"
    ! grep -q "resuming" "$dir/restart.out" || fail "--restart resumed"
    first=$(sed -n 2p "$out/history.csv")
    [ "$(echo "$first" | cut -d, -f2)" = 0 ] && close "$(echo "$first" | cut -d, -f6)" 0.525 &&
        close "$(echo "$first" | cut -d, -f7)" 3e10 ||
        fail "--restart: history.csv does not start at the spec's start (0.525, 3e10): $first"
    echo "stopped, resumed, restarted"
    ;;
*)
    fail "unknown case $what"
    ;;
esac
