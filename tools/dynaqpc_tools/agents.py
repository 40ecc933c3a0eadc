# SPDX-License-Identifier: MIT
"""The learning algorithms the firmware registers (firmware/agent/include/agent/algorithms.h), as
``dynaqpc-sim agents --json`` prints them: the tools' one list of names, numbers and labels.

Nothing in the tools names an algorithm: adding a line to the registry adds it to the emulated
board's ``--agent``, the experiment runner's ``--agents`` and the tables' labels. Without a built
simulator the registry's own lines are read (names, numbers and labels; no counters).
"""

from __future__ import annotations

import functools
import json
import os
import re
import subprocess
from typing import Dict, List, Optional, Tuple

from .common import ToolError, repo_root

FORMAT = "dynaqpc-agents 1"
REGISTRY_H = os.path.join("firmware", "agent", "include", "agent", "algorithms.h")
# X(AGENT_DYNA_Q, 1, "dyna-q", "Dyna-Q", dyna_q, d): a line of AGENT_ALGORITHMS.
_LINE = re.compile(r'X\(\s*AGENT_\w+\s*,\s*(\d+)\s*,\s*"([^"]+)"\s*,\s*"([^"]+)"\s*,\s*\w+\s*(?:,\s*d\s*)?\)')


def default_sim() -> Optional[str]:
    """A built dynaqpc-sim of this checkout, if any."""
    root = str(repo_root() or ".")
    for rel in ("build/host-release/bin", "build/host/bin", "build/cortex-m4/host-sim/bin"):
        p = os.path.join(root, rel, "dynaqpc-sim")
        if os.access(p, os.X_OK):
            return p
    return None


def _from_sim(sim: str) -> Optional[Tuple[dict, ...]]:
    try:
        out = subprocess.run([sim, "agents", "--json"], capture_output=True, text=True, timeout=60)
    except (OSError, subprocess.SubprocessError):
        return None
    if out.returncode != 0:
        return None
    try:
        d = json.loads(out.stdout)
    except ValueError:
        return None
    if not isinstance(d, dict) or d.get("format") != FORMAT:
        return None
    return tuple(d["agents"])


def _from_header() -> Optional[Tuple[dict, ...]]:
    root = repo_root()
    if root is None:
        return None
    try:
        text = (root / REGISTRY_H).read_text(encoding="utf-8")
    except OSError:
        return None
    m = re.search(r"#define AGENT_ALGORITHMS(?:_WITH)?\(X", text)
    if m is None:
        return None
    body = text[m.start() : text.find("\n\n", m.start())]
    return (
        tuple({"name": name, "number": int(number), "label": label} for number, name, label in _LINE.findall(body))
        or None
    )


@functools.lru_cache(maxsize=None)
def registry(sim: Optional[str] = None) -> Tuple[dict, ...]:
    """Every algorithm, in agent_kind_t order: name, number, label and, from a simulator, its
    plan_cycles, counters and models."""
    sim = sim or default_sim()
    found = (_from_sim(sim) if sim else None) or _from_header()
    if not found:
        raise ToolError(f"cannot list the algorithms: no dynaqpc-sim built and no {REGISTRY_H} to read")
    return found


def names() -> List[str]:
    """The algorithms' names, in agent_kind_t order (the choices of --agent)."""
    return [a["name"] for a in registry()]


def labels() -> Dict[str, str]:
    """Name to label ("dyna-q" -> "Dyna-Q"), for tables and plots."""
    return {a["name"]: a["label"] for a in registry()}


def number(name: str) -> int:
    """The agent_kind_t value of `name` (what the board's `agent=` takes)."""
    for a in registry():
        if a["name"] == name:
            return int(a["number"])
    raise ToolError(f"unknown agent {name!r} (agents are {', '.join(names())})")
