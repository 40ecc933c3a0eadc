# SPDX-License-Identifier: MIT
"""tools/dev.sh docs-check: re-runs the cheap figures the README and docs/results/ quote, and fails
when one has drifted from what the page says.

Each check trains with the command the page names (the host-release build), tables the CSV with
dynaqpc-experiment (Table 1: sets learned, real steps or robot hours to learn over all sets), and
compares the figure with the one the page carries, found by a pattern next to it. A figure that
moved is one line naming the page, what it says and what was measured; exit 1. Expensive figures
(Dyna-Q in idle time, the far-goal rooms, the emulated board) are left to their benches.

    python3 tools/docs_check.py [--sim build/host-release/bin/dynaqpc-sim] [--only NAME]
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# (name, train arguments, learned threshold, [(page, pattern with one group per figure, figures)])
# where each figure is "sets" (sets learned, e.g. 20/20), "steps" (real steps to learn, the mean)
# or "hours" (robot hours to learn, the mean), read from the run's Table 1 row.
LAB = ["--scenario", "paper-lab", "--sets", "20", "--episodes", "20", "--seed", "9001"]
LAB_REAL = ["--scenario", "paper-lab-real", "--sets", "20", "--episodes", "20", "--seed", "9001"]
SIM = ["--scenario", "paper-sim", "--sets", "8", "--episodes", "60", "--seed", "9001"]
SIM_REAL = ["--scenario", "paper-sim-real", "--sets", "8", "--episodes", "60", "--seed", "9001"]
CHECKS = [
    (
        "paper-lab dyna-qpc N=1000",
        ["--agent", "dyna-qpc", "--planning", "1000", *LAB],
        50,
        [
            ("README.md", r"exact robot \(`paper-lab`\): Dyna-QPC ([\d,]+) \((\d+/\d+) sets\)", ("steps", "sets")),
            ("docs/results/README.md", r"Dyna-QPC ([\d,]+) real steps to learn, (\d+/\d+) sets", ("steps", "sets")),
            (
                "docs/results/paper-lab.md",
                r"\| \*\*Dyna-QPC\*\* \| 1,000 \| \*\*(\d+/\d+)\*\* \| \*\*([\d,]+)\*\* \|",
                ("sets", "steps"),
            ),
        ],
    ),
    (
        "paper-lab dyna-q N=1000",
        ["--agent", "dyna-q", "--planning", "1000", *LAB],
        50,
        [
            (
                "README.md",
                r"exact robot \(`paper-lab`\): Dyna-QPC [\d,]+ \(\d+/\d+ sets\), Dyna-Q ([\d,]+) \((\d+/\d+)\)",
                ("steps", "sets"),
            ),
            ("docs/results/README.md", r"against Dyna-Q's ([\d,]+) \(N = 1,000", ("steps",)),
            ("docs/results/paper-lab.md", r"\| Dyna-Q \| 1,000 \| (\d+/\d+) \| ([\d,]+) \|", ("sets", "steps")),
        ],
    ),
    (
        "paper-lab-real dyna-qpc N=1000",
        ["--agent", "dyna-qpc", "--planning", "1000", *LAB_REAL],
        50,
        [
            ("README.md", r"\*\*Dyna-QPC ([\d,]+)\*\* \((\d+/\d+) sets\)", ("steps", "sets")),
            (
                "docs/results/paper-lab.md",
                r"\| \*\*Dyna-QPC\*\* \| realistic \(`paper-lab-real`\) \| \*\*(\d+/\d+)\*\* \| \*\*([\d,]+) ±",
                ("sets", "steps"),
            ),
        ],
    ),
    (
        "paper-lab-real dyna-q N=1000",
        ["--agent", "dyna-q", "--planning", "1000", *LAB_REAL],
        50,
        [
            (
                "README.md",
                r"\*\*Dyna-QPC [\d,]+\*\* \(\d+/\d+ sets\), Dyna-Q ([\d,]+) \((\d+/\d+)\)",
                ("steps", "sets"),
            ),
            (
                "docs/results/paper-lab.md",
                r"\| Dyna-Q \| realistic \(`paper-lab-real`\) \| (\d+/\d+) \| ([\d,]+) ±",
                ("sets", "steps"),
            ),
        ],
    ),
    (
        "paper-lab dyna-qpc N=5",
        ["--agent", "dyna-qpc", "--planning", "5", *LAB],
        50,
        [
            (
                "docs/results/paper-lab.md",
                r"\| \*\*Dyna-QPC\*\* \| 5 \| \*\*(\d+/\d+)\*\* \| \*\*([\d,]+)\*\* \|",
                ("sets", "steps"),
            ),
        ],
    ),
    (
        "paper-lab dyna-q N=5",
        ["--agent", "dyna-q", "--planning", "5", *LAB],
        50,
        [
            ("docs/results/paper-lab.md", r"\| Dyna-Q \| 5 \| (\d+/\d+) \| ([\d,]+) \|", ("sets", "steps")),
        ],
    ),
    (
        "paper-sim dyna-qpc N=1000",
        ["--agent", "dyna-qpc", "--planning", "1000", *SIM],
        500,
        [
            ("README.md", r"exact robot \(`paper-sim`\): Dyna-QPC ([\d.]+) h \((\d+/\d+) sets[;)]", ("hours", "sets")),
            (
                "docs/results/README.md",
                r"Dyna-QPC ([\d.]+) h of robot time to learn, (\d+/\d+) sets",
                ("hours", "sets"),
            ),
            (
                "docs/results/paper-sim.md",
                r"\| \*\*Dyna-QPC\*\* \| 1,000 \| [\d.,]+ \| \*\*(\d+/\d+)\*\* \| [\d,]+ ± [\d,]+ \| "
                r"\*\*([\d.]+) ± [\d.]+\*\* \|",
                ("sets", "hours"),
            ),
        ],
    ),
    (
        "paper-sim-real dyna-qpc N=1000",
        ["--agent", "dyna-qpc", "--planning", "1000", *SIM_REAL],
        500,
        [
            ("README.md", r"\*\*Dyna-QPC ([\d.]+) h\*\* \((\d+/\d+) sets[;)]", ("hours", "sets")),
            (
                "docs/results/paper-sim.md",
                r"\| \*\*Dyna-QPC, realistic robot\*\* \(`paper-sim-real`\) \| 1,000 \| [\d.,]+ \| \*\*(\d+/\d+)\*\* \| "
                r"[\d,]+ ± [\d,]+ \| \*\*([\d.]+) ±",
                ("sets", "hours"),
            ),
        ],
    ),
]


def measure(sim: str, exp: str, train_args, threshold: int, work: str) -> dict:
    csv = os.path.join(work, "run.csv")
    subprocess.run([sim, "train", *train_args, "--jobs", "2", "--quiet", "--no-wall-time", "--csv", csv], check=True)
    table = subprocess.run(
        [exp, "table", "--learned-steps", str(threshold), "--csv", csv], check=True, capture_output=True, text=True
    ).stdout
    header = next(ln for ln in table.splitlines() if ln.startswith("| Agent"))
    row = next(ln for ln in table.splitlines() if ln.startswith("| ") and not ln.startswith(("| Agent", "|---")))
    cols = [c.strip() for c in header.strip("|").split("|")]
    vals = [c.strip() for c in row.strip("|").split("|")]
    cell = dict(zip(cols, vals))
    return {
        "sets": cell["Sets learned"],
        "steps": cell["Real steps to learn"].split(" ±")[0],
        "hours": cell["Robot time to learn (h)"].split(" ±")[0],
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="docs-check", description=__doc__.split("\n\n")[0])
    ap.add_argument("--sim", default=str(ROOT / "build" / "host-release" / "bin" / "dynaqpc-sim"))
    ap.add_argument("--experiment", default=str(ROOT / ".venv" / "bin" / "dynaqpc-experiment"))
    ap.add_argument("--only", default=None, help="run the checks whose name contains this")
    args = ap.parse_args(argv)
    for tool in (args.sim, args.experiment):
        if not os.access(tool, os.X_OK):
            print(
                f"docs-check: {tool} missing (tools/dev.sh setup; cmake --build --preset host-release)", file=sys.stderr
            )
            return 2
    drifted = 0
    with tempfile.TemporaryDirectory(prefix="docs-check-") as work:
        for name, train_args, threshold, places in CHECKS:
            if args.only and args.only not in name:
                continue
            got = measure(args.sim, args.experiment, train_args, threshold, work)
            shown = ", ".join(f"{k} {got[k]}" for k in ("sets", "steps", "hours"))
            print(f"docs-check: {name}: {shown}", flush=True)
            for page, pattern, figures in places:
                text = (ROOT / page).read_text(encoding="utf-8")
                m = re.search(pattern, text)
                if not m:
                    print(f"DRIFT: {page}: no figure for {name} (pattern {pattern!r} not found)")
                    drifted += 1
                    continue
                for i, fig in enumerate(figures, 1):
                    if m.group(i) != got[fig]:
                        print(f"DRIFT: {page}: {name}: the page says {fig} {m.group(i)}, measured {got[fig]}")
                        drifted += 1
    if drifted:
        print(f"docs-check: {drifted} figure(s) drifted; re-measure and update the pages")
        return 1
    print("docs-check: every checked figure is the one the pages quote")
    return 0


if __name__ == "__main__":
    sys.exit(main())
