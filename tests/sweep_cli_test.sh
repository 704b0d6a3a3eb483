#!/usr/bin/env bash
# `stackbeam sweep` (docs/sweep.md) on tests/sweep/map_small.toml (2 x 2 x 2 points of a
# coarse rig loop, seconds in all):
#   sweep_cli_test.sh <stackbeam> <work dir> simulate   every point's row and series equal the
#                                                        single `simulate` run of its scenario
#   sweep_cli_test.sh <stackbeam> <work dir> parallel [mpirun]  --jobs 1, --jobs 2 (and mpirun -n 2)
#                                                        give the same table
#   sweep_cli_test.sh <stackbeam> <work dir> failed     a failed point: its row, the others run, exit 3
#   sweep_cli_test.sh <stackbeam> <work dir> resume     stopped after 3 points (--stop-after, as
#                                                        SIGINT), resumed: the full table, no point
#                                                        twice; SIGINT stops cleanly; another spec's
#                                                        directory refused; --restart
#   sweep_cli_test.sh <stackbeam> <work dir> owner      issue 41: a second sweep on a directory in use
#                                                        refused naming the holder (also with --restart);
#                                                        resume after kill -9; a FIFO scenario and
#                                                        --out DIR refused at once
# "The same table": every column but the last (wall_time_s), compared as text (floats are
# printed in the fewest digits that read back exactly, so equal text is equal doubles). No wall-clock threshold anywhere.
set -u
cli=$1 dir=$2 what=$3 mpirun=${4:-}
src=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
spec=$src/sweep/map_small.toml
mkdir -p "$dir"
fail() { echo "FAIL: $*"; exit 1; }
# the table without its last column (wall_time_s)
table() { sed 's/,[^,]*$//' "$1/points.csv"; }

case $what in
simulate)
    out=$dir/simulate
    rm -rf "$out"
    "$cli" sweep "$spec" --out-dir "$out" --jobs 2 --keep-series --no-plot || fail "sweep exit status $?"
    header=$(head -1 "$out/points.csv")
    [ "$(wc -l < "$out/points.csv")" = 9 ] || fail "points.csv has not 8 rows"
    col() {  # col NAME: the 1-based column of NAME in points.csv
        echo "$header" | tr ',' '\n' | grep -nx "$1" | cut -d: -f1
    }
    for ((i = 0; i < 8; ++i)); do
        scenario=$(printf '%s/scenarios/point-%04d.toml' "$out" $i)
        series=$(printf '%s/series/point-%04d.csv' "$out" $i)
        "$cli" simulate --scenario "$scenario" --out "$dir/single.csv" --summary "$dir/single.json" --quiet >/dev/null ||
            fail "simulate of point $i: exit status $?"
        cmp "$dir/single.csv" "$series" || fail "point $i: the sweep's series differs from simulate's CSV"
        row=$(awk -F, -v i=$i '$1 == i' "$out/points.csv")
        [ "$(echo "$row" | cut -d, -f$(col status))" = ok ] || fail "point $i is not ok: $row"
        hyst=$(sed -n '/"hysteresis": {/,/}/p' "$dir/single.json")
        fancher=$(sed -n '/"fancher": {/,/}/p' "$dir/single.json")
        for name in loop_area_j friction_work_j secant_stiffness_n_per_m dynamic_rate_n_per_m loss_factor \
                    equivalent_damping_ratio force_min_n force_max_n w_min_m w_max_m \
                    fancher_upper_rate_n_per_m fancher_upper_offset_n fancher_lower_rate_n_per_m \
                    fancher_lower_offset_n fancher_beta_m fancher_rms_error_relative energy_balance_error_j; do
            key=$name
            [ $name = energy_balance_error_j ] && key=balance_error_max_abs
            if [ $name = energy_balance_error_j ]; then
                json=$(grep "\"$key\":" "$dir/single.json" | head -1 | sed 's/.*: *//; s/,$//')
            elif [ "${name#fancher_}" != "$name" ]; then  # simulate's "fancher" object, without the prefix
                json=$(echo "$fancher" | grep "\"${name#fancher_}\":" | sed 's/.*: *//; s/,$//')
            else
                json=$(echo "$hyst" | grep "\"$key\":" | sed 's/.*: *//; s/,$//')
            fi
            cell=$(echo "$row" | cut -d, -f$(col $name))
            [ -n "$json" ] && [ -n "$cell" ] || fail "point $i: $name missing (table '$cell', simulate '$json')"
            # equal doubles (awk reads both with strtod; both texts read back as the doubles written)
            awk -v a="$cell" -v b="$json" 'BEGIN { exit !(a + 0 == b + 0) }' ||
                fail "point $i: $name is $cell in the table, $json from simulate"
        done
        # the fitted loop beside the loop: the same samples (t, w), the model's force
        loop=$(printf '%s/loops/point-%04d.csv' "$out" $i)
        fitted=$(printf '%s/loops/point-%04d-fancher.csv' "$out" $i)
        [ -f "$fitted" ] || fail "point $i: no $fitted"
        diff <(cut -d, -f1,2 "$loop" | tail -n +2) <(cut -d, -f1,2 "$fitted" | tail -n +2) >/dev/null ||
            fail "point $i: the fitted loop is not along the loop's samples"
    done
    echo "every point equals its single simulate run"
    ;;
