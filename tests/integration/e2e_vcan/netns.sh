# SPDX-License-Identifier: MIT
# Sourced by the e2e scripts once they run inside their private network namespace: loopback up
# with a multicast route (the virtual CAN bus stays inside the namespace), a scratch folder $TMP,
# the background processes in $PIDS killed and the folder removed on exit, and fail(), which
# prints the last lines of $TMP/<name>.out for every name in $LOGS and exits 1.
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
