# SPDX-License-Identifier: MIT
"""dynaqpc-experiment: the paper's protocol, end to end.

  run         trains Q, Dyna-Q and Dyna-QPC with dynaqpc-sim (one CSV per agent), then plots
  plot        only the plots and the table, from CSVs already written
  trajectory  runs a learned agent from K starts and draws the paths over the arena

Outputs (in the scenario's results folder): fig13.png (mean steps per episode per agent, with
the band between the 25th and 75th percentile across sets), table1.md (robot time to learn per
agent, next to the paper's figures), trajectories.png.

Robot time to learn, per set: the cumulative robot_time_s up to and including the first episode
from which the set's learning curve (steps per episode, trailing mean over --smooth episodes)
stays at or below a threshold until the end of the run. The threshold is --learned-steps if
given, else --learned-factor (1.5) times the mean of the set's last --final-window (10)
episodes. The table gives the mean and sample standard deviation over sets that learned.
"""

from __future__ import annotations

import argparse
import csv
import math
import os
import shlex
import subprocess
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Dict, List, Optional, Sequence

from .common import ToolError, repo_root, run_main

COLUMNS = ["agent", "set", "episode", "steps", "reward", "reached_goal", "bumps", "robot_time_s",
           "updates", "wall_s"]
TRAJECTORY_COLUMNS = ["start", "step", "time_s", "x", "y", "heading", "action", "reward", "bump", "in_goal"]
AGENTS = ["q", "dyna-q", "dyna-qpc"]
AGENT_LABELS = {"q": "Q-learning", "dyna-q": "Dyna-Q", "dyna-qpc": "Dyna-QPC"}
#: The paper's robot time to learn in its simulated scenario.
PAPER_SIM_HOURS = {"dyna-qpc": 5.2, "dyna-q": 8.9}
PAPER_LAB_NOTE = "Paper, lab robot: Dyna-QPC learned in 2,019 real steps (1.12 h)."
REPORT_EPISODES = (10, 50, 100, 200)
MEAN_BELOW = 500


@dataclass
class AgentRuns:
    """One agent's runs: steps and robot time per set (rows) and episode (columns)."""

    agent: str
    sets: List[int]
    episodes: List[int]
    steps: "np.ndarray"        # noqa: F821 (numpy arrays, sets x episodes)
    robot_time_s: "np.ndarray"  # noqa: F821
    wall_s: float
    updates: int


def _parse_row(row: Dict[str, str], path: str, line: int):
    try:
        return (row["agent"].strip(), int(row["set"]), int(row["episode"]), int(row["steps"]),
                float(row["robot_time_s"]), float(row["wall_s"]), int(row["updates"]))
    except (ValueError, TypeError, AttributeError) as e:
        raise ToolError(f"{path}:{line}: bad value ({e})") from None


def read_runs(path: str) -> Dict[str, AgentRuns]:
    """Reads one training CSV (it may hold several agents). Errors name the file and line."""
    import numpy as np

    try:
        f = open(path, newline="", encoding="utf-8")
    except OSError as e:
        raise ToolError(f"cannot read {path}: {e}") from e
    cells: Dict[str, Dict[tuple, tuple]] = {}
    wall: Dict[str, float] = {}
    upd: Dict[str, int] = {}
    with f:
        reader = csv.DictReader(f)
        if reader.fieldnames is None or [c.strip() for c in reader.fieldnames] != COLUMNS:
            raise ToolError(f"{path}: columns {reader.fieldnames} are not {','.join(COLUMNS)}")
        for row in reader:
            agent, s, e, steps, rt, w, u = _parse_row(row, path, reader.line_num)
            if steps < 0 or rt < 0 or e < 1:
                raise ToolError(f"{path}:{reader.line_num}: negative steps/time or episode < 1")
            per = cells.setdefault(agent, {})
            if (s, e) in per:
                raise ToolError(f"{path}:{reader.line_num}: set {s} episode {e} twice")
            per[(s, e)] = (steps, rt)
            wall[agent] = wall.get(agent, 0.0) + w
            upd[agent] = upd.get(agent, 0) + u
    if not cells:
        raise ToolError(f"{path}: no rows")
    out = {}
    for agent, per in cells.items():
        sets = sorted({s for s, _ in per})
        by_set = {s: sorted(e for ss, e in per if ss == s) for s in sets}
        n_ep = min(len(v) for v in by_set.values())
        for s, eps in by_set.items():
            if eps[:n_ep] != list(range(1, n_ep + 1)):
                raise ToolError(f"{path}: agent {agent} set {s}: episodes are not 1..{n_ep} in sequence")
            if len(eps) != n_ep:
                print(f"warning: {path}: agent {agent}: sets have different episode counts; "
                      f"using the first {n_ep}", file=sys.stderr)
        steps = np.array([[per[(s, e)][0] for e in range(1, n_ep + 1)] for s in sets], dtype=float)
        rt = np.array([[per[(s, e)][1] for e in range(1, n_ep + 1)] for s in sets], dtype=float)
        out[agent] = AgentRuns(agent, sets, list(range(1, n_ep + 1)), steps, rt, wall[agent], upd[agent])
    return out


