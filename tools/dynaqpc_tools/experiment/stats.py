# SPDX-License-Identifier: MIT
"""What a run measures: when a set learned, what it cost, and Table 1.

Learned, per set: the trailing mean of steps per episode over `smooth` (5) episodes stays at or
below the threshold from some episode i to the end of the set. The threshold is absolute
(`learned_steps`, e.g. 50 on paper-lab, 500 on paper-sim) or else `learned_factor` (1.5) times
the mean of the set's last `final_window` (10) episodes.

Real steps to learn: the steps of episodes 1..i, the episode at whose end the trailing mean
reaches the threshold for good. Robot time to learn: the robot time of the same episodes. A set
that never learns counts its whole run, so the mean over ALL sets is never flattered by leaving
the slow sets out; "learned k/n" is shown beside it.

Planning updates per real step: the CSV's `updates` column counts the agent's Q updates in the
episode, real plus planning (agent_updates() of firmware/agent: stats.real_updates +
stats.planning_updates, taken per episode in host_sim/src/lockstep.cpp). Each real step makes one
real Q update, so planning updates per real step = (updates - steps) / steps, summed over every
episode of every set. Q-learning shows 0.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence

from .. import agents as registry
from ..common import ToolError
from .runs import AgentRuns

REPORT_EPISODES = (10, 50, 100, 200)
#: The paper's sampling interval: one real step.
PAPER_STEP_S = 0.192
#: The paper's figures per scenario and agent (Table 1 for the simulation, section 4.4 for the lab).
PAPER = {
    "paper-sim": {"dyna-qpc": "5.2 h (18,618 s)", "dyna-q": "8.9 h (32,193 s)", "q": "unable to learn"},
    "paper-lab": {"dyna-qpc": "2,019 steps (1.12 h)"},
}


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


#: Episodes running that must reach the goal within the threshold before relapses are counted
#: (host_sim/src/learning_record.h: the same rule as `dynaqpc-sim train`'s learning record).
LEARNED_RUN = 3


@dataclass
class Relapses:
    """After the first LEARNED_RUN episodes running that reach the goal within the threshold,
    the episodes that miss it or take more than twice the threshold."""

    learned: bool = False
    after: int = 0
    relapses: int = 0
    longest_run: int = 0


def relapses_of_set(steps: Sequence[float], reached: Sequence[float], threshold: float) -> Relapses:
    good = [bool(g) and s <= threshold for s, g in zip(steps, reached)]
    for i in range(len(good) - LEARNED_RUN + 1):
        if all(good[i : i + LEARNED_RUN]):
            out = Relapses(True)
            run = 0
            for s, g in zip(steps[i + LEARNED_RUN :], reached[i + LEARNED_RUN :]):
                out.after += 1
                if not g or s > 2 * threshold:
                    out.relapses += 1
                    run += 1
                    out.longest_run = max(out.longest_run, run)
                else:
                    run = 0
            return out
    return Relapses()


@dataclass
class LearnSettings:
    learned_steps: Optional[float] = None
    learned_factor: float = 1.5
    final_window: int = 10
    smooth: int = 5

    def check(self) -> None:
        if self.learned_steps is not None and not (self.learned_steps > 0 and math.isfinite(self.learned_steps)):
            raise ToolError(f"--threshold/--learned-steps: {self.learned_steps:g} is not a positive number")
        if not (self.learned_factor > 0 and math.isfinite(self.learned_factor)):
            raise ToolError(f"--learned-factor: {self.learned_factor:g} is not a positive number")
        if self.final_window < 1:
            raise ToolError(f"--final-window: {self.final_window} is not at least 1")
        if self.smooth < 1:
            raise ToolError(f"--smooth: {self.smooth} is not at least 1")

    def short_rule(self) -> str:
        """The threshold in a few words, for a table's title."""
        if self.learned_steps is not None:
            return f"learned: trailing {self.smooth}-episode mean <= {self.learned_steps:g} steps"
        return (
            f"learned: trailing {self.smooth}-episode mean <= {self.learned_factor:g} x the set's "
            f"last-{self.final_window} mean (no absolute threshold)"
        )

    def warnings(self, n_episodes: int) -> List[str]:
        """Why "learned" may mislead on a run of n_episodes episodes."""
        out = []
        if self.learned_steps is None and n_episodes <= self.final_window:
            out.append(
                f"the runs have {n_episodes} episodes, no more than the final window of "
                f'{self.final_window}: without --threshold, "learned" is measured against the whole '
                f"run's own mean, so a set that never improved reads as learned; give --threshold STEPS "
                f"or run more episodes"
            )
        elif self.learned_steps is None and n_episodes < 2 * self.final_window:
            out.append(
                f"the runs have {n_episodes} episodes, fewer than twice the final window of "
                f'{self.final_window}: without --threshold, "learned" is measured against the run\'s '
                f"own end; give --threshold STEPS for an absolute rule"
            )
        if n_episodes < self.smooth:
            out.append(
                f"the runs have {n_episodes} episodes, fewer than the --smooth window of "
                f"{self.smooth}: the trailing mean never covers a full window"
            )
        return out

    def rule(self) -> str:
        if self.learned_steps is not None:
            return f"the trailing {self.smooth}-episode mean of steps stays <= {self.learned_steps:g}"
        return (
            f"the trailing {self.smooth}-episode mean of steps stays <= {self.learned_factor:g} x "
            f"the set's mean of its last {self.final_window} episodes"
        )


