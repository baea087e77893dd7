"""Run every golden case file in ``tests/cases`` (see ``tests/golden.py``)."""

from __future__ import annotations

from pathlib import Path

import pytest

from golden import CASES, all_cases, read_case, run_case, write_case


@pytest.mark.parametrize("path", all_cases(), ids=lambda p: str(p.relative_to(CASES)))
def test_case(path: Path, tmp_path: Path, update_goldens: bool) -> None:
    case = read_case(path)
    exit_code, output = run_case(case, tmp_path)
    if update_goldens:
        write_case(case, exit_code, output)
        return
    assert output == case.output
    assert exit_code == case.exit_code
