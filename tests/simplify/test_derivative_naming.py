"""Index reduction names every derivative variable that one Pantelides step creates,
whatever their numbering (regression: a chain through an algebraic variable lost its
second derivatives and was reported structurally singular)."""

from __future__ import annotations

import numpy as np

import springc

CHAIN = """
model Chain "s and ms are both differentiated twice; fs links them algebraically"
  Real s(start = 0, fixed = true), v(start = 0, fixed = true), a, fs;
  Real ms, mv, ma;
equation
  s = 2 * fs;
  v = der(s);
  a = der(v);
  a = 1;
  fs = ms - 0.5;
  mv = der(ms);
  ma = der(mv);
end Chain;
"""


def test_a_chain_through_an_algebraic_variable_is_reduced() -> None:
    model = springc.load_model_from_string(CHAIN, cache=False)
    result = springc.simulate(model, stop=1.0, interval=0.01, rtol=1e-10, atol=1e-12)
    t = result.time
    # s'' = 1: s = t^2/2; ms = s/2 + 0.5.
    assert np.max(np.abs(result["s"] - t ** 2 / 2)) < 1e-9
    assert np.max(np.abs(result["ms"] - (t ** 2 / 4 + 0.5))) < 1e-9