parallel)
    for jobs in 1 2; do
        rm -rf "$dir/jobs$jobs"
        "$cli" sweep "$spec" --out-dir "$dir/jobs$jobs" --jobs $jobs --no-plot || fail "--jobs $jobs: exit status $?"
    done
    diff <(table "$dir/jobs1") <(table "$dir/jobs2") || fail "--jobs 1 and --jobs 2 tables differ"
    if [ -n "$mpirun" ]; then
        rm -rf "$dir/mpi"
        # (as root OpenMPI wants the two ALLOW variables; vader's single copy needs ptrace rights
        # containers often lack.) In the sanitizer build the ranks run without leak checking:
        # OpenMPI's components are plugins it dlopens and dlcloses before exit, so the leak
        # report's stacks of its start-up allocations name no module and no suppression can
        # match them (seen: 116 kB in 3,339 allocations, every frame "<unknown module>"). The
        # sweep's own code is leak-checked by the --jobs runs above; memory errors stay fatal.
        ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" \
        OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_btl_vader_single_copy_mechanism=none \
            "$mpirun" -n 2 --oversubscribe "$cli" sweep "$spec" --out-dir "$dir/mpi" --no-plot || fail "mpirun: exit status $?"
        grep -q '"processes": 2' "$dir/mpi/sweep.json" || fail "sweep.json does not say 2 processes"
        diff <(table "$dir/jobs1") <(table "$dir/mpi") || fail "--jobs 1 and mpirun -n 2 tables differ"
    fi
    echo "the tables are the same"
    ;;
