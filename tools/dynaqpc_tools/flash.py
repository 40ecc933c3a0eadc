# SPDX-License-Identifier: MIT
"""dynaqpc-flash: build, flash and verify the robot's image on a board, and back up / restore
what it learned.

    dynaqpc-flash build                      # cmake --preset cortex-m4; build dynaqpc-fw-paper-lab.elf
    dynaqpc-flash flash                      # build, then program the .bin at 0x08000000 and verify it
    dynaqpc-flash backup learned.bin         # the learned-data sectors -> a file
    dynaqpc-flash restore learned.bin        # a file -> the learned-data sectors (verified)

The board is reached through a debug probe (ST-Link, CMSIS-DAP, J-Link) with pyOCD's Python API
(pip-installed with the tools; docs/flashing.md says why pyOCD and not OpenOCD). ``--target``
names the MCU as pyOCD does and picks the image: stm32f405/407/415/417 run paper-lab (learned data
in sectors 10-11, 0x080C0000, 256 KB), stm32f427/429/437/439 run paper-sim (bank 2, sectors
20-23, 0x08180000, 512 KB). pyOCD knows the STM32F429 built in; for the F405/F407 install its
CMSIS pack once: ``pyocd pack install stm32f407vg``.

The backup file is the simulator's flash image: ``dynaqpc-sim run --load FILE`` boots from it and
``dynaqpc-learned FILE`` draws it, and ``dynaqpc-sim train --save FILE`` writes one that
``restore`` puts on a board. The simulator's image is four 128 KB sectors, two slots of 256 KB
(paper-sim's board region exactly); paper-lab's board slots are one 128 KB sector each, so its
backup puts each sector at the start of its 256 KB slot and pads with erased bytes (0xFF), and
a restore to paper-lab refuses a record that would not fit a 128 KB slot.

Programming the image erases only the sectors the image covers, so what was learned survives a
reflash (the record is refused at boot only if the agent's layout changed).

Exit status: 0 done; 1 the board was reached but programming or verifying failed; 2 bad usage,
no probe or board, a file that is not a learned-store image (one line saying why).
"""

from __future__ import annotations

import argparse
import logging
import os
import shutil
import struct
import subprocess
import sys
import zlib
from dataclasses import dataclass
from pathlib import Path
from typing import List, Optional, Tuple

from .common import ToolArgumentParser, ToolError, repo_root, run_main

# The learned store's record header (firmware/robot/include/robot/learned_store.h; the tests
# check these against it).
LEARNED_STORE_MAGIC = 0x43505144  # "DQPC"
LEARNED_STORE_VERSION = 2
HEADER = struct.Struct("<8I")  # magic version sequence layout payload_size payload_crc episodes header_crc
# The simulator's flash (hal/ports/host/include/hal_host/hal_host_config.h): 4 x 128 KB, 2 slots.
HOST_SECTOR = 128 * 1024
HOST_SECTORS = 4
HOST_IMAGE = HOST_SECTOR * HOST_SECTORS
HOST_SLOT = HOST_IMAGE // 2

FLASH_BASE = 0x08000000


@dataclass(frozen=True)
class Board:
    image: str  # dynaqpc-fw-<image>
    region: int  # address of the learned-data region
    size: int  # its bytes (two slots)
    default_target: str

    @property
    def slot(self) -> int:
        return self.size // 2


BOARDS = {
    "paper-lab": Board("paper-lab", 0x080C0000, 0x40000, "stm32f407vg"),
    "paper-sim": Board("paper-sim", 0x08180000, 0x80000, "stm32f429xi"),
}
_FAMILIES = {
    "stm32f405": "paper-lab",
    "stm32f407": "paper-lab",
    "stm32f415": "paper-lab",
    "stm32f417": "paper-lab",
    "stm32f427": "paper-sim",
    "stm32f429": "paper-sim",
    "stm32f437": "paper-sim",
    "stm32f439": "paper-sim",
}


def board_for(target: Optional[str], image: Optional[str]) -> Tuple[Board, str]:
    """The board layout and pyOCD target name for --target / --image."""
    if target is None:
        b = BOARDS[image or "paper-lab"]
        return b, b.default_target
    t = target.lower()
    fam = _FAMILIES.get(t[:9])
    if fam is None:
        raise ToolError(
            f"--target {target}: not an STM32F405/407/415/417 (paper-lab) or STM32F427/429/437/439 (paper-sim)"
        )
    if image is not None and image != fam:
        raise ToolError(f"--image {image} does not run on {target} (it takes {fam})")
    if fam == "paper-sim" and len(t) > 9 and not t.endswith("i"):
        # 1 MB parts (xg, ...): no bank 2, the firmware runs without persistence.
        raise ToolError(
            f"--target {target}: paper-sim keeps what it learned in bank 2 of a 2 MB "
            f"part (an 'I' part such as stm32f429xi)"
        )
    return BOARDS[fam], t


