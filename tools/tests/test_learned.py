# SPDX-License-Identifier: MIT
"""dynaqpc-learned: the firmware learns paper-lab, the tool draws what its flash image holds, and
the greedy arrows it draws lead to the goal; an image that cannot be restored is one line, exit 2."""

import json
import math
import struct
import subprocess
import sys
import zlib

import pytest
from conftest import TOOLS, c_binary

SLOT = 2 * 128 * 1024  # the host flash: 4 sectors of 128 KB, two per slot (learned_store.h)


def learned(*args):
    return subprocess.run(
        [sys.executable, "-m", "dynaqpc_tools.learned", *map(str, args)],
        cwd=TOOLS,
        capture_output=True,
        text=True,
        timeout=300,
    )


@pytest.fixture(scope="module")
def sim():
    s = c_binary("dynaqpc-sim")
    if not s.exists():
        pytest.skip(f"{s} not built")
    return s


def train_image(sim, scenario, path, episodes, seed, *extra):
    """Dyna-QPC at N = 1,000 trains one set on `scenario` and saves its flash image to `path`."""
    subprocess.run(
        [str(sim), "train", "--scenario", str(scenario), "--agent", "dyna-qpc", "--planning", "1000", "--sets", "1"]
        + [str(a) for a in extra]
        + ["--episodes", str(episodes), "--seed", str(seed), "--quiet", "--save", str(path)],
        check=True,
        capture_output=True,
        timeout=600,
    )
    return path


@pytest.fixture(scope="module")
def image(sim, tmp_path_factory):
    """Dyna-QPC trained on paper-lab long enough to learn (the issue's recipe)."""
    return train_image(sim, "paper-lab", tmp_path_factory.mktemp("learned") / "lab.flash", 60, 7)


def step(grid, x, y, h, a):
    """Where action a leads on the grid (the firmware's aligned actions, robot_motion.c): a step
    crosses the edge that the heading's ray from the cell's centre meets first (both at a corner);
    a turn goes to the next multiple of 90 degrees that is more than a quarter turn away."""
    n = grid["headings"]
    q = n // 4
    if a in (0, 1):  # forward, backward
        ang = 2 * math.pi * h / n + (math.pi if a == 1 else 0)
        c, s = math.cos(ang), math.sin(ang)
        tx = grid["cell_w"] / 2 / abs(c) if abs(c) > 1e-6 else math.inf
        ty = grid["cell_h"] / 2 / abs(s) if abs(s) > 1e-6 else math.inf
        dx = (1 if c > 0 else -1) if tx <= ty + 1e-9 else 0
        dy = (1 if s > 0 else -1) if ty <= tx + 1e-9 else 0
        return x + dx, y + dy, h
    k = math.floor(h / q + 0.25) + 1 if a == 2 else math.ceil(h / q - 0.25) - 1
    return x, y, (k * q) % n


def test_greedy_arrows_lead_to_the_goal(sim, image, tmp_path):
    out, png = tmp_path / "view.json", tmp_path / "lab.png"
    p = learned(image, "--scenario", "paper-lab", "--sim", sim, "--json", out, "--png", png)
    assert p.returncode == 0, p.stderr
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert str(png) in p.stdout
    view = json.loads(out.read_text())
    assert view["agent"] == "dyna-qpc" and view["record"]["episodes"] == 60
    grid = view["grid"]
    goal = {tuple(c) for c in grid["goal_cells"]}
    assert goal == {(6, 6), (7, 6)}  # the cells whose centres lie inside the scenario's goal circle
    arrows = {(c["x"], c["y"], c["heading"]): c["greedy"] for c in view["cells"]}
    starts = [(c["x"], c["y"], c["heading"]) for c in view["cells"] if c["visited"] and (c["x"], c["y"]) not in goal]
    assert len(starts) >= 100
    reached = left = 0
    for x, y, h in starts:
        seen = set()
        while (x, y) not in goal and (x, y, h) in arrows and (x, y, h) not in seen:
            seen.add((x, y, h))
            x, y, h = step(grid, x, y, h, arrows[(x, y, h)])
            if not (0 <= x < grid["cells_x"] and 0 <= y < grid["cells_y"]):
                left += 1
                break
        reached += (x, y) in goal
    # Measured: 223 of 261 starts (85 %) reach the goal; the rest mostly turn into a heading the
    # robot never had in that cell (no Q row there), 2 leave the arena.
    assert reached / len(starts) >= 0.8, (reached, len(starts))
    assert left <= 0.02 * len(starts)
    # The tool's own count says the same.
    assert view["arrows_followed"]["outcomes"]["goal"] == reached