def read_csvs(paths: Sequence[str], where: str) -> Dict[str, AgentRuns]:
    """The runs in these training CSVs, by agent; an agent may appear in only one of them."""
    runs: Dict[str, AgentRuns] = {}
    for p in paths:
        for agent, r in read_runs(str(p)).items():
            if agent in runs:
                raise ToolError(f"agent {agent} appears in more than one CSV in {where}")
            runs[agent] = r
    if not runs:
        raise ToolError(f"no training CSVs in {where}")
    return runs


def read_csv_dir(directory: str) -> Dict[str, AgentRuns]:
    """Every training CSV in a folder (trajectory CSVs, told apart by their header, are left out)."""
    paths = []
    for p in sorted(Path(directory).glob("*.csv")):
        with open(p, newline="", encoding="utf-8") as f:
            header = f.readline().strip().split(",")
        if header != TRAJECTORY_COLUMNS:
            paths.append(str(p))
    return read_csvs(paths, directory)


def trailing_mean(values: Sequence[float], window: int) -> List[float]:
    out, acc = [], 0.0
    for i, v in enumerate(values):
        acc += v
        if i >= window:
            acc -= values[i - window]
        out.append(acc / min(i + 1, window))
    return out


def learned_episode_index(steps: Sequence[float], threshold: float, smooth: int = 1) -> Optional[int]:
    """0-based index of the first episode from which the smoothed curve stays <= threshold."""
    curve = trailing_mean(list(steps), max(1, smooth))
    idx = None
    for i in range(len(curve) - 1, -1, -1):
        if curve[i] <= threshold:
            idx = i
        else:
            break
    return idx


@dataclass
class LearnSettings:
    learned_steps: Optional[float] = None
    learned_factor: float = 1.5
    final_window: int = 10
    smooth: int = 5


@dataclass
class AgentSummary:
    agent: str
    n_sets: int
    n_episodes: int
    learn_hours: List[float]        # per set that learned
    learn_episodes: List[int]       # 1-based, per set that learned
    mean_steps_at: Dict[int, Optional[float]]
    first_mean_below: Optional[int]  # 1-based episode
    wall_s: float
    updates: int

    @staticmethod
    def _mean_sd(xs: Sequence[float]):
        if not xs:
            return None, None
        m = sum(xs) / len(xs)
        sd = math.sqrt(sum((x - m) ** 2 for x in xs) / (len(xs) - 1)) if len(xs) > 1 else 0.0
        return m, sd

    @property
    def hours_mean_sd(self):
        return self._mean_sd(self.learn_hours)

    @property
    def episodes_mean_sd(self):
        return self._mean_sd([float(e) for e in self.learn_episodes])


def summarise(runs: AgentRuns, settings: LearnSettings) -> AgentSummary:
    hours, episodes = [], []
    for row_steps, row_time in zip(runs.steps, runs.robot_time_s):
        if settings.learned_steps is not None:
            threshold = settings.learned_steps
        else:
            tail = row_steps[-settings.final_window:]
            threshold = settings.learned_factor * float(sum(tail)) / len(tail)
        i = learned_episode_index(list(row_steps), threshold, settings.smooth)
        if i is not None:
            episodes.append(i + 1)
            hours.append(float(sum(row_time[: i + 1])) / 3600.0)
    mean_curve = runs.steps.mean(axis=0)
    at = {e: (float(mean_curve[e - 1]) if e <= len(mean_curve) else None) for e in REPORT_EPISODES}
    below = next((i + 1 for i, v in enumerate(mean_curve) if v < MEAN_BELOW), None)
    return AgentSummary(runs.agent, len(runs.sets), len(runs.episodes), hours, episodes, at, below,
                        runs.wall_s, runs.updates)