@dataclass
class SetResult:
    set: int
    learned: bool
    episodes: int  # to learn (1-based episode i), or the whole run
    steps: float  # real steps to learn, or the whole run's
    robot_time_s: float  # the same episodes' robot time
    threshold: float = 0.0  # steps: the set's learned threshold (absolute, or relative to its end)
    relapses: Optional[Relapses] = None  # with an absolute threshold and the goal column


def set_results(runs: AgentRuns, settings: LearnSettings) -> List[SetResult]:
    out = []
    for s, row_steps, row_time in zip(runs.sets, runs.steps, runs.robot_time_s):
        if settings.learned_steps is not None:
            threshold = settings.learned_steps
        else:
            tail = row_steps[-settings.final_window :]
            threshold = settings.learned_factor * float(sum(tail)) / len(tail)
        i = learned_episode_index(list(row_steps), threshold, settings.smooth)
        n = len(row_steps) if i is None else i + 1
        rel = None
        if settings.learned_steps is not None and runs.reached is not None:
            rel = relapses_of_set(list(row_steps), list(runs.reached[len(out)]), threshold)
        out.append(
            SetResult(s, i is not None, n, float(sum(row_steps[:n])), float(sum(row_time[:n])), float(threshold), rel)
        )
    return out


def mean_sd(xs: Sequence[float]):
    if not xs:
        return None, None
    m = sum(xs) / len(xs)
    sd = math.sqrt(sum((x - m) ** 2 for x in xs) / (len(xs) - 1)) if len(xs) > 1 else 0.0
    return m, sd


@dataclass
class AgentSummary:
    agent: str
    label: str
    source: str
    budget: Optional[int]
    n_sets: int
    n_episodes: int
    sets: List[SetResult]
    real_steps: int
    robot_time_s: float
    updates: int
    wall_s: float
    mean_steps_at: Dict[int, Optional[float]]

    @property
    def n_learned(self) -> int:
        return sum(1 for r in self.sets if r.learned)

    def relapse_text(self) -> str:
        """Relapses after learning over every set that reached the goal within the threshold
        LEARNED_RUN episodes running: 'r/n (p %) in K sets, longest L'. K is that rule's count of
        sets, which may differ from the 'Sets learned' column's trailing mean."""
        rel = [r.relapses for r in self.sets if r.relapses is not None and r.relapses.learned]
        if not any(r.relapses is not None for r in self.sets):
            return "–"
        if not rel:
            return "none learned"
        after = sum(r.relapses.after for r in self.sets if r.relapses is not None)
        n = sum(r.relapses.relapses for r in self.sets if r.relapses is not None)
        longest = max(r.relapses.longest_run for r in self.sets if r.relapses is not None)
        pct = 100.0 * n / after if after else 0.0
        sets = f"{len(rel)} set" + ("" if len(rel) == 1 else "s")
        return f"{n}/{after} ({pct:.1f} %) in {sets}, longest {longest}"

    @property
    def steps_mean_sd(self):
        """Real steps to learn over ALL sets (a set that never learned counts its whole run)."""
        return mean_sd([r.steps for r in self.sets])

    @property
    def hours_mean_sd(self):
        return mean_sd([r.robot_time_s / 3600.0 for r in self.sets])

    @property
    def episodes_mean_sd(self):
        return mean_sd([float(r.episodes) for r in self.sets])

    @property
    def planning_per_step(self) -> float:
        """(updates - steps) / steps over the whole run: planning Q updates per real step."""
        return (self.updates - self.real_steps) / self.real_steps if self.real_steps else 0.0

    @property
    def s_per_step(self) -> float:
        return self.robot_time_s / self.real_steps if self.real_steps else 0.0


def summarise(runs: AgentRuns, settings: LearnSettings, label: Optional[str] = None) -> AgentSummary:
    mean_curve = runs.steps.mean(axis=0)
    at = {e: (float(mean_curve[e - 1]) if e <= len(mean_curve) else None) for e in REPORT_EPISODES}
    return AgentSummary(
        runs.agent,
        label or registry.labels().get(runs.agent, runs.agent),
        runs.source,
        runs.budget,
        len(runs.sets),
        len(runs.episodes),
        set_results(runs, settings),
        int(runs.steps.sum()),
        float(runs.robot_time_s.sum()),
        runs.total_updates,
        runs.wall_s,
        at,
    )


def agent_rank(agent: str) -> int:
    order = registry.names()
    return order.index(agent) if agent in order else len(order)


