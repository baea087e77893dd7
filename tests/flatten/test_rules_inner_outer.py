"""An inner element is a subtype of its outer elements (Modelica 3.6 section 5.4): the
same predefined type, number of dimensions and sizes. Valid models (their balance
summary) and invalid ones (the exact error, location and help)."""

from __future__ import annotations

from pathlib import Path

import pytest

from rule_outcome import outcome

HELP = ("help: an inner element must be a subtype of its outer elements, with the same "
        "sizes (Modelica 3.6, section 5.4)")

MODEL = """\
model M
  model A
    outer {outer} p{dims};
    Real x = p[2];
  end A;
  inner {inner} p[3] = {{1, 2, 3}};
  A a;
end M;
"""

CASES = {
    "same_type_and_sizes": (MODEL.format(outer="Real", dims="[3]", inner="Real"),
                            "M: 4 unknowns, 4 equations, 0 parameters: balanced"),
    "same_integer_type": (MODEL.format(outer="Integer", dims="[3]", inner="Integer"),
                          "M: 4 unknowns (3 discrete), 4 equations, 0 parameters: balanced"),
    "other_size": (MODEL.format(outer="Real", dims="[2]", inner="Real"),
                   "3:16: the outer element 'p' is of type Real[2], but its inner element "
                   f"is of type Real[3]\n{HELP}"),
    "scalar_outer": (MODEL.format(outer="Real", dims="", inner="Real"),
                     "3:16: the outer element 'p' is of type Real, but its inner element "
                     f"is of type Real[3]\n{HELP}"),
    "more_dimensions": (MODEL.format(outer="Real", dims="[1, 3]", inner="Real"),
                        "3:16: the outer element 'p' is of type Real[1,3], but its inner "
                        f"element is of type Real[3]\n{HELP}"),
    "other_type": (MODEL.format(outer="Integer", dims="[3]", inner="Real"),
                   "3:19: the outer element 'p' is of type Integer[3], but its inner "
                   f"element is of type Real[3]\n{HELP}"),
}


@pytest.mark.parametrize("name", list(CASES))
def test_rule(tmp_path: Path, name: str) -> None:
    text, expected = CASES[name]
    assert outcome(tmp_path, text) == expected
