# SPDX-License-Identifier: MIT
"""Running the simulator: `dynaqpc-sim train` for one agent, its sets spread over processes.

Each set runs in its own process (`--first-set K --sets 1`); set K gets the same seed and so the
same rows as in one `--sets N` run, so a block of sets run anywhere (another process, a Dask
worker) merges into the CSV one run would have written. The simulator writes a row as each
episode ends, and the rows counted as they arrive drive the progress bar.
"""

from __future__ import annotations

import os
import shlex
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import List, Optional, Sequence, Tuple

from ..common import ToolError, repo_root
from .runs import COLUMNS, read_runs


def default_sim() -> str:
    root = repo_root()
    return str((root or Path.cwd()) / "build" / "host-release" / "bin" / "dynaqpc-sim")


def shipped_scenarios() -> List[str]:
    """The scenarios the simulator takes by name (host_sim/scenarios/*.scn), sorted."""
    root = repo_root()
    if root is None:
        return []
    return sorted(p.stem for p in (root / "host_sim" / "scenarios").glob("*.scn"))


def check_scenario(scenario: str) -> None:
    """Refuses, before anything is trained or written, a scenario that is neither a file nor a
    shipped name; the message lists the shipped names and the nearest one."""
    import difflib

    shipped = shipped_scenarios()
    if Path(scenario).is_file() or scenario in shipped or not shipped:
        return
    near = difflib.get_close_matches(scenario, shipped, n=1)
    hint = f" (did you mean {near[0]}?)" if near else ""
    raise ToolError(
        f"--scenario {scenario}: not a shipped scenario or a file{hint}; the shipped scenarios are {', '.join(shipped)}"
    )


def scenario_protocol(scenario: str) -> Optional[Tuple[int, int]]:
    """(sets, episodes) of the scenario's `learning` line: a scenario file, or a built-in name
    read from host_sim/scenarios/NAME.scn. None when neither can be read."""
    learning = _learning_line(scenario)
    if learning is None:
        return None
    try:
        return int(learning.get("sets", 1)), int(learning["episodes"])
    except (KeyError, ValueError):
        return None


def scenario_planning(scenario: str) -> Optional[int]:
    """The scenario's planning updates per real step (its `learning ... planning N`), if known."""
    return _learning_int(scenario, "planning")


def scenario_step_cap(scenario: str) -> Optional[int]:
    """The scenario's step cap (its `learning ... step_cap N`), if known."""
    return _learning_int(scenario, "step_cap")


def _learning_int(scenario: str, key: str) -> Optional[int]:
    """The number N of the scenario's `learning ... KEY N`; None when it has none or it is not one."""
    learning = _learning_line(scenario)
    try:
        return int(learning[key]) if learning is not None else None
    except (KeyError, ValueError):
        return None


def _learning_line(scenario: str) -> Optional[dict]:
    candidates = [Path(scenario)]
    root = repo_root()
    if root is not None:
        candidates.append(root / "host_sim" / "scenarios" / f"{scenario}.scn")
    for path in candidates:
        try:
            text = path.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError):
            continue
        for line in text.splitlines():
            words = line.split("#", 1)[0].split()
            if words[:1] == ["learning"]:
                return dict(zip(words[1::2], words[2::2]))
    return None


def check_output_csv(path: str, columns: Sequence[str] = COLUMNS, what: str = "training") -> None:
    """Refuses to overwrite a file that is not a CSV of ours (header `columns`): it is not ours
    to replace."""
    p = Path(path)
    if not p.exists():
        return
    ours = False
    if p.is_file():
        try:
            with open(p, newline="", encoding="utf-8") as f:
                first = f.readline()
            ours = not first or first.strip().split(",") == list(columns)
        except (OSError, UnicodeDecodeError):
            ours = False
    if not ours:
        raise ToolError(f"{path}: exists and is not a {what} CSV; not overwriting it")


def train_command(
    sim: str,
    scenario: str,
    agent: str,
    seed: int,
    sets: int,
    episodes: int,
    planning: Optional[int] = None,
    extra: Sequence[str] = (),
    first_set: int = 1,
) -> List[str]:
    cmd = [
        sim,
        "train",
        "--scenario",
        scenario,
        "--agent",
        agent,
        "--sets",
        str(sets),
        "--episodes",
        str(episodes),
        "--seed",
        str(seed),
    ]
    if first_set != 1:
        cmd += ["--first-set", str(first_set)]
    if planning is not None and agent != "q":
        cmd += ["--planning", str(planning)]
    return cmd + list(extra)


def _tail(path: str) -> str:
    try:
        lines = Path(path).read_text(encoding="utf-8", errors="replace").strip().splitlines()
    except OSError:
        return ""
    return lines[-1] if lines else ""