# --- the learned-store image ---------------------------------------------------------------------


def records(image: bytes, slot_size: int = HOST_SLOT) -> List[Tuple[int, int, int]]:
    """The whole records in an image of two slots: (slot, sequence, episodes) each."""
    out = []
    for slot in range(2):
        base = slot * slot_size
        h = HEADER.unpack_from(image, base)
        magic, version, sequence, _layout, payload_size, payload_crc, episodes, header_crc = h
        if magic != LEARNED_STORE_MAGIC or version != LEARNED_STORE_VERSION:
            continue
        if zlib.crc32(image[base : base + HEADER.size - 4]) != header_crc:
            continue
        if payload_size > slot_size - HEADER.size:
            continue
        start = base + HEADER.size
        if zlib.crc32(image[start : start + payload_size]) != payload_crc:
            continue
        out.append((slot, sequence, episodes))
    return out


def _erased(b: bytes) -> bool:
    return b.count(0xFF) == len(b)


def read_image_file(path: str) -> bytes:
    """A learned-store image (the simulator's format) with at least one whole record."""
    try:
        data = Path(path).read_bytes()
    except OSError as e:
        raise ToolError(f"cannot read {path}: {e.strerror or e}") from None
    if len(data) != HOST_IMAGE:
        raise ToolError(
            f"{path}: {len(data)} bytes; a learned-store image (dynaqpc-flash backup, "
            f"dynaqpc-sim train --save) is {HOST_IMAGE}"
        )
    if not records(data):
        what = (
            "erased (holds nothing learned)"
            if _erased(data)
            else "no whole learned-store record (magic, version, CRCs)"
        )
        raise ToolError(f"{path}: not a learned-store image: {what}")
    return data


def board_to_image(region: bytes, board: Board) -> bytes:
    """The board's learned-data region as the simulator's image."""
    assert len(region) == board.size and board.slot <= HOST_SLOT
    pad = b"\xff" * (HOST_SLOT - board.slot)
    return b"".join(region[i * board.slot : (i + 1) * board.slot] + pad for i in range(2))


def image_to_board(image: bytes, board: Board, path: str = "the image") -> bytes:
    """The simulator's image as the board's region; a ToolError if a record would not fit."""
    out = []
    for i in range(2):
        slot = image[i * HOST_SLOT : (i + 1) * HOST_SLOT]
        if not _erased(slot[board.slot :]):
            raise ToolError(
                f"{path}: slot {i} holds more than {board.slot // 1024} KB, more than a "
                f"slot of {board.image}'s flash (a record of another agent or profile?)"
            )
        out.append(slot[: board.slot])
    return b"".join(out)


# --- building ------------------------------------------------------------------------------------


def build(board: Board, root: Path, quiet: bool = False) -> Path:
    cmake = shutil.which("cmake")
    if cmake is None:
        raise ToolError("cmake not found (install cmake and the arm-none-eabi toolchain: docs/flashing.md)")
    out = root / "build" / "cortex-m4"
    steps = []
    if not (out / "build.ninja").exists():
        steps.append([cmake, "--preset", "cortex-m4"])
    steps.append([cmake, "--build", "--preset", "cortex-m4", "--target", f"dynaqpc-fw-{board.image}.elf"])
    for argv in steps:
        print("$ cmake " + " ".join(argv[1:]), file=sys.stderr, flush=True)
        try:
            p = subprocess.run(argv, cwd=root, stdout=subprocess.DEVNULL if quiet else None)
        except OSError as e:
            raise ToolError(f"cannot run cmake: {e}") from None
        if p.returncode != 0:
            raise ToolError(f"build failed: {' '.join(['cmake', *argv[1:]])} exited {p.returncode}")
    binary = out / "bin" / f"dynaqpc-fw-{board.image}.bin"
    if not binary.is_file():
        raise ToolError(f"the build gave no {binary}")
    return binary


# --- the board -----------------------------------------------------------------------------------


