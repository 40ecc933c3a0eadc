# SPDX-License-Identifier: MIT
"""dynaqpc-experiment: aggregation and Table 1 from hand-made CSVs with known answers; PNGs."""

import json
import subprocess

import pytest
from conftest import c_binary

from dynaqpc_tools import experiment
from dynaqpc_tools.common import ToolError
from dynaqpc_tools.experiment import LearnSettings, runs

HEADER = "agent,set,episode,steps,reward,reached_goal,bumps,robot_time_s,updates,wall_s\n"
# Set 1 stays <= 1.5 x its final-10 mean (170 -> 255) from episode 5 on.
SET1 = [900, 800, 600, 300, 100, 100, 100, 100, 100, 100, 100, 100]
# Set 2: final-10 mean 241 -> threshold 361.5; the spike at episode 7 delays learning to 8.
SET2 = [1000, 1000, 500, 200, 150, 160, 900, 100, 100, 100, 100, 100]


def write_runs(path, agent, sets, robot_time=100.0):
    rows = [HEADER]
    for s, steps in enumerate(sets, 1):
        for e, n in enumerate(steps, 1):
            rows.append(f"{agent},{s},{e},{n},{-n},1,0,{robot_time},{10 * n},0.5\n")
    path.write_text("".join(rows))


@pytest.fixture
def csv_dir(tmp_path):
    write_runs(tmp_path / "q.csv", "q", [SET1, SET2])
    write_runs(
        tmp_path / "dyna-qpc.csv", "dyna-qpc", [[600, 400, 50, 50, 50, 50, 50, 50, 50, 50, 50, 50]] * 2, robot_time=36.0
    )
    return tmp_path


def test_learned_episode_index():
    assert experiment.learned_episode_index(SET1, 255) == 4
    assert experiment.learned_episode_index(SET2, 361.5) == 7
    assert experiment.learned_episode_index(SET2, 361.5, smooth=2) == 8  # (900+100)/2 > 361.5
    assert experiment.learned_episode_index([5, 5, 9], 6) is None
    assert experiment.trailing_mean([2, 4, 6, 8], 3) == [2, 3, 4, 6]


def test_relapses_after_learning():
    # Episodes 2-4 reach the goal within 50 steps: learned. After them: 90 (<= 2 x 50, not a
    # relapse), a miss, 101 steps, 20, a miss: 3 relapses of 5, the longest run 2.
    steps = [200, 50, 12, 30, 90, 200, 101, 20, 200]
    goal = [0, 1, 1, 1, 1, 0, 1, 1, 0]
    r = experiment.relapses_of_set(steps, goal, 50)
    assert (r.learned, r.after, r.relapses, r.longest_run) == (True, 5, 3, 2)
    # A short episode that missed the goal does not count towards learning.
    assert not experiment.relapses_of_set([40, 50, 50], [0, 1, 1], 50).learned


def test_table_reports_relapses(tmp_path):
    rows = [HEADER]
    for e, (n, g) in enumerate(zip([200, 50, 12, 30, 90, 200, 101, 20, 200], [0, 1, 1, 1, 1, 0, 1, 1, 0]), 1):
        rows.append(f"dyna-qpc,1,{e},{n},{-n},{g},0,10.0,{10 * n},0.5\n")
    (tmp_path / "dyna-qpc.csv").write_text("".join(rows))
    runs = experiment.read_csv_dir(str(tmp_path))
    s = experiment.summarise(runs[0], LearnSettings(learned_steps=50, smooth=1))
    assert s.relapse_text() == "3/5 (60.0 %) in 1 set, longest 2"
    table = experiment.table_markdown([s], LearnSettings(learned_steps=50, smooth=1), "paper-lab")
    assert "Relapses after learning" in table and "3/5 (60.0 %) in 1 set, longest 2" in table


def _by_agent(runs):
    return {r.agent: r for r in runs}


