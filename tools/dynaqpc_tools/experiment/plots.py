# SPDX-License-Identifier: MIT
"""The experiment's figures: learning curves (the paper's Fig. 13) and replayed trajectories."""

from __future__ import annotations

import os
from typing import List, Optional, Sequence

from .. import agents as registry
from .. import arena as arena_mod
from .runs import AgentRuns, read_trajectory
from .stats import agent_rank


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(fig, path: str) -> None:
    """Saves a PNG at the experiment's resolution (arena.save_figure)."""
    arena_mod.save_figure(fig, path, dpi=120)


def _curve_label(r: AgentRuns, repeated: bool) -> str:
    label = registry.labels().get(r.agent, r.agent)
    if r.budget is not None and r.agent != "q":
        label += ", idle-time planning" if r.budget == 0 else f", N = {r.budget:,}"
    elif repeated and r.source:
        label += f" ({os.path.basename(r.source)})"
    return f"{label} ({len(r.sets)} sets)"


def plot_fig13(
    runs: Sequence[AgentRuns], path: str, title: str = "", threshold: Optional[float] = None, cap: Optional[int] = None
) -> None:
    """Mean steps per episode per agent (and budget), band = 25th-75th percentile across sets; a
    line at the learned threshold and at the step cap when they are known."""
    import numpy as np
    from matplotlib.ticker import MaxNLocator

    plt = _pyplot()
    agents = [r.agent for r in runs]
    fig, ax = plt.subplots(figsize=(8, 5.6), layout="constrained")
    n_sets = sorted({len(r.sets) for r in runs})
    n_eps = max((len(r.episodes) for r in runs), default=0)
    for r in sorted(runs, key=lambda r: (agent_rank(r.agent), r.budget if r.budget is not None else -1)):
        ep = np.array(r.episodes)
        mean = r.steps.mean(axis=0)
        lo, hi = np.percentile(r.steps, [25, 75], axis=0)
        (line,) = ax.plot(ep, mean, linewidth=2, label=_curve_label(r, agents.count(r.agent) > 1), zorder=3)
        # A light band with its edges drawn: overlapping bands stay readable.
        ax.fill_between(ep, lo, hi, color=line.get_color(), alpha=0.10, linewidth=0, zorder=1)
        for edge in (lo, hi):
            ax.plot(ep, edge, color=line.get_color(), linewidth=0.7, alpha=0.6, linestyle=":", zorder=2)
    if cap:
        ax.axhline(
            cap,
            color="0.35",
            linestyle="--",
            linewidth=1,
            zorder=0,
            label=f"step cap ({cap:,}): the episode is cut off",
        )
    if threshold:
        ax.axhline(
            threshold,
            color="black",
            linestyle="-.",
            linewidth=1.1,
            zorder=0,
            label=f"learned threshold ({threshold:,.0f} steps, trailing 5-episode mean)",
        )
    ax.xaxis.set_major_locator(MaxNLocator(integer=True))  # episodes are whole
    ax.set_xlabel("episode")
    ax.set_ylabel("steps per episode: mean over the sets\n(dotted band: 25-75 % of the sets)")
    sets = "/".join(map(str, n_sets))
    what = f"learning curves, {sets} sets × {n_eps} episodes (the paper's Fig. 13)"
    ax.set_title(f"{title}: {what}" if title else what.capitalize())
    ax.set_ylim(bottom=0)
    ax.grid(True, alpha=0.3)
    # Under the plot, never over a curve.
    fig.legend(loc="outside lower center", ncol=2, fontsize=8, frameon=False)
    save_figure(fig, path)


def plot_trajectories(
    traj_csv: str,
    arena_json: Optional[str],
    path: str,
    title: str = "",
    image: Optional[str] = None,
    agent: Optional[str] = None,
) -> None:
    """The replayed greedy paths over the room, with a key of every mark."""
    from matplotlib.lines import Line2D

    plt = _pyplot()
    paths = read_trajectory(traj_csv)
    fig, ax = plt.subplots(figsize=(9.5, 6.5), layout="constrained")
    room = arena_mod.load_arena(arena_json) if arena_json else None
    if room is not None:
        arena_mod.draw_arena(ax, room)
    else:
        ax.set_aspect("equal")
    handles = []
    for start in sorted(paths):
        pts = paths[start]
        xs, ys = [p["x"] for p in pts], [p["y"] for p in pts]
        end = "reached the goal" if pts[-1]["in_goal"] else "stopped short"
        steps = max(p["step"] for p in pts)  # real steps (actions); the rows are control periods
        (line,) = ax.plot(xs, ys, "-", linewidth=1.4, label=f"start {start}: {steps} steps, {end}")
        ax.plot(xs[0], ys[0], "o", color=line.get_color(), markersize=7)
        ax.plot(
            xs[-1],
            ys[-1],
            "*" if pts[-1]["in_goal"] else "s",
            color=line.get_color(),
            markersize=11,
            markeredgecolor="black",
            markeredgewidth=0.5,
        )
        bumps = [(p["x"], p["y"]) for p in pts if p["bump"]]
        if bumps:
            ax.plot(*zip(*bumps), "x", color="tab:red", markersize=7)
        if len(paths) <= 12:
            handles.append(line)
    marks = [
        Line2D([], [], marker="o", linestyle="", color="0.3", label="where a path starts"),
        Line2D([], [], marker="*", linestyle="", color="0.3", markersize=11, label="where it reached the goal"),
        Line2D([], [], marker="s", linestyle="", color="0.3", label="where it stopped short (step cap)"),
        Line2D([], [], marker="x", linestyle="", color="tab:red", label="a bump"),
    ]
    handles += marks + (arena_mod.arena_key(room) if room is not None else [])
    # Beside the room, not over it: the goal and the beacons stay visible.
    ax.legend(handles=handles, fontsize=7.5, loc="upper left", bbox_to_anchor=(1.02, 1.0), borderaxespad=0)
    who = agent or "the learned agent"
    from_image = f" (flash image {os.path.basename(image)})" if image else ""
    n = len(paths)
    ax.set_title(
        f"{title + ': ' if title else ''}{who}{from_image} driving greedily, frozen, from {n} random "
        f"start{'s' if n != 1 else ''}",
        fontsize=10,
    )
    save_figure(fig, path)


def trajectory_inputs(csv_dir: str, trajectory: Optional[str], arena: Optional[str]) -> List[Optional[str]]:
    """The trajectory CSV and arena JSON to draw: the ones given, else the folder's traj.csv and
    arena.json when they are there."""
    if trajectory is None and os.path.isfile(os.path.join(csv_dir, "traj.csv")):
        trajectory = os.path.join(csv_dir, "traj.csv")
    if trajectory and arena is None and os.path.isfile(os.path.join(csv_dir, "arena.json")):
        arena = os.path.join(csv_dir, "arena.json")
    return [trajectory, arena]
