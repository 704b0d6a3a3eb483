#!/usr/bin/env bash
# Interruption of `stackbeam simulate` (apps/cli/run.hpp): a long run is stopped by a
# signal once its first rows are on disk; the files must end on whole rows and the
# summary must say the run was interrupted.
#   cli_interrupt_test.sh <stackbeam> <INT|TERM> <expected exit status> <work dir>
# No wall-clock threshold: the script waits for rows to appear (a 120 s guard only
# stops a hung run).
set -u
cli=$1 sig=$2 expect_rc=$3 dir=$4
mkdir -p "$dir"
csv=$dir/interrupt_$sig.csv pairs=$dir/interrupt_${sig}_pairs.csv json=$dir/interrupt_$sig.json
rm -f "$csv" "$csv.partial" "$pairs" "$pairs.partial" "$json"
fail() { echo "FAIL: $*"; exit 1; }

# 100 s of the friction case at dt = 1e-3 s: 1e5 steps, far longer than the wait below.
"$cli" simulate --case friction --t-end 100 --quiet --out "$csv" --pairs "$pairs" --summary "$json" &
pid=$!
for ((i = 0; i < 2400; ++i)); do  # until 3 records (header + 3 lines) are on disk, at most 120 s
    [ -f "$csv.partial" ] && [ "$(wc -l < "$csv.partial")" -ge 4 ] && break
    kill -0 $pid 2>/dev/null || fail "the run ended before it was interrupted"
    sleep 0.05
done
kill -s "$sig" $pid
wait $pid
rc=$?
echo "exit status $rc (expected $expect_rc)"
[ "$rc" = "$expect_rc" ] || fail "exit status $rc, expected $expect_rc"
[ -f "$csv" ] && fail "$csv exists: an interrupted run must keep the .partial name"
[ -f "$csv.partial" ] || fail "$csv.partial is missing"
[ -f "$pairs.partial" ] || fail "$pairs.partial is missing"
[ -f "$json" ] || fail "the summary $json is missing"

# Every line of a CSV has the header's number of fields, and the file ends with a newline.
whole_rows() {
    local f=$1
    [ "$(tail -c 1 "$f" | od -An -c | tr -d ' ')" = '\n' ] || fail "$f does not end with a newline"
    awk -F, 'NR == 1 { n = NF } NF != n { print FILENAME ": line " NR " has " NF " fields, the header " n; bad = 1 }
             END { exit bad }' "$f" || fail "$f has a torn row"
}
whole_rows "$csv.partial"
whole_rows "$pairs.partial"
records=$(($(wc -l < "$csv.partial") - 1))
[ "$records" -ge 3 ] || fail "$csv.partial has $records records"
# The pairs file holds the same records: its last time is the CSV's last time (the two
# files print t with different digits: equal to 1e-12 s, far below dt = 1e-3 s).
last_t=$(tail -n 1 "$csv.partial" | cut -d, -f1)
last_pair_t=$(tail -n 1 "$pairs.partial" | cut -d, -f1)
awk -v a="$last_t" -v b="$last_pair_t" 'BEGIN { d = a - b; exit !(d < 1e-12 && d > -1e-12) }' ||
    fail "the CSV ends at t = $last_t, the pairs at t = $last_pair_t"
# ... and every pair of that last record.
per_record=$(awk -F, 'NR == 2 { t = $1 } NR > 1 && $1 == t { n++ } END { print n }' "$pairs.partial")
in_last=$(awk -F, -v t="$last_pair_t" 'NR > 1 && $1 == t { n++ } END { print n }' "$pairs.partial")
[ "$per_record" = "$in_last" ] || fail "the last record has $in_last pairs in $pairs.partial, the first $per_record"

grep -q '"interrupted": true' "$json" || fail "$json does not say \"interrupted\": true"
grep -q "\"records\": $records," "$json" || fail "$json does not count the $records records of the CSV"
grep -q '"csv": ".*\.partial"' "$json" || fail "$json does not name the .partial file"
echo "OK: $records whole records, summary marked interrupted"
