# SPDX-License-Identifier: MIT
"""Run by test_foxglove.py inside a private network namespace: `dynaqpc-monitor --foxglove 0`
serving the bus, a WebSocket client (tornado, Foxglove's protocol foxglove.sdk.v1) subscribed to
every channel it advertises, then the firmware's host build (dynaqpc-fw) and the simulated robot
(dynaqpc-sim devices --supervise) on the virtual CAN bus. Checks that the pose, /tf, the rays and
the plot channels arrive within 5 s of the firmware starting, and what they hold. Prints PASS or
FAIL: <why> (exit 1).

    python foxglove_scenario.py BUILD_BIN_DIR WORK_DIR
"""

import asyncio
import base64
import json
import os
import re
import struct
import subprocess
import sys
import time

from google.protobuf import descriptor_pb2, descriptor_pool, message_factory
from tornado.websocket import websocket_connect

from dynaqpc_tools.foxglove_live import scenario_grid

bin_dir, work = sys.argv[1], sys.argv[2]
SPEED = "10"
WITHIN_S = 5.0
procs = []
ARENA = {
    "width": 8.0,
    "height": 8.0,
    "obstacles": [{"kind": "circle", "cx": 2.0, "cy": 2.0, "r": 0.3}],
    "goal": {"cx": 7.0, "cy": 7.0, "r": 0.5, "cells": [[6.5, 6.5, 7.5, 7.5]]},
}
REQUIRED = [
    "/robot/pose",
    "/tf",
    "/robot/rays",
    "/robot/state",
    "/arena",
    "/can/TLM_POSE",
    "/can/TLM_SCHED",
    "/can/FW_STATUS",
    "/can/MOTOR_STATUS",
    "/can/SONAR_RANGES_A",
    "/robot/true_pose",
    "/robot/values",
    "/can/TLM_VALUE",
]


def fail(msg):
    print("FAIL: " + msg, flush=True)
    for name, p, log in procs:
        p.kill()
        p.wait()
        print(f"--- {name}\n" + open(log, encoding="utf-8", errors="replace").read()[-2000:])
    sys.exit(1)


def start(name, argv):
    log = f"{work}/{name}.out"
    p = subprocess.Popen(argv, stdout=open(log, "w"), stderr=subprocess.STDOUT)
    procs.append((name, p, log))
    return log


def wait_for(log, pattern, seconds):
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        m = re.search(pattern, open(log, encoding="utf-8", errors="replace").read())
        if m:
            return m
        time.sleep(0.05)
    return None


with open(f"{work}/arena.json", "w") as f:
    json.dump(ARENA, f)
SCENARIO = os.path.join(
    os.path.dirname(os.path.abspath(__file__)), "..", "..", "host_sim", "scenarios", "paper-sim.scn"
)
mon = start(
    "monitor",
    [
        sys.executable,
        "-m",
        "dynaqpc_tools.monitor",
        "--foxglove",
        "0",
        "--arena",
        f"{work}/arena.json",
        "--scenario",
        SCENARIO,
        "--refresh",
        "0",
        "--duration",
        "40",
    ],
)
m = wait_for(mon, r"Foxglove on ws://127\.0\.0\.1:(\d+)", 30)
if not m:
    fail("dynaqpc-monitor --foxglove did not say where it serves")
port = int(m.group(1))
if not wait_for(mon, "listening on", 10):
    fail("dynaqpc-monitor did not open the bus")


async def client():
    conn = await websocket_connect(f"ws://127.0.0.1:{port}", subprotocols=["foxglove.sdk.v1"])
    channels, subs, first, last = {}, {}, {}, {}
    t_fw = None
    next_sub = 1
    deadline = time.monotonic() + 30
    while time.monotonic() < deadline:
        if t_fw is None and channels:
            # Subscribed to what is there; now the firmware and the robot start.
            start("fw", [f"{bin_dir}/dynaqpc-fw", "--scenario", "paper-sim", "--speed", SPEED, "--duration", "30"])
            start(
                "devices",
                [
                    f"{bin_dir}/dynaqpc-sim",
                    "devices",
                    "--scenario",
                    "paper-sim",
                    "--speed",
                    SPEED,
                    "--supervise",
                    "--duration",
                    "30",
                ],
            )
            t_fw = time.monotonic()
        if t_fw is not None and all(t in first for t in REQUIRED) and time.monotonic() - t_fw > 3:
            break
        try:
            msg = await asyncio.wait_for(conn.read_message(), 0.5)
        except asyncio.TimeoutError:
            continue
        if msg is None:
            fail("the server closed the connection")
        if isinstance(msg, str):
            j = json.loads(msg)
            if j.get("op") == "advertise":
                new = []
                for ch in j["channels"]:
                    channels[ch["id"]] = ch
                    subs[next_sub] = ch
                    new.append({"id": next_sub, "channelId": ch["id"]})
                    next_sub += 1
                await conn.write_message(json.dumps({"op": "subscribe", "subscriptions": new}))
            continue
        if msg[0] != 1:  # message data
            continue
        sid, _ts = struct.unpack_from("<IQ", msg, 1)
        ch = subs.get(sid)
        if ch is None:
            continue
        topic = ch["topic"]
        if t_fw is not None:
            first.setdefault(topic, time.monotonic() - t_fw)
        last[topic] = (ch, bytes(msg[13:]))
    conn.close()
    return channels, first, last, t_fw