class _SetProcess:
    def __init__(self, cmd: List[str], csv_path: str, err_path: str):
        self.csv_path, self.err_path = csv_path, err_path
        self.rows = 0
        self._offset = 0
        self._header = False
        with open(err_path, "wb") as err:
            try:
                self.proc = subprocess.Popen(
                    cmd + ["--csv", csv_path, "--quiet"], stdout=subprocess.DEVNULL, stderr=err
                )
            except OSError as e:
                raise ToolError(
                    f"cannot run {cmd[0]}: {e.strerror or e} (build it: cmake --preset "
                    "host-release && cmake --build --preset host-release)"
                ) from None

    def new_rows(self) -> int:
        """Rows (episodes) written since the last call."""
        try:
            with open(self.csv_path, "rb") as f:
                f.seek(self._offset)
                chunk = f.read()
        except OSError:
            return 0
        complete = chunk[: chunk.rfind(b"\n") + 1]
        self._offset += len(complete)
        n = complete.count(b"\n")
        if n and not self._header:  # the first line is the header
            self._header, n = True, n - 1
        self.rows += n
        return n


def _merge_sets(tmp: str, done: List[int], csv_path: str, sim: str, agent: str, sets: int, episodes: int) -> None:
    """The sets' rows in set order, checked whole, into csv_path."""
    merged = os.path.join(tmp, "merged.csv")
    with open(merged, "w", encoding="utf-8") as out:
        out.write(",".join(COLUMNS) + "\n")
        for k in sorted(done):
            with open(os.path.join(tmp, f"set{k}.csv"), encoding="utf-8") as f:
                f.readline()
                out.write(f.read())
    runs = read_runs(merged).get(agent)
    if runs is None or len(runs.sets) != sets or len(runs.episodes) != episodes:
        raise ToolError(f"{sim} train for {agent}: rows missing from the simulator's output")
    try:
        os.replace(merged, csv_path)
    except OSError as e:
        raise ToolError(f"cannot write {csv_path}: {e.strerror or e}") from None


def run_sets(
    sim: str,
    scenario: str,
    agent: str,
    csv_path: str,
    sets: int,
    episodes: int,
    seed: int,
    jobs: int = 1,
    planning: Optional[int] = None,
    extra: Sequence[str] = (),
    first_set: int = 1,
    progress: bool = True,
    desc: str = "",
) -> None:
    """Trains sets first_set..first_set+sets-1 of one agent, `jobs` processes at a time, and
    writes their rows in set order into csv_path (the rows `--sets N` would have written)."""
    from tqdm import tqdm

    check_output_csv(csv_path)
    shown = train_command(sim, scenario, agent, seed, sets, episodes, planning, extra, first_set)
    print(
        "$ "
        + " ".join(shlex.quote(c) for c in shown)
        + f" --csv {shlex.quote(csv_path)}"
        + (f"   (one process per set, {jobs} at a time)" if jobs > 1 and sets > 1 else ""),
        flush=True,
    )
    out_dir = os.path.dirname(os.path.abspath(csv_path))
    os.makedirs(out_dir, exist_ok=True)
    bar = tqdm(
        total=sets * episodes,
        desc=desc or agent,
        unit="episode",
        file=sys.stderr,
        disable=not progress or None,
        dynamic_ncols=True,
        leave=True,
    )
    started = time.monotonic()
    with tempfile.TemporaryDirectory(prefix=".sets-", dir=out_dir) as tmp:
        pending = list(range(first_set, first_set + sets))
        running = {}
        done = []
        try:
            while pending or running:
                while pending and len(running) < jobs:
                    k = pending.pop(0)
                    cmd = train_command(sim, scenario, agent, seed, 1, episodes, planning, extra, k)
                    running[k] = _SetProcess(cmd, os.path.join(tmp, f"set{k}.csv"), os.path.join(tmp, f"set{k}.err"))
                time.sleep(0.1)
                for k, sp in list(running.items()):
                    rc = sp.proc.poll()
                    bar.update(sp.new_rows())
                    if rc is None:
                        continue
                    del running[k]
                    if rc != 0:
                        raise ToolError(
                            f"{sim} train (set {k} of {agent}) exited with status {rc}: {_tail(sp.err_path)}"
                        )
                    done.append(k)
                    bar.set_postfix_str(f"set {len(done)}/{sets}")
        finally:
            for sp in running.values():
                sp.proc.kill()
                sp.proc.wait()
            bar.close()
        _merge_sets(tmp, done, csv_path, sim, agent, sets, episodes)
    if not bar.disable:
        return
    print(f"{desc or agent}: {sets} sets x {episodes} episodes in {time.monotonic() - started:.0f} s", flush=True)


def run_command(cmd: List[str]) -> str:
    """Runs a simulator command in the foreground; a failure is a ToolError carrying the
    simulator's own last line (its stderr is passed on only when it succeeds)."""
    print("$ " + " ".join(shlex.quote(c) for c in cmd), flush=True)
    try:
        p = subprocess.run(cmd, stderr=subprocess.PIPE, text=True, errors="replace")
    except OSError as e:
        raise ToolError(
            f"cannot run {cmd[0]}: {e.strerror or e} (build it: cmake --preset host-release && "
            "cmake --build --preset host-release)"
        ) from None
    if p.returncode != 0:
        name = os.path.basename(cmd[0])
        last = (p.stderr.strip().splitlines() or [f"exited with status {p.returncode}"])[-1]
        raise ToolError(last if last.startswith(name) else f"{name}: {last}")
    sys.stderr.write(p.stderr)
    return p.stderr
