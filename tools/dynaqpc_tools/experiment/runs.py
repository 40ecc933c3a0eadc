# SPDX-License-Identifier: MIT
"""Reading what dynaqpc-sim wrote: training CSVs (one row per set and episode) and trajectories.

Every error names the file and, where there is one, the line: a garbage file, a wrong header,
a bad value, a set with a gap in its episodes.
"""

from __future__ import annotations

import csv
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, Iterator, List, Optional, Sequence, Tuple

from .. import agents as _registry
from ..common import ToolError


def __getattr__(name: str):
    """AGENTS (the algorithms, in agent_kind_t order: the tables' order) and AGENT_LABELS (name to
    label), read from the firmware's registry when first asked for (agents.py)."""
    if name == "AGENTS":
        return _registry.names()
    if name == "AGENT_LABELS":
        return _registry.labels()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


COLUMNS = ["agent", "set", "episode", "steps", "reward", "reached_goal", "bumps", "robot_time_s", "updates", "wall_s"]
TRAJECTORY_COLUMNS = ["start", "step", "time_s", "x", "y", "heading", "action", "reward", "bump", "in_goal"]
#: What `run` and a sweep compare unless told otherwise.
DEFAULT_AGENTS = ["q", "dyna-q", "dyna-qpc"]
#: A CSV named <agent>-p<N>.csv holds runs at N planning updates per real step (p0: idle time).
BUDGET_IN_NAME = re.compile(r"-p(\d+)$")


@dataclass
class AgentRuns:
    """One agent's runs from one CSV: per set (rows) and episode (columns)."""

    agent: str
    sets: List[int]
    episodes: List[int]
    steps: "np.ndarray"  # noqa: F821 (numpy arrays, sets x episodes)
    robot_time_s: "np.ndarray"  # noqa: F821
    updates: "np.ndarray"  # noqa: F821 (Q updates in the episode, real plus planning)
    wall_s: float
    source: str = ""
    #: The planning budget asked for (updates per real step; 0 = idle time), when known.
    budget: Optional[int] = None
    extra: Dict[str, str] = field(default_factory=dict)
    #: 1 where the episode reached the goal (sets x episodes), or None when not known.
    reached: Optional["np.ndarray"] = None  # noqa: F821

    @property
    def total_updates(self) -> int:
        return int(self.updates.sum())


def _open_text(path: str):
    try:
        return open(path, newline="", encoding="utf-8")
    except OSError as e:
        raise ToolError(f"cannot read {path}: {e.strerror or e}") from None


def _csv_rows(path: str, kind: str, columns: Sequence[str]) -> Iterator[Tuple[int, Dict[str, str]]]:
    """The rows of a `kind` CSV ("training", "trajectory") whose header must be `columns`, each with
    its line number; a file that cannot be read, another header, a row with more or fewer fields
    than the header, text that is not UTF-8 or not CSV is a ToolError."""
    try:
        with _open_text(path) as f:
            reader = csv.DictReader(f)
            if reader.fieldnames is None or [c.strip() for c in reader.fieldnames] != list(columns):
                raise ToolError(f"{path}: not a {kind} CSV (columns {reader.fieldnames}, want {','.join(columns)})")
            for row in reader:
                # DictReader pads a short row with None and puts a long row's extra fields in a
                # list under None: the row's own field count, not len(row).
                n = sum(v is not None for k, v in row.items() if k is not None) + len(row.get(None) or ())
                if n != len(columns):
                    raise ToolError(f"{path}:{reader.line_num}: {n} fields, want {len(columns)}")
                yield reader.line_num, row
    except UnicodeDecodeError:
        raise ToolError(f"{path}: not a {kind} CSV (not UTF-8 text)") from None
    except csv.Error as e:
        raise ToolError(f"{path}: not a {kind} CSV ({e})") from None


def _parse_row(row: Dict[str, str], path: str, line: int):
    try:
        return (
            row["agent"].strip(),
            int(row["set"]),
            int(row["episode"]),
            int(row["steps"]),
            float(row["robot_time_s"]),
            float(row["wall_s"]),
            int(row["updates"]),
            int(row["reached_goal"]),
        )
    except (ValueError, TypeError, AttributeError, KeyError) as e:
        raise ToolError(f"{path}:{line}: bad value ({e})") from None