class Probe:
    """A pyOCD session on the board, opened on entry (ToolError if there is no probe or board)."""

    def __init__(self, target: str, probe: Optional[str], frequency: Optional[int] = None):
        self.target_name, self.probe_id, self.frequency = target, probe, frequency
        self.session = None

    def find(self) -> list:
        """The one connected probe (--probe's), as a one-element list; a ToolError otherwise."""
        try:
            from pyocd.core.helpers import ConnectHelper
        except ImportError:
            raise ToolError("pyOCD is not installed (pip install pyocd; tools/requirements.txt)") from None
        # pyOCD logs what it tries at WARNING and above; the one line here says what matters.
        logging.getLogger("pyocd").setLevel(logging.CRITICAL)
        try:
            probes = ConnectHelper.get_all_connected_probes(blocking=False, unique_id=self.probe_id)
        except Exception as e:  # libusb missing and the like
            raise ToolError(f"cannot look for debug probes: {e}") from None
        if not probes:
            which = f" with ID {self.probe_id}" if self.probe_id else ""
            raise ToolError(
                f"no debug probe{which} found (plug in the ST-Link or CMSIS-DAP probe; "
                f"`pyocd list` lists them; without one see docs/flashing.md, ROM bootloader)"
            )
        if len(probes) > 1:
            ids = ", ".join(p.unique_id for p in probes)
            raise ToolError(f"{len(probes)} debug probes found ({ids}): pick one with --probe ID")
        return probes

    def __enter__(self):
        from pyocd.core.helpers import ConnectHelper

        # pyOCD logs what it tries at WARNING and above; the one line here says what matters.
        probes = self.find()
        options = {"target_override": self.target_name, "connect_mode": "under-reset"}
        if self.frequency:
            options["frequency"] = self.frequency
        try:
            self.session = ConnectHelper.session_with_chosen_probe(
                blocking=False, return_first=True, unique_id=probes[0].unique_id, options=options
            )
            if self.session is None:
                raise ToolError("the debug probe went away")
            self.session.open()
        except ToolError:
            raise
        except Exception as e:
            msg = str(e).splitlines()[0] if str(e) else type(e).__name__
            if "target" in msg.lower() and "not" in msg.lower() and "recogni" in msg.lower():
                raise ToolError(
                    f"pyOCD does not know {self.target_name}: pyocd pack install {self.target_name}"
                ) from None
            raise ToolError(
                f"no board on probe {probes[0].unique_id} ({self.target_name}): {msg} "
                f"(powered? SWD wired? docs/flashing.md)"
            ) from None
        return self

    def __exit__(self, *exc):
        if self.session is not None:
            try:
                self.session.close()
            except Exception:
                pass

    @property
    def target(self):
        return self.session.board.target

    def read(self, address: int, size: int) -> bytes:
        self.target.reset_and_halt()
        return bytes(self.target.read_memory_block8(address, size))

    def program(self, address: int, data: bytes) -> None:
        from pyocd.flash.loader import MemoryLoader

        try:
            self.target.reset_and_halt()
            loader = MemoryLoader(self.session, chip_erase="sector", smart_flash=False)
            loader.add_data(address, data)
            loader.commit()
        except Exception as e:
            raise FlashFailed(f"programming 0x{address:08X} failed: {e}") from None

    def verify(self, address: int, data: bytes) -> None:
        got = bytes(self.target.read_memory_block8(address, len(data)))
        if got != data:
            bad = next(i for i in range(len(data)) if got[i] != data[i])
            raise FlashFailed(f"verify failed at 0x{address + bad:08X}: read 0x{got[bad]:02X}, wrote 0x{data[bad]:02X}")

    def reset(self) -> None:
        self.target.reset()


class FlashFailed(Exception):
    """The board was reached but the bytes did not land (exit status 1)."""


# --- commands ------------------------------------------------------------------------------------


def cmd_build(args, board: Board, target: str) -> int:
    binary = build(board, _root())
    print(f"built {binary} ({binary.stat().st_size} bytes)")
    return 0


