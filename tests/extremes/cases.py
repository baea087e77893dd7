"""Models, closed forms and references of the extremes suite (shared with
``benchmarks/extremes.py``, which measures the published table)."""

from __future__ import annotations

import numpy as np
import scipy.linalg

MODELS = """
model Harmonic "one mass on a spring: x = x0*cos(sqrt(k/m)*t)"
  parameter Real k = 1;
  parameter Real m = 1;
  parameter Real a = 1 "start position";
  Real x(start = a);
  Real v(start = 0);
equation
  der(x) = v;
  m * der(v) = -k * x;
end Harmonic;

model StiffPair "wall -1- m1 -k- m2 -k2- wall, unit masses: with k2 = 1 the stiff mode x2 - x1
  stays at rest; with k2 = 2 (uneven walls) it is excited at ~1/k"
  parameter Real k = 1e8;
  parameter Real k2 = 1;
  Real x1(start = 1);
  Real x2(start = 1);
  Real v1(start = 0);
  Real v2(start = 0);
equation
  der(x1) = v1;
  der(x2) = v2;
  der(v1) = -x1 + k * (x2 - x1);
  der(v2) = -k2 * x2 - k * (x2 - x1);
end StiffPair;

model Through "2D zero-rest-length spring to the origin: the mass passes through the anchor"
  parameter Real k = 100;
  parameter Real r = 1 "start position on the x axis";
  Real pos[2](start = {r, 0});
  Real v[2](start = {0, 0});
  Real len;
  Real dir[2];
equation
  len = sqrt(pos * pos);
  dir = pos / len "divides by the length";
  der(pos) = v;
  der(v) = -k * len * dir;
end Through;

model BigChain "N unit masses in a line, unit springs between neighbours, fixed ends"
  parameter Integer N = 10000;
  parameter Real k = 1;
  Real x[N](start = {if i == 1 then 1 else 0 for i in 1:N});
  Real v[N](start = zeros(N));
equation
  der(x) = v;
  der(v[1]) = k * (x[2] - 2 * x[1]);
  for i in 2:N - 1 loop
    der(v[i]) = k * (x[i - 1] - 2 * x[i] + x[i + 1]);
  end for;
  der(v[N]) = k * (x[N - 1] - 2 * x[N]);
end BigChain;
"""

STIFFNESSES = (1.0, 1e4, 1e8, 1e12)
MASSES = (1e-6, 1.0, 1e6)


def harmonic(t: np.ndarray, k: float = 1.0, m: float = 1.0, a: float = 1.0) -> np.ndarray:
    return a * np.cos(np.sqrt(k / m) * t)


def stiff_pair(t: np.ndarray, k: float) -> np.ndarray:
    """x1 (= x2) of StiffPair: only the slow mode (omega = 1) moves."""
    del k  # the stiff mode stays at rest
    return np.cos(t)


def stiff_pair_expm(t: np.ndarray, k: float) -> np.ndarray:
    """x1 from the matrix exponential (checks :func:`stiff_pair` for moderate k)."""
    a = np.array([[0, 0, 1, 0], [0, 0, 0, 1], [-1 - k, k, 0, 0], [k, -1 - k, 0, 0]])
    return np.array([(scipy.linalg.expm(a * s) @ [1.0, 1.0, 0.0, 0.0])[0] for s in t])


def uneven_pair(t: np.ndarray, k: float) -> np.ndarray:
    """x1, x2, v1, v2 of StiffPair with k2 = 2 (columns) by its two modes, free of cancellation.

    Stiffness matrix ``[[1 + k, -k], [-k, 2 + k]]``: the large eigenvalue from the
    quadratic formula (no cancellation), the small one as ``det / large``.
    """
    trace, det = 3 + 2 * k, 2 + 3 * k
    large = (trace + np.sqrt(trace * trace - 4 * det)) / 2
    out = np.zeros((len(t), 4))
    for lam in (det / large, large):
        shape = np.array([k, 1 + k - lam])
        shape /= np.linalg.norm(shape)
        weight, omega = shape @ [1.0, 1.0], np.sqrt(lam)
        out[:, :2] += np.outer(np.cos(omega * t), shape * weight)
        out[:, 2:] -= np.outer(omega * np.sin(omega * t), shape * weight)
    return out


def uneven_pair_expm(t: np.ndarray, k: float) -> np.ndarray:
    """:func:`uneven_pair` from the matrix exponential (moderate k only)."""
    a = np.array([[0, 0, 1, 0], [0, 0, 0, 1], [-1 - k, k, 0, 0], [k, -2 - k, 0, 0]])
    return np.array([scipy.linalg.expm(a * s) @ [1.0, 1.0, 0.0, 0.0] for s in t])


def big_chain(t: np.ndarray, n: int, k: float = 1.0) -> np.ndarray:
    """x[1], x[2] of BigChain at times ``t`` (sparse matrix exponential)."""
    import scipy.sparse as sp
    from scipy.sparse.linalg import expm_multiply

    lap = sp.diags([np.ones(n - 1), -2 * np.ones(n), np.ones(n - 1)], [-1, 0, 1]) * k
    a = sp.bmat([[None, sp.identity(n)], [lap, None]], format="csc")
    x0 = np.zeros(2 * n)
    x0[0] = 1.0
    out = expm_multiply(a, x0, start=float(t[0]), stop=float(t[-1]), num=len(t),
                        endpoint=True)
    return out[:, :2]
