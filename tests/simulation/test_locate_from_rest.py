"""A relation whose zero-crossing function is exactly 0 where the bracket starts (a
velocity at rest, then growing as (t - t0)^2 / 2: a friction's ``v > 0`` after it starts
forward, Translational.HeatLosses' supportFriction once its velocity is computed from
the springs' relative states) is located where it switches. Before, regula falsi with
the left value 0 put every secant point on the left end, the Illinois halving of the
right value could not move it, and the event was placed at the bracket's right end: a
whole step late (HeatLosses: 0.0319 s instead of 0.02918 s)."""

from __future__ import annotations

import operator
from types import SimpleNamespace

import numpy as np

from springc.simulation.events import EventLoop


def _loop(g: object) -> EventLoop:
    """An event loop over one relation ``g(t) > 0``, held false (only what ``locate``
    reads)."""
    loop = EventLoop.__new__(EventLoop)
    loop.mod = SimpleNamespace(zero_crossings=lambda t, x, p, z: np.array([g(t)]))
    loop.ops, loop.first, loop.z, loop.p = [operator.gt], 0, np.zeros(1), np.zeros(0)
    return loop


def test_a_crossing_from_exactly_zero_is_located_where_it_starts() -> None:
    # g = 0 until 0.3, then (t - 0.3)^2 / 2 > 0: the relation switches at 0.3
    loop = _loop(lambda t: 0.5 * max(t - 0.3, 0.0) ** 2)
    located = loop.locate(lambda t: np.array([t]), 0.0, 1.0, 0)
    assert 0.3 < located <= 0.3 + 1e-11


def test_a_crossing_from_below_is_still_located_by_regula_falsi() -> None:
    loop = _loop(lambda t: t - 0.3)
    located = loop.locate(lambda t: np.array([t]), 0.0, 1.0, 0)
    assert 0.3 < located <= 0.3 + 1e-11
