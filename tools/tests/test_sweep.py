# SPDX-License-Identifier: MIT
"""dynaqpc-experiment sweep: the grid file, and a sweep on a Dask scheduler and two workers
started on 127.0.0.1 (loopback only), with the real simulator."""

import csv
import os
import socket
import subprocess
import sys
import time

import pytest
from conftest import c_binary

from dynaqpc_tools import experiment
from dynaqpc_tools.common import ToolError
from dynaqpc_tools.experiment import sweep

GRID = """
scenario = "paper-lab"
agents = ["q", "dyna-qpc"]
sets = 2
episodes = 2
seed = 3
block = 1
threshold = 50
[grid]
epsilon = [0.05, 0.1]
"""


def test_grid_points_and_tasks(tmp_path):
    p = tmp_path / "g.toml"
    p.write_text(GRID + "planning = [5, 1000]\n")
    g = sweep.load_grid(str(p))
    assert g.points() == [
        {"epsilon": 0.05, "planning": 5},
        {"epsilon": 0.05, "planning": 1000},
        {"epsilon": 0.1, "planning": 5},
        {"epsilon": 0.1, "planning": 1000},
    ]
    tasks = sweep.tasks_of(g, "/x/dynaqpc-sim")
    assert len(tasks) == 4 * 2 * 2
    t = tasks[0]
    assert t["extra"] == ["--epsilon", "0.05", "--planning", "5"] and (t["first_set"], t["sets"]) == (1, 1)
    assert len({x["name"] for x in tasks}) == len(tasks)


@pytest.mark.parametrize(
    "text, message",
    [
        ("scenario = 'paper-lab'\nsets = 2\n", "'episodes' is missing"),
        ("scenario = 'paper-lab'\nsets = 0\nepisodes = 2\n", "'sets' = 0"),
        ("scenario = 'paper-lab'\nsets = 2\nepisodes = 2\nagents = ['sarsa']\n", "agents"),
        ("scenario = 'paper-lab'\nsets = 2\nepisodes = 2\n[grid]\nseed = [1, 2]\n", "the sweep sets"),
        ("scenario = 'paper-lab'\nsets = 2\nepisodes = 2\n[grid]\nepsilon = 0.1\n", "non-empty list"),
        ("scenario = 'paper-lab'\nsets = 2\nepisodes = 2\n[grid]\nepsilon = [0.1, 0.1]\n", "twice"),
        ("scenario = 'paper-lab'\nsets = 2\nepisodes = 2\nthreshold = -1\n", "threshold"),
        ("scenario = 'paper-lab'\nsets = 2\nepisodes = 2\nepsilon = [0.1]\n", "unknown key"),
        ("not = toml = at all", "not TOML"),
    ],
)
def test_bad_grids_are_named(tmp_path, text, message):
    p = tmp_path / "g.toml"
    p.write_text(text)
    with pytest.raises(ToolError, match=message):
        sweep.load_grid(str(p))


def _free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _start_cluster(tmp_path, nanny=True):
    """A scheduler and two single-thread workers, on 127.0.0.1 only, as docs/sweeps.md starts
    them; returns (address, [scheduler, worker1, worker2] processes, log files)."""
    dask = os.path.join(os.path.dirname(sys.executable), "dask")
    port = _free_port()
    address = f"tcp://127.0.0.1:{port}"
    logs = [open(tmp_path / f"{n}.log", "w") for n in ("scheduler", "worker1", "worker2")]
    procs = [
        subprocess.Popen(
            [dask, "scheduler", "--host", "127.0.0.1", "--port", str(port), "--no-dashboard"],
            stdout=logs[0],
            stderr=subprocess.STDOUT,
        )
    ]
    for i in (1, 2):
        procs.append(
            subprocess.Popen(
                [dask, "worker", address, "--host", "127.0.0.1", "--nthreads", "1", "--no-dashboard", "--name", f"w{i}"]
                + ([] if nanny else ["--no-nanny"]),
                stdout=logs[i],
                stderr=subprocess.STDOUT,
            )
        )
    return address, procs, logs


def _stop_cluster(procs, logs):
    for p in procs[::-1]:
        if p.poll() is None:
            p.terminate()
    for p in procs:
        try:
            p.wait(20)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()
    for f in logs:
        f.close()


@pytest.fixture
def dask_cluster(tmp_path):
    address, procs, logs = _start_cluster(tmp_path)
    try:
        from dask.distributed import Client

        with Client(address, timeout=30) as c:
            c.wait_for_workers(2, timeout=60)
        yield address
    finally:
        _stop_cluster(procs, logs)


