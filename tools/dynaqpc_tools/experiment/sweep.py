# SPDX-License-Identifier: MIT
"""dynaqpc-experiment sweep: a grid of training settings over a Dask cluster (docs/sweeps.md).

The grid file (TOML) names the protocol and lists settings:

    scenario = "paper-lab"          # or a .scn file (the same path on every worker)
    agents = ["dyna-q", "dyna-qpc"]
    sets = 20
    episodes = 20
    seed = 101
    block = 5                       # sets per task (default: 5)
    threshold = 50                  # for the summary: learned at <= 50 steps (default: 1.5 x final)
    [grid]
    epsilon = [0.05, 0.1]           # any `dynaqpc-sim train` option, a list of values each
    planning = [5, 1000]

Each task runs `dynaqpc-sim train` for one grid point, one agent and one block of sets
(`--first-set K --sets B`: the rows one run of all the sets would give) and returns its CSV text;
the sweep writes it to OUT/tasks/. A rerun skips the tasks whose CSV is complete. A worker lost
mid-task has its task rerun elsewhere by the Dask scheduler (up to its allowed-failures, 3 by
default); a task that fails is retried once. At the end: OUT/sweep.csv (the grid columns, then the
simulator's), OUT/summary.md (Table 1 per grid point) and OUT/sweep.png.
"""

from __future__ import annotations

import csv
import hashlib
import io
import itertools
import json
import math
import os
import re
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Dict, List, Optional, Sequence

from .. import agents as registry
from ..common import ToolError
from .runs import COLUMNS, DEFAULT_AGENTS, read_runs
from .stats import LearnSettings, summarise_all, table_markdown

#: Options the sweep sets itself; a grid may not list them.
RESERVED = {"scenario", "agent", "sets", "first-set", "episodes", "seed", "csv", "save", "jobs", "quiet", "help"}
_OPTION = re.compile(r"^[a-z][a-z0-9_-]*$")


@dataclass
class Grid:
    scenario: str
    agents: List[str]
    sets: int
    episodes: int
    seed: int
    block: int
    threshold: Optional[float]
    settings: Dict[str, list]  # option -> values, in file order

    def points(self) -> List[Dict[str, object]]:
        keys = list(self.settings)
        return [dict(zip(keys, combo)) for combo in itertools.product(*(self.settings[k] for k in keys))]


def _int(d, key, lo, hi, default=None, path=""):
    v = d.get(key, default)
    if v is None:
        raise ToolError(f"{path}: '{key}' is missing")
    if not isinstance(v, int) or isinstance(v, bool) or not lo <= v <= hi:
        raise ToolError(f"{path}: '{key}' = {v!r} is not an integer in [{lo}, {hi}]")
    return v


def load_grid(path: str) -> Grid:
    """Reads and checks a grid file; every problem is a ToolError naming the file and key."""
    try:
        import tomllib
    except ImportError:  # Python < 3.11
        import tomli as tomllib
    try:
        with open(path, "rb") as f:
            d = tomllib.load(f)
    except OSError as e:
        raise ToolError(f"cannot read {path}: {e.strerror or e}") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as e:
        raise ToolError(f"{path}: not TOML ({e})") from None
    known = {"scenario", "agents", "sets", "episodes", "seed", "block", "threshold", "grid"}
    unknown = sorted(set(d) - known)
    if unknown:
        raise ToolError(f"{path}: unknown key(s) {', '.join(unknown)} (known: {', '.join(sorted(known))})")
    scenario = d.get("scenario")
    if not isinstance(scenario, str) or not scenario:
        raise ToolError(f"{path}: 'scenario' must name a scenario (paper-lab, paper-sim or a .scn file)")
    agents = d.get("agents", list(DEFAULT_AGENTS))
    known = registry.names()
    if (
        not isinstance(agents, list)
        or not agents
        or any(a not in known for a in agents)
        or len(set(agents)) != len(agents)
    ):
        raise ToolError(f"{path}: 'agents' = {agents!r}: a list of distinct agents out of {', '.join(known)}")
    sets = _int(d, "sets", 1, 100000, path=path)
    episodes = _int(d, "episodes", 1, 10000000, path=path)
    seed = _int(d, "seed", 0, 2**32 - 1, 1, path)
    block = _int(d, "block", 1, 100000, min(5, sets), path)
    threshold = d.get("threshold")
    if threshold is not None and (
        isinstance(threshold, bool)
        or not isinstance(threshold, (int, float))
        or not threshold > 0
        or not math.isfinite(threshold)
    ):
        raise ToolError(f"{path}: 'threshold' = {threshold!r} is not a positive number")
    grid = d.get("grid", {})
    if not isinstance(grid, dict):
        raise ToolError(f"{path}: [grid] must be a table of option = [values]")
    settings = {}
    for key, values in grid.items():
        opt = key.replace("_", "-")
        if not _OPTION.match(opt) or opt in RESERVED:
            raise ToolError(
                f"{path}: [grid] {key}: not a train option the grid may set "
                f"(the sweep sets {', '.join(sorted(RESERVED - {'help', 'quiet'}))} itself)"
            )
        if not isinstance(values, list) or not values:
            raise ToolError(f"{path}: [grid] {key} must be a non-empty list of values")
        for v in values:
            if isinstance(v, (dict, list)) or (isinstance(v, float) and not math.isfinite(v)):
                raise ToolError(f"{path}: [grid] {key}: {v!r} is not a single value")
        if len({json.dumps(v) for v in values}) != len(values):
            raise ToolError(f"{path}: [grid] {key} lists a value twice")
        settings[opt] = values
    return Grid(
        scenario, agents, sets, episodes, seed, block, None if threshold is None else float(threshold), settings
    )


