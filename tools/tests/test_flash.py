# SPDX-License-Identifier: MIT
"""dynaqpc-flash without a board: --help, no probe, no board, files that are not a learned store,
the store's constants against the firmware's headers, and backup/restore through a fake pyOCD
session (the board's flash a bytearray)."""

import re
import struct
import subprocess
import sys
import zlib

import pytest
from conftest import REPO, c_binary

from dynaqpc_tools import flash

pyocd = pytest.importorskip("pyocd")


def _record(sequence=1, episodes=3, payload=b"\x11" * 4096):
    h = struct.pack(
        "<7I",
        flash.LEARNED_STORE_MAGIC,
        flash.LEARNED_STORE_VERSION,
        sequence,
        0x1234,
        len(payload),
        zlib.crc32(payload),
        episodes,
    )
    return h + struct.pack("<I", zlib.crc32(h)) + payload


def _image(*slots):
    out = bytearray(b"\xff" * flash.HOST_IMAGE)
    for i, rec in enumerate(slots):
        if rec:
            out[i * flash.HOST_SLOT : i * flash.HOST_SLOT + len(rec)] = rec
    return bytes(out)


def _one_line(capsys):
    cap = capsys.readouterr()
    lines = [ln for ln in cap.err.splitlines() if ln.strip()]
    assert len(lines) == 1, cap.err
    return lines[0]


@pytest.fixture
def no_probe(monkeypatch):
    from pyocd.core.helpers import ConnectHelper

    monkeypatch.setattr(ConnectHelper, "get_all_connected_probes", staticmethod(lambda **kw: []))


@pytest.fixture
def no_usb(monkeypatch):
    """Any attempt to reach a probe fails the test: the file is refused first."""
    from pyocd.core.helpers import ConnectHelper

    def boom(**kw):
        raise AssertionError("looked for a probe")

    monkeypatch.setattr(ConnectHelper, "get_all_connected_probes", staticmethod(boom))


def test_help():
    p = subprocess.run([sys.executable, "-m", "dynaqpc_tools.flash", "--help"], capture_output=True, text=True)
    assert p.returncode == 0 and "backup" in p.stdout and "restore" in p.stdout
    for sub in ("build", "flash", "backup", "restore"):
        with pytest.raises(SystemExit) as e:
            flash.main([sub, "--help"])
        assert e.value.code == 0


def test_no_command_is_one_line(capsys):
    with pytest.raises(SystemExit) as e:
        flash.main([])
    assert e.value.code == 2
    _one_line(capsys)


@pytest.mark.parametrize(
    "argv",
    [
        ["backup", "{tmp}/out.bin"],
        ["restore", "{img}"],
        ["flash", "--bin", "{img}"],
        ["flash"],
        ["backup", "{tmp}/out.bin", "--target", "stm32f429xi"],
    ],
)
def test_no_probe_is_one_line_and_exit_2(argv, tmp_path, capsys, no_probe):
    img = tmp_path / "learned.bin"
    img.write_bytes(_image(_record()))
    argv = [a.format(tmp=tmp_path, img=img) for a in argv]
    assert flash.main(argv) == 2
    assert "no debug probe found" in _one_line(capsys)
    assert not (tmp_path / "out.bin").exists()


def test_no_board_behind_the_probe_is_one_line(tmp_path, capsys, monkeypatch):
    from pyocd.core.helpers import ConnectHelper

    class FakeProbe:
        unique_id = "0670FF3837"

    class DeadSession:
        def open(self):
            raise pyocd.core.exceptions.TransferError("no ACK received")

        def close(self):
            pass

    monkeypatch.setattr(ConnectHelper, "get_all_connected_probes", staticmethod(lambda **kw: [FakeProbe()]))
    monkeypatch.setattr(ConnectHelper, "session_with_chosen_probe", staticmethod(lambda **kw: DeadSession()))
    assert flash.main(["backup", str(tmp_path / "out.bin")]) == 2
    line = _one_line(capsys)
    assert "no board on probe 0670FF3837" in line and "no ACK" in line


