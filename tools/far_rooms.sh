#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# Writes the committed far-goal room sets (docs/scenarios.md, "Far-goal rooms"): far-tune (seed
# 3000) and far-eval (seed 4000), 12 rooms per robot each on floors the firmware accepts today,
# and far-large-tune / far-large-eval (paper-sim on 16 x 16 m). Regenerate them only on purpose
# (a generator change), then measure again everything measured on them: unit.world_rooms fails
# while a committed room differs from what its command writes.
#
#   tools/far_rooms.sh [ROOMS_DIR]     (default: host_sim/rooms of this tree; needs host-release)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
sim=$root/build/host-release/bin/dynaqpc-sim
out=${1:-$root/host_sim/rooms}
for set in "3000 far-tune" "4000 far-eval"; do
    read -r seed dir <<<"$set"
    for floor in 4.3x3.2 8.6x3.2 8.6x1.6; do
        "$sim" rooms --robot paper-lab --far mixed --floor "$floor" --seed "$seed" --count 4 --out "$out/$dir"
    done
    "$sim" rooms --robot paper-sim --far mixed --floor 8x8 --seed "$seed" --count 8 --out "$out/$dir"
    "$sim" rooms --robot paper-sim --far mixed --floor 16x4 --seed "$seed" --count 4 --out "$out/$dir"
done
"$sim" rooms --robot paper-sim --far mixed --floor 16x16 --seed 3000 --count 4 --out "$out/far-large-tune"
"$sim" rooms --robot paper-sim --far mixed --floor 16x16 --seed 4000 --count 4 --out "$out/far-large-eval"