@pytest.mark.skipif(not c_binary("dynaqpc-sim").exists(), reason="build dynaqpc-sim first or set DYNAQPC_BUILD_DIR")
def test_sweep_on_a_scheduler_and_two_workers(tmp_path, dask_cluster, capsys):
    grid = tmp_path / "grid.toml"
    grid.write_text(GRID)
    out = tmp_path / "out"
    argv = [
        "sweep",
        "--grid",
        str(grid),
        "--out",
        str(out),
        "--scheduler",
        dask_cluster,
        "--sim",
        str(c_binary("dynaqpc-sim")),
        "--no-progress",
    ]
    assert experiment.main(argv) == 0
    assert "8 tasks; 0 done before, 8 to run" in capsys.readouterr().out
    with open(out / "sweep.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    # A row per grid point, agent, set and episode: 2 x 2 x 2 x 2.
    assert len(rows) == 16
    keys = {(r["epsilon"], r["agent"], r["set"], r["episode"]) for r in rows}
    assert len(keys) == 16 and {r["epsilon"] for r in rows} == {"0.05", "0.1"}
    # Blocks of sets give the rows one run would: set 2 of epsilon 0.1 as `train --sets 2` has it.
    whole = subprocess.run(
        [
            str(c_binary("dynaqpc-sim")),
            "train",
            "--scenario",
            "paper-lab",
            "--agent",
            "dyna-qpc",
            "--sets",
            "2",
            "--episodes",
            "2",
            "--seed",
            "3",
            "--epsilon",
            "0.1",
            "--csv",
            "-",
            "--quiet",
        ],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.splitlines()[1:]
    got = [",".join(list(r.values())[1:-1]) for r in rows if r["epsilon"] == "0.1" and r["agent"] == "dyna-qpc"]
    assert got == [ln.rsplit(",", 1)[0] for ln in whole]  # all but wall_s
    summary = (out / "summary.md").read_text()
    assert summary.count("| Dyna-QPC |") == 2 and "epsilon 0.05" in summary
    assert (out / "sweep.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # A rerun skips what is done: nothing is submitted.
    (out / "tasks").joinpath(sorted(os.listdir(out / "tasks"))[0], "q-sets1-1.csv").unlink()
    assert experiment.main(argv) == 0
    assert "8 tasks; 7 done before, 1 to run" in capsys.readouterr().out
    with open(out / "sweep.csv", newline="") as f:
        assert len(list(csv.DictReader(f))) == 16


def test_sweep_reports_an_unreachable_scheduler(tmp_path, capsys):
    grid = tmp_path / "grid.toml"
    grid.write_text(GRID)
    port = _free_port()  # nothing listens there
    t = time.monotonic()
    rc = experiment.main(
        [
            "sweep",
            "--grid",
            str(grid),
            "--out",
            str(tmp_path / "o"),
            "--scheduler",
            f"tcp://127.0.0.1:{port}",
            "--no-progress",
        ]
    )
    assert rc == 2 and "cannot reach the Dask scheduler" in capsys.readouterr().err
    assert time.monotonic() - t < 60


@pytest.mark.skipif(not c_binary("dynaqpc-sim").exists(), reason="build dynaqpc-sim first or set DYNAQPC_BUILD_DIR")
def test_a_worker_lost_mid_task_has_its_task_rerun(tmp_path, capsys):
    """Worker w1 is killed (SIGKILL) while it runs a task: the scheduler reruns that task on w2,
    and the sweep's rows are those of one run, every set there once."""
    import threading

    from dask.distributed import Client

    address, procs, logs = _start_cluster(tmp_path, nanny=False)
    try:
        with Client(address, timeout=30) as c:
            c.wait_for_workers(2, timeout=60)
            grid = tmp_path / "grid.toml"
            grid.write_text('scenario = "paper-lab"\nagents = ["q"]\nsets = 4\nepisodes = 40\nseed = 5\nblock = 1\n')
            out = tmp_path / "out"
            result = {}
            t = threading.Thread(
                target=lambda: result.setdefault(
                    "rc",
                    experiment.main(
                        [
                            "sweep",
                            "--grid",
                            str(grid),
                            "--out",
                            str(out),
                            "--scheduler",
                            address,
                            "--sim",
                            str(c_binary("dynaqpc-sim")),
                            "--no-progress",
                        ]
                    ),
                )
            )
            t.start()
            w1 = next(a for a, w in c.scheduler_info()["workers"].items() if w["name"] == "w1")
            deadline = time.monotonic() + 60
            while not c.processing().get(w1) and time.monotonic() < deadline:
                time.sleep(0.02)
            busy = c.processing().get(w1)
            assert busy, "w1 never got a task"
            procs[1].kill()  # mid-task: the task is on w1 and its simulator is running
            t.join(240)
            assert not t.is_alive() and result["rc"] == 0
    finally:
        _stop_cluster(procs, logs)
    with open(out / "sweep.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert sorted({int(r["set"]) for r in rows}) == [1, 2, 3, 4] and len(rows) == 4 * 40
    whole = subprocess.run(
        [
            str(c_binary("dynaqpc-sim")),
            "train",
            "--scenario",
            "paper-lab",
            "--agent",
            "q",
            "--sets",
            "4",
            "--episodes",
            "40",
            "--seed",
            "5",
            "--csv",
            "-",
            "--quiet",
        ],
        capture_output=True,
        text=True,
        check=True,
    ).stdout.splitlines()[1:]
    assert [",".join(list(r.values())[:-1]) for r in rows] == [ln.rsplit(",", 1)[0] for ln in whole]


@pytest.mark.skipif(not c_binary("dynaqpc-sim").exists(), reason="build dynaqpc-sim first or set DYNAQPC_BUILD_DIR")
def test_sweep_without_a_scheduler_runs_a_local_cluster(tmp_path, capsys):
    grid = tmp_path / "grid.toml"
    grid.write_text('scenario = "paper-lab"\nagents = ["dyna-q"]\nsets = 2\nepisodes = 2\n[grid]\nstep_cap = [50]\n')
    out = tmp_path / "out"
    assert (
        experiment.main(
            [
                "sweep",
                "--grid",
                str(grid),
                "--out",
                str(out),
                "--workers",
                "1",
                "--planning",
                "5,100",
                "--sim",
                str(c_binary("dynaqpc-sim")),
                "--no-progress",
            ]
        )
        == 0
    )
    with open(out / "sweep.csv", newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 8 and {r["step-cap"] for r in rows} == {"50"} and {r["planning"] for r in rows} == {"5", "100"}
    assert all(int(r["steps"]) <= 50 for r in rows)  # the grid's setting reached the simulator
    summary = (out / "summary.md").read_text()
    assert "| Dyna-Q | 5 |" in summary and "| Dyna-Q | 100 |" in summary  # the budget, by the table
