# SPDX-License-Identifier: MIT
"""What a tool that listens to the robot's bus shares (dynaqpc-monitor, dynaqpc-viewer): its
arguments (the bus, --replay FILE to read instead of it, --count and --duration to stop) and the
frames it reads. Below both UIs: they import it, and it imports neither."""

from __future__ import annotations

import argparse
from typing import Callable, Iterator, Optional

from .common import ToolArgumentParser, add_bus_arguments, bus_from_args, float_in, int_in


def listener_parser(prog: str, description: str, counted: str) -> ToolArgumentParser:
    """A listener's parser: the bus and its database (add_bus_arguments), --replay FILE, and when
    to stop: --count N of what it counts (`counted`), --duration S."""
    p = ToolArgumentParser(prog=prog, description=description, formatter_class=argparse.RawDescriptionHelpFormatter)
    add_bus_arguments(p)
    p.add_argument("--replay", metavar="FILE", help="read a recording (.mcap, .asc, .blf, ...) instead of a bus")
    p.add_argument("--count", type=int_in(1), default=None, help=f"stop after N {counted}")
    p.add_argument("--duration", type=float_in(0, lo_open=True), default=None, help="stop after S seconds")
    return p


def frames(args, timeout: float, on_open: Optional[Callable[[], None]] = None) -> Iterator:
    """The frames of --replay FILE until it ends; or those heard on the bus, which this opens
    (calling `on_open` once it listens) and shuts down when the caller closes it (contextlib.closing),
    with None for each read that timed out."""
    if args.replay:
        from .canlog import read_log

        yield from read_log(args.replay)
        return
    bus = bus_from_args(args)
    try:
        if on_open is not None:
            on_open()
        while True:
            yield bus.recv(timeout=timeout)
    finally:
        bus.shutdown()
