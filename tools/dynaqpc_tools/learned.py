# SPDX-License-Identifier: MIT
"""dynaqpc-learned: what the robot learned, drawn from its flash image.

The image (``dynaqpc-sim train --save FILE``, or a board's backup of its learned-data sector) is
decoded by the firmware itself: ``dynaqpc-sim learned --scenario S --load FILE`` boots the
firmware's own restore code on it (learned_store_load: CRCs, layout, the agent's checks) and
prints what it restored as JSON, read through the agent's own functions (agent_walk: each module
describes its rows, visits, predictions and counts; agent_greedy). This tool only combines and
draws that JSON:
no offset of the store's layout is written down a second time here, so a change to the firmware's
tables cannot make the picture silently wrong.

A state is (x cell, y cell, heading sector, range code) (the scenario's ``encode`` line). The map
is over (cell, heading); where a (cell, heading) has Q rows for several range codes (the robot
perceived different codes at different places within the cell), one is shown, chosen by
``--combine``:

- ``max`` (default): the code with the largest V = max_a Q (ties: the most experienced);
- ``visits``: the code with the most real experience there (the sum over actions of CMAC-Model's
  training counts, Dyna-QPC; Dyna-Q's tried actions; ties, and Q-learning, which keeps no
  counts, by the larger V): what the robot usually saw in that cell.

On paper-lab (Dyna-QPC, 60 episodes, planning 1,000, seeds 1, 2, 3, 7, 11) the two agree on four
seeds; on the fifth, following ``visits`` arrows ends in loops from 46 of 336 starts and ``max``
arrows reach the goal from 90 % (docs/tools.md).

Exit status: 0 drawn, 2 bad usage or an image that cannot be restored (one line saying why).
"""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import textwrap
from pathlib import Path
from typing import Any, Dict, List, Optional, Tuple

from . import agents as registry
from .arena import goal_key, save_figure
from .common import ToolArgumentParser, ToolError, read_json, repo_root, run_main

ACTIONS = ("forward", "backward", "left", "right")
FORMAT = "dynaqpc-learned 1"


def default_sim() -> str:
    root = repo_root()
    return str((root or Path.cwd()) / "build" / "host-release" / "bin" / "dynaqpc-sim")


def dump_image(sim: str, scenario: str, image: str, agent: Optional[str] = None) -> Dict[str, Any]:
    """The simulator's JSON of what `image` holds; a ToolError with its one line if it refuses."""
    if not os.path.exists(image):
        raise ToolError(f"cannot open {image}: no such file")
    if not (os.path.isfile(sim) and os.access(sim, os.X_OK)):
        raise ToolError(f"--sim: {sim} is not an executable (build it: cmake --build --preset host-release)")
    argv = [sim, "learned", "--scenario", scenario, "--load", image]
    if agent:
        argv += ["--agent", agent]
    try:
        p = subprocess.run(argv, capture_output=True, text=True, timeout=120)
    except OSError as e:
        raise ToolError(f"cannot run {sim}: {e}") from e
    if p.returncode != 0:
        lines = [ln for ln in p.stderr.strip().splitlines() if ln.strip()]
        msg = lines[-1] if lines else f"exit status {p.returncode}"
        # The simulator's line names itself; keep what it says about the image.
        if msg.startswith("dynaqpc-sim learned: "):
            msg = msg[len("dynaqpc-sim learned: ") :]
        if msg.startswith("--load: "):
            msg = msg[len("--load: ") :]
        raise ToolError(msg)
    for ln in p.stderr.strip().splitlines():
        print(ln.replace("dynaqpc-sim learned", "dynaqpc-learned"), file=sys.stderr)
    try:
        d = json.loads(p.stdout)
    except ValueError as e:
        raise ToolError(f"{sim} learned gave no JSON ({e})") from e
    if d.get("format") != FORMAT:
        raise ToolError(f"{sim} learned speaks {d.get('format')!r}, this tool {FORMAT!r}")
    return d


def load_dump(path: str) -> Dict[str, Any]:
    d = read_json(path)
    if not isinstance(d, dict) or d.get("format") != FORMAT:
        raise ToolError(f"{path}: not the output of dynaqpc-sim learned ({FORMAT})")
    return d


