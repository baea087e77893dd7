"""The grammar must be found both in a source/editable install and in a built wheel."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import springc
from springc.parse.parser import parse_text
from springc.resources import grammar_path

REPO = Path(__file__).resolve().parents[2]
TINY = "model Tiny\n  Real x(start = 1);\nequation\n  der(x) = -x;\nend Tiny;\n"


def test_grammar_loads_from_the_source_tree() -> None:
    assert Path(springc.__file__).resolve().is_relative_to(REPO / "src")
    assert grammar_path().resolve() == REPO / "grammar" / "modelica.lark"
    (tiny,) = parse_text(TINY, "tiny.mo").classes
    assert (tiny.name, [c.name for c in tiny.elements]) == ("Tiny", ["x"])


def _project_copy(dest: Path) -> Path:
    """The files a wheel is built from, copied so the build leaves the checkout alone."""
    ignore = shutil.ignore_patterns("__pycache__", "*.pyc")
    for folder in ("src", "grammar", "models"):
        shutil.copytree(REPO / folder, dest / folder, ignore=ignore)
    shutil.copy2(REPO / "pyproject.toml", dest / "pyproject.toml")
    readme = REPO / "README.md"
    if readme.exists():
        shutil.copy2(readme, dest / "README.md")
    else:  # pyproject.toml names a readme; the checkout may not have one yet
        (dest / "README.md").write_text("# springc\n", encoding="utf-8")
    return dest


def test_grammar_loads_from_a_built_wheel(tmp_path: Path) -> None:
    project = _project_copy(tmp_path / "project")
    dist, target = tmp_path / "dist", tmp_path / "installed"
    subprocess.run(
        [sys.executable, "-m", "build", "--wheel", "--no-isolation", "-o", str(dist),
         str(project)],
        check=True, capture_output=True, text=True,
    )
    (wheel,) = dist.glob("springc-*.whl")
    subprocess.run(
        [sys.executable, "-m", "pip", "install", "--no-deps", "--quiet", "--target",
         str(target), str(wheel)],
        check=True, capture_output=True, text=True,
    )
    script = (
        "import pathlib, sys, springc\n"
        "from springc.parse.parser import parse_text\n"
        "from springc.resources import grammar_path\n"
        "target = pathlib.Path(sys.argv[1]).resolve()\n"
        "assert pathlib.Path(springc.__file__).resolve().is_relative_to(target), springc.__file__\n"
        "assert grammar_path().resolve() == target / 'springc' / 'grammar' / 'modelica.lark'\n"
        "stored = parse_text(sys.argv[2], 'tiny.mo')\n"
        "print(stored.classes[0].name, stored.classes[0].equations[0].lhs.func.dotted)\n"
    )
    env = {**os.environ, "PYTHONPATH": str(target)}
    result = subprocess.run(
        [sys.executable, "-c", script, str(target), TINY],
        cwd=tmp_path, env=env, capture_output=True, text=True, check=False,
    )
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["Tiny", "der"]