def budget_from_name(path: str) -> Optional[int]:
    m = BUDGET_IN_NAME.search(Path(path).stem)
    return int(m.group(1)) if m else None


def read_runs(path: str, extra_columns: Sequence[str] = ()) -> Dict[str, AgentRuns]:
    """Reads one training CSV (it may hold several agents). `extra_columns` may come before the
    simulator's columns (a sweep's grid settings); their values must be the same on every row
    of an agent."""
    import numpy as np

    want = list(extra_columns) + COLUMNS
    cells: Dict[str, Dict[tuple, tuple]] = {}
    wall: Dict[str, float] = {}
    extra: Dict[str, Dict[str, str]] = {}
    for line, row in _csv_rows(path, "training", want):
        agent, s, e, steps, rt, w, u, goal = _parse_row(row, path, line)
        if steps < 0 or rt < 0 or u < 0 or e < 1:
            raise ToolError(f"{path}:{line}: negative steps/time/updates or episode < 1")
        if goal not in (0, 1):
            raise ToolError(f"{path}:{line}: reached_goal {goal}, want 0 or 1")
        per = cells.setdefault(agent, {})
        if (s, e) in per:
            raise ToolError(f"{path}:{line}: agent {agent} set {s} episode {e} twice")
        per[(s, e)] = (steps, rt, u, goal)
        wall[agent] = wall.get(agent, 0.0) + w
        extra.setdefault(agent, {c: row[c] for c in extra_columns})
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
        if any(len(v) != n_ep for v in by_set.values()):
            print(
                f"warning: {path}: agent {agent}: sets have different episode counts; using the first {n_ep}",
                file=sys.stderr,
            )

        def matrix(k):
            return np.array([[per[(s, e)][k] for e in range(1, n_ep + 1)] for s in sets], dtype=float)

        out[agent] = AgentRuns(
            agent,
            sets,
            list(range(1, n_ep + 1)),
            matrix(0),
            matrix(1),
            matrix(2),
            wall[agent],
            source=str(path),
            budget=budget_from_name(path),
            extra=extra[agent],
            reached=matrix(3),
        )
    return out


def read_csvs(paths: Sequence[str], where: str = "", allow_repeats: bool = False) -> List[AgentRuns]:
    """The runs in these training CSVs, in the order given. Unless `allow_repeats`, an agent
    may appear in only one of them (one experiment); with it, each (CSV, agent) is its own row
    (the same agent at several planning budgets)."""
    runs: List[AgentRuns] = []
    seen = set()
    for p in paths:
        for agent, r in read_runs(str(p)).items():
            if agent in seen and not allow_repeats:
                raise ToolError(f"agent {agent} appears in more than one CSV{' in ' + where if where else ''}")
            seen.add(agent)
            runs.append(r)
    if not runs:
        raise ToolError(f"no training CSVs{' in ' + where if where else ''}")
    return runs


def is_training_csv_header(path: Path) -> bool:
    try:
        with open(path, newline="", encoding="utf-8") as f:
            return f.readline().strip().split(",") == COLUMNS
    except (OSError, UnicodeDecodeError):
        return False


def read_csv_dir(directory: str) -> List[AgentRuns]:
    """Every training CSV in a folder (trajectory CSVs and others, told apart by their header,
    are left out)."""
    if not Path(directory).is_dir():
        raise ToolError(f"{directory}: not a folder")
    paths = [str(p) for p in sorted(Path(directory).glob("*.csv")) if is_training_csv_header(p)]
    return read_csvs(paths, directory, allow_repeats=True)


def read_trajectory(path: str) -> Dict[int, List[dict]]:
    paths: Dict[int, List[dict]] = {}
    for line, row in _csv_rows(path, "trajectory", TRAJECTORY_COLUMNS):
        try:
            p = {
                "start": int(row["start"]),
                "step": int(row["step"]),
                "x": float(row["x"]),
                "y": float(row["y"]),
                "bump": int(row["bump"]) != 0,
                "in_goal": int(row["in_goal"]) != 0,
            }
        except (ValueError, TypeError) as e:
            raise ToolError(f"{path}:{line}: bad value ({e})") from None
        paths.setdefault(p["start"], []).append(p)
    if not paths:
        raise ToolError(f"{path}: no rows")
    return paths