def cmd_flash(args, board: Board, target: str) -> int:
    if args.bin:
        binary = Path(args.bin)
        if not binary.is_file():
            raise ToolError(f"--bin: cannot open {binary}")
    elif args.no_build:
        binary = _root() / "build" / "cortex-m4" / "bin" / f"dynaqpc-fw-{board.image}.bin"
        if not binary.is_file():
            raise ToolError(f"{binary} not built (drop --no-build, or: dynaqpc-flash build)")
    else:
        Probe(target, args.probe).find()  # no probe: say so before minutes of building
        binary = build(board, _root())
    data = binary.read_bytes()
    if FLASH_BASE + len(data) > board.region:
        raise ToolError(f"{binary}: {len(data)} bytes would reach the learned-data region at 0x{board.region:08X}")
    with Probe(target, args.probe, args.frequency) as p:
        print(f"flashing {binary.name} ({len(data)} bytes) to {target} at 0x{FLASH_BASE:08X}", file=sys.stderr)
        p.program(FLASH_BASE, data)
        p.verify(FLASH_BASE, data)
        p.reset()
    print(f"flashed and verified {binary.name} on {target}; learned data at 0x{board.region:08X} kept")
    return 0


def cmd_backup(args, board: Board, target: str) -> int:
    if os.path.exists(args.file) and not args.force:
        raise ToolError(f"{args.file} exists (pass --force to overwrite)")
    with Probe(target, args.probe, args.frequency) as p:
        region = p.read(board.region, board.size)
        p.reset()
    image = board_to_image(region, board)
    Path(args.file).write_bytes(image)
    recs = records(image)
    if not recs:
        print(
            f"wrote {args.file}: the board's learned-data region holds no whole record "
            f"({'erased' if _erased(region) else 'damaged'})",
            file=sys.stderr,
        )
        return 0
    newest = max(recs, key=lambda r: r[1])
    print(
        f"wrote {args.file} ({len(image)} bytes): {len(recs)} record(s), newest sequence {newest[1]}, "
        f"{newest[2]} episodes (draw it: dynaqpc-learned {args.file} --scenario {board.image})"
    )
    return 0


def cmd_restore(args, board: Board, target: str) -> int:
    image = read_image_file(args.file)
    region = image_to_board(image, board, args.file)
    with Probe(target, args.probe, args.frequency) as p:
        p.program(board.region, region)
        p.verify(board.region, region)
        p.reset()
    newest = max(records(image), key=lambda r: r[1])
    print(
        f"restored {args.file} to 0x{board.region:08X} on {target} (newest sequence {newest[1]}, "
        f"{newest[2]} episodes) and verified; the firmware restores it at boot if its layout matches"
    )
    return 0


def _root() -> Path:
    root = repo_root()
    if root is None:
        raise ToolError("not in a dynaqpc checkout (run from the repository, or pass --bin)")
    return root


def build_parser() -> argparse.ArgumentParser:
    p = ToolArgumentParser(
        prog="dynaqpc-flash", description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument(
        "--target",
        metavar="MCU",
        help="pyOCD target name (default stm32f407vg for paper-lab, stm32f429xi for paper-sim)",
    )
    common.add_argument("--image", choices=sorted(BOARDS), help="the robot image (default: the --target's)")
    common.add_argument("--probe", metavar="ID", help="the debug probe's unique ID (`pyocd list`)")
    common.add_argument("--frequency", type=int, metavar="HZ", help="SWD clock (default pyOCD's)")
    sub = p.add_subparsers(dest="command", metavar="{build,flash,backup,restore}", parser_class=ToolArgumentParser)
    sub.required = True
    sub.add_parser("build", parents=[common], help="build the image (cmake preset cortex-m4)")
    f = sub.add_parser("flash", parents=[common], help="build, program and verify the image, then reset")
    f.add_argument("--no-build", action="store_true", help="program what is built")
    f.add_argument("--bin", metavar="FILE", help="program this .bin (at 0x08000000) instead")
    b = sub.add_parser("backup", parents=[common], help="the learned-data sectors to FILE")
    b.add_argument("file", metavar="FILE")
    b.add_argument("--force", action="store_true", help="overwrite FILE")
    r = sub.add_parser("restore", parents=[common], help="FILE to the learned-data sectors")
    r.add_argument("file", metavar="FILE")
    return p


COMMANDS = {"build": cmd_build, "flash": cmd_flash, "backup": cmd_backup, "restore": cmd_restore}


def main(argv=None) -> int:
    args = build_parser().parse_args(argv)

    def body() -> int:
        board, target = board_for(args.target, args.image)
        try:
            return COMMANDS[args.command](args, board, target)
        except FlashFailed as e:
            print(f"error: {e}", file=sys.stderr)
            return 1

    return run_main(body)


if __name__ == "__main__":
    sys.exit(main())