def point_id(point: Dict[str, object]) -> str:
    """A short stable name for a grid point: readable settings and a hash."""
    text = ",".join(f"{k}={point[k]}" for k in point) or "default"
    safe = re.sub(r"[^A-Za-z0-9._=,-]", "_", text)[:60]
    return f"{safe}-{hashlib.sha1(text.encode()).hexdigest()[:8]}"


def _value_text(v) -> str:
    if isinstance(v, bool):
        return "1" if v else "0"
    return repr(v) if isinstance(v, float) else str(v)


def tasks_of(grid: Grid, sim: str) -> List[dict]:
    """Every (point, agent, block of sets) as a task spec, a plain dict a worker can run."""
    out = []
    for point in grid.points():
        pid = point_id(point)
        extra = []
        for k, v in point.items():
            if isinstance(v, bool):
                if v:
                    extra.append(f"--{k}")  # a flag
            else:
                extra += [f"--{k}", _value_text(v)]
        for agent in grid.agents:
            for first in range(1, grid.sets + 1, grid.block):
                n = min(grid.block, grid.sets - first + 1)
                out.append(
                    {
                        "sim": sim,
                        "scenario": grid.scenario,
                        "agent": agent,
                        "first_set": first,
                        "sets": n,
                        "episodes": grid.episodes,
                        "seed": grid.seed,
                        "extra": extra,
                        "point": point,
                        "point_id": pid,
                        "name": f"{pid}/{agent}-sets{first}-{first + n - 1}.csv",
                    }
                )
    return out


def run_task(spec: dict) -> str:
    """Runs one task where it is called (a Dask worker) and returns the CSV text. The simulator
    must be at spec['sim'] there."""
    with tempfile.TemporaryDirectory(prefix="dynaqpc-task-") as tmp:
        csv_path = os.path.join(tmp, "out.csv")
        cmd = [
            spec["sim"],
            "train",
            "--scenario",
            spec["scenario"],
            "--agent",
            spec["agent"],
            "--first-set",
            str(spec["first_set"]),
            "--sets",
            str(spec["sets"]),
            "--episodes",
            str(spec["episodes"]),
            "--seed",
            str(spec["seed"]),
            *spec["extra"],
            "--csv",
            csv_path,
            "--quiet",
        ]
        try:
            p = subprocess.run(cmd, capture_output=True, text=True)
        except OSError as e:
            raise RuntimeError(f"cannot run {spec['sim']} on this worker: {e}") from None
        if p.returncode != 0:
            last = (p.stderr.strip().splitlines() or ["(no message)"])[-1]
            raise RuntimeError(f"{' '.join(cmd[:2])} exited with {p.returncode}: {last}")
        with open(csv_path, encoding="utf-8") as f:
            return f.read()


def task_complete(path: Path, spec: dict) -> bool:
    if not path.is_file():
        return False
    try:
        r = read_runs(str(path)).get(spec["agent"])
    except ToolError:
        return False
    want = list(range(spec["first_set"], spec["first_set"] + spec["sets"]))
    return r is not None and r.sets == want and len(r.episodes) == spec["episodes"]