def combine(dump: Dict[str, Any], how: str = "max") -> Dict[str, Any]:
    """Per (cell, heading): the row of one range code (see the module's doc), and per cell the
    headings visited and modelled. Returns the view --json writes."""
    cols = dump["states_columns"]
    ix = {c: i for i, c in enumerate(cols)}
    best: Dict[Tuple[int, int, int], Tuple[Tuple[float, float], list]] = {}
    codes: Dict[Tuple[int, int, int], List[int]] = {}
    visited: Dict[Tuple[int, int], set] = {}
    modelled: Dict[Tuple[int, int], set] = {}
    nx, ny = dump["grid"]["cells_x"], dump["grid"]["cells_y"]
    for r in dump["states"]:
        x, y, h, c = r[ix["x"]], r[ix["y"]], r[ix["heading"]], r[ix["code"]]
        if x >= nx or y >= ny:
            # A fitted grid of 9 cells has 16 slots in its 4 bits: the slots past the room are no
            # place (the model answers for them by situation, but nothing is ever learned there).
            continue
        if r[ix["visited"]]:
            visited.setdefault((x, y), set()).add(h)
        if r[ix["modelled"]]:
            modelled.setdefault((x, y), set()).add(h)
        if not r[ix["row"]]:
            continue
        v = r[ix["v"]]
        v = -math.inf if v is None else v
        n = sum(r[ix["n"]])
        key = (n, v) if how == "visits" else (v, n)
        codes.setdefault((x, y, h), []).append(c)
        if (x, y, h) not in best or key > best[(x, y, h)][0]:
            best[(x, y, h)] = (key, r)
    cells = []
    for (x, y, h), (_, r) in sorted(best.items()):
        g = r[ix["greedy"]]
        cells.append(
            {
                "x": x,
                "y": y,
                "heading": h,
                "code": r[ix["code"]],
                "codes": sorted(codes[(x, y, h)]),
                "greedy": g,
                "action": ACTIONS[g] if g < len(ACTIONS) else str(g),
                "v": r[ix["v"]],
                "q": r[ix["q"]],
                "experience": sum(r[ix["n"]]),
                "visited": bool(r[ix["visited"]]),
            }
        )
    return {
        "format": "dynaqpc-learned view 1",
        "scenario": dump["scenario"],
        "agent": dump["agent"],
        "record": dump["record"],
        "fill": dump["fill"],
        "grid": dump["grid"],
        "combine": how,
        "actions": list(ACTIONS),
        "cells": cells,
        "visited_cells": [[x, y, sorted(hs)] for (x, y), hs in sorted(visited.items())],
        "modelled_cells": [[x, y, sorted(hs)] for (x, y), hs in sorted(modelled.items())],
    }


def cell_rect(grid: Dict[str, Any], x: int, y: int) -> Tuple[float, float, float, float]:
    """A cell's lower-left corner and size (m): from its edges (`x_edges`, `y_edges`: a grid
    fitted to the room has cells of different sizes), else the equal grid's cell_w and cell_h."""
    xe, ye = grid.get("x_edges"), grid.get("y_edges")
    if xe and ye and x + 1 < len(xe) and y + 1 < len(ye):
        return xe[x], ye[y], xe[x + 1] - xe[x], ye[y + 1] - ye[y]
    return x * grid["cell_w"], y * grid["cell_h"], grid["cell_w"], grid["cell_h"]


# --- following the arrows ------------------------------------------------------------------------


def _step(grid: Dict[str, Any], x: int, y: int, h: int, action: int) -> Tuple[int, int, int]:
    """The (cell, heading) an action leads to on the grid, as the firmware's aligned actions move
    (robot_motion.c): a step leaves the cell across the edge its heading's ray from the cell's
    centre meets first; a turn goes to the next multiple of 90 degrees, skipping one nearer than a
    quarter turn."""
    n_h = grid["headings"]
    quarter = n_h // 4
    if action in (0, 1):
        ang = 2 * math.pi * h / n_h + (math.pi if action == 1 else 0.0)
        c, s = math.cos(ang), math.sin(ang)
        _, _, cw, ch = cell_rect(grid, x, y)
        tx = (cw / 2) / abs(c) if abs(c) > 1e-6 else math.inf
        ty = (ch / 2) / abs(s) if abs(s) > 1e-6 else math.inf
        if tx < ty - 1e-9:
            return x + (1 if c > 0 else -1), y, h
        if ty < tx - 1e-9:
            return x, y + (1 if s > 0 else -1), h
        return x + (1 if c > 0 else -1), y + (1 if s > 0 else -1), h
    turns = h / quarter
    k = math.floor(turns + 0.25) + 1 if action == 2 else math.ceil(turns - 0.25) - 1
    return x, y, (k * quarter) % n_h


