# SPDX-License-Identifier: MIT
"""Run by test_operator.py inside a private network namespace: the firmware's host build
(dynaqpc-fw) and the simulated devices (dynaqpc-sim devices) on the virtual CAN bus, commanded
by dynaqpc-operator as a user would, one process per command. Prints each command's output and
exits non-zero with a message on the first check that fails.

    python operator_scenario.py BUILD_BIN_DIR WORK_DIR
"""

import json
import re
import subprocess
import sys
import time

bin_dir, work = sys.argv[1], sys.argv[2]
SPEED = "10"
procs = []


def fail(msg):
    print("FAIL: " + msg)
    for name, p, log in procs:
        p.kill()
        p.wait()
        print(f"--- {name}\n" + open(log, encoding="utf-8", errors="replace").read()[-3000:])
    sys.exit(1)


def start(name, argv):
    log = f"{work}/{name}.out"
    p = subprocess.Popen(argv, stdout=open(log, "w"), stderr=subprocess.STDOUT)
    procs.append((name, p, log))
    return log


def wait_for(log, text, seconds):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if text in open(log, encoding="utf-8", errors="replace").read():
            return True
        time.sleep(0.1)
    return False


def operator(*argv):
    p = subprocess.run(
        [sys.executable, "-m", "dynaqpc_tools.operator", *argv], capture_output=True, text=True, timeout=60
    )
    print(f"$ dynaqpc-operator {' '.join(argv)}  -> exit {p.returncode}\n{p.stdout}{p.stderr}", end="")
    return p.returncode, p.stdout


# The firmware is silent before it starts: status says so, exit 1.
rc, out = operator("status", "--timeout", "1")
if rc != 1 or "silent" not in out:
    fail("status with no firmware on the bus must exit 1 and say it is silent")

fw = start(
    "fw",
    [
        f"{bin_dir}/dynaqpc-fw",
        "--scenario",
        "paper-sim",
        "--speed",
        SPEED,
        "--flash",
        f"{work}/flash.bin",
        "--duration",
        "60",
    ],
)
if not wait_for(fw, "ready", 10):
    fail("dynaqpc-fw did not start")
start("devices", [f"{bin_dir}/dynaqpc-sim", "devices", "--scenario", "paper-sim", "--speed", SPEED, "--duration", "60"])

rc, out = operator("status")
if rc != 0 or "mode IDLE" not in out or "MotorSilent=" not in out or "uptime" not in out:
    fail("status must name the mode (IDLE), every error flag and the uptime")
rc, out = operator("start", "--heading", "90")
if rc != 0 or "mode RUNNING" not in out:
    fail("start must start an episode (FW_STATUS RUNNING)")
rc, out = operator("safe-stop")
if rc != 0 or "mode SAFE_STOP" not in out:
    fail("safe-stop must stop the episode (FW_STATUS SAFE_STOP)")
time.sleep(1.0)  # held: the sensors are fine, yet it stays stopped
rc, out = operator("status")
if rc != 0 or "mode SAFE_STOP" not in out:
    fail("the operator's safe stop must hold until the next start")
# Two more one-shot commands in a row: each new process picks its own counters, none is refused.
for _ in range(2):
    rc, out = operator("start")
    if rc != 0 or "mode RUNNING" not in out:
        fail("a second start must be accepted (the counter scheme)")
watch_log = start("watch", [sys.executable, "-m", "dynaqpc_tools.operator", "watch", "--duration", "40"])
time.sleep(1.0)
rc, out = operator("save")
m = re.search(r"SAVE_LEARNED: done, record (\d+) written \((\d+) episodes\)", out)
if rc != 0 or not m:
    fail("save must be answered: done, with the record's sequence number and episodes")
rc, out = operator("reset")
if rc != 1 or "refused, NOT_IDLE" not in out:
    fail("reset of a running robot must be refused (NOT_IDLE), exit 1")
rc, out = operator("stop")
if rc != 0 or "STOP: done" not in out or "mode IDLE" not in out:
    fail("stop must leave the firmware IDLE")
rc, out = operator("save", "--json")
try:
    saved = json.loads(out)
except ValueError:
    fail("save --json must print one JSON object")
if rc != 0 or saved["answer"]["result"] != "DONE" or saved["exit"] != 0 or saved["answer"]["sequence"] < 1:
    fail("save --json must carry the answer")
learned_episodes = saved["answer"]["episodes"]
# The loss: reset then save. Learning was saved since boot, so reset wants --yes.
rc, out = operator("reset")
if rc != 1 or "refused, CONFIRM" not in out or "--yes" not in out:
    fail("reset of learning saved since boot must be refused without --yes, naming it")
rc, out = operator("reset", "--yes")
if rc != 0 or "RESET_LEARNING: done" not in out or "mode IDLE" not in out:
    fail("reset --yes must wipe (FW_STATUS IDLE)")
rc, out = operator("save")
if rc != 0 or "(0 episodes)" not in out:
    fail("save after reset must save the wiped learning (0 episodes)")
rc, out = operator("restore-previous", "--json")
restored = json.loads(out)
if rc != 0 or restored["answer"]["result"] != "DONE" or restored["answer"]["episodes"] != learned_episodes:
    fail(f"restore-previous must bring back the {learned_episodes} episodes saved before the reset")
rc, out = operator("save")
if rc != 0 or f"({learned_episodes} episodes)" not in out:
    fail("the restored learning must save again")
rc, out = operator("ping")
if rc != 0 or "NOP: done, newest record in flash" not in out or f"{learned_episodes} episodes learned" not in out:
    fail("ping must be answered with the newest record and the episodes learned")
time.sleep(0.5)

for name, p, log in procs:
    p.terminate()
    p.wait(timeout=10)
fwlog = open(fw, encoding="utf-8", errors="replace").read()
print("--- fw\n" + fwlog[-1500:])
if "saves=" not in fwlog or "saves=0 " in fwlog:
    fail("the firmware did not count the save")
m = re.search(r"q_rows=(\d+)/", fwlog)
if not m or int(m.group(1)) == 0:
    fail("after reset, save and restore-previous the firmware must hold what it learned (q_rows > 0)")
if "resets=1 restores=1" not in fwlog:
    fail("the firmware must count one reset and one restore")
watched = open(watch_log, encoding="utf-8", errors="replace").read()
print("--- watch\n" + watched[-2500:])
for want in (
    "TOOL_CMD SAVE_LEARNED",
    "TOOL_ACK counter",
    "RESET_LEARNING: refused, CONFIRM",
    "RESTORE_PREVIOUS: done",
    "FW_STATUS mode RUNNING -> IDLE",
):
    if want not in watched:
        fail(f"watch must show {want!r}")
print("PASS")
