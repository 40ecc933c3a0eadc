#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# dynaqpc developer entry point: sets up a fresh Debian 12 machine, builds, and runs.
#
#   tools/dev.sh demo    set up, build, train the agents on the Dyna maze and show what they learned
#   tools/dev.sh test    set up, build, and run every test (host, host-asan, cortex-m4)
#   tools/dev.sh bench   set up, build optimised, print the agent's benchmark figures
#   tools/dev.sh setup   only install what is missing
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

apt_packages=(
    cmake ninja-build gcc g++ make
    libcmocka-dev libbox2d-dev
    gcc-arm-none-eabi libnewlib-arm-none-eabi binutils-arm-none-eabi qemu-system-arm
    valgrind python3 python3-venv iproute2 util-linux
)

log() { printf '\033[1m== %s\033[0m\n' "$*"; }

setup() {
    local missing=()
    for p in "${apt_packages[@]}"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
    done
    if ((${#missing[@]})); then
        log "installing: ${missing[*]}"
        local sudo=""
        [ "$(id -u)" -eq 0 ] || sudo="sudo"
        $sudo apt-get update -qq
        # --no-install-recommends: qemu's recommends pull in a whole desktop.
        DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
    fi
    if [ -f tools/requirements.txt ]; then
        if [ ! -x .venv/bin/python ]; then
            log "creating the Python venv in .venv"
            python3 -m venv .venv
        fi
        if ! cmp -s tools/requirements.txt .venv/.requirements.txt; then
            .venv/bin/pip install -q --disable-pip-version-check -r tools/requirements.txt
            cp tools/requirements.txt .venv/.requirements.txt
        fi
        # The tools' own package (console scripts dynaqpc-monitor, -viewer, -cricket, -experiment).
        if ! .venv/bin/python -c "import dynaqpc_tools" 2>/dev/null; then
            .venv/bin/pip install -q --disable-pip-version-check --no-deps -e tools
        fi
    fi
}

build() {  # build <preset>
    log "build $1"
    cmake --preset "$1" >/dev/null
    cmake --build --preset "$1"
}

demo() {
    setup
    build host-release
    local bin=build/host-release/bin
    mkdir -p results
    log "Dyna maze (Sutton & Barto Fig. 8.2), 30 runs x 50 episodes, N = 5 planning updates per step"
    for agent in q dyna-q dyna-qpc; do
        "$bin/dynaqpc-sim" maze --map dyna-maze --agent "$agent" --runs 30 --episodes 50 \
            --planning 5 --seed 1 --csv "results/dyna-maze-$agent.csv"
    done
    log "first episode whose mean over the 30 runs is <= 20 steps (optimal: 14; Sutton & Barto's Dyna-Q reference: 6)"
    for agent in q dyna-q dyna-qpc; do
        awk -F, -v agent="$agent" 'NR > 1 { sum[$3] += $4; n[$3]++ }
            END { for (e = 1; e in sum; e++) if (sum[e] / n[e] <= 20) { printf "  %-9s %d\n", agent, e; exit }
                  printf "  %-9s never\n", agent }' "results/dyna-maze-$agent.csv"
    done
    log "CSV files are in results/"
}

run_tests() {
    setup
    build host
    ctest --preset host
    build host-asan
    ctest --preset host-asan
    build cortex-m4
    ctest --preset cortex-m4
}

bench() {
    setup
    build host-release
    build/host-release/bin/dynaqpc-bench
}

case "${1:-}" in
setup) setup ;;
demo) demo ;;
test) run_tests ;;
bench) bench ;;
*)
    sed -n '3,9p' "$0"
    exit 2
    ;;
esac
