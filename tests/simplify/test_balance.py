"""Balance check: the summary line, and the variables and equations named on failure."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.errors import BalanceError
from springc.ir.flat import FlatModel
from springc.pipeline.files import flatten_files
from springc.simplify.balance import check_balance

ROOT = Path(__file__).resolve().parents[2]


def flat_of(tmp_path: Path, text: str) -> FlatModel:
    path = tmp_path / "m.mdl"
    path.write_text(text)
    return flatten_files([path])


def failure(tmp_path: Path, text: str) -> BalanceError:
    with pytest.raises(BalanceError) as info:
        check_balance(flat_of(tmp_path, text))
    return info.value


def noted(err: BalanceError) -> set[tuple[str, int]]:
    """The notes as (message, line) pairs."""
    return {(n.message, n.span.line if n.span else 0) for n in err.notes}


def test_seed_summary_accepts_unbalanced_components() -> None:
    balance = check_balance(flatten_files([ROOT / "models" / "SpringMass.mdl"]))
    assert balance.summary() == ("SpringMass: 7 unknowns, 7 equations, 3 parameters, "
                                 "4 parameter arrays: balanced")


def test_summary_singular_plural(tmp_path: Path) -> None:
    m = flat_of(tmp_path, "model M\n  parameter Real p[2] = {1, 2};\n  Real x;\nequation\n"
                "  x = p[1];\nend M;\n")
    assert check_balance(m).summary() == (
        "M: 1 unknown, 1 equation, 0 parameters, 1 parameter array: balanced")


def test_under_determined_names_the_free_variables(tmp_path: Path) -> None:
    err = failure(tmp_path, """
model A
  Real u;
  Real w;
equation
  w = 1;
end A;
model M
  A a[2];
  Real x;
  Real y;
equation
  der(x) = -x;
  x + y + a[1].u = 0;
end M;
""")
    assert err.message == "model 'M' is under-determined: 6 unknowns, 4 equations"
    assert noted(err) == {
        ("'a[1].u' (in a[1]) is left undetermined: 1 equation for the 2 unknowns "
         "'a[1].u', 'y'", 3),
        ("'a[2].u' (in a[2]) appears in no equation", 3),
        ("'y' is left undetermined: 1 equation for the 2 unknowns 'a[1].u', 'y'", 11)}


def test_over_determined_names_the_redundant_equations(tmp_path: Path) -> None:
    err = failure(tmp_path, """
model A
  Real u = 2;
end A;
model M
  A a;
  Real z;
equation
  z = 1;
  a.u = 3;
end M;
""")
    assert err.message == "model 'M' is over-determined: 2 unknowns, 3 equations"
    assert noted(err) == {
        ("binding equation in a `a.u = 2` is one of 2 equations for only 1 unknown 'a.u'", 3),
        ("equation `a.u = 3` is one of 2 equations for only 1 unknown 'a.u'", 10)}
    assert "remove the redundant equations" in err.hint


def test_structurally_singular_with_equal_counts(tmp_path: Path) -> None:
    err = failure(tmp_path, """
model M
  Real x;
  Real y;
  Real z;
equation
  x = 1;
  x = 2 * time;
  der(y) = z - y;
end M;
""")
    assert err.message == ("model 'M' is structurally singular: 3 unknowns, 3 equations, "
                           "but they do not match")
    assert noted(err) == {
        ("'y' is left undetermined: 1 equation for the 2 unknowns 'y', 'z'", 4),
        ("'z' is left undetermined: 1 equation for the 2 unknowns 'y', 'z'", 5),
        ("equation `x = 1` is one of 2 equations for only 1 unknown 'x'", 7),
        ("equation `x = 2 * time` is one of 2 equations for only 1 unknown 'x'", 8)}


def test_connection_equations_are_named_by_kind(tmp_path: Path) -> None:
    err = failure(tmp_path, """
connector Pin
  Real v;
  flow Real i;
end Pin;
model Ground
  Pin p;
equation
  p.v = 0;
end Ground;
model M
  Ground g1;
  Ground g2;
equation
  connect(g1.p, g2.p);
end M;
""")
    assert err.message == ("model 'M' is structurally singular: 4 unknowns, 4 equations, "
                           "but they do not match")
    assert {m for m, _ in noted(err)} == {
        "'g1.p.i' (in g1.p) is left undetermined: 1 equation for the 2 unknowns "
        "'g1.p.i', 'g2.p.i'",
        "'g2.p.i' (in g2.p) is left undetermined: 1 equation for the 2 unknowns "
        "'g1.p.i', 'g2.p.i'",
        "equation in g1 `g1.p.v = 0` is one of 3 equations for only 2 unknowns "
        "'g1.p.v', 'g2.p.v'",
        "equation in g2 `g2.p.v = 0` is one of 3 equations for only 2 unknowns "
        "'g1.p.v', 'g2.p.v'",
        "connection equation `g1.p.v = g2.p.v` is one of 3 equations for only 2 unknowns "
        "'g1.p.v', 'g2.p.v'"}


def test_equation_without_unknowns(tmp_path: Path) -> None:
    err = failure(tmp_path, "model M\n  parameter Real p = 1;\n  Real x;\nequation\n"
                  "  x = 1;\n  p = 2;\nend M;\n")
    assert err.message == "model 'M' is over-determined: 1 unknown, 2 equations"
    assert noted(err) == {("equation `p = 2` involves no unknown", 6)}


def test_summary_escapes_a_model_name_with_control_characters(tmp_path: Path) -> None:
    path = tmp_path / "q.mdl"
    path.write_text("model 'M\"\"\"\\n'\n  Real x(start = 1, fixed = true);\nequation\n"
                    "  der(x) = -x;\nend 'M\"\"\"\\n';\n")
    balance = check_balance(flatten_files([path]))
    assert balance.summary() == "'M\"\"\"\\n': 1 unknown, 1 equation, 0 parameters: balanced"
