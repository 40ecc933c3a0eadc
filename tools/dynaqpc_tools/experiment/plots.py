# SPDX-License-Identifier: MIT
"""The experiment's figures: learning curves (the paper's Fig. 13) and replayed trajectories."""

from __future__ import annotations

import os
from typing import List, Optional, Sequence

from ..common import ToolError
from .runs import AGENT_LABELS, AgentRuns, read_trajectory
from .stats import agent_rank


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path: str) -> None:
    """Saves a PNG; a folder that is missing or not writable is a ToolError naming the path."""
    plt = _pyplot()
    try:
        fig.savefig(path, dpi=120)
    except OSError as e:
        raise ToolError(f"cannot write {path}: {e.strerror or e}") from None
    finally:
        plt.close(fig)


def _curve_label(r: AgentRuns, repeated: bool) -> str:
    label = AGENT_LABELS.get(r.agent, r.agent)
    if r.budget is not None and r.agent != "q":
        label += ", idle-time planning" if r.budget == 0 else f", N = {r.budget:,}"
    elif repeated and r.source:
        label += f" ({os.path.basename(r.source)})"
    return f"{label} ({len(r.sets)} sets)"


def plot_fig13(runs: Sequence[AgentRuns], path: str, title: str = "") -> None:
    """Mean steps per episode per agent (and budget), band = 25th-75th percentile across sets."""
    import numpy as np
    from matplotlib.ticker import MaxNLocator

    plt = _pyplot()
    agents = [r.agent for r in runs]
    fig, ax = plt.subplots(figsize=(8, 5))
    for r in sorted(runs, key=lambda r: (agent_rank(r.agent), r.budget if r.budget is not None else -1)):
        ep = np.array(r.episodes)
        mean = r.steps.mean(axis=0)
        lo, hi = np.percentile(r.steps, [25, 75], axis=0)
        (line,) = ax.plot(ep, mean, label=_curve_label(r, agents.count(r.agent) > 1))
        ax.fill_between(ep, lo, hi, color=line.get_color(), alpha=0.2, linewidth=0)
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))  # episodes are whole
    ax.set_xlabel("episode")
    ax.set_ylabel("steps per episode (mean; band: 25-75 % of sets)")
    ax.set_title(title or "Learning curves (paper Fig. 13)")
    ax.grid(True, alpha=0.3)
    ax.legend()
    fig.tight_layout()
    save_figure(fig, path)


def plot_trajectories(traj_csv: str, arena_json: Optional[str], path: str, title: str = "") -> None:
    from .. import arena as arena_mod

    plt = _pyplot()
    paths = read_trajectory(traj_csv)
    fig, ax = plt.subplots(figsize=(8.5, 7))
    if arena_json:
        arena_mod.draw_arena(ax, arena_mod.load_arena(arena_json))
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
        # Beside the room, not over it: the goal and the beacons stay visible.
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0)
    fig.tight_layout()
    save_figure(fig, path)


def trajectory_inputs(csv_dir: str, trajectory: Optional[str], arena: Optional[str]) -> List[Optional[str]]:
    """The trajectory CSV and arena JSON to draw: the ones given, else the folder's traj.csv and
    arena.json when they are there."""
    if trajectory is None and os.path.isfile(os.path.join(csv_dir, "traj.csv")):
        trajectory = os.path.join(csv_dir, "traj.csv")
    if trajectory and arena is None and os.path.isfile(os.path.join(csv_dir, "arena.json")):
        arena = os.path.join(csv_dir, "arena.json")
    return [trajectory, arena]