resume)
    ref=$dir/resume_ref out=$dir/resume
    rm -rf "$ref" "$out"
    "$cli" sweep "$spec" --out-dir "$ref" --jobs 1 --no-plot >/dev/null || fail "reference run: exit status $?"
    "$cli" sweep "$spec" --out-dir "$out" --jobs 1 --no-plot --stop-after 3 2>"$dir/stop.err"
    rc=$?
    [ $rc = 130 ] || fail "--stop-after 3: exit status $rc, expected 130 (as SIGINT)"
    grep -q "run the same command again to resume" "$dir/stop.err" || fail "no resume advice on stderr"
    [ "$(($(wc -l < "$out/finished.csv") - 2))" = 3 ] || fail "finished.csv has not 3 rows after --stop-after 3"
    # a cut last row (a crash while writing) is dropped on resume, its point runs again
    printf '7,0.02,2,0.5,ok,,0.0' >> "$out/finished.csv"
    "$cli" sweep "$spec" --out-dir "$out" --jobs 2 --no-plot > "$dir/resume.out" || fail "resume: exit status $?"
    grep -q "resuming .* 3 of 8 points finished" "$dir/resume.out" || fail "the resume does not say 3 of 8 finished"
    diff <(table "$ref") <(table "$out") || fail "the resumed table differs from an uninterrupted run's"
    # none twice: the journal has each point once (3 before the stop + 5 after)
    [ "$(tail -n +3 "$out/finished.csv" | cut -d, -f1 | sort -n | uniq -d | wc -l)" = 0 ] || fail "a point ran twice"
    [ "$(tail -n +3 "$out/finished.csv" | wc -l)" = 8 ] || fail "finished.csv has not 8 rows"
    # a finished sweep run again runs nothing and writes the same table
    "$cli" sweep "$spec" --out-dir "$out" --no-plot >/dev/null || fail "rerun of a finished sweep: exit status $?"
    [ "$(tail -n +3 "$out/finished.csv" | wc -l)" = 8 ] || fail "a rerun of a finished sweep ran points again"
    # another spec in the same directory: refused, the difference named; --restart starts over
    other=$dir/other_spec.toml
    sed 's/values = \[0.3, 0.5\]/values = [0.3, 0.4]/' "$spec" | sed "s|\"rig_small.toml\"|\"$src/sweep/rig_small.toml\"|" > "$other"
    "$cli" sweep "$other" --out-dir "$out" --no-plot 2>"$dir/other.err"
    rc=$?
    [ $rc = 2 ] || fail "another spec in the directory: exit status $rc, expected 2"
    grep -q 'axes\[2\] (interfaces\[\*\].friction_coefficient) had values \["0.3","0.5"\]' "$dir/other.err" ||
        fail "the refusal does not name the difference: $(cat "$dir/other.err")"
    "$cli" sweep "$other" --out-dir "$out" --no-plot --restart --jobs 2 >/dev/null || fail "--restart: exit status $?"
    [ "$(tail -n +3 "$out/finished.csv" | wc -l)" = 8 ] || fail "--restart did not start over"
    # SIGINT: stops cleanly (130), the points finished so far kept, advice given
    slow=$src/sweep/slow_map.toml
    rm -rf "$dir/sigint" "$dir/sigint_ref"
    "$cli" sweep "$slow" --out-dir "$dir/sigint" --jobs 2 --no-plot 2>"$dir/sigint.err" &
    pid=$!
    for ((k = 0; k < 2400; ++k)); do  # until a first row is on disk (at most 120 s)
        [ -f "$dir/sigint/finished.csv" ] && [ "$(wc -l < "$dir/sigint/finished.csv")" -ge 3 ] && break
        sleep 0.05
    done
    kill -s INT $pid
    wait $pid
    rc=$?
    if [ $rc = 0 ]; then
        echo "note: the sweep finished before SIGINT reached it"
    else
        [ $rc = 130 ] || fail "SIGINT: exit status $rc, expected 130"
        grep -q "run the same command again to resume" "$dir/sigint.err" || fail "SIGINT: no resume advice"
        done=$(($(wc -l < "$dir/sigint/finished.csv") - 2))
        [ $done -lt 40 ] || fail "SIGINT: every point finished, yet the exit status is $rc"
        "$cli" sweep "$slow" --out-dir "$dir/sigint" --no-plot >/dev/null || fail "resume after SIGINT: exit status $?"
        [ "$(tail -n +3 "$dir/sigint/finished.csv" | cut -d, -f1 | sort -n | uniq -d | wc -l)" = 0 ] ||
            fail "a point ran twice after SIGINT"
        "$cli" sweep "$slow" --out-dir "$dir/sigint_ref" --no-plot >/dev/null || fail "reference of the slow map: exit status $?"
        diff <(table "$dir/sigint_ref") <(table "$dir/sigint") || fail "the table resumed after SIGINT differs"
        echo "SIGINT after $done of 40 points; resumed to the full table"
    fi
    echo "resume: the full table, no point twice"
    ;;