def follow(view: Dict[str, Any], x: int, y: int, h: int, max_steps: int = 200) -> Tuple[str, int]:
    """Follows the greedy arrows from (x, y, h): 'goal', 'left the arena', 'loop', 'no arrow' or
    'step cap', and the steps taken."""
    grid = view["grid"]
    goal = {tuple(c) for c in grid["goal_cells"]}
    arrows = {(c["x"], c["y"], c["heading"]): c["greedy"] for c in view["cells"]}
    seen = set()
    for steps in range(max_steps + 1):
        if (x, y) in goal:
            return "goal", steps
        if not (0 <= x < grid["cells_x"] and 0 <= y < grid["cells_y"]):
            return "left the arena", steps
        if (x, y, h) in seen:
            return "loop", steps
        seen.add((x, y, h))
        a = arrows.get((x, y, h))
        if a is None:
            return "no arrow", steps
        x, y, h = _step(grid, x, y, h, a)
    return "step cap", max_steps


def follow_all(view: Dict[str, Any]) -> Dict[str, Any]:
    """Follows the arrows from every visited (cell, heading) outside the goal that has an arrow."""
    goal = {tuple(c) for c in view["grid"]["goal_cells"]}
    outcomes: Dict[str, int] = {}
    starts = 0
    for c in view["cells"]:
        if not c["visited"] or (c["x"], c["y"]) in goal:
            continue
        starts += 1
        o, _ = follow(view, c["x"], c["y"], c["heading"])
        outcomes[o] = outcomes.get(o, 0) + 1
    return {"starts": starts, "outcomes": outcomes}


# --- regions the model closed off ----------------------------------------------------------------

# A state reads "hopeless" when its V is within this share of the value of wandering for ever
# (reward_step / (1 - gamma)): on paper-lab's gamma 0.9, within 0.1 of -10, a goal some 60 steps
# away or none the model knows of.
HOPELESS_SHARE = 0.01


def _experience(dump: Dict[str, Any]) -> Optional[str]:
    """What the dump's `n` column says of a pair (docs/tools.md, *Experience*): 'count' (CMAC-Model's
    training count, Dyna-QPC), 'recorded' (1 if the pair is recorded, Dyna-Q), or None
    (Q-learning keeps no counts)."""
    agent = dump.get("agent", "dyna-qpc")
    if agent.startswith("dyna-qpc"):
        return "count"
    if agent.startswith("dyna-q"):
        return "recorded"
    return None


def steps_aligned(dump: Dict[str, Any]) -> bool:
    """Whether a step moves to the next cell on the grid (aligned actions), so that _step() says
    where it leads; fixed steps and turns (paper-lab-motion) may stay in a cell or end between
    headings."""
    return bool(dump.get("space", {}).get("aligned", True))


def closed_regions(dump: Dict[str, Any]) -> Optional[Dict[str, Any]]:
    """Where the model sees no way home, and the moves that bumped on the way out of it.

    A visited state whose V sits at the value of wandering for ever (within HOPELESS_SHARE of it,
    either side) believes that no path the model knows reaches the goal from it; its actions'
    values then differ by planning's noise and a greedy robot turns or steps on one spot
    (docs/agent.md, "What it does not handle yet"). A move tried from such a state whose value is
    a bump's (below the value of wandering by a quarter of a bump or more) and whose next cell on
    the grid is a goal cell or holds a visited state worth more is a *closed passage*: often one
    bump, from a place in the cell the state does not show, closed the way on. Passages are named
    only where a step moves to the next cell (aligned actions) and the agent keeps experience per
    pair (not Q-learning). None for a dump without the values (an older dynaqpc-sim) or with
    gamma 1 (no value of wandering)."""
    vals = dump.get("values")
    if not vals or vals.get("wander") is None:
        return None
    wander = vals["wander"]
    tol = HOPELESS_SHARE * abs(wander)
    bumped = wander + vals["reward_bump"] / 4.0
    grid = dump["grid"]
    aligned = steps_aligned(dump)
    experience = _experience(dump)
    ix = {c: i for i, c in enumerate(dump["states_columns"])}
    goal = {tuple(c) for c in grid["goal_cells"]}
    rows = [r for r in dump["states"] if r[ix["visited"]] and r[ix["row"]] and r[ix["v"]] is not None]
    best: Dict[Tuple[int, int], float] = {}
    for r in rows:
        key = (r[ix["x"]], r[ix["y"]])
        best[key] = max(best.get(key, -math.inf), r[ix["v"]])
    for key in goal:  # a step into the goal ends the episode with its reward
        best[key] = vals["reward_goal"]
    outside = [r for r in rows if (r[ix["x"]], r[ix["y"]]) not in goal]
    hopeless = [r for r in outside if abs(r[ix["v"]] - wander) <= tol]
    cells: Dict[Tuple[int, int], int] = {}
    passages: Dict[Tuple[int, int, int, int], Dict[str, Any]] = {}
    for r in hopeless:
        x, y, h = r[ix["x"]], r[ix["y"]], r[ix["heading"]]
        cells[(x, y)] = cells.get((x, y), 0) + 1
        if not aligned or experience is None:
            continue
        for a in (0, 1):  # the moves; turns stay in the cell
            q, n = r[ix["q"]][a], r[ix["n"]][a]
            if q is None or not n or q > bumped:
                continue
            bx, by, _ = _step(grid, x, y, h, a)
            beyond = best.get((bx, by))
            if beyond is None or beyond <= wander + tol:
                continue
            k = (x, y, h, a)
            p = passages.get(k)
            # One per (cell, heading, move), of its range codes the least certain bump: the
            # highest Q, then the fewest tries.
            if p is None or (q, -n) > (p["q"], -p["tries"]):
                passages[k] = {
                    "cell": [x, y],
                    "heading": h,
                    "action": ACTIONS[a],
                    "code": r[ix["code"]],
                    "tries": n,
                    "q": q,
                    "into": [bx, by],
                    "into_v": beyond,
                }
    return {
        "wander": wander,
        "experience": experience,
        "aligned": aligned,
        "closed_cells": sorted([x, y] for (x, y) in cells if best[(x, y)] <= wander + tol),
        "visited_states": len(outside),
        "hopeless_states": len(hopeless),
        "hopeless_cells": [[x, y, k] for (x, y), k in sorted(cells.items())],
        "closed_passages": sorted(passages.values(), key=lambda p: (-p["q"], p["tries"], p["cell"], p["heading"])),
    }


