"""Sums of thousands of terms built by flattening (``sum(z)`` over a large array) go
through alias elimination, causalization and code generation without recursing once
per term: flatten folds them in chunks of 64 combined pairwise, and alias elimination
rebuilds a solved sum the same way."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import springc
from springc.flatten.arrays import fold
from springc.ir import expr as x
from springc.ir.expr import FOLD_CHUNK

MODEL = """
model SumZ
  parameter Real z[20000] = fill(1e-4, 20000);
  Real y;
  Real v(start = 1, fixed = true);
equation
  y = sum(z);
  der(v) = -y*v;
end SumZ;
"""


def _depth(e: x.Expr) -> int:
    deepest, stack = 0, [(e, 1)]
    while stack:
        node, depth = stack.pop()
        deepest = max(deepest, depth)
        stack += [(child, depth + 1) for child in x.children(node)]
    return deepest


def test_fold_is_the_left_fold_up_to_a_chunk_and_shallow_beyond() -> None:
    names = [x.Var(f"a{i}") for i in range(20000)]
    small = fold(x.add, names[:FOLD_CHUNK], x.ZERO)
    left: x.Expr = x.ZERO
    for v in names[:FOLD_CHUNK]:
        left = x.add(left, v)
    assert small == left
    big = fold(x.add, names, x.ZERO)
    assert _depth(big) == FOLD_CHUNK + math.ceil(math.log2(20000 / FOLD_CHUNK))
    assert sorted(v.name for v in x.walk(big) if isinstance(v, x.Var)) == sorted(
        v.name for v in names)


def test_a_sum_of_20000_parameters_simulates(tmp_path: Path) -> None:
    path = tmp_path / "sumz.mdl"
    path.write_text(MODEL)
    result = springc.simulate([path], stop=1.0, interval=0.25, rtol=1e-9, cache=False)
    assert np.allclose(result["y"], 2.0, rtol=1e-12, atol=0)
    # v' = -2 v: v = exp(-2 t), at rtol 1e-9
    assert np.allclose(result["v"], np.exp(-2.0 * result.time), rtol=1e-7, atol=0)
