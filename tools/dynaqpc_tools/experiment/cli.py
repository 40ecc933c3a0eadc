# SPDX-License-Identifier: MIT
"""The dynaqpc-experiment command line: run, table, plot, trajectory, sweep."""

from __future__ import annotations

import argparse
import os
import re
import shlex
import sys
from pathlib import Path
from typing import List, Optional

from .. import agents as registry
from ..common import ToolArgumentParser, ToolError, float_in, int_in, run_main
from . import orchestrate, plots, stats
from .runs import DEFAULT_AGENTS, TRAJECTORY_COLUMNS, read_csv_dir, read_csvs
from .stats import LearnSettings

DOC = """dynaqpc-experiment: the paper's protocol, end to end, measured at matched compute.

  run         trains the agents with dynaqpc-sim (one CSV per agent and planning budget), then
              plots and prints Table 1
  table       Table 1 from training CSVs already written (an agent may appear at several budgets)
  plot        the plots and Table 1 from a folder of CSVs
  trajectory  runs a learned agent from K starts and draws the paths over the arena
  sweep       a grid of settings over a Dask cluster, merged into one CSV (docs/sweeps.md)

Outputs (in the scenario's results folder): fig13.png (mean steps per episode, band 25-75 % of
sets), table1.md, trajectories.png.

Table 1, per agent and planning budget: planning updates per real step ((updates - steps) /
steps from the CSV), sets learned k/n, real steps and robot time to learn averaged over ALL sets
(a set that never learns counts its whole run), episodes to learn, robot seconds per real step
(the paper: 0.192 s). Learned: the trailing --smooth (5) episode mean of steps stays at or
below --threshold (or --learned-factor x the set's final mean) to the end of the set; to learn
= the episodes up to the one where it gets there for good.

`run --planning 5,1000,0` runs every Dyna agent at each budget (0 = the MCU's idle time,
modelled) into <agent>-p<N>.csv; Q-learning, which does not plan, runs once into q.csv.
"""

MAX_PLANNING = 1000000


def planning_list(text: str) -> List[int]:
    conv = int_in(0, MAX_PLANNING)
    try:
        values = [conv(t.strip()) for t in text.split(",") if t.strip()]
    except argparse.ArgumentTypeError as e:
        raise argparse.ArgumentTypeError(f"{e} (updates per real step, 0..{MAX_PLANNING:,}; 0 = idle time)")
    if not values:
        raise argparse.ArgumentTypeError("no budget given")
    if len(set(values)) != len(values):
        raise argparse.ArgumentTypeError(f"{text!r} names a budget twice")
    return values


def agent_list(text: str) -> List[str]:
    agents = [a.strip() for a in text.split(",") if a.strip()]
    known = registry.names()
    bad = [a for a in agents if a not in known]
    if bad or not agents:
        raise argparse.ArgumentTypeError(f"{','.join(bad) or text!r}: agents are {', '.join(known)}")
    if len(set(agents)) != len(agents):
        raise argparse.ArgumentTypeError(f"{text!r} names an agent twice")
    return agents


def scenario_name(scenario: str) -> str:
    return Path(scenario).stem if scenario.endswith(".scn") else scenario


def _settings(args) -> LearnSettings:
    s = LearnSettings(args.learned_steps, args.learned_factor, args.final_window, args.smooth)
    s.check()
    return s


def write_text(path: str, text: str) -> None:
    try:
        with open(path, "w", encoding="utf-8") as f:
            f.write(text)
    except OSError as e:
        raise ToolError(f"cannot write {path}: {e.strerror or e}") from None


def warn_table(summaries, settings: LearnSettings) -> None:
    for w in stats.table_warnings(summaries, settings):
        print(f"warning: Table 1: {w}", file=sys.stderr)