def describe_closed(closed: Optional[Dict[str, Any]], most: int = 3) -> str:
    """One sentence for the summary line ('' without values or without a hopeless state)."""
    if not closed or not closed["hopeless_states"]:
        return ""
    who = "the model sees" if closed.get("experience", "count") else "its Q values see"
    text = (
        f"; {closed['hopeless_states']} of {closed['visited_states']} visited states read the value of "
        f"wandering for ever ({closed['wander']:g}): {who} no way home from them"
    )
    if not closed.get("aligned", True):
        return text + " (steps not aligned to the grid: no moves named)"
    ps = closed["closed_passages"]
    if ps:

        def tried(p: Dict[str, Any]) -> str:
            if closed.get("experience") == "recorded":
                return "recorded"
            return f"{p['tries']} {'try' if p['tries'] == 1 else 'tries'}"

        shown = ", ".join(
            f"cell ({p['cell'][0]}, {p['cell'][1]}) heading {p['heading']} {p['action']} "
            f"({tried(p)}, Q {p['q']:.0f}) into ({p['into'][0]}, {p['into'][1]}) worth {p['into_v']:.1f}"
            for p in ps[:most]
        )
        text += f"; {len(ps)} move(s) that bumped lead out of them: {shown}"
    return text


# --- drawing -------------------------------------------------------------------------------------


def _arrow(
    ax, cell: Tuple[float, float, float, float], grid: Dict[str, Any], h: int, a: int, color: str, scale: float = 1.0
) -> None:
    """The greedy action's mark at the centre of `cell` (cell_rect)."""
    ang = 2 * math.pi * h / grid["headings"]
    x0, y0 = cell[0] + cell[2] / 2, cell[1] + cell[3] / 2
    size = 0.38 * min(cell[2], cell[3])
    if a in (0, 1):
        if a == 1:
            ang += math.pi
        dx, dy = size * math.cos(ang), size * math.sin(ang)
        ax.annotate(
            "",
            xy=(x0 + dx, y0 + dy),
            xytext=(x0 - dx * 0.6, y0 - dy * 0.6),
            arrowprops=dict(
                arrowstyle="-|>", color=color, lw=1.4 * scale, shrinkA=0, shrinkB=0, mutation_scale=10 * scale
            ),
        )
    else:
        ax.text(
            x0,
            y0,
            "\u21ba" if a == 2 else "\u21bb",
            ha="center",
            va="center",
            fontsize=11 * scale,
            color=color,
            fontweight="bold",
        )


