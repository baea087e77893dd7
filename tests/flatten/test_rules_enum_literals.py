"""Enumeration literals cannot be named like the attributes of enumeration types
(Modelica 3.6 section 4.8.5.1): a valid model (its balance summary) and an invalid one
for each attribute name (the exact error, location and help)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome

HELP = ("help: the literals and the attributes of an enumeration type share one scope, so "
        "quantity, min, max, start and fixed cannot be literals; rename the literal "
        "(Modelica 3.6, section 4.8.5.1)")


def test_literals_other_names(tmp_path: Path) -> None:
    text = """\
model M
  type E = enumeration(low, fixedPoint, maximum);
  E e = E.fixedPoint;
end M;
"""
    assert outcome(tmp_path, text) == ("M: 1 unknown (1 discrete), 1 equation, "
                                       "0 parameters: balanced")


@pytest.mark.parametrize("literal", ["quantity", "min", "max", "start", "fixed"])
def test_literal_named_like_attribute(tmp_path: Path, literal: str) -> None:
    text = f"""\
model M
  type E = enumeration(broken, {literal});
  E e = E.broken;
end M;
"""
    assert outcome(tmp_path, text) == (
        f"2:8: enumeration 'E' has a literal named '{literal}', like an attribute of "
        f"enumeration types\n{HELP}")