def decode(topic):
    """The last message on `topic`, decoded as a Foxglove client does: protobuf through the schema
    the server advertised (a FileDescriptorSet), JSON as JSON."""
    ch, data = last[topic]
    if ch["encoding"] == "json":
        return json.loads(data)
    fds = descriptor_pb2.FileDescriptorSet.FromString(base64.b64decode(ch["schema"]))
    pool = descriptor_pool.DescriptorPool()
    for f in fds.file:
        pool.Add(f)
    return message_factory.GetMessageClass(pool.FindMessageTypeByName(ch["schemaName"])).FromString(data)


channels, first, last, t_fw = asyncio.run(client())
print("first message after the firmware started (s):")
for topic in sorted(first):
    print(f"  {topic:24s} {first[topic]:.2f}  {last[topic][0]['schemaName']} ({last[topic][0]['encoding']})")
late = [t for t in REQUIRED if first.get(t, 99) > WITHIN_S]
if late:
    fail(f"not within {WITHIN_S:g} s of the firmware starting: {late}")
schemas = {c["topic"]: c["schemaName"] for c in channels.values()}
want = {
    "/robot/pose": "foxglove.PoseInFrame",
    "/tf": "foxglove.FrameTransforms",
    "/robot/rays": "foxglove.SceneUpdate",
    "/arena": "foxglove.SceneUpdate",
    "/robot/bumps": "foxglove.SceneUpdate",
    "/robot/values": "foxglove.SceneUpdate",
}
for topic, name in want.items():
    if schemas.get(topic) != name:
        fail(f"{topic} has schema {schemas.get(topic)}, not {name}")
pose = decode("/robot/pose")
if pose.frame_id != "arena" or not (0 < pose.pose.position.x < 8 and 0 < pose.pose.position.y < 8):
    fail(f"/robot/pose is not in the arena: {pose}")
tf = decode("/tf")
frames = {(t.parent_frame_id, t.child_frame_id) for t in tf.transforms}
if not frames & {("arena", "base_link"), ("arena", "true_base_link")}:
    fail(f"/tf holds {frames}")
rays = decode("/robot/rays")
ent = rays.entities[0]
if ent.frame_id != "base_link" or len(ent.lines) != 16 or "episode" not in ent.texts[0].text:
    fail(f"/robot/rays: frame {ent.frame_id}, {len(ent.lines)} lines, label {ent.texts[0].text!r}")
state = decode("/robot/state")
if state["mode"] not in ("RUNNING", "IDLE", "SAFE_STOP") or "episode" not in state:
    fail(f"/robot/state: {state}")
sched = decode("/can/TLM_SCHED")
if "QueueLength" not in sched or "IdlePercent" not in sched:
    fail(f"/can/TLM_SCHED: {sched}")
status = decode("/can/FW_STATUS")
if status.get("Mode_name") not in ("RUNNING", "IDLE", "SAFE_STOP"):
    fail(f"/can/FW_STATUS: {status}")
arena = decode("/arena")
if len(arena.entities[0].cubes) != 5 or len(arena.entities[0].cylinders) != 1:  # 4 walls + a goal cell; the post
    fail("/arena does not hold the walls, the goal cell and the obstacle")
values = decode("/robot/values").entities[0]
if values.frame_id != "arena" or not values.cubes or "cells" not in values.texts[0].text:
    fail(f"/robot/values: {len(values.cubes)} tiles, {values.texts[0].text if values.texts else ''!r}")
# paper-sim's cells, fitted to the room (encode auto): each tile is 0.95 of one, at its centre
grid = scenario_grid(SCENARIO, f"{bin_dir}/dynaqpc-sim")
cells_x = {(round((a + b) / 2, 4), round((b - a) * 0.95, 4)) for a, b in zip(grid["x_edges"], grid["x_edges"][1:])}
cells_y = {(round((a + b) / 2, 4), round((b - a) * 0.95, 4)) for a, b in zip(grid["y_edges"], grid["y_edges"][1:])}
for c in values.cubes:
    if (round(c.pose.position.x, 4), round(c.size.x, 4)) not in cells_x or (
        round(c.pose.position.y, 4),
        round(c.size.y, 4),
    ) not in cells_y:
        fail(f"/robot/values: a tile of {c.size.x} x {c.size.y} m at ({c.pose.position.x}, {c.pose.position.y})")
print(f"values: {values.texts[0].text}")
print(
    f"pose ({pose.pose.position.x:.2f}, {pose.pose.position.y:.2f}), tf {sorted(frames)}, "
    f"rays {len(ent.lines)}: {ent.texts[0].text!r}, state {state}"
)
for name, p, log in procs:
    p.terminate()
    p.wait(timeout=10)
print("PASS")