def test_visited_modelled_and_fill(sim, image, tmp_path):
    p = learned(image, "--scenario", "paper-lab", "--sim", sim, "--json", "-")
    assert p.returncode == 0, p.stderr
    view = json.loads(p.stdout)
    fill = view["fill"]
    assert 0 < fill["q"]["rows"] <= fill["q"]["capacity"] == 1024
    assert 0 < fill["cmac"]["cells"] <= fill["cmac"]["capacity"]
    visited = {(x, y) for x, y, _ in view["visited_cells"]}
    modelled = {(x, y) for x, y, _ in view["modelled_cells"]}
    assert len(visited) >= 40 and visited <= modelled
    assert all(c["code"] in c["codes"] for c in view["cells"])
    # Several range codes in one (cell, heading): --combine max shows the one of largest V.
    several = [c for c in view["cells"] if len(c["codes"]) > 1]
    assert several


def test_a_learned_table_has_no_closed_region(sim, image):
    p = learned(image, "--scenario", "paper-lab", "--sim", sim, "--json", "-")
    assert p.returncode == 0, p.stderr
    closed = json.loads(p.stdout)["closed"]
    # paper-lab's gamma 0.9 and step reward -1: wandering for ever is worth -10.
    assert closed["wander"] == pytest.approx(-10.0, abs=1e-4)
    assert closed["hopeless_states"] == 0 and closed["closed_passages"] == []
    assert "wandering" not in p.stderr


def synthetic_dump():
    """Three cells in a row, headings every 90 degrees: from (0, 0) facing east (heading 0) the
    robot once bumped stepping into (1, 0), which is worth 30; (0, 0) reads the value of wandering."""
    grid = {"cells_x": 3, "cells_y": 1, "headings": 4, "codes": 1, "cell_w": 0.5, "cell_h": 0.5, "goal_cells": [[2, 0]]}
    cols = ["s", "x", "y", "heading", "code", "row", "visited", "modelled", "greedy", "v", "q", "n"]
    states = [
        [0, 0, 0, 0, 0, 1, 1, 1, 2, -9.999, [-74.0, -9.999, -9.999, -9.999], [1, 0, 2, 2]],  # one bump east
        [1, 0, 0, 2, 0, 1, 1, 1, 2, -9.998, [-109.0, -9.998, -9.998, -9.998], [3, 0, 1, 1]],  # a wall west
        [2, 1, 0, 0, 0, 1, 1, 1, 0, 30.0, [30.0, -5.0, 20.0, 20.0], [2, 1, 0, 0]],
        [3, 1, 0, 2, 0, 1, 1, 1, 0, -5.0, [-5.0, -109.0, -6.0, -6.0], [1, 1, 0, 0]],  # far, not hopeless
    ]
    values = {"gamma": 0.9, "reward_goal": 100, "reward_bump": -100, "reward_step": -1, "wander": -10, "prior": 0}
    return {"grid": grid, "states_columns": cols, "states": states, "values": values}


