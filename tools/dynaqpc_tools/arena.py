# SPDX-License-Identifier: MIT
"""The arena JSON file the simulator writes, and drawing it with matplotlib.

Format (metres, degrees)::

    {"width": W, "height": H,
     "obstacles": [{"kind": "box", "cx": .., "cy": .., "w": .., "h": .., "angle_deg": ..},
                   {"kind": "circle", "cx": .., "cy": .., "r": ..}],
     "goal": {"cx": .., "cy": .., "r": .., ["cells": [[x0, y0, x1, y1], ..]]},
     "beacons": [{"id": "..", "x": .., "y": .., "z": ..}]}
"""

from __future__ import annotations

import math
from typing import Any, Dict

from .common import ToolError, read_json


def _num(obj: Dict[str, Any], key: str, where: str, positive: bool = False) -> float:
    v = obj.get(key)
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise ToolError(f"arena: {where}.{key} must be a number, got {v!r}")
    if positive and v <= 0:
        raise ToolError(f"arena: {where}.{key} must be > 0, got {v}")
    return float(v)


def load_arena(path: str) -> Dict[str, Any]:
    """Reads and checks an arena file; a ToolError names the first problem."""
    a = read_json(path, "arena ")
    if not isinstance(a, dict):
        raise ToolError(f"arena {path}: not a JSON object")
    _num(a, "width", "arena", True)
    _num(a, "height", "arena", True)
    for i, ob in enumerate(a.get("obstacles", [])):
        where = f"obstacles[{i}]"
        if not isinstance(ob, dict) or ob.get("kind") not in ("box", "circle"):
            raise ToolError(f"arena: {where} needs kind 'box' or 'circle'")
        _num(ob, "cx", where), _num(ob, "cy", where)
        if ob["kind"] == "box":
            _num(ob, "w", where, True), _num(ob, "h", where, True)
            ob.setdefault("angle_deg", 0.0)
            _num(ob, "angle_deg", where)
        else:
            _num(ob, "r", where, True)
    if a.get("goal") is not None:
        for k in ("cx", "cy"):
            _num(a["goal"], k, "goal")
        _num(a["goal"], "r", "goal", True)
        cells = a["goal"].get("cells", [])
        if not isinstance(cells, list):
            raise ToolError("arena: goal.cells must be a list")
        for i, c in enumerate(cells):
            if (
                not isinstance(c, list)
                or len(c) != 4
                or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in c)
                or c[2] <= c[0]
                or c[3] <= c[1]
            ):
                raise ToolError(f"arena: goal.cells[{i}] must be [x0, y0, x1, y1] with x1 > x0, y1 > y0")
    for i, b in enumerate(a.get("beacons", [])):
        for k in ("x", "y", "z"):
            _num(b, k, f"beacons[{i}]")
    return a


def box_corners(ob: Dict[str, Any]):
    c, s = math.cos(math.radians(ob["angle_deg"])), math.sin(math.radians(ob["angle_deg"]))
    hw, hh = ob["w"] / 2.0, ob["h"] / 2.0
    return [
        (ob["cx"] + c * dx - s * dy, ob["cy"] + s * dx + c * dy)
        for dx, dy in ((-hw, -hh), (hw, -hh), (hw, hh), (-hw, hh))
    ]


def draw_arena(ax, arena: Dict[str, Any]) -> None:
    """Walls, obstacles (grey), goal (green), beacons (triangles) on a matplotlib Axes."""
    from matplotlib.patches import Circle, Polygon, Rectangle

    w, h = arena["width"], arena["height"]
    ax.add_patch(Rectangle((0, 0), w, h, fill=False, edgecolor="black", linewidth=2))
    for ob in arena.get("obstacles", []):
        if ob["kind"] == "box":
            ax.add_patch(Polygon(box_corners(ob), closed=True, facecolor="0.6", edgecolor="0.3"))
        else:
            ax.add_patch(Circle((ob["cx"], ob["cy"]), ob["r"], facecolor="0.6", edgecolor="0.3"))
    goal = arena.get("goal")
    if goal and goal.get("cells"):  # the goal is the cells; the circle that chose them is outlined
        for i, (x0, y0, x1, y1) in enumerate(goal["cells"]):
            ax.add_patch(
                Rectangle(
                    (x0, y0),
                    x1 - x0,
                    y1 - y0,
                    facecolor="tab:green",
                    alpha=0.35,
                    edgecolor="tab:green",
                    label="goal" if i == 0 else None,
                )
            )
        ax.add_patch(Circle((goal["cx"], goal["cy"]), goal["r"], fill=False, edgecolor="tab:green", linestyle="--"))
    elif goal:
        ax.add_patch(
            Circle(
                (goal["cx"], goal["cy"]),
                goal["r"],
                facecolor="tab:green",
                alpha=0.35,
                edgecolor="tab:green",
                label="goal",
            )
        )
    for k, b in enumerate(arena.get("beacons", []), 1):
        ax.plot(
            b["x"],
            b["y"],
            marker="^",
            color="black",
            markerfacecolor="white",
            markersize=8,
            markeredgewidth=1.2,
            zorder=4,
        )
        # B1, B2, ... (arena_key says what they are); the label leans into the room, so a beacon on a
        # wall or in a corner keeps it on the plot.
        right, up = b["x"] < w / 2, b["y"] < h / 2
        ax.annotate(
            f"B{k}",
            (b["x"], b["y"]),
            textcoords="offset points",
            xytext=(6 if right else -6, 6 if up else -6),
            ha="left" if right else "right",
            va="bottom" if up else "top",
            fontsize=7.5,
            color="black",
            zorder=4,
        )
    margin = 0.05 * max(w, h)
    ax.set_xlim(-margin, w + margin)
    ax.set_ylim(-margin, h + margin)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")