def report(
    runs,
    out_dir: str,
    settings: LearnSettings,
    scenario: str,
    title: str = "",
    trajectory: Optional[str] = None,
    arena: Optional[str] = None,
    cap: Optional[int] = None,
    image: Optional[str] = None,
    agent: Optional[str] = None,
) -> str:
    """fig13.png, table1.md and (given a trajectory) trajectories.png in out_dir; returns Table 1."""
    try:
        os.makedirs(out_dir, exist_ok=True)
    except OSError as e:
        raise ToolError(f"cannot make {out_dir}: {e.strerror or e}") from None
    summaries = stats.summarise_all(runs, settings)
    table = stats.table_markdown(summaries, settings, scenario)
    warn_table(summaries, settings)
    plots.plot_fig13(runs, os.path.join(out_dir, "fig13.png"), title or scenario, settings.learned_steps, cap)
    write_text(os.path.join(out_dir, "table1.md"), table)
    if trajectory:
        plots.plot_trajectories(
            trajectory, arena, os.path.join(out_dir, "trajectories.png"), title or scenario, image=image, agent=agent
        )
    return table


def run_plan(args):
    """(agent, budget or None, CSV path) for each training the run does, in order."""
    out_dir = os.path.join(args.results, scenario_name(args.scenario))
    plan = []
    for agent in args.agents:
        if args.planning is None or agent == "q":
            plan.append((agent, None, os.path.join(out_dir, f"{agent}.csv")))
        else:
            plan += [(agent, n, os.path.join(out_dir, f"{agent}-p{n}.csv")) for n in args.planning]
    return out_dir, plan


def protocol(args):
    sets, episodes = args.sets, args.episodes
    if sets is None or episodes is None:
        proto = orchestrate.scenario_protocol(args.scenario)
        if proto is None:
            orchestrate.check_scenario(args.scenario)
            raise ToolError(f"--scenario {args.scenario}: cannot read its protocol; give --sets and --episodes")
        sets = sets if sets is not None else proto[0]
        episodes = episodes if episodes is not None else proto[1]
    return sets, episodes


def _complete(path: str, agent: str, sets: int, episodes: int) -> bool:
    from .runs import read_runs

    try:
        r = read_runs(path).get(agent)
    except ToolError:
        return False
    return r is not None and len(r.sets) == sets and len(r.episodes) >= episodes


def _new_dirs(path: str) -> list:
    """The folders making `path` that do not exist yet, deepest first."""
    made = []
    p = os.path.abspath(path)
    while not os.path.exists(p):
        made.append(p)
        parent = os.path.dirname(p)
        if parent == p:
            break
        p = parent
    return made


def _remove_if_empty(dirs) -> None:
    """Removes the folders a failed run made, deepest first, as long as they are empty."""
    for d in dirs:
        try:
            os.rmdir(d)
        except OSError:
            return


def cmd_run(args) -> int:
    settings = _settings(args)
    out_dir, plan = run_plan(args)
    sets, episodes = protocol(args)
    made = _new_dirs(out_dir)
    try:
        return _run(args, settings, out_dir, plan, sets, episodes)
    except BaseException:
        _remove_if_empty(made)  # a failed run leaves no empty folder behind
        raise


def _run(args, settings, out_dir, plan, sets, episodes) -> int:
    extra = shlex.split(args.sim_args)
    if args.planning is not None and "--planning" in extra:
        raise ToolError("--sim-args: give the planning budget with --planning, not in --sim-args")
    for agent, budget, csv_path in plan:
        if args.skip_existing and _complete(csv_path, agent, sets, episodes):
            print(f"{csv_path} is complete: skipped")
            continue
        orchestrate.check_scenario(args.scenario)  # before the first training: a misspelt name
        desc = agent if budget is None else f"{agent} N={budget}" if budget else f"{agent} idle"
        orchestrate.run_sets(
            args.sim,
            args.scenario,
            agent,
            csv_path,
            sets,
            episodes,
            args.seed,
            args.jobs,
            budget,
            extra,
            progress=not args.no_progress,
            desc=desc,
        )
    traj = arena = agent = None
    if args.load:
        traj, arena, agent = _run_trajectory(args, out_dir)
    # Only this run's CSVs: the folder may hold others (tools/dev.sh demo's long run, a user's).
    runs = read_csvs([p for _, _, p in plan], out_dir, allow_repeats=True)
    default_budget = None if "--planning" in extra else orchestrate.scenario_planning(args.scenario)
    for r, (_, budget, _) in zip(runs, plan):
        r.budget = budget if budget is not None else default_budget  # None: not known (a file elsewhere)
    table = report(
        runs,
        out_dir,
        settings,
        scenario_name(args.scenario),
        trajectory=traj,
        arena=arena,
        cap=orchestrate.scenario_step_cap(args.scenario),
        image=args.load,
        agent=agent,
    )
    print(table)
    print(f"wrote {out_dir}/fig13.png, {out_dir}/table1.md")
    return 0