def _write_atomic(path: Path, text: str) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(path.name + ".part")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)


def _client(scheduler: Optional[str], workers: int):
    from dask.distributed import Client, LocalCluster

    if scheduler:
        try:
            return Client(scheduler, timeout=10), None
        except Exception as e:  # OSError, TimeoutError, ...
            raise ToolError(f"cannot reach the Dask scheduler {scheduler}: {e}") from None
    cluster = LocalCluster(
        n_workers=workers, threads_per_worker=1, host="127.0.0.1", dashboard_address=None, processes=True
    )
    return Client(cluster), cluster


def merge(grid: Grid, specs: Sequence[dict], out: Path) -> Path:
    """OUT/sweep.csv: the grid's columns, then the simulator's, every task's rows in task order."""
    keys = list(grid.settings)
    path = out / "sweep.csv"
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(keys + COLUMNS)
    for spec in specs:
        with open(out / "tasks" / spec["name"], newline="", encoding="utf-8") as f:
            rows = list(csv.reader(f))[1:]
        for row in rows:
            w.writerow([_value_text(spec["point"][k]) for k in keys] + row)
    _write_atomic(path, buf.getvalue())
    return path


def summarise_sweep(grid: Grid, specs: Sequence[dict], out: Path) -> str:
    """OUT/summary.md (Table 1 per grid point) and OUT/sweep.png (real steps to learn per point)."""
    from .runs import read_csvs

    settings = LearnSettings(grid.threshold)
    lines = [f"# Sweep: {grid.scenario}, {grid.sets} sets x {grid.episodes} episodes, seed {grid.seed}", ""]
    bars = []  # (point label, agent, mean steps, sd)
    by_point: Dict[str, List[dict]] = {}
    for spec in specs:
        by_point.setdefault(spec["point_id"], []).append(spec)
    for pid, group in by_point.items():
        point = group[0]["point"]
        label = ", ".join(f"{k} {v}" for k, v in point.items()) or "scenario defaults"
        tmp_paths = []
        with tempfile.TemporaryDirectory() as tmp:
            for agent in grid.agents:  # one CSV per agent: its blocks in set order
                parts = [s for s in group if s["agent"] == agent]
                text = [",".join(COLUMNS) + "\n"]
                for s in sorted(parts, key=lambda s: s["first_set"]):
                    with open(out / "tasks" / s["name"], encoding="utf-8") as f:
                        f.readline()
                        text.append(f.read())
                p = os.path.join(tmp, f"{agent}.csv")
                with open(p, "w", encoding="utf-8") as f:
                    f.write("".join(text))
                tmp_paths.append(p)
            runs = read_csvs(tmp_paths, allow_repeats=True)
            if "planning" in point:
                for r in runs:
                    r.budget = int(point["planning"])
            summaries = summarise_all(runs, settings)
        lines.append(table_markdown(summaries, settings, f"{grid.scenario} — {label}").replace("### Table 1: ", "## "))
        for s in summaries:
            m, sd = s.steps_mean_sd
            bars.append((label, s.label, m, sd, s.n_learned, s.n_sets))
    text = "\n".join(lines)
    _write_atomic(out / "summary.md", text)
    _plot(bars, out / "sweep.png", grid)
    return text