class _MarkHandler:
    """Draws a key entry as the map draws it: a mark (an arrow or a turn symbol) on a cell."""

    def __init__(self, mark: str, bg: Any):
        self.mark, self.bg = mark, bg  # mark: "right", "left" (arrows) or a turn symbol

    def legend_artist(self, legend, orig_handle, fontsize, handlebox):
        from matplotlib.patches import FancyArrow, Rectangle
        from matplotlib.text import Text

        x0, y0, w, h = handlebox.xdescent, handlebox.ydescent, handlebox.width, handlebox.height
        side = min(w, h * 1.6)
        cx, cy = x0 + w / 2, y0 + h / 2
        handlebox.add_artist(
            Rectangle(
                (cx - side / 2, y0 - h * 0.3),
                side,
                h * 1.6,
                facecolor=self.bg,
                edgecolor="none",
                transform=handlebox.get_transform(),
            )
        )
        color = orig_handle.get_color()
        if self.mark in ("right", "left"):
            d = side * 0.8 * (1 if self.mark == "right" else -1)
            a = FancyArrow(
                cx - d / 2,
                cy,
                d,
                0,
                width=h * 0.1,
                head_width=h * 0.55,
                head_length=abs(d) * 0.35,
                length_includes_head=True,
                color=color,
                transform=handlebox.get_transform(),
            )
        else:
            a = Text(
                cx,
                cy,
                self.mark,
                ha="center",
                va="center",
                fontsize=fontsize * 1.3,
                fontweight="bold",
                color=color,
                transform=handlebox.get_transform(),
            )
        handlebox.add_artist(a)
        return a


_KEY_HANDLERS: Dict[Any, Any] = {}


def _key_handles(arena: Dict[str, Any], cmap, norm, vmax: float, closed: Optional[Dict[str, Any]] = None) -> list:
    """Proxy artists for the key; _KEY_HANDLERS says how the arrows and turns are drawn."""
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    bg = cmap(norm(vmax * 0.3))
    marks = [
        ("right", "white", "step forward, along the heading"),
        ("left", "white", "step backward (the arrow points\nagainst the heading)"),
        ("\u21ba", "white", "turn left"),
        ("\u21bb", "white", "turn right"),
        ("right", "0.75", "grey mark: valued by planning only;\nthe robot never had this heading here"),
    ]
    _KEY_HANDLERS.clear()
    handles = []
    for mark, color, label in marks:
        h = Line2D([], [], color=color, label=label)
        _KEY_HANDLERS[h] = _MarkHandler(mark, bg)
        handles.append(h)
    handles.append(Patch(facecolor="white", edgecolor="0.5", label="white cell: no value for this heading"))
    handles.append(Patch(facecolor="0.6", edgecolor="0.3", label="obstacle"))
    if closed and closed["closed_cells"]:
        handles.append(
            Patch(
                facecolor="none",
                edgecolor="0.2",
                hatch="xx",
                label="cross-hatched (last panel): the model sees\nno way home from this cell",
            )
        )
    if closed and closed["closed_passages"]:
        handles.append(
            Line2D(
                [],
                [],
                color="red",
                linewidth=3,
                label="red bar: a move that bumped from a state\nwith no way home (least certain first)",
            )
        )
    return handles + goal_key(arena, "goal cells (the episode ends there:\nno action drawn)")


def _draw_heading_panel(ax, view, arena, h, visited, cmap, norm, scale) -> None:
    """One heading's panel: each cell's V as its colour, the greedy action as its mark."""
    from matplotlib.patches import Rectangle

    from .arena import draw_arena

    grid = view["grid"]
    nh = grid["headings"]
    by_h = [c for c in view["cells"] if c["heading"] == h]
    for c in by_h:
        x0, y0, cw, ch = cell_rect(grid, c["x"], c["y"])
        ax.add_patch(Rectangle((x0, y0), cw, ch, facecolor=cmap(norm(c["v"])), edgecolor="none", alpha=0.85))
    draw_arena(ax, arena)
    goal_cells = {tuple(g) for g in grid["goal_cells"]}
    for c in by_h:
        if (c["x"], c["y"]) in goal_cells:
            continue  # the episode ends there: no action is taken in a goal cell
        vis = h in visited.get((c["x"], c["y"]), ())
        _arrow(ax, cell_rect(grid, c["x"], c["y"]), grid, h, c["greedy"], "white" if vis else "0.75", scale)
    deg = 360.0 * h / nh
    ax.set_title(f"heading {h} ({deg:.1f}\u00b0): {len(by_h)} cells", fontsize=9)
    ax.set_xlabel("")
    ax.set_ylabel("")


# The closed passages drawn (the least certain bumps first): more would mark every wall.
CLOSED_DRAWN = 5


def _draw_edge(ax, grid: Dict[str, Any], cell: List[int], into: List[int]) -> None:
    """A red bar on the edge between two neighbouring cells (a move that bumped there)."""
    x0, y0, cw, ch = cell_rect(grid, cell[0], cell[1])
    dx, dy = into[0] - cell[0], into[1] - cell[1]
    if dx and not dy:
        ex = x0 + cw if dx > 0 else x0
        xs, ys = [ex, ex], [y0 + 0.15 * ch, y0 + 0.85 * ch]
    elif dy and not dx:
        ey = y0 + ch if dy > 0 else y0
        xs, ys = [x0 + 0.15 * cw, x0 + 0.85 * cw], [ey, ey]
    else:  # a diagonal step: a bar across the corner
        cx, cy = x0 + (cw if dx > 0 else 0.0), y0 + (ch if dy > 0 else 0.0)
        xs, ys = [cx - 0.2 * cw, cx + 0.2 * cw], [cy + 0.2 * ch * dx * dy, cy - 0.2 * ch * dx * dy]
    ax.plot(xs, ys, color="red", linewidth=3, solid_capstyle="butt", zorder=5)