def _run_trajectory(args, out_dir: str):
    if not os.path.isfile(args.load):
        raise ToolError(f"--load {args.load}: no such file (a flash image from dynaqpc-sim train --save)")
    traj, arena = os.path.join(out_dir, "traj.csv"), os.path.join(out_dir, "arena.json")
    orchestrate.check_output_csv(traj, TRAJECTORY_COLUMNS, "trajectory")
    said = orchestrate.run_command(
        [
            args.sim,
            "run",
            "--scenario",
            args.scenario,
            "--load",
            args.load,
            "--starts",
            str(args.starts),
            "--trajectory",
            traj,
            "--arena",
            arena,
        ]
    )
    # Its summary names the agent the image holds: "dyna-qpc on paper-lab (frozen): ...".
    m = re.search(r"^(\S+) on \S+ \((?:frozen|learning)", said, re.M)
    return traj, arena, m.group(1) if m else None


def cmd_trajectory(args) -> int:
    orchestrate.check_scenario(args.scenario)
    out_dir = args.out or os.path.join(args.results, scenario_name(args.scenario))
    made = _new_dirs(out_dir)
    os.makedirs(out_dir, exist_ok=True)
    try:
        traj, arena, agent = _run_trajectory(args, out_dir)
    except BaseException:
        _remove_if_empty(made)
        raise
    png = os.path.join(out_dir, "trajectories.png")
    plots.plot_trajectories(traj, arena, png, scenario_name(args.scenario), image=args.load, agent=agent)
    print(f"wrote {png}")
    return 0


def cmd_plot(args) -> int:
    settings = _settings(args)
    out_dir = args.out or args.csv_dir
    runs = read_csv_dir(args.csv_dir)
    traj, arena = plots.trajectory_inputs(args.csv_dir, args.trajectory, args.arena)
    name = args.scenario or os.path.basename(os.path.normpath(args.csv_dir))
    cap = orchestrate.scenario_step_cap(args.scenario) if args.scenario else None
    table = report(runs, out_dir, settings, name, args.title or name, traj, arena, cap=cap)
    print(table)
    print(f"wrote {out_dir}/fig13.png, {out_dir}/table1.md")
    return 0


def cmd_table(args) -> int:
    settings = _settings(args)
    runs = read_csvs(args.csv, allow_repeats=True)
    summaries = stats.summarise_all(runs, settings)
    table = stats.table_markdown(summaries, settings, args.scenario or "")
    warn_table(summaries, settings)
    if args.out:
        write_text(args.out, table)
    print(table)
    return 0


def learn_opts(sp) -> None:
    sp.add_argument(
        "--threshold",
        "--learned-steps",
        dest="learned_steps",
        type=float_in(0, lo_open=True),
        default=None,
        metavar="STEPS",
        help="learned when the trailing mean of steps per episode stays <= STEPS (paper-lab 50, paper-sim 500)",
    )
    sp.add_argument(
        "--learned-factor",
        type=float_in(0, lo_open=True),
        default=1.5,
        help="without --threshold: this times the set's final mean (default %(default)s)",
    )
    sp.add_argument(
        "--final-window", type=int_in(1), default=10, help="episodes in the final mean (default %(default)s)"
    )
    sp.add_argument("--smooth", type=int_in(1), default=5, help="trailing mean window (episodes, default 5)")