def test_closed_regions_name_the_bumps_that_closed_the_way():
    from dynaqpc_tools.learned import closed_regions, describe_closed

    c = closed_regions(synthetic_dump())
    assert c["hopeless_states"] == 2 and c["visited_states"] == 4
    assert c["closed_cells"] == [[0, 0]]
    # Only the east step leads out to a cell worth more; the west one meets the arena's edge.
    assert [(p["cell"], p["heading"], p["action"], p["into"]) for p in c["closed_passages"]] == [
        ([0, 0], 0, "forward", [1, 0])
    ]
    assert c["closed_passages"][0]["tries"] == 1 and c["closed_passages"][0]["into_v"] == 30.0
    assert "cell (0, 0) heading 0 forward (1 try, Q -74) into (1, 0) worth 30.0" in describe_closed(c)
    old = synthetic_dump()
    del old["values"]  # a dump from before the values were written: nothing to say
    assert closed_regions(old) is None and describe_closed(None) == ""


def test_slots_past_a_fitted_grid_are_no_cells():
    """A fitted grid of 3 cells keeps 4 slots in its 2 bits: the model answers for the fourth by
    situation, but it is no place, and the picture once labelled it outside the arena."""
    from dynaqpc_tools.learned import combine

    d = synthetic_dump()
    d.update(scenario="s", agent="dyna-qpc", record={"episodes": 1}, fill={})
    d["states"].append([4, 3, 0, 0, 0, 0, 0, 1, 0, None, [0, 0, 0, 0], [0, 0, 0, 0]])  # modelled, x = 3
    view = combine(d)
    assert [c[:2] for c in view["modelled_cells"]] == [[0, 0], [1, 0]]
    assert all(c["x"] < 3 for c in view["cells"])


def test_closed_regions_edge_cases():
    from dynaqpc_tools.learned import closed_regions, describe_closed

    d = synthetic_dump()
    # (1, 0) facing east once bumped stepping into the goal, and now reads the value of wandering
    # too (by 0.5 % below it); a state far below that value (every action bumped) is not hopeless.
    d["states"][2] = [2, 1, 0, 0, 0, 1, 1, 1, 2, -10.05, [-74.0, -10.05, -10.05, -10.05], [1, 0, 1, 1]]
    d["states"].append([4, 0, 0, 1, 0, 1, 1, 1, 2, -60.0, [-100.0, -100.0, -60.0, -60.0], [1, 1, 1, 1]])
    c = closed_regions(d)
    assert c["hopeless_states"] == 3 and c["visited_states"] == 5
    assert [(p["cell"], p["into"], p["into_v"]) for p in c["closed_passages"]] == [
        ([0, 0], [1, 0], -5.0),
        ([1, 0], [2, 0], 100),
    ]
    assert "1 try" in describe_closed(c)
    d["agent"] = "dyna-q"  # n: 1 if the pair is recorded, not a count of tries
    assert "(recorded, Q -74)" in describe_closed(closed_regions(d))
    d["agent"] = "q"  # no counts: the hopeless states, no moves
    c = closed_regions(d)
    assert c["hopeless_states"] == 3 and c["closed_passages"] == []
    assert "its Q values see no way home" in describe_closed(c)
    d["agent"] = "dyna-qpc"
    d["space"] = {"aligned": False}  # fixed steps: the next cell is a guess, no moves named
    c = closed_regions(d)
    assert c["hopeless_states"] == 3 and c["closed_passages"] == []
    assert "no moves named" in describe_closed(c)
    d["values"]["wander"] = None  # gamma 1: wandering has no value
    assert closed_regions(d) is None


