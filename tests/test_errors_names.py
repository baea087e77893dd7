"""Near names for "did you mean": the edit distance and its threshold."""

from __future__ import annotations

import pytest

from springc.errors import close_names, did_you_mean, edit_distance


@pytest.mark.parametrize(("a", "b", "distance"), [
    ("kitten", "sitting", 3), ("ab", "ba", 1), ("", "abc", 3), ("stifness", "stiffness", 1),
    ("spring.kk", "spring.k", 1), ("Bodie", "Body", 2), ("same", "same", 0),
])
def test_edit_distance(a: str, b: str, distance: int) -> None:
    assert edit_distance(a, b) == distance
    assert edit_distance(b, a) == distance


def test_close_names_threshold_scales_with_length() -> None:
    assert close_names("k", ["x", "kk"]) == []  # one letter: nothing is near
    assert close_names("Bodie", ["Body", "Bode", "Mass"]) == ["Bode", "Body"]
    assert close_names("velocty", ["velocity", "position", "v"]) == ["velocity"]
    assert close_names("Scenes.Chian", ["Scenes.Chain", "Scenes.Cloth"]) == ["Scenes.Chain"]
    assert close_names("Wall", ["Mech.Wall", "Mech.Floor"]) == ["Mech.Wall"]
    assert close_names("SPEED", ["speed"]) == ["speed"]


def test_did_you_mean_text() -> None:
    assert did_you_mean("spring.kk", ["spring.k", "spring.c", "mass.m"]) == \
        "did you mean 'spring.k'?"
    assert did_you_mean("mass.x", ["mass.v", "mass.a", "mass.s", "spring.k"]) == \
        "did you mean 'mass.a', 'mass.s' or 'mass.v'?"
    assert did_you_mean("zzz", ["spring.k"]) is None