def test_a_target_pyocd_lacks_names_the_pack(tmp_path, capsys, monkeypatch):
    from pyocd.core.helpers import ConnectHelper

    def unknown(**kw):
        raise pyocd.core.exceptions.TargetSupportError(
            "Target type stm32f407vg not recognized. Use 'pyocd list --targets' to see ..."
        )

    probe = type("P", (), {"unique_id": "FAKE1"})()
    monkeypatch.setattr(ConnectHelper, "get_all_connected_probes", staticmethod(lambda **kw: [probe]))
    monkeypatch.setattr(ConnectHelper, "session_with_chosen_probe", staticmethod(unknown))
    assert flash.main(["backup", str(tmp_path / "out.bin")]) == 2
    assert "pyocd pack install stm32f407vg" in _one_line(capsys)


@pytest.mark.parametrize(
    "content,why",
    [
        (b"", "0 bytes"),
        (b"\xff" * 1000, "1000 bytes"),
        (b"\xff" * (flash.HOST_IMAGE + 1), "524289 bytes"),
        (b"\xff" * flash.HOST_IMAGE, "erased"),
        (b"\x00" * flash.HOST_IMAGE, "not a learned-store image"),
        (_image(_record()[:-1] + b"\x00"), "not a learned-store image"),  # payload CRC
        (_image(b"\x00" + _record()[1:]), "not a learned-store image"),  # magic
    ],
)
def test_restore_refuses_what_is_not_a_learned_store(content, why, tmp_path, capsys, no_usb):
    f = tmp_path / "x.bin"
    f.write_bytes(content)
    assert flash.main(["restore", str(f)]) == 2
    assert why in _one_line(capsys)


def test_restore_of_a_missing_file(tmp_path, capsys, no_usb):
    assert flash.main(["restore", str(tmp_path / "none.bin")]) == 2
    assert "cannot read" in _one_line(capsys)


def test_a_record_too_big_for_paper_labs_slot_is_refused(tmp_path, capsys, no_usb):
    f = tmp_path / "sim.bin"
    f.write_bytes(_image(_record(payload=b"\x22" * 143360)))
    assert flash.main(["restore", str(f), "--target", "stm32f407vg"]) == 2
    assert "more than a slot of paper-lab" in _one_line(capsys)


@pytest.mark.parametrize(
    "argv,why",
    [
        (["--target", "stm32f103c8"], "not an STM32F405"),
        (["--target", "stm32f429xg"], "2 MB part"),
        (["--target", "stm32f407vg", "--image", "paper-sim"], "does not run on"),
    ],
)
def test_targets_are_checked(argv, why, tmp_path, capsys, no_usb):
    assert flash.main(["backup", str(tmp_path / "o.bin"), *argv]) == 2
    assert why in _one_line(capsys)


def test_constants_match_the_firmware():
    h = (REPO / "firmware/robot/include/robot/learned_store.h").read_text()
    assert int(re.search(r"#define LEARNED_STORE_MAGIC (0x[0-9A-Fa-f]+)u", h).group(1), 16) == flash.LEARNED_STORE_MAGIC
    assert int(re.search(r"#define LEARNED_STORE_VERSION (\d+)u", h).group(1)) == flash.LEARNED_STORE_VERSION
    fields = re.search(r"typedef struct learned_header \{(.*?)\} learned_header_t;", h, re.S).group(1)
    assert re.findall(r"uint32_t (\w+);", fields) == [
        "magic",
        "version",
        "sequence",
        "layout",
        "payload_size",
        "payload_crc",
        "episodes",
        "header_crc",
    ]
    c = (REPO / "hal/ports/host/include/hal_host/hal_host_config.h").read_text()
    size = re.search(r"#define FW_CFG_HOST_FLASH_SECTOR_SIZE \((\d+)u \* (\d+)u\)", c)
    assert int(size.group(1)) * int(size.group(2)) == flash.HOST_SECTOR
    assert int(re.search(r"#define FW_CFG_HOST_FLASH_SECTOR_COUNT (\d+)u", c).group(1)) == flash.HOST_SECTORS
    doc = (REPO / "docs/flashing.md").read_text()
    for b in flash.BOARDS.values():
        assert f"0x{b.region:08X}" in doc


# --- backup and restore through a fake pyOCD session ---------------------------------------------


class FakeTarget:
    def __init__(self, mem):
        self.mem, self.resets = mem, 0

    def reset_and_halt(self):
        pass

    def reset(self):
        self.resets += 1

    def read_memory_block8(self, addr, n):
        return list(self.mem[addr - flash.FLASH_BASE : addr - flash.FLASH_BASE + n])


