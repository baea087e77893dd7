"""Models given as text (``<string>``): the excerpts of their errors come from the text
each error points into, carried by its spans, not from a table of the process."""

from __future__ import annotations

import pickle

import pytest

from springc.errors import SpringcError
from springc.parse import load

FIRST = "model A\n  Real x\nend A;\n"
SECOND = "model B\n  Real y;\n  Real z = ;\nend B;\n"
FIRST_ERROR = ("<string>:3:1: error: unexpected 'end', expected one of: ';', ',', '=', '(', "
               "'[', ...\n"
               "    3 | end A;\n"
               "      | ^^^\n"
               "help: a ';' may be missing at the end of line 2")


def _error(text: str) -> SpringcError:
    with pytest.raises(SpringcError) as info:
        load([], texts=[("<string>", text)])
    return info.value


def test_two_texts_under_one_name_keep_their_own_excerpts() -> None:
    first = _error(FIRST)
    second = _error(SECOND)
    assert str(second) == ("<string>:3:12: error: unexpected ';', expected one of: '(', "
                           "'[', identifier, '{', 'false', ...\n"
                           "    3 |   Real z = ;\n"
                           "      |            ^")
    assert str(first) == FIRST_ERROR


def test_a_pickled_error_keeps_its_excerpt() -> None:
    assert str(pickle.loads(pickle.dumps(_error(FIRST)))) == FIRST_ERROR