def test_a_relapsing_set_shows_its_closed_region(sim, tmp_path):
    """A realistic tuning room whose set learned at episode 10 and relapsed in 3 of the 6 episodes
    after (seed 101, set 3; the set of seed 105 this test named before no longer relapses since the
    first state waits for a fix taken since the start): after 18 episodes most visited states read
    the value of wandering, and the least certain bump that closed them is listed first."""
    rooms = tmp_path / "rooms"
    subprocess.run(
        [
            str(sim),
            "rooms",
            "--robot",
            "paper-lab",
            "--profile",
            "real",
            "--far",
            "mixed",
            "--floor",
            "4.3x3.2",
            "--seed",
            "3000",
            "--count",
            "4",
            "--out",
            str(rooms),
        ],
        check=True,
        capture_output=True,
        timeout=120,
    )
    room = next(rooms.glob("*culdesac*.scn"))
    img = train_image(sim, room, tmp_path / "cd.flash", 18, 101, "--first-set", 3)
    p = learned(img, "--scenario", room, "--sim", sim, "--json", "-")
    assert p.returncode == 0, p.stderr
    c = json.loads(p.stdout)["closed"]
    assert c["hopeless_states"] > 0.3 * c["visited_states"], c["hopeless_states"]
    ps = c["closed_passages"]
    assert ps and [p["q"] for p in ps] == sorted((p["q"] for p in ps), reverse=True)
    pure_bump = -100 + 0.9 * c["wander"]
    assert ps[0]["q"] > pure_bump + 10  # the first is a bump the model is not sure of
    assert all(p["q"] <= c["wander"] - 25 and p["into_v"] > c["wander"] for p in ps)
    assert "the model sees no way home" in p.stderr


def test_arrows_are_not_followed_where_steps_are_not_aligned(sim, tmp_path):
    """paper-lab-motion's fixed 25 cm steps and 45-degree turns may stay in a cell or end between
    headings: walking the grid there would be a guess, so the tool does not claim a count."""
    img = train_image(sim, "paper-lab-motion", tmp_path / "motion.flash", 3, 3)
    p = learned(img, "--scenario", "paper-lab-motion", "--sim", sim, "--json", "-")
    assert p.returncode == 0, p.stderr
    view = json.loads(p.stdout)
    assert view["arrows_followed"] is None
    assert "the arrows are not followed" in p.stderr and "reach the goal from" not in p.stderr


def test_panels_keep_a_long_hall_readable():
    """A hall five times as long as wide gets fewer, wider columns than a square room, rows tall
    enough for a title, and cells as wide as a square room's of as many cells; paper-lab keeps its
    four columns; a tall narrow floor gets more columns."""
    from dynaqpc_tools.learned import PANEL_MIN_SIDE, panel_columns, panel_size

    lab_w, lab_h, _ = panel_size({"width": 4.3, "height": 3.2}, 8, 8)
    assert (lab_w, round(lab_h, 3)) == (4.0, round(4.0 * 3.2 / 4.3, 3))
    assert panel_columns(10, lab_w, lab_h) == 4
    hall_w, hall_h, _ = panel_size({"width": 8.6, "height": 1.6}, 16, 4)
    assert hall_h == PANEL_MIN_SIDE and math.isclose(hall_w / 16, 4.0 * math.sqrt(2) / 16)
    hall_cols = panel_columns(10, hall_w, hall_h)
    assert 2 <= hall_cols < 4
    tall_w, tall_h, _ = panel_size({"width": 1.6, "height": 8.6}, 4, 16)
    assert tall_w == PANEL_MIN_SIDE and panel_columns(10, tall_w, tall_h) > 4


def corrupt(src, dst, offsets):
    data = bytearray(src.read_bytes())
    for o in offsets:
        data[o] ^= 0xFF
    dst.write_bytes(bytes(data))


