# SPDX-License-Identifier: MIT
import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


def pytest_addoption(parser):
    parser.addoption("--can-vectors", default=None,
                     help="path of the can_vectors executable (ctest passes it; default: "
                          "build/host/bin/can_vectors)")


@pytest.fixture(scope="session")
def can_vectors_path(request):
    given = request.config.getoption("--can-vectors")
    path = pathlib.Path(given) if given else ROOT / "build" / "host" / "bin" / "can_vectors"
    if not path.is_file():
        if given:
            pytest.fail(f"--can-vectors={given}: no such file")
        pytest.skip(f"{path} not built: cmake --build --preset host --target can_vectors")
    return path
