#!/bin/sh
# SPDX-License-Identifier: MIT
# The soak's short version (tools/soak.sh, docs/reliability.md): 30 s of wall time at 10x with one
# power cut, two 1 s stalls, 50 garbage datagrams/s and 50 random frames/s. Passes when the run
# printed its row, the cut's boot restored the flash's record, and some episode ran.
# Usage: run_soak_short.sh BIN_DIR REPO. Exit 77 (skipped) without the venv or a namespace.
BIN=$1
REPO=$2
out=$("$REPO/tools/soak.sh" --bin "$BIN" --seconds 30 --only all --cuts 1 --stalls 2 --garbage 50 --frames 50)
rc=$?
echo "$out"
[ $rc -eq 77 ] && exit 77
[ $rc -eq 0 ] || { echo "FAIL: soak.sh exited with $rc"; exit 1; }
row=$(echo "$out" | grep '^| all |') || { echo "FAIL: no row"; exit 1; }
episodes=$(echo "$row" | awk -F'|' '{gsub(/ /, "", $3); print $3}')
restored=$(echo "$row" | awk -F'|' '{gsub(/ /, "", $9); print $9}')
[ "$restored" = "1/1" ] || { echo "FAIL: the cut's boot restored $restored"; exit 1; }
[ "${episodes:-0}" -ge 1 ] || { echo "FAIL: no episode"; exit 1; }
echo "PASS"