def test_an_image_that_cannot_be_restored_is_one_line_and_exit_2(sim, image, tmp_path):
    bad = tmp_path / "bad.flash"
    cases = {
        "corrupted": lambda: corrupt(image, bad, [64 + 100, SLOT + 64 + 100]),  # both records' payloads
        "truncated": lambda: bad.write_bytes(image.read_bytes()[:1000]),
        "erased": lambda: bad.write_bytes(b"\xff" * (2 * SLOT)),
        "not an image": lambda: bad.write_bytes(b"hello\n"),
    }
    for name, make in cases.items():
        make()
        p = learned(bad, "--scenario", "paper-lab", "--sim", sim)
        assert p.returncode == 2, (name, p.stderr)
        lines = p.stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: "), (name, p.stderr)
        assert "Traceback" not in p.stderr
    p = learned(image, "--scenario", "paper-sim", "--sim", sim)
    assert p.returncode == 2 and "holds no record" in p.stderr
    p = learned(tmp_path / "missing.flash", "--scenario", "paper-lab", "--sim", sim)
    assert p.returncode == 2 and "missing.flash" in p.stderr
    for out in (["--png", tmp_path / "no" / "such" / "x.png"], ["--json", tmp_path / "no" / "x.json"]):
        p = learned(image, "--scenario", "paper-lab", "--sim", sim, *out)
        assert p.returncode == 2 and p.stderr.startswith("error: cannot write") and "Traceback" not in p.stderr
    p = learned(image, "--scenario", "paper-lab", "--sim", tmp_path / "no-sim")
    assert p.returncode == 2 and "--sim" in p.stderr


def test_a_record_whose_crcs_hold_but_whose_tables_fail_the_firmwares_checks_is_refused(sim, image, tmp_path):
    """Only the firmware's own checks (agent_learned_check) can catch this: a Q value of NaN,
    with both CRCs recomputed (the header is learned_store.h's: eight little-endian words)."""
    data = bytearray(image.read_bytes())
    for slot in (0, 1):
        base = slot * SLOT
        words = list(struct.unpack_from("<8I", data, base))
        payload_size = words[4]
        struct.pack_into("<f", data, base + 32, float("nan"))  # the first Q value (qstore's region first)
        words[5] = zlib.crc32(bytes(data[base + 32 : base + 32 + payload_size]))
        words[7] = zlib.crc32(struct.pack("<7I", *words[:7]))
        struct.pack_into("<8I", data, base, *words)
    bad = tmp_path / "refused.flash"
    bad.write_bytes(bytes(data))
    p = learned(bad, "--scenario", "paper-lab", "--sim", sim)
    assert p.returncode == 2 and p.stderr.count("\n") == 1
    assert "CRCs hold but its tables fail the firmware's checks" in p.stderr


def test_a_damaged_newest_record_falls_back_as_the_firmware_does(sim, image, tmp_path):
    shown = json.loads(learned(image, "--scenario", "paper-lab", "--sim", sim, "--json", "-").stdout)
    slots = shown["record"]["slots"]
    newest = max(range(2), key=lambda i: slots[i]["sequence"])
    bad = tmp_path / "newest-damaged.flash"
    corrupt(image, bad, [newest * SLOT + 64 + 100])
    p = learned(bad, "--scenario", "paper-lab", "--sim", sim, "--json", "-")
    assert p.returncode == 0, p.stderr
    view = json.loads(p.stdout)
    assert view["record"]["fell_back"] and view["record"]["episodes"] == shown["record"]["episodes"] - 1
    assert "warning" in p.stderr and "older" in p.stderr


def test_run_warns_when_it_replays_the_older_record(sim, image, tmp_path):
    """`dynaqpc-sim run --load` boots as the firmware does: from the older record when the newest
    is damaged. It says so on stderr, and says nothing when the newest is whole."""
    shown = json.loads(learned(image, "--scenario", "paper-lab", "--sim", sim, "--json", "-").stdout)
    slots = shown["record"]["slots"]
    newest = max(range(2), key=lambda i: slots[i]["sequence"])
    bad = tmp_path / "newest-damaged.flash"
    corrupt(image, bad, [newest * SLOT + 64 + 100])
    run = [str(sim), "run", "--scenario", "paper-lab", "--starts", "1", "--load"]
    p = subprocess.run(run + [str(bad)], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    assert "warning: the newest record" in p.stderr and "running the older one" in p.stderr
    assert f"({shown['record']['episodes'] - 1} episodes)" in p.stderr
    p = subprocess.run(run + [str(image)], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0 and "warning" not in p.stderr
