#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# dynaqpc developer entry point: sets up a fresh Debian 12 machine, builds, and runs.
#
#   tools/dev.sh demo    set up, build, train the firmware on the simulated lab robot, show what it learned
#   tools/dev.sh test    set up, build, and run every test (host, host-asan, cortex-m4, fuzz)
#   tools/dev.sh bench   set up, build optimised, print the agent's benchmark figures
#   tools/dev.sh fuzz    set up, build the fuzz targets, run a campaign (tests/fuzz/campaign.sh args)
#   tools/dev.sh docs-check  set up, build optimised, re-run the cheap figures README and docs/results/
#                        quote and fail when one drifted (a few minutes)
#   tools/dev.sh setup   only install what is missing
set -euo pipefail

root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"

apt_packages=(
    cmake ninja-build gcc g++ make
    libcmocka-dev libbox2d-dev
    gcc-arm-none-eabi libnewlib-arm-none-eabi binutils-arm-none-eabi qemu-system-arm
    valgrind python3 python3-venv iproute2 util-linux
    clang libclang-rt-14-dev
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
        # The tools' own package (console scripts dynaqpc-operator, -monitor, -viewer, -cricket,
        # -experiment, -learned), again whenever tools/pyproject.toml changed (a new console script).
        if ! .venv/bin/python -c "import dynaqpc_tools" 2>/dev/null || ! cmp -s tools/pyproject.toml .venv/.pyproject.toml; then
            .venv/bin/pip install -q --disable-pip-version-check --no-deps -e tools
            cp tools/pyproject.toml .venv/.pyproject.toml
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
    local bin=build/host-release/bin out=results/paper-lab
    # The long run and its replay go beside the experiment's CSVs, not among them: the experiment
    # reads every training CSV in $out as one agent's runs.
    local long=$out/demo
    mkdir -p "$long"
    log "paper-lab, the paper's lab robot simulated: the firmware learns with Q-learning, Dyna-Q and Dyna-QPC (5 sets x 20 episodes each); Table 1 at the end"
    # The paper's protocol, N = 5 planning updates after each step (the firmware ships idle-time
    # planning; `--planning 5,0` would compare both).
    .venv/bin/dynaqpc-experiment run --scenario paper-lab --sim "$bin/dynaqpc-sim" --results results --jobs 2 \
        --planning 5 --learned-steps 50
    log "Dyna-QPC, 150 episodes; what it learned is saved in its flash image $long/dyna-qpc.flash"
    "$bin/dynaqpc-sim" train --scenario paper-lab --agent dyna-qpc --sets 1 --episodes 150 --seed 7 \
        --save "$long/dyna-qpc.flash" --csv "$long/dyna-qpc-150.csv" --counters
    log "the firmware reboots with that flash and drives greedily, without learning, from 10 random starts"
    "$bin/dynaqpc-sim" run --scenario paper-lab --load "$long/dyna-qpc.flash" --starts 10 \
        --trajectory "$long/trajectory.csv" --arena "$long/arena.json" > "$long/replay.csv"
    .venv/bin/dynaqpc-experiment trajectory --scenario paper-lab --sim "$bin/dynaqpc-sim" --results results \
        --load "$long/dyna-qpc.flash" --starts 5 >/dev/null
    log "what it learned, read from its flash image: per heading, the greedy action over V = max_a Q"
    .venv/bin/dynaqpc-learned "$long/dyna-qpc.flash" --scenario paper-lab --sim "$bin/dynaqpc-sim" \
        --png "$long/learned.png" --json "$long/learned.json"
    log "plots and CSVs are in $out/ (table1.md: Table 1, printed above; fig13.png: learning curves; trajectories.png: the replayed paths; demo/: the long run)"
    log "what the robot learned: $long/learned.png (the greedy action per heading over V; docs/tools.md, dynaqpc-learned)"
}

run_tests() {
    setup
    # The style check's verdict comes last, so that a formatting slip does not hide the tests.
    log "style: ruff (tools/), clang-format (tools/clang-format-files.txt)"
    local style=0
    tools/check_style.sh || style=1
    build host
    ctest --preset host
    build host-asan
    ctest --preset host-asan
    build cortex-m4
    ctest --preset cortex-m4
    build fuzz
    ctest --preset fuzz
    if [ "$style" -ne 0 ]; then
        log "style: FAILED (above); fix with: .venv/bin/ruff check --fix tools && .venv/bin/ruff format tools"
        return 1
    fi
}

fuzz() {
    setup
    build fuzz
    tests/fuzz/campaign.sh "$@"
}

bench() {
    setup
    build host-release
    build/host-release/bin/dynaqpc-bench
}

docs_check() {
    setup
    build host-release
    .venv/bin/python tools/docs_check.py "$@"
}

case "${1:-}" in
setup) setup ;;
demo) demo ;;
test) run_tests ;;
bench) bench ;;
fuzz) shift; fuzz "$@" ;;
docs-check) shift; docs_check "$@" ;;
*)
    sed -n '3,12p' "$0"
    exit 2
    ;;
esac
