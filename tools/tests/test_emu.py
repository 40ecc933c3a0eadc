# SPDX-License-Identifier: MIT
"""dynaqpc-emu without QEMU: the board's report lines and the command line."""
from dynaqpc_tools import emu


def test_report_lines_parse():
    line = ("report: t_ms=2000 episodes=0 real_steps=3 planning_updates=8 idle_loop_updates=0 "
            "control_runs=11 control_worst_run_us=3115 misses=0 stack_unused=2460 ")
    r = emu.parse_report(line)
    assert r["real_steps"] == 3 and r["planning_updates"] == 8 and r["stack_unused"] == 2460
    assert emu.parse_report("final: t_ms=5 misses=1")["misses"] == 1
    assert emu.parse_report("netduinoplus2: paper-lab firmware running; step_cap=200") is None


def test_qemu_names_its_pty():
    m = emu.PTY_RE.search("char device redirected to /dev/pts/7 (label serial0)")
    assert m.group(1) == "/dev/pts/7" and m.group(2) == "serial0"


def test_run_options():
    args = emu.build_parser().parse_args(["run", "--agent", "dyna-q", "--icount", "3", "--speed", "8",
                                          "--min-idle-loop-updates", "5", "--no-persist"])
    assert args.agent == "dyna-q" and args.icount == 3 and args.speed == 8
    assert args.min_idle_loop_updates == 5 and args.no_persist
    assert emu.AGENTS.index("dyna-qpc") == 2  # agent_kind_t's AGENT_DYNA_QPC


def test_the_board_gets_the_devices_seed():
    """`run --set K` hands the board the seed the devices print: that of train's set K."""
    import subprocess
    from conftest import c_binary, in_netns
    sim = c_binary("dynaqpc-sim")
    if not sim.exists():
        import pytest
        pytest.skip(f"{sim} not built")
    seeds = []
    for k in ("1", "2", "2"):
        out = subprocess.run(in_netns([str(sim), "devices", "--scenario", "paper-lab", "--seed", "1", "--set", k,
                                       "--wait-firmware", "--duration", "0.2"]),
                             capture_output=True, text=True, timeout=30).stdout
        m = emu.SEED_RE.search(out)
        assert m, out
        seeds.append(int(m.group(1)))
    assert seeds[0] != seeds[1] and seeds[1] == seeds[2] and seeds[0] != 1
    args = emu.build_parser().parse_args(["run", "--seed", "1", "--set", "2"])
    assert args.set == 2 and args.seed == 1
