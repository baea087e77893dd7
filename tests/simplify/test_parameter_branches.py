"""If-expressions chosen by Boolean or Integer parameters with ``der`` in a branch
(simplify/parameter_branches.py): the branch the parameters choose is the equation
(the MSL's ``PotentialToFlowAdaptor``: ``y1 = if use_fder then -der(y) else 0``);
other if-expressions stay."""

from __future__ import annotations

from pathlib import Path

import pytest

from springc.ir import expr as x
from springc.pipeline.files import flatten_files
from springc.simplify.parameter_branches import parameter_branches

MODEL = '''\
model PB
  parameter Boolean use_fder = {use};
  parameter Integer order = 2;
  parameter Boolean twice = use_fder and order > 1;
  parameter Real k = 1;
  Real s(start = 0, fixed = true), y, y1, y2, w;
equation
  der(s) = 1 - s;
  y = 2*s;
  y1 = if use_fder then -der(y) else 0;
  y2 = if twice then -der(y1) else 3;
  w = if k > 0 then s else -s;
end PB;
'''


def _equations(tmp_path: Path, use: str) -> dict[str, x.Expr]:
    path = tmp_path / "PB.mo"
    path.write_text(MODEL.format(use=use))
    model = parameter_branches(flatten_files((str(path),), "PB"))
    return {eq.lhs.name: eq.rhs for eq in model.equations if isinstance(eq.lhs, x.Var)}


@pytest.mark.parametrize(("use", "y1", "y2"), [
    ("false", "0", "3"),
    ("true", "-der(y)", "-der(y1)"),
])
def test_the_parameters_choose_the_branch(tmp_path: Path, use: str, y1: str, y2: str
                                          ) -> None:
    rhs = _equations(tmp_path, use)
    assert x.to_text(rhs["y1"]) == y1
    assert x.to_text(rhs["y2"]) == y2
    # a Real parameter's condition without der in its branches stays
    assert x.to_text(rhs["w"]) == "if k > 0 then s else -s"