def sim_opts(sp) -> None:
    sp.add_argument("--scenario", required=True, help="simulator scenario (paper-sim, paper-lab or a .scn file)")
    sp.add_argument("--sim", default=orchestrate.default_sim(), help="dynaqpc-sim binary (default %(default)s)")
    sp.add_argument("--results", default="results", help="results root (default %(default)s)")


def build_parser() -> argparse.ArgumentParser:
    p = ToolArgumentParser(
        prog="dynaqpc-experiment", description=DOC, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    sub = p.add_subparsers(dest="command", required=True)

    r = sub.add_parser("run", help="train every agent (at every budget), then plot and tabulate")
    sim_opts(r)
    r.add_argument(
        "--agents",
        type=agent_list,
        default=list(DEFAULT_AGENTS),
        help=f"comma-separated, out of {','.join(registry.names())} (default {','.join(DEFAULT_AGENTS)})",
    )
    r.add_argument(
        "--planning",
        type=planning_list,
        default=None,
        metavar="N[,N...]",
        help="planning updates per real step for the Dyna agents, e.g. 5,1000,0 (0: the MCU's "
        "idle time, its cost modelled); default: the scenario's",
    )
    r.add_argument("--sets", type=int_in(1, 100000), default=None, help="default: the scenario's protocol")
    r.add_argument("--episodes", type=int_in(1, 10000000), default=None, help="default: the scenario's protocol")
    r.add_argument("--seed", type=int_in(0, 2**32 - 1), default=1)
    r.add_argument("--jobs", type=int_in(1, 256), default=1, help="sets run at once (default 1)")
    r.add_argument("--skip-existing", action="store_true", help="keep trainings whose CSV is already complete")
    r.add_argument("--sim-args", default="", help="extra arguments for 'dynaqpc-sim train'")
    r.add_argument("--load", metavar="FILE", help="a learned agent: also run and draw trajectories")
    r.add_argument("--starts", type=int_in(1, 100000), default=5, help="trajectory starts (default %(default)s)")
    r.add_argument("--no-progress", action="store_true", help="no progress bar")
    learn_opts(r)
    r.set_defaults(fn=cmd_run)

    t1 = sub.add_parser("table", help="Table 1 from training CSVs")
    t1.add_argument(
        "--csv",
        nargs="+",
        required=True,
        metavar="CSV",
        help="training CSVs; <agent>-p<N>.csv is read as planning budget N",
    )
    t1.add_argument("--scenario", default=None, help="its name, for the title and the paper's figures")
    t1.add_argument("--out", default=None, metavar="FILE.md", help="also write the table here")
    learn_opts(t1)
    t1.set_defaults(fn=cmd_table)

    pl = sub.add_parser("plot", help="plots and table from existing CSVs")
    pl.add_argument("--csv-dir", required=True)
    pl.add_argument("--out", default=None, help="output folder (default: the CSV folder)")
    pl.add_argument("--title", default=None)
    pl.add_argument("--scenario", default=None, help="scenario name for the paper's figures (default: the folder's)")
    pl.add_argument("--trajectory", default=None, help="trajectory CSV (default: CSV folder's traj.csv)")
    pl.add_argument("--arena", default=None, help="arena JSON (default: CSV folder's arena.json)")
    learn_opts(pl)
    pl.set_defaults(fn=cmd_plot)

    t = sub.add_parser("trajectory", help="run a learned agent from K starts and draw the paths")
    sim_opts(t)
    t.add_argument("--load", required=True, metavar="FILE")
    t.add_argument("--starts", type=int_in(1, 100000), default=5)
    t.add_argument("--out", default=None)
    t.set_defaults(fn=cmd_trajectory)

    from . import sweep

    sweep.add_parser(sub, orchestrate.default_sim(), lambda a: sweep.cmd_sweep(a), planning_list)
    return p


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)
    return run_main(lambda: args.fn(args))


if __name__ == "__main__":
    sys.exit(main())