failed)
    # a failed point does not stop the sweep: its row says failed with the message, exit status 3
    out=$dir/failed
    rm -rf "$out"
    "$cli" sweep "$src/sweep/some_fail.toml" --out-dir "$out" --jobs 2 --no-plot 2>"$dir/failed.err"
    rc=$?
    [ $rc = 3 ] || fail "a failed point: exit status $rc, expected 3"
    grep -q "1 of 2 points failed" "$dir/failed.err" || fail "stderr does not say 1 of 2 points failed"
    grep -q '^0,paper,failed,"solver failure at step 1 ' "$out/points.csv" || fail "point 0's row does not say failed"
    grep -q '^1,exact,ok,' "$out/points.csv" || fail "point 1 did not run to the end"
    grep -q '"failed": 1' "$out/sweep.json" || fail "sweep.json does not count 1 failed"
    echo "one point failed, the other ran"
    ;;
owner)
    # two sweeps on one directory: the second is refused (exit 2) naming the holder, with or
    # without --restart, and the holder's results are untouched
    slow=$src/sweep/slow_map.toml out=$dir/owner
    rm -rf "$out" "$dir/owner_ref"
    "$cli" sweep "$slow" --out-dir "$out" --jobs 1 --no-plot >/dev/null 2>&1 &
    pid=$!
    for ((k = 0; k < 2400; ++k)); do  # until the holder has written its name and a first row
        [ -f "$out/finished.csv" ] && [ "$(wc -l < "$out/finished.csv")" -ge 3 ] && break
        sleep 0.05
    done
    for restart in "" --restart; do
        "$cli" sweep "$spec" --out-dir "$out" --no-plot $restart 2>"$dir/owner.err"
        rc=$?
        [ $rc = 2 ] || fail "a second sweep ${restart:+($restart) }on a directory in use: exit status $rc, expected 2"
        grep -q "is in use by another sweep (pid $pid on .*, spec $slow)" "$dir/owner.err" ||
            fail "the refusal does not name the holder: $(cat "$dir/owner.err")"
    done
    grep -q "^# stackbeam sweep journal: spec [0-9a-f]\{16\} ($slow)" "$out/finished.csv" ||
        fail "the holder's journal was touched: $(head -1 "$out/finished.csv")"
    # the lock dies with its holder, even by SIGKILL: the same command resumes
    kill -s KILL $pid
    wait $pid 2>/dev/null
    "$cli" sweep "$slow" --out-dir "$out" --jobs 2 --no-plot >"$dir/owner.out" 2>&1 || fail "resume after kill -9: exit status $?"
    "$cli" sweep "$slow" --out-dir "$dir/owner_ref" --jobs 2 --no-plot >/dev/null || fail "reference: exit status $?"
    diff <(table "$dir/owner_ref") <(table "$out") || fail "the table resumed after kill -9 differs"
    # inputs refused at once by name: a FIFO (no writer: reading it would block for ever), a directory as --out
    rm -f "$dir/fifo.toml"
    mkfifo "$dir/fifo.toml" || fail "mkfifo"
    "$cli" simulate --scenario "$dir/fifo.toml" --out "$dir/fifo.csv" 2>"$dir/fifo.err"
    rc=$?
    [ $rc = 2 ] || fail "a FIFO as scenario: exit status $rc, expected 2"
    grep -q "is a FIFO (named pipe): a regular file is required" "$dir/fifo.err" || fail "FIFO: $(cat "$dir/fifo.err")"
    "$cli" simulate --scenario "$src/sweep/rig_small.toml" --out "$dir" 2>"$dir/outdir.err"
    rc=$?
    [ $rc = 2 ] || fail "--out DIR: exit status $rc, expected 2"
    grep -q -- "--out: value '$dir' is a directory: give a file name" "$dir/outdir.err" || fail "--out DIR: $(cat "$dir/outdir.err")"
    [ ! -e "$dir.partial" ] || fail "--out DIR left $dir.partial (the run started)"
    echo "one owner per directory; resumed after kill -9; a FIFO and --out DIR refused"
    ;;
*) fail "unknown test '$what'" ;;
esac