def test_table1_numbers(csv_dir):
    runs = _by_agent(experiment.read_csv_dir(str(csv_dir)))
    assert sorted(runs) == ["dyna-qpc", "q"]
    q = experiment.summarise(runs["q"], LearnSettings(smooth=1))
    assert [(r.learned, r.episodes) for r in q.sets] == [(True, 5), (True, 8)]
    # Real steps to learn: the steps of episodes 1..i.
    assert [r.steps for r in q.sets] == [2700, 4010]
    sm, ssd = q.steps_mean_sd
    assert sm == pytest.approx(3355) and ssd == pytest.approx(1310 / 2**0.5)
    hm, hsd = q.hours_mean_sd
    assert hm == pytest.approx(650 / 3600) and hsd == pytest.approx(150 * 2**0.5 / 3600)
    assert q.mean_steps_at == {10: 100.0, 50: None, 100: None, 200: None}
    # updates = 10 x steps: 9 planning updates per real step.
    assert q.planning_per_step == pytest.approx(9.0)
    assert q.s_per_step == pytest.approx(100.0 * 24 / (sum(SET1) + sum(SET2)))
    assert q.updates == 10 * (sum(SET1) + sum(SET2)) and q.wall_s == pytest.approx(12.0)
    # An absolute threshold.
    q150 = experiment.summarise(runs["q"], LearnSettings(learned_steps=150, smooth=1))
    assert [r.episodes for r in q150.sets] == [5, 8]
    # Never learned: every set counts its whole run, and the count says 0/2.
    q99 = experiment.summarise(runs["q"], LearnSettings(learned_steps=99, smooth=1))
    assert q99.n_learned == 0 and [r.steps for r in q99.sets] == [sum(SET1), sum(SET2)]
    assert q99.steps_mean_sd[0] == pytest.approx((sum(SET1) + sum(SET2)) / 2)

    dq = experiment.summarise(runs["dyna-qpc"], LearnSettings(smooth=1))
    assert [r.episodes for r in dq.sets] == [3, 3] and dq.sets[0].robot_time_s == pytest.approx(108)
    table = experiment.table_markdown([q, dq], LearnSettings(smooth=1), "paper-lab")
    rows = [ln for ln in table.splitlines() if ln.startswith("| ")]
    assert rows[0].count("|") == 12  # one column per measure: ep. 10 only (12 episodes), the paper's
    assert rows[1].startswith(
        "| Q-learning | none (Q-learning) | 9.0 | 2/2 | 3,355 ± 926 | 0.18 ± 0.06 | 6.5 ± 2.1 | 0.307 | – | 100.0 | – |"
    )
    assert rows[2].startswith(
        "| Dyna-QPC | not in the CSV (name it AGENT-pN.csv) | 9.0 | 2/2 | 1,050 ± 0 | 0.03 ± 0.00 | 3.0 ± 0.0 |"
    )
    assert rows[2].endswith("| 2,019 steps (1.12 h) |")
    assert "paper 0.192" in table


def test_the_threshold_is_explicit_and_short_runs_are_warned_about(tmp_path, capsys):
    # A Q-learning run stuck at the 200-step cap: relative to its own end it "learns" at once.
    write_runs(tmp_path / "q.csv", "q", [[200] * 8, [200] * 6 + [150, 150]])
    rc = experiment.main(["table", "--csv", str(tmp_path / "q.csv"), "--scenario", "paper-lab"])
    assert rc == 0
    cap = capsys.readouterr()
    assert "### Table 1: paper-lab (learned: trailing 5-episode mean <= 1.5 x the set's last-10 mean" in cap.out
    # The thresholds the relative rule gave, in steps, are in the caption: 1.5 x 200 and 1.5 x 187.5.
    assert "per set: Q-learning 281.2–300.0" in cap.out and "No absolute threshold was given" in cap.out
    assert "**Warning:** the runs have 8 episodes, no more than the final window of 10" in cap.out
    err = cap.err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("warning: Table 1: the runs have 8 episodes")
    # With --threshold: explicit in the title and the caption, and no warning.
    rc = experiment.main(["table", "--csv", str(tmp_path / "q.csv"), "--scenario", "paper-lab", "--threshold", "50"])
    cap = capsys.readouterr()
    assert rc == 0 and "(learned: trailing 5-episode mean <= 50 steps)" in cap.out
    assert "(threshold 50 steps for every set)" in cap.out and "| 0/2 |" in cap.out
    assert "Warning" not in cap.out and cap.err == ""
    # Fewer episodes than the smoothing window: warned about even with a threshold.
    write_runs(tmp_path / "short.csv", "q", [[200] * 3])
    experiment.main(["table", "--csv", str(tmp_path / "short.csv"), "--threshold", "50"])
    assert "fewer than the --smooth window of 5" in capsys.readouterr().err


