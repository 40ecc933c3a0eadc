#!/bin/sh
# SPDX-License-Identifier: MIT
# dynaqpc-fw checks every argument before it touches the flash: a --cricket-tty that is no serial
# line exits 2 and leaves the --flash image as it was (the boot used to append its journal entry
# first). Usage: run_args_first.sh BIN_DIR
set -eu
BIN=$1
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
head -c 524288 /dev/zero | tr '\000' '\377' > "$TMP/fw.flash"  # 4 x 128 KB, erased
cp "$TMP/fw.flash" "$TMP/before.flash"
rc=0
"$BIN/dynaqpc-fw" --scenario paper-lab --flash "$TMP/fw.flash" --cricket-tty /dev/null > "$TMP/out" 2>&1 || rc=$?
cat "$TMP/out"
[ "$rc" -eq 2 ] || { echo "FAIL: exit $rc, not 2"; exit 1; }
grep -q -- "--cricket-tty: cannot open /dev/null as a serial line" "$TMP/out" || { echo "FAIL: no message"; exit 1; }
cmp -s "$TMP/fw.flash" "$TMP/before.flash" || { echo "FAIL: the flash image changed"; exit 1; }
echo PASS