def _agent_order(agents):
    return sorted(agents, key=lambda a: (AGENTS.index(a) if a in AGENTS else len(AGENTS), a))


def table1_markdown(summaries: Dict[str, AgentSummary], settings: LearnSettings, title: str = "") -> str:
    if settings.learned_steps is not None:
        rule = f"smoothed steps per episode stay <= {settings.learned_steps:g}"
    else:
        rule = (f"smoothed steps per episode stay <= {settings.learned_factor:g} x the set's mean of its "
                f"last {settings.final_window} episodes")
    lines = []
    if title:
        lines += [f"### {title}", ""]
    lines += [
        "| Agent | Sets | Episodes | Robot time to learn (h) | Episodes to learn | Sets learned | "
        + " | ".join(f"Mean steps ep. {e}" for e in REPORT_EPISODES)
        + f" | First ep. mean < {MEAN_BELOW} | Paper (sim) |",
        "|---|---:|---:|---:|---:|---:|" + "---:|" * len(REPORT_EPISODES) + "---:|---:|",
    ]
    for agent in _agent_order(summaries):
        s = summaries[agent]
        hm, hsd = s.hours_mean_sd
        em, esd = s.episodes_mean_sd
        hours = f"{hm:.2f} ± {hsd:.2f}" if hm is not None else "not learned"
        eps = f"{em:.1f} ± {esd:.1f}" if em is not None else "–"
        at = " | ".join(f"{v:.1f}" if v is not None else "–" for v in s.mean_steps_at.values())
        below = str(s.first_mean_below) if s.first_mean_below is not None else "never"
        paper = f"{PAPER_SIM_HOURS[agent]} h" if agent in PAPER_SIM_HOURS else "–"
        lines.append(f"| {AGENT_LABELS.get(agent, agent)} | {s.n_sets} | {s.n_episodes} | {hours} | {eps} | "
                     f"{len(s.learn_hours)}/{s.n_sets} | {at} | {below} | {paper} |")
    lines += ["", f"Robot time to learn: cumulative robot time until the per-set learning curve ({rule}; "
              f"trailing mean over {settings.smooth} episodes) stays there to the end; mean ± sample sd "
              "over the sets that learned.", PAPER_LAB_NOTE, ""]
    return "\n".join(lines)