def test_table_command_at_several_budgets(tmp_path, capsys):
    # The same agent at two budgets (named <agent>-p<N>.csv) is two rows, budget order, idle last.
    write_runs(tmp_path / "dyna-q-p0.csv", "dyna-q", [[60, 40, 40, 40, 40, 40]])
    write_runs(tmp_path / "dyna-q-p5.csv", "dyna-q", [[300, 200, 100, 60, 45, 40]])
    write_runs(tmp_path / "q.csv", "q", [[300, 300, 300, 300, 300, 300]])
    rc = experiment.main(
        [
            "table",
            "--csv",
            str(tmp_path / "dyna-q-p0.csv"),
            str(tmp_path / "dyna-q-p5.csv"),
            str(tmp_path / "q.csv"),
            "--threshold",
            "50",
            "--smooth",
            "2",
            "--out",
            str(tmp_path / "t.md"),
        ]
    )
    assert rc == 0
    rows = [ln for ln in capsys.readouterr().out.splitlines() if ln.startswith("| ")]
    assert [r.split(" | ")[:2] for r in rows[1:]] == [
        ["| Q-learning", "none (Q-learning)"],
        ["| Dyna-Q", "5"],
        ["| Dyna-Q", "idle time (MCU model)"],
    ]
    # q never learns: its whole run (1,800 steps), 0/1. N=5: (45+40)/2 <= 50 from episode 6 on; idle: (60+40)/2 from episode 2.
    assert "| 0/1 | 1,800 ± 0 |" in rows[1]
    assert "| 1/1 | 745 ± 0 |" in rows[2]
    assert "| 1/1 | 100 ± 0 |" in rows[3]
    assert (tmp_path / "t.md").read_text().count("| Dyna-Q |") == 2


def test_measure_is_the_reusable_entry(csv_dir):
    summaries, table = experiment.measure(
        [str(csv_dir / "q.csv"), str(csv_dir / "dyna-qpc.csv")], threshold=150, smooth=1, scenario="paper-sim"
    )
    assert [s.agent for s in summaries] == ["q", "dyna-qpc"]
    assert summaries[0].n_learned == 2
    assert "| 5.2 h (18,618 s) |" in table and "unable to learn" in table


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--smooth", "0"], "--smooth: 0 is outside"),
        (["--learned-factor", "-1"], "--learned-factor: -1 is outside"),
        (["--threshold", "nan"], "--threshold"),
        (["--final-window", "x"], "'x' is not an integer"),
    ],
)
def test_numeric_arguments_are_range_checked(csv_dir, capsys, argv, message):
    with pytest.raises(SystemExit) as e:
        experiment.main(["table", "--csv", str(csv_dir / "q.csv"), *argv])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--sets", "0"], "--sets: 0 is outside"),
        (["--jobs", "-5"], "--jobs: -5 is outside"),
        (["--planning", "5,-1"], "--planning"),
        (["--planning", "5,5"], "twice"),
        (["--agents", "q,sarsa"], "sarsa"),
        (["--starts", "0"], "--starts"),
    ],
)
def test_run_arguments_are_range_checked(tmp_path, capsys, argv, message):
    with pytest.raises(SystemExit) as e:
        experiment.main(["run", "--scenario", "paper-lab", "--results", str(tmp_path), *argv])
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


