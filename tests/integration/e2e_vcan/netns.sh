# SPDX-License-Identifier: MIT
# Sourced by the e2e scripts once they run inside their private network namespace: loopback up
# with a multicast route (the virtual CAN bus stays inside the namespace), a scratch folder $TMP,
# the background processes in $PIDS killed and the folder removed on exit, and fail(), which
# prints the last lines of $TMP/<name>.out for every name in $LOGS and exits 1, and
# cricket_tty_of(), which waits for `dynaqpc-sim devices` to name its Cricket pty.
ip link set lo up && ip route add 224.0.0.0/4 dev lo || { echo "FAIL: cannot route multicast over lo"; exit 1; }
TMP=$(mktemp -d) || exit 1
PIDS=""
cleanup() {
    for p in $PIDS; do kill "$p" 2>/dev/null; done
    for p in $PIDS; do wait "$p" 2>/dev/null; done
    rm -rf "$TMP"
}
trap cleanup EXIT
trap 'exit 1' INT TERM

fail() {
    echo "FAIL: $*"
    for f in $LOGS; do
        [ -f "$TMP/$f.out" ] && { echo "--- $f"; tail -n 20 "$TMP/$f.out"; }
    done
    exit 1
}

# cricket_tty_of <devices output file>: the pty `dynaqpc-sim devices` printed (cricket_tty=...),
# waiting up to 10 s for it.
cricket_tty_of() {
    local n=0
    until grep -q '^cricket_tty=' "$1" 2>/dev/null; do
        n=$((n + 1)); [ $n -gt 100 ] && fail "dynaqpc-sim devices printed no cricket_tty" >&2
        sleep 0.1
    done
    sed -n 's/^cricket_tty=//p' "$1" | head -n 1
}