@pytest.fixture
def board(monkeypatch):
    """A 2 MB STM32F4 behind a probe; returns its flash (a bytearray at 0x08000000)."""
    import pyocd.flash.loader as loader
    from pyocd.core.helpers import ConnectHelper

    mem = bytearray(b"\xff" * (2 * 1024 * 1024))

    class Session:
        def __init__(self):
            self.board = type("B", (), {"target": FakeTarget(mem)})()

        def open(self):
            pass

        def close(self):
            pass

    class Loader:
        def __init__(self, session, **kw):
            self.parts = []

        def add_data(self, addr, data):
            self.parts.append((addr, bytes(data)))

        def commit(self):
            for addr, data in self.parts:  # sector erase, then program
                lo = (addr - flash.FLASH_BASE) // 0x20000 * 0x20000
                hi = -(-(addr - flash.FLASH_BASE + len(data)) // 0x20000) * 0x20000
                mem[lo:hi] = b"\xff" * (hi - lo)
                mem[addr - flash.FLASH_BASE : addr - flash.FLASH_BASE + len(data)] = data

    probe = type("P", (), {"unique_id": "FAKE1"})()
    monkeypatch.setattr(ConnectHelper, "get_all_connected_probes", staticmethod(lambda **kw: [probe]))
    monkeypatch.setattr(ConnectHelper, "session_with_chosen_probe", staticmethod(lambda **kw: Session()))
    monkeypatch.setattr(loader, "MemoryLoader", Loader)
    return mem


@pytest.mark.parametrize("target", ["stm32f407vg", "stm32f429xi"])
def test_restore_then_backup_round_trips(target, board, tmp_path, capsys):
    img = _image(_record(1, 5), _record(2, 9))
    f = tmp_path / "in.bin"
    f.write_bytes(img)
    assert flash.main(["restore", str(f), "--target", target]) == 0
    b, _ = flash.board_for(target, None)
    off = b.region - flash.FLASH_BASE
    assert board[off : off + 32] == img[:32]
    assert board[off + b.slot : off + b.slot + 32] == img[flash.HOST_SLOT : flash.HOST_SLOT + 32]
    assert board[:off] == b"\xff" * off  # nothing outside the region touched
    out = tmp_path / "out.bin"
    assert flash.main(["backup", str(out), "--target", target]) == 0
    assert out.read_bytes() == img
    assert "newest sequence 2, 9 episodes" in capsys.readouterr().out
    assert flash.main(["backup", str(out), "--target", target]) == 2  # exists
    assert "--force" in _one_line(capsys)


def test_flash_programs_and_verifies_below_the_learned_data(board, tmp_path, capsys):
    lab = flash.BOARDS["paper-lab"]
    board[lab.region - flash.FLASH_BASE : lab.region - flash.FLASH_BASE + 4] = b"DQPC"
    fw = tmp_path / "fw.bin"
    fw.write_bytes(bytes(range(256)) * 1000)
    assert flash.main(["flash", "--bin", str(fw)]) == 0
    assert bytes(board[:256000]) == fw.read_bytes()
    assert board[lab.region - flash.FLASH_BASE :][:4] == b"DQPC"  # learned data kept
    assert "flashed and verified" in capsys.readouterr().out


@pytest.mark.skipif(not c_binary("dynaqpc-sim").exists(), reason="build dynaqpc-sim first or set DYNAQPC_BUILD_DIR")
def test_a_simulators_save_restores_and_backs_up_to_what_the_simulator_loads(board, tmp_path):
    sim = str(c_binary("dynaqpc-sim"))
    saved = tmp_path / "train.bin"
    subprocess.run(
        [sim, "train", "--scenario", "paper-lab", "--agent", "dyna-qpc", "--episodes", "2", "--save", str(saved)],
        check=True,
        capture_output=True,
        timeout=300,
    )
    assert flash.main(["restore", str(saved)]) == 0
    back = tmp_path / "backup.bin"
    assert flash.main(["backup", str(back)]) == 0
    assert back.read_bytes() == saved.read_bytes()
    p = subprocess.run(
        [sim, "learned", "--scenario", "paper-lab", "--load", str(back)], capture_output=True, text=True, timeout=300
    )
    assert p.returncode == 0, p.stderr
