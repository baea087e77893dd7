"""Golden case files: input models, a springc command, its expected output and exit code.

Format (``tests/cases/**/*.case``)::

    # One line saying what the case checks.
    $ springc check input.mdl --model M
    --- file input.mdl
    model M ... end M;
    --- exit 1
    --- output
    input.mdl:3:5: error: ...

Files named ``models/...`` refer to the repository's model library instead of an
inline file. The command runs in a temporary folder holding the inline files, with
``models/`` linked in; the output is stdout followed by stderr. Locations in the
bundled library (an absolute path that depends on the install) are shown as
``models/...`` so that goldens do not depend on where springc is installed.
"""

from __future__ import annotations

import os
import re
import shlex
from dataclasses import dataclass
from pathlib import Path

from click.testing import CliRunner

from springc.cli import main
from springc.resources import models_dir

ROOT = Path(__file__).resolve().parents[1]
CASES = Path(__file__).resolve().parent / "cases"


@dataclass
class Case:
    path: Path
    title: str
    command: list[str]
    files: dict[str, str]
    exit_code: int
    output: str


def read_case(path: Path) -> Case:
    text = path.read_text()
    head, *sections = re.split(r"^--- ", text, flags=re.M)
    lines = head.splitlines()
    title = lines[0].lstrip("# ").strip()
    command = next(line[2:] for line in lines if line.startswith("$ "))
    files: dict[str, str] = {}
    exit_code, output = 0, ""
    for section in sections:
        header, _, body = section.partition("\n")
        kind, _, arg = header.partition(" ")
        if kind == "file":
            files[arg.strip()] = body
        elif kind == "exit":
            exit_code = int(arg)
        elif kind == "output":
            output = body
    return Case(path, title, shlex.split(command)[1:], files, exit_code, output)


def write_case(case: Case, exit_code: int, output: str) -> None:
    parts = [f"# {case.title}\n$ springc {shlex.join(case.command)}\n"]
    parts += [f"--- file {name}\n{body}" for name, body in case.files.items()]
    parts.append(f"--- exit {exit_code}\n")
    parts.append(f"--- output\n{output}")
    case.path.write_text("".join(parts))


def run_case(case: Case, workdir: Path) -> tuple[int, str]:
    for name, body in case.files.items():
        target = workdir / name
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(body)
    if not (workdir / "models").exists():
        (workdir / "models").symlink_to(ROOT / "models")
    old = os.getcwd()
    os.chdir(workdir)
    try:
        result = CliRunner().invoke(main, case.command, prog_name="springc",
                                    env={"SPRINGC_PATH": "", "MODELICAPATH": ""})
    finally:
        os.chdir(old)
    output = result.stdout + result.stderr
    return result.exit_code, output.replace(str(models_dir()) + os.sep, "models/")


def all_cases() -> list[Path]:
    return sorted(CASES.rglob("*.case"))
