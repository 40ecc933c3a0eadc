# SPDX-License-Identifier: MIT
"""Run by test_operator.py inside a private network namespace: the firmware's host build
(dynaqpc-fw) and the simulated devices (dynaqpc-sim devices) on the virtual CAN bus, commanded
by dynaqpc-operator as a user would, one process per command. Prints each command's output and
exits non-zero with a message on the first check that fails.

    python operator_scenario.py BUILD_BIN_DIR WORK_DIR
"""

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
    p = subprocess.run([sys.executable, "-m", "dynaqpc_tools.operator", *argv], capture_output=True, text=True,
                       timeout=60)
    print(f"$ dynaqpc-operator {' '.join(argv)}  -> exit {p.returncode}\n{p.stdout}{p.stderr}", end="")
    return p.returncode, p.stdout


# The firmware is silent before it starts: status says so, exit 1.
rc, out = operator("status", "--timeout", "1")
if rc != 1 or "silent" not in out:
    fail("status with no firmware on the bus must exit 1 and say it is silent")

fw = start("fw", [f"{bin_dir}/dynaqpc-fw", "--scenario", "paper-sim", "--speed", SPEED, "--flash",
                  f"{work}/flash.bin", "--duration", "60"])
if not wait_for(fw, "ready", 10):
    fail("dynaqpc-fw did not start")
start("devices", [f"{bin_dir}/dynaqpc-sim", "devices", "--scenario", "paper-sim", "--speed", SPEED,
                  "--duration", "60"])

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
rc, out = operator("save")
if rc != 0 or "FW_STATUS" not in out:
    fail("save must be answered by a FW_STATUS")
rc, out = operator("stop")
if rc != 0 or "mode IDLE" not in out:
    fail("stop must leave the firmware IDLE")
rc, out = operator("reset")
if rc != 0 or "mode IDLE" not in out:
    fail("reset must leave the firmware IDLE")

for name, p, log in procs:
    p.terminate()
    p.wait(timeout=10)
fwlog = open(fw, encoding="utf-8", errors="replace").read()
print("--- fw\n" + fwlog[-1500:])
if "saves=" not in fwlog or "saves=0 " in fwlog:
    fail("the firmware did not count the save")
print("PASS")
