# SPDX-License-Identifier: MIT
"""dynaqpc-experiment: aggregation and Table 1 from hand-made CSVs with known answers; PNGs."""

import json

import pytest

from dynaqpc_tools import experiment
from dynaqpc_tools.common import ToolError
from dynaqpc_tools.experiment import LearnSettings

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
    write_runs(tmp_path / "dyna-qpc.csv", "dyna-qpc", [[600, 400, 50, 50, 50, 50, 50, 50, 50, 50, 50, 50]],
               robot_time=36.0)
    return tmp_path


def test_learned_episode_index():
    assert experiment.learned_episode_index(SET1, 255) == 4
    assert experiment.learned_episode_index(SET2, 361.5) == 7
    assert experiment.learned_episode_index(SET2, 361.5, smooth=2) == 8  # (900+100)/2 > 361.5
    assert experiment.learned_episode_index([5, 5, 9], 6) is None
    assert experiment.trailing_mean([2, 4, 6, 8], 3) == [2, 3, 4, 6]


def test_table1_numbers(csv_dir):
    runs = experiment.read_csv_dir(str(csv_dir))
    assert sorted(runs) == ["dyna-qpc", "q"]
    q = experiment.summarise(runs["q"], LearnSettings(smooth=1))
    assert q.learn_episodes == [5, 8]
    assert q.learn_hours == pytest.approx([500 / 3600, 800 / 3600])
    hm, hsd = q.hours_mean_sd
    assert hm == pytest.approx(650 / 3600) and hsd == pytest.approx(150 * 2 ** 0.5 / 3600)
    em, esd = q.episodes_mean_sd
    assert em == pytest.approx(6.5) and esd == pytest.approx(1.5 * 2 ** 0.5)
    assert q.mean_steps_at == {10: 100.0, 50: None, 100: None, 200: None}
    assert q.first_mean_below == 4  # 950, 900, 550, 250
    assert q.updates == 10 * (sum(SET1) + sum(SET2)) and q.wall_s == pytest.approx(12.0)
    # An absolute threshold.
    q150 = experiment.summarise(runs["q"], LearnSettings(learned_steps=150, smooth=1))
    assert q150.learn_episodes == [5, 8]
    q99 = experiment.summarise(runs["q"], LearnSettings(learned_steps=99, smooth=1))
    assert q99.learn_episodes == [] and q99.hours_mean_sd == (None, None)

    dq = experiment.summarise(runs["dyna-qpc"], LearnSettings(smooth=1))
    assert dq.learn_episodes == [3] and dq.learn_hours == pytest.approx([108 / 3600])
    table = experiment.table1_markdown({"q": q, "dyna-qpc": dq}, LearnSettings(smooth=1), "unit")
    rows = [ln for ln in table.splitlines() if ln.startswith("| ")]
    assert rows[1].startswith("| Q-learning | 2 | 12 | 0.18 ± 0.06 | 6.5 ± 2.1 | 2/2 | 100.0 | – | – | – | 4 | – |")
    assert rows[2].startswith("| Dyna-QPC | 1 | 12 | 0.03 ± 0.00 | 3.0 ± 0.0 | 1/1 |")
    assert rows[2].endswith("| 5.2 h |")
    assert "2,019 real steps" in table


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


def _is_png(path):
    return path.is_file() and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and path.stat().st_size > 5000


def test_plot_command_writes_fig13_table_and_trajectories(csv_dir, tmp_path, capsys):
    (csv_dir / "arena.json").write_text(json.dumps({
        "width": 4.0, "height": 3.0,
        "obstacles": [{"kind": "box", "cx": 2.0, "cy": 1.5, "w": 0.5, "h": 1.0, "angle_deg": 30},
                      {"kind": "circle", "cx": 1.0, "cy": 2.2, "r": 0.2}],
        "goal": {"cx": 3.5, "cy": 2.5, "r": 0.3},
        "beacons": [{"id": "b1", "x": 0.0, "y": 0.0, "z": 2.5}]}))
    rows = ["start,step,time_s,x,y,heading,action,reward,bump,in_goal\n"]
    for start in range(2):
        for step in range(20):
            x, y = 0.3 + 0.16 * step, 0.3 + start * 0.5 + 0.1 * step
            rows.append(f"{start},{step},{0.192 * step:.3f},{x:.3f},{y:.3f},0.5,1,-1,{int(step == 5)},"
                        f"{int(step == 19)}\n")
    (csv_dir / "traj.csv").write_text("".join(rows))
    out = tmp_path / "out"
    assert experiment.main(["plot", "--csv-dir", str(csv_dir), "--out", str(out), "--smooth", "1"]) == 0
    assert _is_png(out / "fig13.png") and _is_png(out / "trajectories.png")
    table = (out / "table1.md").read_text()
    assert "| Q-learning | 2 | 12 | 0.18 ± 0.06 |" in table
    assert "Q-learning" in capsys.readouterr().out


def test_run_skip_existing_does_not_call_the_simulator(csv_dir, tmp_path):
    results = tmp_path / "results"
    (results / "s").mkdir(parents=True)
    for name in ("q.csv", "dyna-qpc.csv"):
        (results / "s" / name).write_bytes((csv_dir / name).read_bytes())
    rc = experiment.main(["run", "--scenario", "s", "--results", str(results), "--agents", "q,dyna-qpc",
                          "--skip-existing", "--sim", str(tmp_path / "no-such-sim")])
    assert rc == 0
    assert _is_png(results / "s" / "fig13.png")
    # Without --skip-existing the missing simulator is a clear error, not a traceback.
    rc = experiment.main(["run", "--scenario", "s", "--results", str(results), "--agents", "q",
                          "--sim", str(tmp_path / "no-such-sim")])
    assert rc == 2


def test_run_reads_only_its_own_csvs(csv_dir, tmp_path):
    # tools/dev.sh demo keeps a longer Dyna-QPC run beside the experiment's CSVs; a second
    # experiment run in the same folder must not mistake it for its own.
    results = tmp_path / "results"
    (results / "s").mkdir(parents=True)
    for name in ("q.csv", "dyna-qpc.csv"):
        (results / "s" / name).write_bytes((csv_dir / name).read_bytes())
    write_runs(results / "s" / "dyna-qpc-150.csv", "dyna-qpc", [[70] * 150])
    rc = experiment.main(["run", "--scenario", "s", "--results", str(results), "--agents", "q,dyna-qpc",
                          "--skip-existing", "--sim", str(tmp_path / "no-such-sim")])
    assert rc == 0
    table = (results / "s" / "table1.md").read_text()
    assert "| 12 |" in table and "| 150 |" not in table


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
    p.write_text('{"width": 4, "height": 3, "goal": {"cx": 3, "cy": 2, "r": 0.3, '
                 '"cells": [[2.5, 1.5, 3.0, 2.0], [3.0, 1.5, 3.5, 2.0]]}}')
    arena = load_arena(str(p))
    fig, ax = plt.subplots()
    draw_arena(ax, arena)
    green = [q for q in ax.patches if isinstance(q, Rectangle) and q.get_label() != "_nolegend_"
             and q.get_width() == 0.5]
    assert len(green) == 2
    plt.close(fig)
    p.write_text('{"width": 4, "height": 3, "goal": {"cx": 3, "cy": 2, "r": 0.3, "cells": [[1, 1, 0, 2]]}}')
    with pytest.raises(ToolError, match=r"goal\.cells\[0\]"):
        load_arena(str(p))
