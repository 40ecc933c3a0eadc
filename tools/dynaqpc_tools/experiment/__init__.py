# SPDX-License-Identifier: MIT
"""dynaqpc-experiment: the paper's protocol, end to end, measured at matched compute.

By concern:
  runs         reading the simulator's CSVs (training runs, trajectories)
  stats        when a set learned, what it cost, Table 1 (`measure()` is the reusable entry)
  plots        Fig. 13 and the trajectories
  orchestrate  running dynaqpc-sim train, a process per set, with a progress bar
  sweep        a grid of settings over a Dask cluster
  cli          the command line
"""

from .cli import build_parser, main
from .orchestrate import default_sim, run_sets, scenario_protocol
from .plots import plot_fig13, plot_trajectories
from .runs import (
    COLUMNS,
    TRAJECTORY_COLUMNS,
    AgentRuns,
    read_csv_dir,
    read_csvs,
    read_runs,
    read_trajectory,
)
from .stats import (
    PAPER_STEP_S,
    AgentSummary,
    LearnSettings,
    Relapses,
    SetResult,
    learned_episode_index,
    measure,
    relapses_of_set,
    set_results,
    summarise,
    summarise_all,
    table_markdown,
    trailing_mean,
)

__all__ = [
    "AGENT_LABELS",
    "AGENTS",
    "COLUMNS",
    "TRAJECTORY_COLUMNS",
    "PAPER_STEP_S",
    "AgentRuns",
    "AgentSummary",
    "LearnSettings",
    "SetResult",
    "build_parser",
    "default_sim",
    "learned_episode_index",
    "main",
    "measure",
    "plot_fig13",
    "plot_trajectories",
    "Relapses",
    "relapses_of_set",
    "read_csv_dir",
    "read_csvs",
    "read_runs",
    "read_trajectory",
    "run_sets",
    "scenario_protocol",
    "set_results",
    "summarise",
    "summarise_all",
    "table_markdown",
    "trailing_mean",
]


def __getattr__(name: str):
    """AGENTS and AGENT_LABELS: the firmware's registry, read when first asked for (runs.py)."""
    if name in ("AGENTS", "AGENT_LABELS"):
        from . import runs

        return getattr(runs, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
