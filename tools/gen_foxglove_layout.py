#!/usr/bin/env python3
# SPDX-License-Identifier: MIT
"""Writes docs/foxglove-layout.json, the Foxglove layout for `dynaqpc-monitor --foxglove` (and
its recordings), with foxglove-sdk's layout types (foxglove.layouts).

    .venv/bin/python tools/gen_foxglove_layout.py [-o FILE]

Left: a 3D panel fixed on the arena frame with the arena, the value map, the pose, the
rays and the robot's label, the trail and the bumps. Right: plots of the learning (TLM_LEARN
Step and Reward, TLM_EPISODE Steps) and of the scheduler (TLM_SCHED QueueLength, PlanUpdates,
IdlePercent), the mode's transitions (FW_STATUS Mode_name, /robot/state), and the operator's
commands and answers (/can/TOOL_ACK) as raw messages.
"""

import argparse
import pathlib
import sys

import foxglove.layouts as fl

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUT = ROOT / "docs" / "foxglove-layout.json"


def _plot(title: str, *series: tuple) -> fl.PlotPanel:
    """A plot panel with a legend: one line per (message path, label)."""
    return fl.PlotPanel(
        title=title,
        config=fl.PlotConfig(
            paths=[fl.PlotSeries(value=value, label=label) for value, label in series],
            show_legend=True,
        ),
    )


def layout() -> fl.Layout:
    topics = {
        t: fl.BaseRendererSceneUpdateTopicSettings(visible=True)
        for t in ("/arena", "/robot/values", "/robot/rays", "/robot/trail", "/robot/bumps")
    }
    topics["/robot/pose"] = fl.BaseRendererPoseTopicSettings(visible=True, type="arrow", color="#1f77b4")
    topics["/robot/true_pose"] = fl.BaseRendererPoseTopicSettings(visible=True, type="arrow", color="#2ca02c")
    three_d = fl.ThreeDeePanel(
        title="robot in its arena",
        config=fl.ThreeDeeConfig(
            fixed_frame="arena",
            follow_tf="arena",
            topics=topics,
            camera_state=fl.ThreeDeeCameraState(distance=12.0, perspective=False, phi=0.0, target=(4.0, 4.0, 0.0)),
        ),
    )
    learn = _plot(
        "learning",
        ("/can/TLM_LEARN.Step", "step"),
        ("/can/TLM_LEARN.Reward", "reward"),
        ("/can/TLM_EPISODE.Steps", "episode's steps"),
    )
    sched = _plot(
        "planning",
        ("/can/TLM_SCHED.QueueLength", "queue"),
        ("/can/TLM_SCHED.PlanUpdates", "plan updates / period"),
        ("/can/TLM_SCHED.IdlePercent", "idle %"),
    )
    modes = fl.StateTransitionsPanel(
        title="mode",
        config=fl.StateTransitionsConfig(
            paths=[
                fl.StateTransitionsSeries(value="/can/FW_STATUS.Mode_name", label="FW_STATUS"),
                fl.StateTransitionsSeries(value="/robot/state.fix", label="fix"),
            ]
        ),
    )
    answers = fl.RawMessagesPanel(title="operator's answers", config=fl.RawMessagesConfig(topic_path="/can/TOOL_ACK"))
    right = fl.SplitContainer(
        direction="column",
        items=[
            fl.SplitItem(proportion=2, content=learn),
            fl.SplitItem(proportion=2, content=sched),
            fl.SplitItem(proportion=1, content=modes),
            fl.SplitItem(proportion=1, content=answers),
        ],
    )
    return fl.Layout(
        content=fl.SplitContainer(
            direction="row",
            items=[fl.SplitItem(proportion=3, content=three_d), fl.SplitItem(proportion=2, content=right)],
        )
    )


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--output", type=pathlib.Path, default=OUT)
    args = ap.parse_args()
    import json

    text = json.dumps(json.loads(layout().to_json()), indent=2) + "\n"
    args.output.write_text(text)
    print(f"wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
