#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# A fuzz campaign: each target in turn (one at a time, at the lowest CPU priority), for a number
# of executions or seconds, over a scratch copy of its committed corpus. Prints one line per
# target: executions, coverage (edges, features), corpus size, seconds, and crashes/timeouts
# (inputs libFuzzer saved under build/fuzz/artifacts/). Exit 1 if any target failed.
#
#   tests/fuzz/campaign.sh [-r RUNS | -t SECONDS] [-T INPUT_SECONDS] [target...]
#       default: -r 10000000, -T 1 (an input slower than that is a failure), all targets
#
# Build first: cmake --preset fuzz && cmake --build --preset fuzz. A crash input found becomes a
# regression test by copying it into tests/fuzz/corpus/<target>/ (docs/fuzzing.md).
set -uo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
bin=$root/build/fuzz/bin
limit=(-runs=10000000)
per_input=1
while getopts "r:t:T:" opt; do
    case $opt in
    r) limit=(-runs="$OPTARG") ;;
    t) limit=(-max_total_time="$OPTARG") ;;
    T) per_input=$OPTARG ;;
    *) echo "usage: $0 [-r RUNS | -t SECONDS] [-T INPUT_SECONDS] [target...]" >&2; exit 2 ;;
    esac
done
shift $((OPTIND - 1))
targets=("$@")
[ ${#targets[@]} -gt 0 ] || targets=(maze scenario cricket vcan store firmware frames)
for t in "${targets[@]}"; do
    if [ ! -x "$bin/fuzz_$t" ]; then
        echo "$bin/fuzz_$t: not built (cmake --preset fuzz && cmake --build --preset fuzz)" >&2
        exit 2
    fi
done
mkdir -p "$root/build/fuzz/artifacts"
status=0
printf '%-9s %12s %8s %8s %7s %8s %s\n' target executions cov ft corpus seconds result
for t in "${targets[@]}"; do
    work=$root/build/fuzz/campaign/$t
    mkdir -p "$work"
    log=$root/build/fuzz/campaign/$t.log
    start=$(date +%s)
    nice -n 19 "$bin/fuzz_$t" "${limit[@]}" -timeout="$per_input" -rss_limit_mb=2048 -print_final_stats=1 \
        -artifact_prefix="$root/build/fuzz/artifacts/$t-" "$work" "$root/tests/fuzz/corpus/$t" \
        > "$log" 2>&1
    rc=$?
    secs=$(($(date +%s) - start))
    execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -n 1)
    last=$(grep -E '^#[0-9]+' "$log" | tail -n 1)
    cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$last")
    ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$last")
    corp=$(sed -n 's/.* corp: \([0-9]*\).*/\1/p' <<<"$last")
    result=ok
    if [ $rc -ne 0 ]; then
        result="FAILED (exit $rc): see $log"
        status=1
    fi
    printf '%-9s %12s %8s %8s %7s %8s %s\n' "$t" "${execs:-?}" "${cov:-?}" "${ft:-?}" "${corp:-?}" "$secs" "$result"
done
exit $status