def _plot(bars, path: Path, grid: Grid) -> None:
    from .plots import _pyplot, save_figure

    plt = _pyplot()
    labels = list(dict.fromkeys(b[0] for b in bars))
    agents = list(dict.fromkeys(b[1] for b in bars))
    fig, ax = plt.subplots(figsize=(max(6.0, 1.2 * len(labels) * len(agents)), 4.5))
    width = 0.8 / max(1, len(agents))
    for j, agent in enumerate(agents):
        xs, ms, sds, learned = [], [], [], []
        for i, label in enumerate(labels):
            for b in bars:
                if b[0] == label and b[1] == agent:
                    xs.append(i + (j - (len(agents) - 1) / 2) * width)
                    ms.append(b[2])
                    sds.append(b[3])
                    learned.append(f"{b[4]}/{b[5]}")
        ax.bar(xs, ms, width, yerr=sds, capsize=3, label=agent)
        for x, m, k in zip(xs, ms, learned):  # sets learned, at the foot of each bar
            ax.annotate(k, (x, 0), textcoords="offset points", xytext=(0, 3), ha="center", fontsize=7)
    ax.set_xticks(range(len(labels)))
    ax.set_xticklabels(labels, rotation=20, ha="right", fontsize=8)
    ax.set_ylabel("real steps to learn (mean ± sd over all sets; k/n learned)")
    learned = (
        f"trailing 5-episode mean <= {grid.threshold:g} steps"
        if grid.threshold is not None
        else "within 1.5 x each set's final mean"
    )
    ax.set_title(
        f"Sweep on {grid.scenario}: {grid.sets} sets x {grid.episodes} episodes, seed {grid.seed}; learned: {learned}",
        fontsize=9,
    )
    ax.grid(True, axis="y", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    save_figure(fig, str(path))


def cmd_sweep(args) -> int:
    from tqdm import tqdm

    grid = load_grid(args.grid)
    if args.planning is not None:
        if "planning" in grid.settings:
            raise ToolError(f"--planning: {args.grid} lists planning in [grid] already")
        grid.settings["planning"] = list(args.planning)  # every agent at each budget
    out = Path(args.out)
    if out.exists() and not out.is_dir():
        raise ToolError(f"--out {out}: exists and is not a folder")
    if (out / "sweep.csv").exists() and not _is_sweep_csv(out / "sweep.csv", grid):
        raise ToolError(f"{out / 'sweep.csv'}: exists and is not this sweep's CSV; not overwriting it")
    sim = os.path.abspath(args.sim) if not args.scheduler else args.sim
    specs = tasks_of(grid, sim)
    todo = [s for s in specs if not task_complete(out / "tasks" / s["name"], s)]
    print(
        f"sweep: {len(grid.points())} grid points x {len(grid.agents)} agents x "
        f"{math.ceil(grid.sets / grid.block)} blocks = {len(specs)} tasks; "
        f"{len(specs) - len(todo)} done before, {len(todo)} to run",
        flush=True,
    )
    if todo:
        client, cluster = _client(args.scheduler, args.workers)
        try:
            from dask.distributed import as_completed

            futures = {client.submit(run_task, s, key=f"dynaqpc-{s['name']}", pure=False, retries=1): s for s in todo}
            bar = tqdm(total=len(todo), desc="sweep", unit="task", file=sys.stderr, disable=args.no_progress or None)
            try:
                for fut in as_completed(list(futures)):
                    spec = futures[fut]
                    try:
                        text = fut.result()
                    except Exception as e:
                        raise ToolError(f"task {spec['name']} failed: {e}") from None
                    _write_atomic(out / "tasks" / spec["name"], text)
                    bar.update(1)
            finally:
                bar.close()
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    merged = merge(grid, specs, out)
    summary = summarise_sweep(grid, specs, out)
    print(summary)
    print(f"wrote {merged}, {out / 'summary.md'}, {out / 'sweep.png'}")
    return 0


def _is_sweep_csv(path: Path, grid: Grid) -> bool:
    try:
        with open(path, newline="", encoding="utf-8") as f:
            return f.readline().strip().split(",") == list(grid.settings) + COLUMNS
    except (OSError, UnicodeDecodeError):
        return False


def add_parser(sub, sim_default: str, fn, planning_list) -> None:
    from ..common import int_in

    sw = sub.add_parser(
        "sweep",
        help="a grid of settings over a Dask cluster (docs/sweeps.md)",
        description=__doc__,
        formatter_class=__import__("argparse").RawDescriptionHelpFormatter,
    )
    sw.add_argument("--grid", required=True, metavar="TOML", help="the grid file")
    sw.add_argument("--out", required=True, metavar="DIR", help="results folder (tasks/, sweep.csv, summary.md)")
    sw.add_argument(
        "--scheduler",
        default=None,
        metavar="tcp://HOST:PORT",
        help="a running Dask scheduler (default: a LocalCluster on this machine)",
    )
    sw.add_argument(
        "--workers",
        type=int_in(1, 256),
        default=2,
        help="without --scheduler: local worker processes (default %(default)s)",
    )
    sw.add_argument(
        "--sim",
        default=sim_default,
        help="dynaqpc-sim on the workers (default, and without --scheduler made absolute: %(default)s)",
    )
    sw.add_argument(
        "--planning",
        type=planning_list,
        default=None,
        metavar="N[,N...]",
        help="a grid dimension of planning budgets, e.g. 5,1000,0 (as `run --planning`)",
    )
    sw.add_argument("--no-progress", action="store_true", help="no progress bar")
    sw.set_defaults(fn=fn)
