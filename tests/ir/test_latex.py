"""LaTeX rendering (ir/latex.py): exact text for the seed, sympy expressions equal to the
hand-derived ones, readable names, and no sympy import on the check path."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import sympy
from click.testing import CliRunner

from springc.cli import main
from springc.ir import expr as x
from springc.ir.flat import format_flat_latex
from springc.ir.latex import NOTEBOOK_ROWS, align, latex_name, notebook, to_latex, to_sympy
from springc.ir.ode import format_ode_latex
from springc.pipeline import flatten_files
from springc.simplify import simplify

ROOT = Path(__file__).resolve().parents[2]
SEED = str(ROOT / "models" / "SpringMass.mdl")

ACCEL = (r"g_{%d} - \frac{\mathrm{spring.dir}_{%d} \mathrm{spring.k} \left(- \mathrm{spring.l}"
         r" + \mathrm{spring.x}\right)}{\mathrm{mass.m} \mathrm{spring.x}}")
FLAT = "\n".join([
    r"\begin{align}",
    r"\dot{\mathrm{mass.pos}}_{1} &= \mathrm{mass.v}_{1} \\",
    r"\dot{\mathrm{mass.pos}}_{2} &= \mathrm{mass.v}_{2} \\",
    r"\mathrm{spring.x} &= \sqrt{\mathrm{spring.dir}_{1}^{2} + \mathrm{spring.dir}_{2}^{2}} \\",
    r"\mathrm{spring.dir}_{1} &= - \mathrm{center}_{1} + \mathrm{mass.pos}_{1} \\",
    r"\mathrm{spring.dir}_{2} &= - \mathrm{center}_{2} + \mathrm{mass.pos}_{2} \\",
    r"\dot{\mathrm{mass.v}}_{1} &= " + ACCEL % (1, 1) + r" \\",
    r"\dot{\mathrm{mass.v}}_{2} &= " + ACCEL % (2, 2),
    r"\end{align}",
]) + "\n"


def seed_flat():  # type: ignore[no-untyped-def]
    return flatten_files((SEED,), None, ())


def test_seed_flat_equations_render_exactly() -> None:
    assert format_flat_latex(seed_flat()) == FLAT
    assert seed_flat()._repr_latex_() == (
        "$$" + FLAT.strip().replace("{align}", "{aligned}") + "$$")


def test_seed_simplified_system_renders_in_evaluation_order() -> None:
    ode = simplify(seed_flat()).ode
    lines = FLAT.splitlines()
    # the simplified order computes spring.dir before spring.x
    expected = [lines[0], lines[1], lines[2], lines[4], lines[5], lines[3], lines[6],
                lines[7], lines[8]]
    assert format_ode_latex(ode) == "\n".join(expected) + "\n"
    assert ode._repr_latex_() == ("$$" + "\n".join(expected).replace("{align}", "{aligned}")
                                  + "$$")


def test_sympy_expressions_equal_the_hand_derived_ones() -> None:
    flat = seed_flat()
    k, rest, xx, m = sympy.symbols("spring.k spring.l spring.x mass.m")
    for i in (1, 2):
        d, g = sympy.Symbol(f"spring.dir[{i}]"), sympy.Symbol(f"g[{i}]")
        eq = next(e for e in flat.equations if e.lhs == x.Der(x.Var(f"mass.v[{i}]")))
        assert to_sympy(eq.lhs) == sympy.Symbol(f"der(mass.v[{i}])")
        assert sympy.simplify(to_sympy(eq.rhs) - (-k * d * (xx - rest) / xx / m + g)) == 0
    d1, d2 = sympy.symbols("spring.dir[1] spring.dir[2]")
    eq = next(e for e in flat.equations if e.lhs == x.Var("spring.x"))
    assert to_sympy(eq.rhs) == sympy.sqrt(d1**2 + d2**2)


def test_names_are_readable_and_escaped() -> None:
    assert latex_name("mass.pos[1]") == r"\mathrm{mass.pos}_{1}"
    assert latex_name("der(mass.v[2])") == r"\dot{\mathrm{mass.v}}_{2}"
    assert latex_name("x") == "x"
    assert latex_name("der(der(x))") == r"\ddot{x}"
    assert latex_name("der(der(der(der(p[2]))))") == r"{p}^{(4)}_{2}"
    assert latex_name("ms[3].flange_a.f") == r"\mathrm{ms[3].flange\_a.f}"
    assert latex_name("a[1, 2]") == "a_{1,2}"
    assert latex_name("$\\{x}&") == r"\mathrm{\$\textbackslash{}\{x\}\&}"


def test_other_constructs() -> None:
    t = x.TIME
    assert to_latex(x.Der(x.BinOp("*", x.Var("a"), t))) == r"\frac{\partial}{\partial t} t a"
    assert to_latex(x.If(x.BinOp(">", x.Var("a"), x.ZERO), x.Var("a"), x.Neg(x.Var("a")))) \
        == r"\begin{cases} a & \text{for}\: a > 0 \\- a & \text{otherwise} \end{cases}"
    assert to_latex(x.Call("noEvent", (x.Var("a"),))) == \
        r"\operatorname{noEvent}{\left(a \right)}"
    assert align([(x.Var("p"), x.Const(2.5), "initial")]) == (
        "\\begin{align}\np &= 2.5 \\quad\\text{(initial)}\n\\end{align}\n")
    deep: x.Expr = x.Var("a")
    for _ in range(5000):  # conversion is iterative; sympy folds the sum
        deep = x.BinOp("+", deep, x.ONE)
    assert to_sympy(deep) == sympy.Symbol("a") + 5000


def test_notebooks_get_text_for_large_models() -> None:
    rows = [(x.Var(f"v{i}"), x.ONE, "") for i in range(NOTEBOOK_ROWS)]
    assert notebook(rows) == "$$" + align(rows).strip().replace("{align}", "{aligned}") + "$$"
    assert notebook([*rows, (x.Var("w"), x.ZERO, "")]) is None


def test_flatten_latex_on_the_command_line() -> None:
    runner = CliRunner()
    result = runner.invoke(main, ["flatten", "--latex", SEED], catch_exceptions=False)
    assert (result.exit_code, result.stdout) == (0, FLAT)
    result = runner.invoke(main, ["flatten", "--latex", "--json", SEED])
    assert result.exit_code == 2
    assert "--latex and --json cannot be combined" in result.stderr


def test_import_and_check_do_not_import_sympy() -> None:
    code = ("import sys, springc\n"
            "from springc.cli import main\n"
            f"main(['check', {SEED!r}], standalone_mode=False)\n"
            "print('sympy' in sys.modules)\n")
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          env=env, check=True)
    assert done.stdout.splitlines()[-1] == "False"
    assert done.stdout.splitlines()[0].endswith(": balanced")