def _draw_visited_panel(ax, view, arena, visited, plt) -> None:
    """Visited and modelled cells, over all headings."""
    from matplotlib.patches import Rectangle

    from .arena import draw_arena

    grid = view["grid"]
    nx, ny, nh = grid["cells_x"], grid["cells_y"], grid["headings"]
    modelled = {(x, y): set(h) for x, y, h in view["modelled_cells"]}
    oranges = plt.get_cmap("Oranges")
    for x, y in set(visited) | set(modelled):
        nv = len(visited.get((x, y), ()))
        x0, y0, cw, ch = cell_rect(grid, x, y)
        if nv:
            ax.add_patch(Rectangle((x0, y0), cw, ch, facecolor=oranges(0.15 + 0.75 * nv / nh), edgecolor="none"))
        else:  # predicted by the model, never visited
            ax.add_patch(Rectangle((x0, y0), cw, ch, facecolor="none", edgecolor="tab:orange", hatch="//", linewidth=0))
        if max(nx, ny) <= 16:  # beyond, the shades say it
            ax.text(
                x0 + cw / 2,
                y0 + ch / 2,
                f"{nv}/{len(modelled.get((x, y), ()))}",
                ha="center",
                va="center",
                fontsize=7,
                color="black",
            )
    closed = view.get("closed") or {}
    for x, y in closed.get("closed_cells", []):
        x0, y0, cw, ch = cell_rect(grid, x, y)
        ax.add_patch(Rectangle((x0, y0), cw, ch, facecolor="none", edgecolor="0.2", hatch="xx", linewidth=0))
    for p in closed.get("closed_passages", [])[:CLOSED_DRAWN]:
        _draw_edge(ax, grid, p["cell"], p["into"])
    draw_arena(ax, arena)
    title = "visited / modelled headings per cell\n(shade: headings visited; hatched: modelled, never visited)"
    marks = []
    if closed.get("closed_cells"):
        marks.append("cross-hatched: no way home")
    if closed.get("closed_passages"):
        marks.append("red: bumped moves out")
    if marks:
        title += "\n" + "; ".join(marks)
    ax.set_title(title, fontsize=8)
    ax.set_xlabel("")
    ax.set_ylabel("")


def _draw_fill_panel(ax, view) -> None:
    """The tables' fill."""
    names, used, caps = [], [], []
    for name, f in view["fill"].items():
        u = f.get("rows", f.get("cells", f.get("places", f.get("used", f.get("records")))))
        if name == "q" and f.get("dense"):
            u = sum(1 for _ in view["cells"])
        names.append(name)
        used.append(u)
        caps.append(f["capacity"])
    ys = range(len(names))
    ax.barh(ys, [u / c if c else 0 for u, c in zip(used, caps)], color="tab:blue")
    for yy, u, c in zip(ys, used, caps):
        ax.text(0.02, yy, f"{u:,} / {c:,}", va="center", fontsize=8, color="white" if c and u / c > 0.35 else "black")
    ax.set_yticks(list(ys))
    ax.set_yticklabels(names, fontsize=8)
    ax.set_xlim(0, 1)
    ax.invert_yaxis()
    ax.set_title("tables' fill", fontsize=9)