def plot_fig13(runs: Dict[str, AgentRuns], path: str, title: str = "") -> None:
    """Mean steps per episode per agent, band = 25th-75th percentile across sets."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    fig, ax = plt.subplots(figsize=(8, 5))
    for agent in _agent_order(runs):
        r = runs[agent]
        ep = np.array(r.episodes)
        mean = r.steps.mean(axis=0)
        lo, hi = np.percentile(r.steps, [25, 75], axis=0)
        (line,) = ax.plot(ep, mean, label=f"{AGENT_LABELS.get(agent, agent)} ({len(r.sets)} sets)")
        ax.fill_between(ep, lo, hi, color=line.get_color(), alpha=0.2, linewidth=0)
    ax.set_xlabel("episode")
    ax.set_ylabel("steps per episode (mean; band: 25-75 % of sets)")
    ax.set_title(title or "Learning curves (paper Fig. 13)")
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def read_trajectory(path: str) -> Dict[int, List[dict]]:
    try:
        f = open(path, newline="", encoding="utf-8")
    except OSError as e:
        raise ToolError(f"cannot read {path}: {e}") from e
    paths: Dict[int, List[dict]] = {}
    with f:
        reader = csv.DictReader(f)
        if reader.fieldnames is None or [c.strip() for c in reader.fieldnames] != TRAJECTORY_COLUMNS:
            raise ToolError(f"{path}: columns {reader.fieldnames} are not {','.join(TRAJECTORY_COLUMNS)}")
        for row in reader:
            try:
                p = {"start": int(row["start"]), "x": float(row["x"]), "y": float(row["y"]),
                     "bump": int(row["bump"]) != 0, "in_goal": int(row["in_goal"]) != 0}
            except (ValueError, TypeError) as e:
                raise ToolError(f"{path}:{reader.line_num}: bad value ({e})") from None
            paths.setdefault(p["start"], []).append(p)
    if not paths:
        raise ToolError(f"{path}: no rows")
    return paths


def plot_trajectories(traj_csv: str, arena_json: Optional[str], path: str, title: str = "") -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from .arena import draw_arena, load_arena

    paths = read_trajectory(traj_csv)
    fig, ax = plt.subplots(figsize=(7, 7))
    if arena_json:
        draw_arena(ax, load_arena(arena_json))
    else:
        ax.set_aspect("equal")
    for start in sorted(paths):
        pts = paths[start]
        xs, ys = [p["x"] for p in pts], [p["y"] for p in pts]
        (line,) = ax.plot(xs, ys, "-", linewidth=1.2, label=f"start {start}")
        ax.plot(xs[0], ys[0], "o", color=line.get_color())
        ax.plot(xs[-1], ys[-1], "*" if pts[-1]["in_goal"] else "s", color=line.get_color(), markersize=9)
        bumps = [(p["x"], p["y"]) for p in pts if p["bump"]]
        if bumps:
            ax.plot(*zip(*bumps), "x", color="tab:red", markersize=6)
    ax.set_title(title or "Trajectories of the learned agent (o start, * goal reached, x bump)")
    if len(paths) <= 12:
        ax.legend(fontsize=7, loc="upper right")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def plot_all(csv_dir: str, out_dir: str, settings: LearnSettings, title: str = "",
             trajectory: Optional[str] = None, arena: Optional[str] = None,
             csvs: Optional[Sequence[str]] = None) -> str:
    """fig13.png, table1.md and (when a trajectory CSV is there) trajectories.png, from `csvs` or else
    every training CSV in csv_dir. Returns the table."""
    runs = read_csvs(csvs, csv_dir) if csvs is not None else read_csv_dir(csv_dir)
    os.makedirs(out_dir, exist_ok=True)
    plot_fig13(runs, os.path.join(out_dir, "fig13.png"), title)
    table = table1_markdown({a: summarise(r, settings) for a, r in runs.items()}, settings, title)
    with open(os.path.join(out_dir, "table1.md"), "w", encoding="utf-8") as f:
        f.write(table)
    trajectory = trajectory or (os.path.join(csv_dir, "traj.csv") if os.path.isfile(os.path.join(csv_dir, "traj.csv"))
                                else None)
    if trajectory:
        if arena is None and os.path.isfile(os.path.join(csv_dir, "arena.json")):
            arena = os.path.join(csv_dir, "arena.json")
        plot_trajectories(trajectory, arena, os.path.join(out_dir, "trajectories.png"), title)
    return table


def default_sim() -> str:
    root = repo_root()
    return str((root or Path.cwd()) / "build" / "host-release" / "bin" / "dynaqpc-sim")


def _run_sim(cmd: List[str]) -> None:
    print("$ " + " ".join(shlex.quote(c) for c in cmd), flush=True)
    try:
        rc = subprocess.call(cmd)
    except OSError as e:
        raise ToolError(f"cannot run {cmd[0]}: {e} (build it: cmake --preset host-release && "
                        "cmake --build --preset host-release)") from e
    if rc != 0:
        raise ToolError(f"{cmd[0]} exited with status {rc}")


def _csv_complete(path: str) -> bool:
    try:
        return bool(read_runs(path))
    except ToolError:
        return False


def cmd_run(args) -> int:
    out_dir = os.path.join(args.results, args.scenario)
    os.makedirs(out_dir, exist_ok=True)
    csvs = []
    for agent in args.agents.split(","):
        csv_path = os.path.join(out_dir, f"{agent}.csv")
        csvs.append(csv_path)
        if args.skip_existing and _csv_complete(csv_path):
            print(f"{csv_path} exists: skipped")
            continue
        # The paper's protocol (sets, episodes) comes from the scenario unless given.
        protocol = []
        if args.sets is not None:
            protocol += ["--sets", str(args.sets)]
        if args.episodes is not None:
            protocol += ["--episodes", str(args.episodes)]
        _run_sim([args.sim, "train", "--scenario", args.scenario, "--agent", agent, *protocol,
                  "--seed", str(args.seed), "--csv", csv_path, "--quiet",
                  "--jobs", str(args.jobs)] + shlex.split(args.sim_args))
    if args.load:
        _run_trajectory(args, out_dir)
    # Only this run's CSVs: the folder may hold others (tools/dev.sh demo's long run, a user's).
    table = plot_all(out_dir, out_dir, _settings(args), args.scenario, csvs=csvs)
    print(table)
    print(f"wrote {out_dir}/fig13.png, {out_dir}/table1.md")
    return 0


def _run_trajectory(args, out_dir: str) -> None:
    traj, arena = os.path.join(out_dir, "traj.csv"), os.path.join(out_dir, "arena.json")
    _run_sim([args.sim, "run", "--scenario", args.scenario, "--load", args.load, "--starts", str(args.starts),
              "--trajectory", traj, "--arena", arena])


def cmd_trajectory(args) -> int:
    out_dir = args.out or os.path.join(args.results, args.scenario)
    os.makedirs(out_dir, exist_ok=True)
    _run_trajectory(args, out_dir)
    png = os.path.join(out_dir, "trajectories.png")
    plot_trajectories(os.path.join(out_dir, "traj.csv"), os.path.join(out_dir, "arena.json"), png, args.scenario)
    print(f"wrote {png}")
    return 0


def cmd_plot(args) -> int:
    out_dir = args.out or args.csv_dir
    table = plot_all(args.csv_dir, out_dir, _settings(args), args.title or os.path.basename(
        os.path.normpath(args.csv_dir)), args.trajectory, args.arena)
    print(table)
    print(f"wrote {out_dir}/fig13.png, {out_dir}/table1.md")
    return 0


def _settings(args) -> LearnSettings:
    return LearnSettings(args.learned_steps, args.learned_factor, args.final_window, args.smooth)


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="dynaqpc-experiment", description=__doc__,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)

    def learn_opts(sp):
        sp.add_argument("--learned-steps", type=float, default=None,
                        help="absolute threshold (steps per episode) for 'learned'")
        sp.add_argument("--learned-factor", type=float, default=1.5,
                        help="else: this times the set's final mean (default %(default)s)")
        sp.add_argument("--final-window", type=int, default=10, help="episodes in the final mean (default 10)")
        sp.add_argument("--smooth", type=int, default=5, help="trailing mean window (episodes, default 5)")

    def sim_opts(sp):
        sp.add_argument("--scenario", required=True, help="simulator scenario (e.g. paper-sim)")
        sp.add_argument("--sim", default=default_sim(), help="dynaqpc-sim binary (default %(default)s)")
        sp.add_argument("--results", default="results", help="results root (default %(default)s)")

    r = sub.add_parser("run", help="train every agent, then plot")
    sim_opts(r)
    r.add_argument("--agents", default=",".join(AGENTS), help="comma-separated (default %(default)s)")
    r.add_argument("--sets", type=int, default=None, help="default: the scenario's protocol")
    r.add_argument("--episodes", type=int, default=None, help="default: the scenario's protocol")
    r.add_argument("--seed", type=int, default=1)
    r.add_argument("--jobs", type=int, default=1)
    r.add_argument("--skip-existing", action="store_true", help="keep agents whose CSV is already complete")
    r.add_argument("--sim-args", default="", help="extra arguments for 'dynaqpc-sim train'")
    r.add_argument("--load", metavar="FILE", help="a learned agent: also run and draw trajectories")
    r.add_argument("--starts", type=int, default=5, help="trajectory starts (default %(default)s)")
    learn_opts(r)
    r.set_defaults(fn=cmd_run)

    pl = sub.add_parser("plot", help="plots and table from existing CSVs")
    pl.add_argument("--csv-dir", required=True)
    pl.add_argument("--out", default=None, help="output folder (default: the CSV folder)")
    pl.add_argument("--title", default=None)
    pl.add_argument("--trajectory", default=None, help="trajectory CSV (default: CSV folder's traj.csv)")
    pl.add_argument("--arena", default=None, help="arena JSON (default: CSV folder's arena.json)")
    learn_opts(pl)
    pl.set_defaults(fn=cmd_plot)

    t = sub.add_parser("trajectory", help="run a learned agent from K starts and draw the paths")
    sim_opts(t)
    t.add_argument("--load", required=True, metavar="FILE")
    t.add_argument("--starts", type=int, default=5)
    t.add_argument("--out", default=None)
    t.set_defaults(fn=cmd_trajectory)
    return p


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    return run_main(lambda: args.fn(args))


if __name__ == "__main__":
    sys.exit(main())
