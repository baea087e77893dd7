"""The package layout holds (docs/architecture.md): import contracts, faces, private names.

The contracts live in pyproject.toml ([tool.importlinter]) and are checked with
import-linter; the rules it cannot express (no private name across modules, ignores
with an error code) are checked here on the syntax trees.
"""

from __future__ import annotations

import ast
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "src" / "springc"


def _lint_imports(src: Path) -> subprocess.CompletedProcess[str]:
    """Run import-linter on the package found in ``src`` with the project's contracts."""
    env = {**os.environ, "PYTHONPATH": str(src)}
    script = ("import sys; from importlinter.cli import lint_imports_command as c; "
              "sys.argv = ['lint-imports', '--no-cache', '--no-logo', '--config', sys.argv[1]]; "
              "c()")
    return subprocess.run([sys.executable, "-c", script, str(ROOT / "pyproject.toml")],
                          capture_output=True, text=True, env=env, cwd=src, timeout=300)


def test_import_contracts_are_kept() -> None:
    run = _lint_imports(ROOT / "src")
    assert run.returncode == 0, run.stdout + run.stderr
    kept = re.search(r"Contracts: (\d+) kept, (\d+) broken", run.stdout)
    assert kept is not None and int(kept.group(1)) >= 28 and kept.group(2) == "0", run.stdout


@pytest.mark.parametrize(("module", "line", "contract"), [
    # a lower layer reaching up: the IR importing the command line
    ("ir/expr.py", "from ..cli import main as _cli_main", "Stages are layered"),
    # a stage reaching into another stage's module instead of its face
    ("codegen/printer.py", "from ..simplify.isolate import fold as _fold", "through its face"),
    # a cycle inside a package, through a function-level import
    ("flatten/arrays.py", "def _cycle():\n    from . import flattener as _f\n    return _f",
     "No import cycles"),
    # a flatten subpackage reaching up: the scopes importing the static rules
    ("flatten/scopes/scope.py", "from ..checks import rule_error as _rule_error",
     "Flatten's subpackages are layered"),
    # a flatten subpackage reaching into another one's module instead of its face
    ("flatten/events/when.py", "from ..checks.rules import check_class as _check_class",
     "Outside springc.flatten.checks, its modules are reached through its face"),
])
def test_a_broken_import_breaks_a_contract(tmp_path: Path, module: str, line: str,
                                           contract: str) -> None:
    copy = tmp_path / "src" / "springc"
    shutil.copytree(PACKAGE, copy, ignore=shutil.ignore_patterns("__pycache__"))
    target = copy / module
    target.write_text(target.read_text() + "\n\n" + line + "\n")
    run = _lint_imports(tmp_path / "src")
    assert run.returncode == 1, run.stdout
    broken = run.stdout.split("Broken contracts", 1)[1]
    assert contract in broken, run.stdout


def _modules() -> list[tuple[Path, ast.Module]]:
    return [(path, ast.parse(path.read_text(), str(path)))
            for path in sorted(PACKAGE.rglob("*.py"))]


def _is_private(name: str) -> bool:
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def test_no_private_name_crosses_a_module() -> None:
    offences = []
    for path, tree in _modules():
        internal_modules: set[str] = set()
        for node in ast.walk(tree):
            if isinstance(node, ast.ImportFrom) and (node.level or (node.module or "")
                                                     .startswith("springc")):
                for alias in node.names:
                    if _is_private(alias.name):
                        offences.append(f"{path.relative_to(PACKAGE)}:{node.lineno} imports "
                                        f"{alias.name}")
                    internal_modules.add(alias.asname or alias.name)
        for node in ast.walk(tree):
            if (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name)
                    and node.value.id in internal_modules and _is_private(node.attr)):
                offences.append(f"{path.relative_to(PACKAGE)}:{node.lineno} uses "
                                f"{node.value.id}.{node.attr}")
    assert offences == []


def test_type_ignores_name_their_error_code() -> None:
    bare = [f"{path.relative_to(PACKAGE)}:{n}"
            for path in sorted(PACKAGE.rglob("*.py"))
            for n, text in enumerate(path.read_text().splitlines(), 1)
            if re.search(r"#\s*type:\s*ignore(?!\[)", text)]
    assert bare == []


def test_no_module_is_named_after_what_its_package_exports() -> None:
    clashes = []
    for init in sorted(PACKAGE.rglob("__init__.py")):
        tree = ast.parse(init.read_text())
        exported = {elt.value for node in tree.body if isinstance(node, ast.Assign)
                    and any(isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets)
                    for elt in getattr(node.value, "elts", []) if isinstance(elt, ast.Constant)}
        clashes += [f"{init.parent.name}.{name}" for name in sorted(exported)
                    if (init.parent / f"{name}.py").exists()]
    assert clashes == []