def _draw_key(fig, axes, n_panels, nrows, ncols, arena, cmap, norm, vmax, closed=None) -> None:
    """The key: what every mark means, in the first free panel, else under the figure."""
    handles = _key_handles(arena, cmap, norm, vmax, closed)
    if n_panels < nrows * ncols and fig.get_size_inches()[1] / nrows >= KEY_HEIGHT:
        key_ax = axes[n_panels // ncols][n_panels % ncols]
        key_ax.legend(
            handles=handles,
            loc="center left",
            fontsize=8.5,
            frameon=False,
            title="key",
            handlelength=2.6,
            handleheight=1.4,
            title_fontsize=9,
            handler_map=_KEY_HANDLERS,
        )
    else:
        fig.legend(
            handles=handles, loc="outside lower center", ncol=3, fontsize=8, frameon=False, handler_map=_KEY_HANDLERS
        )


# The shortest side a panel may have (inches): its title, its arena and the fill panel's bars.
PANEL_MIN_SIDE = 2.0
# The key (legend) needs about this much height (inches) to sit in a free panel; else it goes under
# the panels.
KEY_HEIGHT = 3.0


def panel_size(arena: Dict[str, Any], nx: int, ny: int) -> Tuple[float, float, float]:
    """One panel's width and height (inches) and a mark's size over a cell's. The arena's longer side
    gets 4 inches on an 8-cell grid and grows with the cells along it (paper-sim's 32), so a long
    hall's cells are as wide as a square room's; marks shrink a little on large grids."""
    n = max(nx, ny)
    side = 4.0 * max(1.0, math.sqrt(n / 8.0))
    aspect = arena["height"] / arena["width"]
    width, height = (side, side * aspect) if aspect <= 1.0 else (side / aspect, side)
    scale = min(1.0, side * 2.0 / n)  # as on an 8-cell grid in 4 inches
    return max(width, PANEL_MIN_SIDE), max(height, PANEL_MIN_SIDE), scale


def panel_columns(n_panels: int, panel_w: float, panel_h: float, most: int = 6) -> int:
    """Columns that make the figure nearest a 16:10 landscape page: 4 for a room about square, 2 for
    a hall five times as long as wide, more for a tall narrow floor."""

    def off(ncols: int) -> float:
        nrows = (n_panels + ncols - 1) // ncols
        return abs(math.log((ncols * panel_w) / (nrows * panel_h) / 1.6))

    return min(range(1, most + 1), key=off)


def draw(
    view: Dict[str, Any], arena: Dict[str, Any], out: str, headings: str = "used", title: Optional[str] = None
) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    arena = dict(arena, beacons=[])  # their labels would cover the arrows
    grid = view["grid"]
    nx, ny, nh = grid["cells_x"], grid["cells_y"], grid["headings"]
    by_h: Dict[int, List[Dict[str, Any]]] = {}
    for c in view["cells"]:
        by_h.setdefault(c["heading"], []).append(c)
    if headings == "used":
        hs = sorted(by_h, key=lambda h: (-len(by_h[h]), h))
        hs = sorted(hs[:8])  # the most used eight; a 90-degree robot uses four
    elif headings == "all":
        hs = list(range(nh))
    else:
        hs = [int(t) for t in headings.split(",")]
    vals = [c["v"] for c in view["cells"] if c["v"] is not None]
    vmin, vmax = (min(vals), max(vals)) if vals else (0.0, 1.0)
    if vmin == vmax:
        vmax = vmin + 1.0
    n_panels = len(hs) + 2
    panel_w, panel_h, scale = panel_size(arena, nx, ny)
    ncols = panel_columns(n_panels, panel_w, panel_h)
    nrows = (n_panels + ncols - 1) // ncols
    fig, axes = plt.subplots(
        nrows, ncols, figsize=(panel_w * ncols + 1.0, panel_h * nrows + 1.2), squeeze=False, layout="constrained"
    )
    cmap = plt.get_cmap("viridis")
    norm = matplotlib.colors.Normalize(vmin=vmin, vmax=vmax)
    visited = {(x, y): set(h) for x, y, h in view["visited_cells"]}
    for i, h in enumerate(hs):
        _draw_heading_panel(axes[i // ncols][i % ncols], view, arena, h, visited, cmap, norm, scale)
    _draw_visited_panel(axes[len(hs) // ncols][len(hs) % ncols], view, arena, visited, plt)
    _draw_fill_panel(axes[(len(hs) + 1) // ncols][(len(hs) + 1) % ncols], view)
    for j in range(n_panels, nrows * ncols):
        axes[j // ncols][j % ncols].axis("off")
    heading_axes = [axes[i // ncols][i % ncols] for i in range(len(hs))]
    fig.colorbar(
        matplotlib.cm.ScalarMappable(norm=norm, cmap=cmap),
        ax=heading_axes,
        location="right",
        shrink=0.9,
        pad=0.01,
        aspect=30,
        label="V = max_a Q (cell colour)",
    )
    _draw_key(fig, axes, n_panels, nrows, ncols, arena, cmap, norm, vmax, view.get("closed"))
    rec = view["record"]
    shown = (
        f"all {nh} headings"
        if len(hs) == nh
        else f"{len(hs)} of the {nh} headings: the {len(hs)} with the most cells (--headings all draws every one)"
        if headings == "used"
        else f"{len(hs)} of the {nh} headings (--headings)"
    )
    codes = "the largest V" if view["combine"] == "max" else "the most experienced"
    if title is None:
        # Each line wrapped to the figure's width (about 14 characters an inch at 10 points): a long
        # hall's figure is narrower than a square room's.
        width = max(60, int(fig.get_size_inches()[0] * 14))
        lines = [
            f"What {view['agent']} learned on {view['scenario']} in {rec['episodes']} episodes, read from its flash image",
            f"per heading: the greedy action in each cell, on V = max_a Q; {shown}; several range codes in a cell: "
            f"{codes}",
        ]
        title = "\n".join(textwrap.fill(line, width) for line in lines)
    fig.suptitle(title, fontsize=10)
    save_figure(fig, out, dpi=110)


def summary_line(view: Dict[str, Any], png: Optional[str]) -> str:
    """The line the tool prints: what the image holds, where its arrows lead, where it sees no way
    home, and the picture."""
    f = view["arrows_followed"]
    rec = view["record"]
    fill = view["fill"]["q"]
    arrows = (
        f"from {f['starts']} visited ones the greedy arrows reach the goal from {f['outcomes'].get('goal', 0)}"
        if f is not None
        else "fixed steps and turns, not aligned to the grid: the arrows are not followed"
    )
    return (
        f"{view['agent']} on {view['scenario']}, {rec['episodes']} episodes: {len(view['cells'])} "
        f"(cell, heading) pairs with Q rows ({fill['rows'] if not fill['dense'] else 'dense'} of "
        f"{fill['capacity']} rows); {arrows}" + describe_closed(view["closed"]) + (f"; picture: {png}" if png else "")
    )


def main(argv: Optional[List[str]] = None) -> int:
    p = ToolArgumentParser(
        prog="dynaqpc-learned",
        description="Draw what the robot learned: per heading, the greedy action over V = max_a Q on the arena's "
        "cells, the visited and modelled cells and the tables' fill, from a flash image.",
        epilog="The image is decoded by the firmware's own restore code (dynaqpc-sim learned); exit 2 when it "
        "cannot be restored. docs/tools.md has an example.",
    )
    p.add_argument("image", help="flash image: dynaqpc-sim train --save FILE, or a board's backup")
    p.add_argument("--scenario", required=True, help="paper-lab, paper-sim or FILE.scn: the one it learned on")
    p.add_argument("--agent", choices=registry.names(), help="default: whichever the image holds")
    p.add_argument("--sim", default=default_sim(), help="dynaqpc-sim binary (default %(default)s)")
    p.add_argument("--png", metavar="OUT", help="write the picture here (default: IMAGE with .png)")
    p.add_argument("--json", metavar="OUT", help="write the combined view as JSON ('-': stdout)")
    p.add_argument(
        "--combine",
        choices=["max", "visits"],
        default="max",
        help="which range code's row a (cell, heading) shows when the robot saw several there: the "
        "largest V (default) or the most experienced",
    )
    p.add_argument(
        "--headings",
        default="used",
        help="headings to draw: 'used' (the eight with most rows), 'all', or a list such as 0,4,8,12",
    )
    args = p.parse_args(argv)
    if args.headings not in ("used", "all"):
        try:
            hs = [int(t) for t in args.headings.split(",")]
        except ValueError:
            p.error(f"--headings: expected used, all or numbers like 0,4,8,12, got {args.headings!r}")
        if not hs or any(h < 0 for h in hs):
            p.error(f"--headings: expected used, all or numbers like 0,4,8,12, got {args.headings!r}")

    def body() -> int:
        dump = dump_image(args.sim, args.scenario, args.image, args.agent)
        view = combine(dump, args.combine)
        if args.headings not in ("used", "all"):
            bad = [h for h in map(int, args.headings.split(",")) if h >= view["grid"]["headings"]]
            if bad:
                raise ToolError(
                    f"--headings: {bad[0]} is not a heading of {view['scenario']} (0..{view['grid']['headings'] - 1})"
                )
        # Following the arrows walks the grid as aligned actions move: elsewhere it would be a guess.
        view["arrows_followed"] = follow_all(view) if steps_aligned(dump) else None
        view["closed"] = closed_regions(dump)
        if args.json:
            text = json.dumps(view, indent=1)
            if args.json == "-":
                print(text)
            else:
                try:
                    Path(args.json).write_text(text + "\n", encoding="utf-8")
                except OSError as e:
                    raise ToolError(f"cannot write {args.json}: {e.strerror or e}") from None
        png = args.png
        if png is None and args.json != "-":
            png = str(Path(args.image).with_suffix(".png"))
        if png:
            draw(view, dump["arena"], png, args.headings)
        out = sys.stderr if args.json == "-" else sys.stdout
        print(summary_line(view, png), file=out)
        return 0

    return run_main(body)


if __name__ == "__main__":
    sys.exit(main())