def arena_key(arena: Dict[str, Any]) -> list:
    """Legend entries for what draw_arena draws: walls and obstacles, the goal, the beacons."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    keys = [Patch(facecolor="0.6", edgecolor="0.3", label="obstacle (black frame: the walls)")]
    keys += goal_key(arena, "goal: the state cells that end an episode")
    beacons = arena.get("beacons", [])
    if beacons:
        keys.append(
            Line2D(
                [],
                [],
                marker="^",
                linestyle="",
                color="black",
                markerfacecolor="white",
                markersize=8,
                label=f"Cricket beacon, B1-B{len(beacons)} (on the ceiling)",
            )
        )
    return keys


def goal_key(arena: Dict[str, Any], cells_label: str) -> list:
    """Legend entries for the goal draw_arena draws: its state cells (labelled `cells_label`) and
    the circle that chose them, or the circle alone; none without a goal."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    goal = arena.get("goal") or {}
    if goal.get("cells"):
        return [
            Patch(facecolor="tab:green", alpha=0.35, edgecolor="tab:green", label=cells_label),
            Line2D([], [], color="tab:green", linestyle="--", label="the goal's circle, which chose them"),
        ]
    if goal:
        return [Patch(facecolor="tab:green", alpha=0.35, edgecolor="tab:green", label="goal")]
    return []


def save_figure(fig, path: str, dpi: int) -> None:
    """Saves a PNG and closes the figure; a folder that is missing or not writable is a ToolError
    naming the path."""
    import matplotlib.pyplot as plt

    try:
        fig.savefig(path, dpi=dpi)
    except OSError as e:
        raise ToolError(f"cannot write {path}: {e.strerror or e}") from None
    finally:
        plt.close(fig)


def ray_hit(arena: Dict[str, Any], x: float, y: float, angle: float, max_len: float) -> float:
    """How far a ray from (x, y) at `angle` (rad) goes before it meets a wall or an obstacle, at
    most max_len: where a drawn range ray must stop."""
    dx, dy = math.cos(angle), math.sin(angle)
    best = max_len

    def segment(ax_, ay_, bx, by):
        nonlocal best
        ex, ey = bx - ax_, by - ay_
        den = dx * ey - dy * ex
        if abs(den) < 1e-12:
            return
        t = ((ax_ - x) * ey - (ay_ - y) * ex) / den  # along the ray
        u = ((ax_ - x) * dy - (ay_ - y) * dx) / den  # along the segment
        if 0.0 <= t < best and 0.0 <= u <= 1.0:
            best = t

    w, h = arena["width"], arena["height"]
    for a, b in (((0, 0), (w, 0)), ((w, 0), (w, h)), ((w, h), (0, h)), ((0, h), (0, 0))):
        segment(a[0], a[1], b[0], b[1])
    for ob in arena.get("obstacles", []):
        if ob["kind"] == "box":
            cs = box_corners(ob)
            for i in range(4):
                segment(cs[i][0], cs[i][1], cs[(i + 1) % 4][0], cs[(i + 1) % 4][1])
        else:
            fx, fy = x - ob["cx"], y - ob["cy"]
            bq = fx * dx + fy * dy
            cq = fx * fx + fy * fy - ob["r"] ** 2
            disc = bq * bq - cq
            if disc >= 0:
                for t in (-bq - math.sqrt(disc), -bq + math.sqrt(disc)):
                    if 0.0 <= t < best:
                        best = t
                        break
    return best
