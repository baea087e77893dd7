"""Instance templates (springc.flatten.instance_templates) and direct connect references
(springc.flatten.connect.connections.direct_reference) give exactly the flat model of the
general path."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.errors import FlattenError
from springc.flatten import flattener as flattening
from springc.flatten.connect import connections
from springc.flatten.instance_templates import InstanceTemplates
from springc.ir import expr as x
from springc.ir import flat
from springc.parse import load

MODELS = Path(__file__).resolve().parents[2] / "models"

# Per-element parameter values, an extends modification, a continuous variable with a
# binding (binding equations), a start value naming a parameter, and an array whose
# elements are given a start value from outside (no template: not a parameter).
SOURCE = """
model Base
  parameter Real k = 1;
  Real y[2](start = {k, 2*k});
end Base;
model Cell
  extends Base(k = 3);
  parameter Real a = 1;
  parameter Real b[2] = {0, 0};
  Real z = 2*a + y[1];
equation
  der(y) = -b .* y;
end Cell;
model Top
  parameter Integer n = 4;
  Cell c[n](each a = 2, b = {{i, -i} for i in 1:n});
  Cell d[3](z(start = {1, 2, 3}));
  Translational.Mass m[n](s0 = {i for i in 1:n});
  Translational.Spring s[n - 1];
equation
  for i in 1:n - 1 loop
    connect(m[i].flange, s[i].flange_a);
    connect(s[i].flange_b, m[i + 1].flange);
  end for;
end Top;
"""


def _flatten(path: Path, model: str, monkeypatch: pytest.MonkeyPatch, fast: bool
             ) -> tuple[flat.FlatModel, int]:
    """The flat model, and how many instances were copied from a template."""
    filled: list[object] = []
    if fast:
        original = InstanceTemplates._fill

        def count(self: InstanceTemplates, scope: object, template: object) -> None:
            filled.append(scope)
            original(self, scope, template)  # type: ignore[arg-type]

        monkeypatch.setattr(InstanceTemplates, "_fill", count)
    else:
        monkeypatch.setattr(InstanceTemplates, "begin", lambda self, scope: None)
        monkeypatch.setattr(connections, "direct_reference", lambda ref, where: None)
    model_ = flattening.flatten(load([path]), model)
    monkeypatch.undo()
    return model_, len(filled)


@pytest.mark.parametrize("model", ["Top", "Scenes.Cloth", "Scenes.Chain"])
def test_fast_paths_give_the_same_flat_model(tmp_path: Path, model: str,
                                             monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "m.mdl"
    path.write_text(SOURCE)
    paths = path if model == "Top" else MODELS / "Scenes.mdl"
    general, _ = _flatten(paths, model, monkeypatch, fast=False)
    fast, copied = _flatten(paths, model, monkeypatch, fast=True)
    assert fast == general
    assert copied > 0


def test_values_from_outside_are_evaluated_per_instance(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    path = tmp_path / "m.mdl"
    path.write_text(SOURCE)
    model, copied = _flatten(path, "Top", monkeypatch, fast=True)
    by_name = {v.name: v for v in model.variables}
    assert by_name["c[4].b[2]"].binding == x.Const(-4)
    assert by_name["c[4].a"].binding == x.Const(2)
    assert by_name["m[4].s0"].binding == x.Const(4)
    assert by_name["c[4].y[2]"].attributes.start == x.BinOp("*", x.Const(2), x.Var("c[4].k"))
    assert by_name["d[3].z"].attributes.start == x.Const(3)
    # Copies: c[3], c[4], m[3], m[4], s[3] (with their flanges), and the flanges of
    # s[1] and s[2] (from the template of m[2].flange); d[*] are not (start from outside).
    assert copied == 9


def test_an_index_out_of_range_is_still_reported(tmp_path: Path) -> None:
    path = tmp_path / "m.mdl"
    path.write_text(SOURCE.replace("m[i + 1].flange", "m[i + 2].flange"))
    with pytest.raises(FlattenError, match=r"index 5 is out of range for 'm' of size 4"):
        flattening.flatten(load([path]), "Top")
