#!/bin/sh
# SPDX-License-Identifier: MIT
# Runs a command inside a private network namespace with multicast routed over loopback, so bus
# tests neither see nor disturb the host's bus (other engineers' simulators on port 43113).
# Needs root (or user namespaces); otherwise runs the command on the host's network, where the
# bus also works (TTL 0 keeps frames on the host) and says so.
if unshare -n true 2>/dev/null; then
    exec unshare -n sh -c 'ip link set lo up && ip route add 224.0.0.0/4 dev lo && exec "$@"' netns "$@"
fi
echo "netns.sh: cannot create a network namespace here; running on the host's network" >&2
exec "$@"