def summarise_all(runs: Sequence[AgentRuns], settings: LearnSettings) -> List[AgentSummary]:
    """Summaries in table order (budget, then Q, Dyna-Q, Dyna-QPC). An agent that appears more
    than once (several budgets or CSVs) is labelled with its CSV's name."""
    from pathlib import Path

    settings.check()
    count: Dict[str, int] = {}
    for r in runs:
        count[r.agent] = count.get(r.agent, 0) + 1
    out = []
    for r in runs:
        label = registry.labels().get(r.agent, r.agent)
        if count[r.agent] > 1 and r.budget is None and r.source:
            label += f" ({Path(r.source).name})"
        out.append(summarise(r, settings, label))
    return sorted(
        out, key=lambda s: (-1 if s.budget is None else (s.budget if s.budget else 10**9), agent_rank(s.agent), s.label)
    )


def budget_text(s: AgentSummary) -> str:
    if s.agent == "q":
        return "none (Q-learning)"
    if s.budget is None:
        # The CSV does not say what --planning was; its name can (runs.budget_from_name()).
        return "not in the CSV (name it AGENT-pN.csv)"
    return "idle time (MCU model)" if s.budget == 0 else f"{s.budget:,}"


def _pm(m, sd, fmt):
    return "–" if m is None else f"{fmt.format(m)} ± {fmt.format(sd)}"


def table_markdown(summaries: Sequence[AgentSummary], settings: LearnSettings, scenario: str = "") -> str:
    """Table 1 for one scenario: one row per agent and planning budget."""
    if not summaries:
        raise ToolError("no runs to tabulate")
    paper = PAPER.get(scenario, {})
    n_max = max(s.n_episodes for s in summaries)
    at_eps = [e for e in REPORT_EPISODES if e <= n_max]
    head = [
        "Agent",
        "Planning budget",
        "Planning updates / real step",
        "Sets learned",
        "Real steps to learn",
        "Robot time to learn (h)",
        "Episodes to learn",
        f"Robot s / real step (paper {PAPER_STEP_S})",
        "Relapses after learning",
    ]
    head += [f"Mean steps ep. {e}" for e in at_eps]
    if paper:
        head.append("Paper")
    lines = []
    if scenario:
        lines += [f"### Table 1: {scenario} ({settings.short_rule()})", ""]
    lines += ["| " + " | ".join(head) + " |", "|---|---|" + "---:|" * (len(head) - 2)]
    for s in summaries:
        cells = [
            s.label,
            budget_text(s),
            f"{s.planning_per_step:,.1f}",
            f"{s.n_learned}/{s.n_sets}",
            _pm(*s.steps_mean_sd, "{:,.0f}"),
            _pm(*s.hours_mean_sd, "{:.2f}"),
            _pm(*s.episodes_mean_sd, "{:.1f}"),
            f"{s.s_per_step:.3f}",
            s.relapse_text(),
        ]
        cells += [f"{s.mean_steps_at[e]:.1f}" if s.mean_steps_at[e] is not None else "–" for e in at_eps]
        if paper:
            cells.append(paper.get(s.agent, "–"))
        lines.append("| " + " | ".join(cells) + " |")
    if settings.learned_steps is not None:
        thresholds = f" (threshold {settings.learned_steps:g} steps for every set)"
    else:

        def _span(s):
            t = sorted(r.threshold for r in s.sets)
            return f"{s.label} {t[0]:,.1f}" + (f"–{t[-1]:,.1f}" if t[-1] != t[0] else "")

        thresholds = (
            "; the thresholds this gives, in steps, per set: "
            + "; ".join(_span(s) for s in summaries)
            + ". No absolute threshold was given (--threshold)"
        )
    warn = settings.warnings(min(s.n_episodes for s in summaries))
    lines += [
        "",
        f"Learned: {settings.rule()} to the end of the set{thresholds}. Real steps and robot time to learn: "
        "those of the episodes up to that point, mean ± sample sd over ALL sets (a set that never "
        "learned counts its whole run). Planning updates / real step: (updates - steps) / steps "
        "from the CSV's updates column (real plus planning Q updates). Relapses after learning "
        f"(with --threshold): after a set first reached the goal within the threshold {LEARNED_RUN} episodes "
        "running, the episodes that missed it or took more than twice the threshold, of all episodes after "
        "those; longest: the longest run of them in one set.",
        "",
    ]
    lines += [f"**Warning:** {w}." for w in warn]
    if warn:
        lines.append("")
    return "\n".join(lines)


def table_warnings(summaries: Sequence[AgentSummary], settings: LearnSettings) -> List[str]:
    """What table_markdown() warns about, for stderr."""
    return settings.warnings(min(s.n_episodes for s in summaries)) if summaries else []


def measure(
    csv_paths: Sequence[str],
    threshold: Optional[float] = None,
    smooth: int = 5,
    scenario: str = "",
    learned_factor: float = 1.5,
    final_window: int = 10,
):
    """The reusable measurement: reads training CSVs (an agent may appear in several, e.g. at
    several budgets), returns (summaries, Table 1 as markdown)."""
    from .runs import read_csvs

    settings = LearnSettings(threshold, learned_factor, final_window, smooth)
    summaries = summarise_all(read_csvs(csv_paths, allow_repeats=True), settings)
    return summaries, table_markdown(summaries, settings, scenario)
