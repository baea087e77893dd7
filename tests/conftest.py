"""Shared pytest configuration: ``--update-goldens`` rewrites golden case files."""

from __future__ import annotations

import os

import pytest

# springc's status lines ("springc: compiling ...", springc.status_line) stay off in the
# suite (subprocesses inherit it), so that outputs compared exactly do not depend on
# which test compiled a model or a kernel first; tests/test_status_lines.py turns them on.
os.environ["SPRINGC_QUIET"] = "1"
# The suite's compiled engine is numba's loop whether or not a C compiler is found, so
# that its figures and engine reasons do not depend on the machine; the tests of the C
# loop (tests/simulation/test_native_engine.py, tests/native/, tests/integrate/
# test_native_loop.py) set SPRINGC_LOOP themselves.
os.environ.setdefault("SPRINGC_LOOP", "numba")


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--update-goldens", action="store_true", default=False,
                     help="rewrite the expected output of golden case files; review the "
                     "diff with git before committing")


@pytest.fixture
def update_goldens(request: pytest.FixtureRequest) -> bool:
    return bool(request.config.getoption("--update-goldens"))
