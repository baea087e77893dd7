"""Dynamic state selection: ``simplify(model, at=...)``, the conditioning monitor and
the switch (the driver that uses them: ``tests/simulation/test_switching_driver.py``)."""

from __future__ import annotations

import math
from functools import cache
from pathlib import Path

import numpy as np
import pytest

from springc.ir.flat import FlatModel
from springc.pipeline.files import flatten_files
from springc.simplify.index_reduction import pivoted_choice
from springc.simplify.initialize import initial_state
from springc.simplify.ode_eval import parameter_values
from springc.simplify.passes import simplify
from springc.simplify.state_choice import (
    conditioning,
    needs_switch,
    select_states,
    state_vector,
    switch,
)
from springc.simulation.switching import EvaluatorFunctions

SCENES = Path(__file__).resolve().parents[2] / "models" / "Scenes.mdl"
G = 9.81


@cache
def scene(name: str) -> FlatModel:
    return flatten_files([SCENES], f"Scenes.{name}")


def rod_at(angle: float) -> dict[str, float]:
    """RigidPair positions with p1 at the spring's rest point and the rod at
    ``angle`` (radians, from the +x axis)."""
    return {"p1.pos[1]": 0.0, "p1.pos[2]": -1.0,
            "p2.pos[1]": math.cos(angle), "p2.pos[2]": -1.0 + math.sin(angle)}


def states(name: str, at: dict[str, float] | None = None) -> set[str]:
    return {s.name for s in simplify(scene(name), at).ode.states}


P1 = {"p1.pos[1]", "p1.pos[2]", "p1.v[1]", "p1.v[2]"}


def test_default_choice_is_unchanged_and_at_none_is_the_default() -> None:
    assert states("RigidPair") == P1 | {"p2.pos[2]", "p2.v[2]"}
    assert states("RigidPair", None) == states("RigidPair")
    assert states("Pendulum") == {"x", "vx"}


@pytest.mark.parametrize(("angle", "kept"), [(0.0, "2"), (-0.6, "2"), (-1.0, "1"),
                                              (-math.pi / 2, "1"), (-2.8, "2")])
def test_choice_at_values_keeps_the_better_conditioned_coordinate(angle: float,
                                                                  kept: str) -> None:
    """p2's coordinate along the rod is solved from the constraint, the other stays
    a state (the crossover is at 45 degrees); p1 keeps its states (priority order)."""
    assert states("RigidPair", rod_at(angle)) == P1 | {f"p2.pos[{kept}]", f"p2.v[{kept}]"}


def test_pivoted_choice_prefers_priority_classes_then_the_largest_pivot() -> None:
    # Class 0: columns 0, 1; class 1: columns 2, 3. Rows: one constraint.
    assert pivoted_choice(np.array([[0.1, 0.5, 9.0, 9.0]]), [0, 0, 1, 1]) == [1]
    assert pivoted_choice(np.array([[0.5, 0.5, 9.0]]), [0, 0, 1]) == [0]  # tie: earlier
    assert pivoted_choice(np.array([[0.0, 0.0, 2.0]]), [0, 0, 1]) == [2]
    assert pivoted_choice(np.array([[1.0, 2.0], [2.0, 4.0]]), [0, 0]) is None


def test_monitor_is_one_after_selection_and_falls_towards_the_singularity() -> None:
    flat = scene("RigidPair")
    horizontal = select_states(flat)  # p2.pos[1] solved from the rod: bad when vertical
    params = parameter_values(horizontal.ode.parameters)
    values = {**params, **rod_at(0.0)}
    assert conditioning(horizontal, values) == pytest.approx(1.0)
    ratios = [conditioning(horizontal, {**params, **rod_at(-a)}) for a in (0.5, 1.2, 1.5)]
    assert ratios[0] > ratios[1] > ratios[2] > 0
    assert not needs_switch(horizontal, {**params, **rod_at(-1.2)})
    assert needs_switch(horizontal, {**params, **rod_at(-1.5)})
    vertical = select_states(flat, at={**params, **rod_at(-1.5)})
    assert conditioning(vertical, {**params, **rod_at(-1.5)}) == pytest.approx(1.0)
    assert select_states(scene("Pendulum")).blocks  # it has a choice to monitor


def test_switch_maps_values_onto_the_new_states_consistently() -> None:
    flat = scene("RigidPair")
    old = select_states(flat)
    _, info = initial_state(old.ode)
    params = parameter_values(old.ode.parameters)
    # Move p2 (with the rod) to -80 degrees, at rest: consistent with the constraints.
    values = {**info.values, **rod_at(-80 * math.pi / 180)}
    new = switch(flat, values)
    assert set(new.states) == P1 | {"p2.pos[1]", "p2.v[1]"}
    x = state_vector(new, values)
    env = EvaluatorFunctions(new, params, values).values(0.0, x)
    assert env["p2.pos[2]"] == pytest.approx(values["p2.pos[2]"], abs=1e-12)  # same branch
    assert env["p2.v[2]"] == pytest.approx(0.0, abs=1e-12)