def test_user_errors_are_one_line_and_status_2(tmp_path, capsys, csv_dir):
    garbage = tmp_path / "garbage.csv"
    garbage.write_bytes(bytes(range(256)) * 4)
    assert experiment.main(["table", "--csv", str(garbage)]) == 2
    assert experiment.main(["table", "--csv", str(tmp_path / "missing.csv")]) == 2
    # An output folder that cannot be made (a file is in the way).
    (tmp_path / "file").write_text("x")
    assert experiment.main(["plot", "--csv-dir", str(csv_dir), "--out", str(tmp_path / "file" / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 3 and all(ln.startswith("error: ") for ln in err)
    assert "not UTF-8" in err[0] or "not a training CSV" in err[0]
    with pytest.raises(ToolError, match="cannot write"):
        experiment.plot_fig13(
            experiment.read_runs(str(csv_dir / "q.csv")).values(), str(tmp_path / "no" / "such" / "fig.png")
        )


def test_run_never_overwrites_a_file_that_is_not_a_training_csv(tmp_path):
    results = tmp_path / "results" / "paper-lab"
    results.mkdir(parents=True)
    (results / "q.csv").write_text("my notes, not a CSV of ours\n")
    rc = experiment.main(
        [
            "run",
            "--scenario",
            "paper-lab",
            "--results",
            str(tmp_path / "results"),
            "--agents",
            "q",
            "--sets",
            "1",
            "--episodes",
            "1",
            "--sim",
            "/bin/false",
        ]
    )
    assert rc == 2
    assert (results / "q.csv").read_text() == "my notes, not a CSV of ours\n"


def test_blocks_of_sets_give_the_rows_of_one_run(tmp_path):
    """The runner's process per set (--first-set K --sets 1), merged, is byte for byte what one
    `train --sets N` writes: the real simulator, both ways."""
    sim = c_binary("dynaqpc-sim")
    if not sim.is_file():
        pytest.skip(f"{sim} not built")
    whole = tmp_path / "whole.csv"
    subprocess.run(
        [
            str(sim),
            "train",
            "--scenario",
            "paper-lab",
            "--agent",
            "dyna-qpc",
            "--sets",
            "3",
            "--episodes",
            "2",
            "--seed",
            "3",
            "--no-wall-time",
            "--quiet",
            "--csv",
            str(whole),
        ],
        check=True,
    )
    merged = tmp_path / "merged.csv"
    experiment.run_sets(
        str(sim),
        "paper-lab",
        "dyna-qpc",
        str(merged),
        sets=3,
        episodes=2,
        seed=3,
        jobs=2,
        extra=["--no-wall-time"],
        progress=False,
    )
    assert merged.read_bytes() == whole.read_bytes()
    assert len(whole.read_text().splitlines()) == 7
    # With --planning the budget reaches the simulator: planning updates per step change.
    p1000 = tmp_path / "dyna-qpc-p1000.csv"
    experiment.run_sets(
        str(sim), "paper-lab", "dyna-qpc", str(p1000), sets=1, episodes=2, seed=3, planning=1000, progress=False
    )
    assert p1000.read_bytes() != whole.read_bytes()
    assert experiment.scenario_protocol("paper-lab") == (5, 20)


def test_bad_csvs_are_refused_with_the_line(tmp_path):
    p = tmp_path / "bad.csv"
    p.write_text("agent,set,episode,steps\nq,1,1,5\n")
    with pytest.raises(ToolError, match="columns"):
        experiment.read_runs(str(p))
    p.write_text(HEADER + "q,1,1,5,0,1,0,1.0,0,0\nq,1,2,five,0,1,0,1.0,0,0\n")
    with pytest.raises(ToolError, match="bad.csv:3"):
        experiment.read_runs(str(p))
    p.write_text(HEADER + "q,1,1,5,0,1,0,1.0,0,0\nq,1,1,5,0,1,0,1.0,0,0\n")
    with pytest.raises(ToolError, match="twice"):
        experiment.read_runs(str(p))
    p.write_text(HEADER + "q,1,1,5,0,1,0,1.0,0,0\nq,1,3,5,0,1,0,1.0,0,0\n")
    with pytest.raises(ToolError, match="in sequence"):
        experiment.read_runs(str(p))
    p.write_text(HEADER)
    with pytest.raises(ToolError, match="no rows"):
        experiment.read_runs(str(p))
    # The row's own field count (DictReader's len(row) said 10 for 4 fields, 11 for 12).
    for row, n in (("q,1,1,5", 4), ("q,1,1,5,0,1,0,1.0,0,0,7,8", 12), ("q,1,1,5,0,1,0,1.0,0", 9)):
        p.write_text(HEADER + "q,1,1,5,0,1,0,1.0,0,0\n" + row + "\n")
        with pytest.raises(ToolError, match=f"bad.csv:3: {n} fields, want 10$"):
            experiment.read_runs(str(p))
    p.write_text(HEADER + "q,1,1,5,0,2,0,1.0,0,0\n")
    with pytest.raises(ToolError, match="bad.csv:2: reached_goal 2, want 0 or 1"):
        experiment.read_runs(str(p))
    t = tmp_path / "traj.csv"
    t.write_text(",".join(runs.TRAJECTORY_COLUMNS) + "\n1,2,3\n")
    with pytest.raises(ToolError, match="traj.csv:2: 3 fields, want"):
        runs.read_trajectory(str(t))


def _is_png(path):
    return path.is_file() and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 5000


def test_plot_command_writes_fig13_table_and_trajectories(csv_dir, tmp_path, capsys):
    (csv_dir / "arena.json").write_text(
        json.dumps(
            {
                "width": 4.0,
                "height": 3.0,
                "obstacles": [
                    {"kind": "box", "cx": 2.0, "cy": 1.5, "w": 0.5, "h": 1.0, "angle_deg": 30},
                    {"kind": "circle", "cx": 1.0, "cy": 2.2, "r": 0.2},
                ],
                "goal": {"cx": 3.5, "cy": 2.5, "r": 0.3},
                "beacons": [{"id": "b1", "x": 0.0, "y": 0.0, "z": 2.5}],
            }
        )
    )
    rows = ["start,step,time_s,x,y,heading,action,reward,bump,in_goal\n"]
    for start in range(2):
        for step in range(20):
            x, y = 0.3 + 0.16 * step, 0.3 + start * 0.5 + 0.1 * step
            rows.append(
                f"{start},{step},{0.192 * step:.3f},{x:.3f},{y:.3f},0.5,1,-1,{int(step == 5)},{int(step == 19)}\n"
            )
    (csv_dir / "traj.csv").write_text("".join(rows))
    out = tmp_path / "out"
    assert experiment.main(["plot", "--csv-dir", str(csv_dir), "--out", str(out), "--smooth", "1"]) == 0
    assert _is_png(out / "fig13.png") and _is_png(out / "trajectories.png")
    table = (out / "table1.md").read_text()
    assert "| Q-learning | none (Q-learning) | 9.0 | 2/2 | 3,355 ± 926 | 0.18 ± 0.06 |" in table
    assert "Q-learning" in capsys.readouterr().out


def test_run_skip_existing_does_not_call_the_simulator(csv_dir, tmp_path):
    results = tmp_path / "results"
    (results / "s").mkdir(parents=True)
    for name in ("q.csv", "dyna-qpc.csv"):
        (results / "s" / name).write_bytes((csv_dir / name).read_bytes())
    rc = experiment.main(
        [
            "run",
            "--scenario",
            "s",
            "--results",
            str(results),
            "--agents",
            "q,dyna-qpc",
            "--skip-existing",
            "--sets",
            "2",
            "--episodes",
            "12",
            "--sim",
            str(tmp_path / "no-such-sim"),
        ]
    )
    assert rc == 0
    assert _is_png(results / "s" / "fig13.png")
    # Without --skip-existing the missing simulator is a clear error, not a traceback.
    rc = experiment.main(
        [
            "run",
            "--scenario",
            "s",
            "--results",
            str(results),
            "--agents",
            "q",
            "--sets",
            "2",
            "--episodes",
            "12",
            "--sim",
            str(tmp_path / "no-such-sim"),
        ]
    )
    assert rc == 2


def test_run_reads_only_its_own_csvs(csv_dir, tmp_path):
    # tools/dev.sh demo keeps a longer Dyna-QPC run beside the experiment's CSVs; a second
    # experiment run in the same folder must not mistake it for its own.
    results = tmp_path / "results"
    (results / "s").mkdir(parents=True)
    for name in ("q.csv", "dyna-qpc.csv"):
        (results / "s" / name).write_bytes((csv_dir / name).read_bytes())
    write_runs(results / "s" / "dyna-qpc-150.csv", "dyna-qpc", [[70] * 150])
    rc = experiment.main(
        [
            "run",
            "--scenario",
            "s",
            "--results",
            str(results),
            "--agents",
            "q,dyna-qpc",
            "--skip-existing",
            "--sets",
            "2",
            "--episodes",
            "12",
            "--sim",
            str(tmp_path / "no-such-sim"),
        ]
    )
    assert rc == 0
    table = (results / "s" / "table1.md").read_text()
    assert "| 2/2 | 1,250 ± 0 |" in table and table.count("| Dyna-QPC |") == 1


def test_arena_errors_are_named(tmp_path):
    from dynaqpc_tools.arena import load_arena

    p = tmp_path / "a.json"
    p.write_text('{"width": 4, "height": 3, "obstacles": [{"kind": "box", "cx": 1, "cy": 1, "w": -1, "h": 1}]}')
    with pytest.raises(ToolError, match=r"obstacles\[0\]\.w"):
        load_arena(str(p))
    p.write_text("{not json")
    with pytest.raises(ToolError, match="cannot read arena"):
        load_arena(str(p))


def test_arena_goal_cells_are_drawn_and_checked(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Rectangle

    from dynaqpc_tools.arena import draw_arena, load_arena

    p = tmp_path / "a.json"
    p.write_text(
        '{"width": 4, "height": 3, "goal": {"cx": 3, "cy": 2, "r": 0.3, '
        '"cells": [[2.5, 1.5, 3.0, 2.0], [3.0, 1.5, 3.5, 2.0]]}}'
    )
    arena = load_arena(str(p))
    fig, ax = plt.subplots()
    draw_arena(ax, arena)
    green = [
        q for q in ax.patches if isinstance(q, Rectangle) and q.get_label() != "_nolegend_" and q.get_width() == 0.5
    ]
    assert len(green) == 2
    plt.close(fig)
    p.write_text('{"width": 4, "height": 3, "goal": {"cx": 3, "cy": 2, "r": 0.3, "cells": [[1, 1, 0, 2]]}}')
    with pytest.raises(ToolError, match=r"goal\.cells\[0\]"):
        load_arena(str(p))


def test_a_simulator_error_is_one_line(tmp_path, capsys):
    sim = tmp_path / "dynaqpc-sim"
    sim.write_text("#!/bin/sh\necho 'dynaqpc-sim run: --load: x: not a flash image' >&2\nexit 2\n")
    sim.chmod(0o755)
    flash = tmp_path / "x.flash"
    flash.write_bytes(b"\0" * 16)
    rc = experiment.main(
        ["trajectory", "--scenario", "paper-lab", "--load", str(flash), "--sim", str(sim), "--out", str(tmp_path / "o")]
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and err == ["error: dynaqpc-sim run: --load: x: not a flash image"]
    # A missing flash image is named before the simulator runs.
    assert (
        experiment.main(
            [
                "trajectory",
                "--scenario",
                "paper-lab",
                "--load",
                str(tmp_path / "none"),
                "--sim",
                str(sim),
                "--out",
                str(tmp_path / "o"),
            ]
        )
        == 2
    )
    assert "no such file" in capsys.readouterr().err


def test_a_misspelt_scenario_names_the_shipped_ones_and_leaves_no_folder(tmp_path, capsys):
    results = tmp_path / "results"
    for extra in (["--sets", "1", "--episodes", "1"], []):
        rc = experiment.main(
            [
                "run",
                "--scenario",
                "paper-lob",
                "--results",
                str(results),
                "--agents",
                "q",
                "--sim",
                "/bin/false",
                *extra,
            ]
        )
        assert rc == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "did you mean paper-lab?" in err[0]
        assert (
            "the shipped scenarios are paper-lab, paper-lab-motion, paper-lab-real, paper-sim, paper-sim-motion, paper-sim-real"
            in err[0]
        )
        assert not results.exists()


def test_a_failed_run_leaves_no_empty_folder(tmp_path):
    # A scenario file the simulator refuses: the run fails in training, and the folders it made go.
    scn = tmp_path / "bad.scn"
    scn.write_text("not a scenario\n")
    results = tmp_path / "results"
    rc = experiment.main(
        [
            "run",
            "--scenario",
            str(scn),
            "--results",
            str(results),
            "--agents",
            "q",
            "--sets",
            "1",
            "--episodes",
            "1",
            "--sim",
            "/bin/false",
            "--no-progress",
        ]
    )
    assert rc == 2
    assert not results.exists()
    # A folder that was there before stays, with what it held.
    results.mkdir()
    (results / "notes.txt").write_text("mine\n")
    rc = experiment.main(
        [
            "run",
            "--scenario",
            str(scn),
            "--results",
            str(results),
            "--agents",
            "q",
            "--sets",
            "1",
            "--episodes",
            "1",
            "--sim",
            "/bin/false",
            "--no-progress",
        ]
    )
    assert rc == 2
    assert sorted(p.name for p in results.iterdir()) == ["notes.txt"]
