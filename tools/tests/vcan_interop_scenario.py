# SPDX-License-Identifier: MIT
"""Run by test_vcan_interop.py, inside a private network namespace when possible:
C (vcan-send) -> python-can, python-can -> C (vcan-dump), and C -> dynaqpc-monitor over the bus.
Exits non-zero with a message on the first mismatch.

    python vcan_interop_scenario.py BUILD_BIN_DIR PORT TEST_DBC
"""

import subprocess
import sys
import time

import can

bin_dir, port, test_dbc = sys.argv[1], int(sys.argv[2]), sys.argv[3]

# cansend notation -> expected python-can message fields
FRAMES = [
    "123#",
    "7FF#01",
    "000#0102",
    "1ABCDE00#A0A1A2A3A4A5A6A7",
    "456#R3",
    "321#DEADBEEF",
    "100#0102030405",
    "101#010203040506",
    "102#01020304050607",
    "00000001#",
]


def expected(spec):
    ident, data = spec.split("#")
    remote = data.startswith("R")
    return (
        int(ident, 16),
        len(ident) == 8,
        remote,
        int(data[1:] or 0) if remote else len(data) // 2,
        b"" if remote else bytes.fromhex(data),
    )


def as_tuple(m):
    return (m.arbitration_id, m.is_extended_id, m.is_remote_frame, m.dlc, bytes(m.data))


def fail(msg):
    print("FAIL: " + msg)
    sys.exit(1)


# 1. C sends, python-can receives.
with can.Bus(interface="udp_multicast", channel="239.74.163.2", port=port, hop_limit=0) as bus:
    subprocess.run([f"{bin_dir}/vcan-send", "--port", str(port), "--repeat", "3", *FRAMES], check=True)
    got = []
    while len(got) < 3 * len(FRAMES):
        m = bus.recv(timeout=5)
        if m is None:
            fail(f"python-can received {len(got)} of {3 * len(FRAMES)} frames from vcan-send")
        got.append(as_tuple(m))
    want = [expected(f) for f in FRAMES] * 3
    if got != want:
        fail(f"C -> python-can mismatch:\n got {got}\nwant {want}")
print(f"C -> python-can: {len(got)} frames identical")

# 2. python-can sends, C receives.
dump = subprocess.Popen(
    [f"{bin_dir}/vcan-dump", "--port", str(port), "--count", str(len(FRAMES)), "--timeout-ms", "5000"],
    stdout=subprocess.PIPE,
    stderr=subprocess.PIPE,
    text=True,
)
if dump.stdout.readline().strip() != "ready":
    fail("vcan-dump did not start")
with can.Bus(interface="udp_multicast", channel="239.74.163.2", port=port, hop_limit=0) as bus:
    for spec in FRAMES:
        ident, ext, remote, dlc, data = expected(spec)
        bus.send(can.Message(arbitration_id=ident, is_extended_id=ext, is_remote_frame=remote, dlc=dlc, data=data))
        time.sleep(0.001)  # pace: UDP has no flow control
out, err = dump.communicate(timeout=10)
lines = out.split()
norm = [f.upper() if "#R" not in f else f for f in FRAMES]
if dump.returncode != 0 or lines != norm:
    fail(f"python-can -> C mismatch (exit {dump.returncode}, {err.strip()}):\n got {lines}\nwant {norm}")
print(f"python-can -> C: {len(lines)} frames identical ({err.strip()})")

# 3. C sends a pose stream with a counter gap; dynaqpc-monitor on the bus sees it.
import cantools  # noqa: E402

db = cantools.database.load_file(test_dbc)
pose = db.get_message_by_name("POSE_T")
counters = [0, 1, 2, 3, 6, 7]  # 2 frames lost between 3 and 6
frames = [
    f"{pose.frame_id:03X}#" + pose.encode({"X": 10 * c, "Y": 0, "Heading": 0, "FixState": 0, "Counter": c}).hex()
    for c in counters
]
mon = subprocess.Popen(
    [
        sys.executable,
        "-m",
        "dynaqpc_tools.monitor",
        "--dbc",
        test_dbc,
        "--count",
        str(len(frames)),
        "--duration",
        "10",
        "--bus-kwarg",
        f"port={port}",
        "--print",
    ],
    stdout=subprocess.PIPE,
    stderr=subprocess.PIPE,
    text=True,
)
# Sent once the monitor has joined the group (it says so on stderr), not after a guessed delay:
# with `time.sleep(1.5)` here, a loaded machine started the monitor later and it heard 0 frames.
joined = mon.stderr.readline()
if "listening on" not in joined:
    mon.kill()
    fail(f"dynaqpc-monitor did not say it was listening: {joined!r}")
subprocess.run([f"{bin_dir}/vcan-send", "--port", str(port), *frames], check=True)
out, err = mon.communicate(timeout=20)
if mon.returncode != 0 or "6 frames" not in out or "2 frames lost" not in out or "3 -> 6" not in err:
    fail(f"monitor over the bus (exit {mon.returncode}):\n{out}\n{err}")
print("dynaqpc-monitor over the bus: 6 frames, 2 lost, as sent")
