"""``springc simulate`` and ``springc compile``: exit codes, CSV, PNG, options, failures."""

from __future__ import annotations

import csv
import os
import re
import stat
from pathlib import Path

import numpy as np
import pytest
from click.testing import CliRunner

from springc.cli import main
from springc.simulation import ALL_SOLVERS, AUTO, COMPILED_SOLVERS, FIXED_STEP, SOLVERS

ROOT = Path(__file__).resolve().parents[2]
SEED = str(ROOT / "models" / "SpringMass.mdl")
SCENES = str(ROOT / "models" / "Scenes.mdl")

BLOWUP = """
model Blowup
  Real x(start = 1);
equation
  der(x) = x^2;
end Blowup;
"""


@pytest.fixture(autouse=True)
def _cache(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("SPRINGC_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def run(*args: str) -> tuple[int, str, str]:
    result = CliRunner().invoke(main, list(args))
    return result.exit_code, result.stdout, result.stderr


def read_csv(path: Path) -> tuple[list[str], np.ndarray]:
    with path.open() as f:
        rows = list(csv.reader(f))
    return rows[0], np.array([[float(v) for v in row] for row in rows[1:]])


def test_seed_csv_and_png(tmp_path: Path) -> None:
    out, png = tmp_path / "seed.csv", tmp_path / "seed.png"
    code, stdout, stderr = run("simulate", SEED, "-o", str(out), "--plot", str(png))
    assert code == 0, stderr
    header, table = read_csv(out)
    assert header == ["time", "mass.pos[1]", "mass.pos[2]", "mass.v[1]", "mass.v[2]",
                      "spring.dir[1]", "spring.dir[2]", "spring.x"]
    assert table.shape == (501, 8)
    assert table[0].tolist() == [0.0, 1.0, -1.0, 0.0, 0.0, 1.0, -1.0, 2**0.5]
    assert table[-1, 0] == 10.0 and np.allclose(np.diff(table[:, 0]), 0.02)
    # full precision: every field reads back to the float that was written
    for line in out.read_text().splitlines()[1:5]:
        assert all(repr(float(v)) == v for v in line.split(","))
    assert stdout == ""
    # the short summary: dop853 at the default rtol 1e-6 misses the rule by 26x, so the
    # run kept is at 1e-9
    summary = stderr.splitlines()[-1]
    assert re.fullmatch(r"SpringMass: dop853 \(auto\), [\d,]+ steps, est\. error \S+ <= "
                        r"0\.0003 at rtol 1e-9, [\d.]+ s", summary), summary
    assert len(summary) <= 120
    import matplotlib.image

    image = matplotlib.image.imread(str(png))
    assert image.shape[0] > 300 and image.shape[1] > 300
    assert image[..., :3].std() > 0.05  # not blank
    assert not list(tmp_path.glob(".*part"))


def test_verbose_summary_has_the_detail(tmp_path: Path) -> None:
    code, _, stderr = run("simulate", SEED, "-o", str(tmp_path / "seed.csv"), "-v")
    assert code == 0, stderr
    # the default engine: the numba module in the compiled loop, and why
    assert "SpringMass: auto -> dop853 (compiled) (non-stiff: " in stderr
    assert "; dop853 ran in the compiled loop (numba, no Python per step))" in stderr
    assert " steps, " in stderr
    # dop853 at the default rtol 1e-6 misses the rule by 26x: rerun at 1e-9, and said so
    assert "; tightened rtol 1e-6 -> 1e-9: est. error " in stderr
    code, _, stderr = run("simulate", SEED, "-o", str(tmp_path / "seed.csv"), "-vv", "-q")
    assert (code, stderr) == (0, "")  # --quiet wins


def test_csv_to_stdout_and_quiet() -> None:
    code, stdout, stderr = run("simulate", SEED, "--stop", "0.1", "--quiet",
                               "--vars", "spring.x")
    assert code == 0
    lines = stdout.splitlines()
    assert lines[0] == "time,spring.x" and len(lines) == 502
    assert stderr == ""


def test_vars_select_columns(tmp_path: Path) -> None:
    out = tmp_path / "v.csv"
    code, _, stderr = run("simulate", SEED, "-o", str(out), "--vars", "mass.pos*",
                          "--vars", "spring.x", "--stop", "1")
    assert code == 0, stderr
    header, table = read_csv(out)
    assert header == ["time", "mass.pos[1]", "mass.pos[2]", "spring.x"]
    assert np.allclose(table[:, 3], np.hypot(table[:, 1], table[:, 2]), rtol=1e-14)


def test_vars_without_match_is_an_error(tmp_path: Path) -> None:
    code, _, stderr = run("simulate", SEED, "--vars", "spring.len", "-o",
                          str(tmp_path / "x.csv"))
    assert code == 1
    assert stderr.endswith("error: --vars 'spring.len' matches no state or observed "
                           "variable\nhelp: use flat names such as 'mass.pos[1]', with * "
                           "and ? as wildcards\n")  # no name is near: no guess
    assert not (tmp_path / "x.csv").exists()
    code, _, stderr = run("simulate", SEED, "--vars", "mass.poss[1]", "-o",
                          str(tmp_path / "x.csv"))
    assert code == 1
    assert stderr.endswith("error: --vars 'mass.poss[1]' matches no state or observed "
                           "variable\nhelp: did you mean 'mass.pos[1]' or 'mass.pos[2]'?\n")


def test_set_changes_the_result(tmp_path: Path) -> None:
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    assert run("simulate", SEED, "-o", str(a), "--stop", "1", "-q")[0] == 0
    code, _, stderr = run("simulate", SEED, "-o", str(b), "--stop", "1", "-q",
                          "--set", "spring.k=1e5", "--set", "mass.xy[1]=1.5")
    assert code == 0, stderr
    _, ta = read_csv(a)
    _, tb = read_csv(b)
    assert tb[0, 1] == 1.5 and ta[0, 1] == 1.0
    assert not np.allclose(ta[5:, 1:], tb[5:, 1:])


def test_set_structural_parameter(tmp_path: Path) -> None:
    out = tmp_path / "c.csv"
    code, _, stderr = run("simulate", SCENES, "--model", "Scenes.Chain", "--set", "N=2",
                          "--vars", "m[*].s", "--stop", "0.5", "-o", str(out))
    assert code == 0, stderr
    header, table = read_csv(out)
    assert header == ["time", "m[1].s", "m[2].s"] and table.shape == (51, 3)


def test_set_unknown_parameter(tmp_path: Path) -> None:
    """A name the model lacks is a misuse of --set: exit 2 naming the option."""
    code, _, stderr = run("simulate", SEED, "--set", "spring.kk=1")
    assert code == 2
    assert stderr.endswith("error: --set spring.kk: 'spring.kk' is not a parameter or a "
                           "state of SpringMass\nhelp: did you mean 'spring.k'?\n")


@pytest.mark.parametrize("args", [["--set", "spring.k"], ["--set", "spring.k=abc"],
                                  ["--solver", "euler"], ["--backend", "c"]])
def test_usage_errors(args: list[str]) -> None:
    assert run("simulate", SEED, *args)[0] == 2


def test_solver_failure_leaves_no_csv(tmp_path: Path) -> None:
    model = tmp_path / "blowup.mdl"
    model.write_text(BLOWUP)
    out = tmp_path / "out.csv"
    code, _, stderr = run("simulate", str(model), "--stop", "3", "-o", str(out),
                          "--plot", str(tmp_path / "out.png"))
    assert code == 1
    # x = 1/(1 - t): auto's 10 compiled dop853 steps leave under 500 to go, and
    # dop853 goes on to the blow-up
    assert "error: the step size of dop853 collapsed at time 1.0" in stderr
    assert "note: x = " in stderr
    assert "help: the system looks stiff or unstable: try --solver radau" in stderr
    assert list(tmp_path.iterdir()) == [model]


def test_each_solver_runs() -> None:
    solver_option = next(p for p in main.commands["simulate"].params if p.name == "solver")
    choices = tuple(solver_option.type.choices)  # type: ignore[attr-defined]
    assert choices == ALL_SOLVERS and set(choices) == {AUTO, *SOLVERS, *FIXED_STEP}
    for solver in choices:
        step = ["--step", "1e-4"] if solver in FIXED_STEP else []
        for backend in ("python", "numba"):  # auto's engine: scipy, then compiled
            code, _, stderr = run("simulate", SEED, "--solver", solver, "--stop", "0.2",
                                  "--vars", "spring.x", "--backend", backend, "-v", *step)
            assert code == 0, stderr
            compiled = backend == "numba" and solver in COMPILED_SOLVERS
            engine = "compiled" if compiled else "scipy"
            shown = "auto -> dop853 (" if solver == AUTO else f"{solver} ({engine})"
            assert f"SpringMass: {shown}" in stderr
            # off the compiled loop without --engine scipy: the summary says why
            assert (f"({solver} ran in " in stderr) == (
                not compiled and solver != AUTO)
        if solver in ("radau", "bdf", "lsoda"):
            assert " 0 Jacobian" not in stderr


def test_cache_and_no_cache() -> None:
    run("simulate", SEED, "--stop", "0.1", "--vars", "spring.x")
    _, _, stderr = run("simulate", SEED, "--stop", "0.1", "--vars", "spring.x", "-v")
    assert "cached in" in stderr
    _, _, stderr = run("simulate", SEED, "--stop", "0.1", "--vars", "spring.x", "--no-cache",
                       "-v")
    assert "compiled in" in stderr


def test_compile_writes_a_module(tmp_path: Path) -> None:
    target = tmp_path / "model.py"
    code, _, stderr = run("compile", SEED, "-o", str(target), "--vars", "spring.x")
    assert code == 0, stderr
    namespace: dict[str, object] = {}
    exec(compile(target.read_text(), str(target), "exec"), namespace)
    assert namespace["OBSERVED"] == ("spring.x",)
    code, stdout, _ = run("compile", SEED)
    assert code == 0 and stdout.startswith('"""springc-generated model SpringMass')


def test_model_error_exit_code(tmp_path: Path) -> None:
    bad = tmp_path / "bad.mdl"
    bad.write_text("model Bad\n  Real x;\nequation\n  der(x) = y;\nend Bad;\n")
    code, _, stderr = run("simulate", str(bad))
    assert code == 1 and "error:" in stderr


def test_outputs_have_the_permissions_of_a_plain_file(tmp_path: Path) -> None:
    mask = os.umask(0o022)
    try:
        out = tmp_path / "seed.csv"
        result = CliRunner().invoke(main, ["simulate", SEED, "--stop", "0.1", "--quiet",
                                           "-o", str(out)])
    finally:
        os.umask(mask)
    assert result.exit_code == 0, result.output
    assert stat.S_IMODE(out.stat().st_mode) == 0o644
