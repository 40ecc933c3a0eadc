# SPDX-License-Identifier: MIT
"""dynaqpc-emu without QEMU: the board's report lines and the command line."""

from dynaqpc_tools import agents, emu


def test_report_lines_parse():
    line = (
        "report: t_ms=2000 episodes=0 real_steps=3 planning_updates=8 idle_loop_updates=0 "
        "control_runs=11 control_worst_run_us=3115 misses=0 stack_unused=2460 "
    )
    r = emu.parse_report(line)
    assert r["real_steps"] == 3 and r["planning_updates"] == 8 and r["stack_unused"] == 2460
    assert emu.parse_report("final: t_ms=5 misses=1")["misses"] == 1
    assert emu.parse_report("netduinoplus2: paper-lab firmware running; step_cap=200") is None


def test_qemu_names_its_pty():
    m = emu.PTY_RE.search("char device redirected to /dev/pts/7 (label serial0)")
    assert m.group(1) == "/dev/pts/7" and m.group(2) == "serial0"


def test_run_options():
    args = emu.build_parser().parse_args(
        ["run", "--agent", "dyna-q", "--icount", "3", "--speed", "8", "--min-idle-loop-updates", "5", "--no-persist"]
    )
    assert args.agent == "dyna-q" and args.icount == 3 and args.speed == 8
    assert args.min_idle_loop_updates == 5 and args.no_persist
    assert agents.number("dyna-qpc") == 2  # agent_kind_t's AGENT_DYNA_QPC


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
        out = subprocess.run(
            in_netns(
                [
                    str(sim),
                    "devices",
                    "--scenario",
                    "paper-lab",
                    "--seed",
                    "1",
                    "--set",
                    k,
                    "--wait-firmware",
                    "--duration",
                    "0.2",
                ]
            ),
            capture_output=True,
            text=True,
            timeout=30,
        ).stdout
        m = emu.SEED_RE.search(out)
        assert m, out
        seeds.append(int(m.group(1)))
    assert seeds[0] != seeds[1] and seeds[1] == seeds[2] and seeds[0] != 1
    args = emu.build_parser().parse_args(["run", "--seed", "1", "--set", "2"])
    assert args.set == 2 and args.seed == 1
    assert args.scenario == "paper-lab"
    real = emu.build_parser().parse_args(["run", "--scenario", "paper-lab-real"])
    assert real.scenario == "paper-lab-real"


class _FakeLines:
    def __init__(self, lines, times):
        self.lines, self.times = lines, times


def test_the_emulated_clock_against_the_host():
    board = _FakeLines(
        ["netduinoplus2: running", "report: t_ms=2000", "report: t_ms=4000", "report: t_ms=6000"],
        [0.0, 10.0, 14.0, 18.0],
    )
    assert emu.emulated_rate(board) == 0.5  # 4 s of firmware time in 8 s of wall
    assert emu.emulated_rate(_FakeLines(["report: t_ms=2000"], [1.0])) is None


def test_falling_behind_is_the_host_and_a_speed_is_suggested():
    # -icount: the board's clock ran 3.1 s a wall second where 8 were asked for.
    msg = emu.behind(8, 3.1, 0.5, 0)
    assert "fell behind" in msg and "3.10 s per wall second, not the 8" in msg and "try --speed 2" in msg
    # No -icount: the board's clock keeps the wall, but the host woke us 30 ms late with misses.
    msg = emu.behind(8, 8.0, 30.0, 188)
    assert "up to 30 ms late" in msg and "188 deadline misses follow from that" in msg
    assert "quieter host" in msg and "the host, not the firmware" in msg
    msg = emu.behind(8, 8.0, 4.0, 12)  # 4 ms late: too late at 8 (2.4 ms), fine at 4 (4.8 ms)
    assert "try --speed 4" in msg
    # On time: nothing to say, and misses stay the firmware's.
    assert emu.behind(1, 1.0, 2.0, 0) is None and emu.behind(8, 7.9, 1.0, 3) is None
    assert all(168 % s == 0 for s in emu.speeds()) and emu.speeds()[:4] == [1, 2, 3, 4]


def test_the_summary_says_goals_and_idle_planning(capsys):
    class Watch:
        frames, sched, sched_planning, plan_updates, deadline_misses, status = 10, 5, 3, 40, 0, 2
        idle_percent = [99.0]
        episodes = [{"Episode": 1, "Steps": 30, "ReachedGoal": 0}, {"Episode": 2, "Steps": 14, "ReachedGoal": 1}]

    class Bridge:
        to_bus, to_board, errors = 100, 100, 0

    args = emu.build_parser().parse_args(["run", "--min-goals", "1", "--min-idle-loop-updates", "1"])
    board = _FakeLines(
        [
            "report: t_ms=1000 real_steps=44 planning_updates=900 idle_loop_updates=600 misses=0",
            "final: t_ms=9000 real_steps=44 planning_updates=900 idle_loop_updates=600 misses=0",
        ],
        [1.0, 9.0],
    )
    assert emu.summarise(args, board, 0, Watch(), Bridge()) == 0
    out = capsys.readouterr().out
    assert "reached the goal in 1 of 2 episodes" in out and "600 updates in its idle loop (13.6 per real step)" in out
    assert "emu: PASS" in out and "fell behind" not in out
    args = emu.build_parser().parse_args(["run", "--min-goals", "2"])
    assert emu.summarise(args, board, 0, Watch(), Bridge()) == 1
    assert "the goal reached in 1 episodes, expected at least 2" in capsys.readouterr().out


def test_a_slow_clock_without_misses_is_reported_not_failed(capsys):
    class Watch:
        frames, sched, sched_planning, plan_updates, deadline_misses, status = 10, 5, 3, 40, 0, 2
        idle_percent = [99.0]
        episodes = [{"Episode": 1, "Steps": 6, "ReachedGoal": 0}]

    class Bridge:
        to_bus, to_board, errors = 100, 100, 0

    args = emu.build_parser().parse_args(["run", "--icount", "3"])
    board = _FakeLines(
        [
            "report: t_ms=2000 real_steps=6 planning_updates=90 idle_loop_updates=0 misses=0",
            "report: t_ms=6000 real_steps=6 planning_updates=90 idle_loop_updates=0 misses=0",
        ],
        [1.0, 9.0],
    )  # 4 s of firmware time in 8 s of wall
    assert emu.summarise(args, board, 0, Watch(), Bridge()) == 0
    out = capsys.readouterr().out
    assert "fell behind" in out and "emu: PASS" in out
    Watch.deadline_misses = 7
    assert emu.summarise(args, board, 0, Watch(), Bridge()) == 1
    assert "FAIL: deadline misses: bus 7, board 0 — the emulation fell behind" in capsys.readouterr().out
