"""An ``inner outer`` element (Modelica 3.6, section 5.4) is an outer element for the
references of its own class and an inner element for the outer ones below it; and
names in a function are looked up from the function (its imports, section 13.2).
Exact flat models."""

from __future__ import annotations

from pathlib import Path

from springc.ir.flat import format_flat
from springc.pipeline.files import flatten_files


def flat(tmp_path: Path, text: str) -> str:
    path = tmp_path / "m.mo"
    path.write_text(text)
    return format_flat(flatten_files([path]))


def test_inner_outer_is_both(tmp_path: Path) -> None:
    assert flat(tmp_path, """model M
  model Leaf
    outer Boolean on;
    Real x(start = 1, fixed = true);
  equation
    der(x) = if on then -x else 0;
  end Leaf;
  model Group
    Boolean enabled = false;
    inner outer Boolean on = on and enabled;
    Leaf leaf;
  end Group;
  Group group;
  inner Boolean on = true;
  Boolean seen = group.on;
end M;
""") == """model M
  discrete Boolean 'group.enabled';
  discrete Boolean 'group.on';
  Real 'group.leaf.x'(start = 1, fixed = true);
  discrete Boolean on;
  discrete Boolean seen;
equation
  'group.enabled' = false;
  on = true;
  'group.on' = on and 'group.enabled';
  seen = on;
  der('group.leaf.x') = if 'group.on' then -'group.leaf.x' else 0;
end M;
"""


def test_a_function_sees_its_imports(tmp_path: Path) -> None:
    assert flat(tmp_path, """model M
  encapsulated package P
    constant Real c = 2.5;
  end P;
  function f
    import M.P.c;
    input Real u;
    output Real y;
  algorithm
    y := c * u;
  end f;
  Real y = f(time);
end M;
""") == "model M\n  Real y;\nequation\n  y = 2.5 * time;\nend M;\n"
