"""The solver registry: every fact about a solver, in one place (the CLI, the API, the
runs, the error estimate and tradeoff read them).

Each solver is one :class:`Solver` row of :data:`REGISTRY`: its kind (adaptive, fixed
step, or ``auto``), the ``scipy.integrate`` class of an adaptive one, whether it is
implicit (it gets the analytic Jacobian), whether it has a compiled loop, and for a
fixed-step one its order (Richardson's gain in the error estimate) and whether it
needs the position/velocity pairs of a mechanical scene. A row that misses a fact its
kind needs is refused when this module loads, so a new solver cannot run without one.
The tables below are derived from the rows:

- :data:`SOLVERS`: the adaptive ``scipy.integrate`` methods, by springc name -> scipy
  class name; :data:`IMPLICIT_SOLVERS` among them get the analytic Jacobian.
- :data:`FIXED_STEP`: the fixed-step scene integrators (:mod:`springc.simulation.integrators`);
  they need a step (``--step H``); :data:`ORDERS` their orders.
- :data:`AUTO`: ``dop853``, or ``radau`` where a race says it is cheaper
  (:mod:`springc.simulation.race`): :data:`EXPLICIT` and :data:`RACE_IMPLICIT`.
- :data:`ALL_SOLVERS`: every name ``--solver`` accepts.

This module imports nothing, so that the CLI can build its options without loading numpy.
"""

from __future__ import annotations

from dataclasses import dataclass

ADAPTIVE, FIXED, CHOOSER = "adaptive", "fixed", "auto"
"""The kinds of :class:`Solver`: an adaptive scipy method, a fixed-step integrator, or
``auto``, which chooses among the others."""


@dataclass(frozen=True)
class Solver:
    """Every fact about one solver (see the module docstring)."""

    name: str
    kind: str
    scipy: str = ""  # adaptive: the scipy.integrate class
    implicit: bool = False  # adaptive: Newton iterations on the analytic Jacobian
    compiled: bool = False  # a compiled loop in springc.integrate
    order: int = 0  # fixed step: the order q (Richardson's gain 2^q)
    pairs: bool = False  # fixed step: needs the position/velocity pairs (symplectic)

    def __post_init__(self) -> None:
        if self.kind not in (ADAPTIVE, FIXED, CHOOSER):
            raise ValueError(f"solver {self.name}: unknown kind {self.kind!r}")
        if self.kind == ADAPTIVE and not self.scipy:
            raise ValueError(f"solver {self.name}: an adaptive solver names its scipy class")
        if self.kind == FIXED and self.order < 1:
            raise ValueError(f"solver {self.name}: a fixed-step solver states its order")

    @property
    def fixed(self) -> bool:
        """A fixed-step solver: it takes ``--step H`` and no tolerance."""
        return self.kind == FIXED

    @property
    def setting(self) -> str:
        """What a run of it is set by: ``step`` (fixed step) or ``rtol``."""
        return "step" if self.fixed else "rtol"


AUTO = "auto"
EXPLICIT = "dop853"
"""``auto``'s explicit method: an 8th-order Runge-Kutta method (the spring-mass scenes
are oscillatory and mostly non-stiff, where it takes far fewer steps than rk45 at
tight tolerances); also the method of the switching driver for non-scipy choices, of
the companion run of an explicit run's error estimate, and tradeoff's pilot and
reference method."""
RACE_IMPLICIT = "radau"
"""``auto``'s implicit method, raced against :data:`EXPLICIT` on stiff runs."""

REGISTRY: dict[str, Solver] = {s.name: s for s in (
    Solver(AUTO, CHOOSER, compiled=True),  # finishes on EXPLICIT or RACE_IMPLICIT compiled
    Solver("rk45", ADAPTIVE, "RK45", compiled=True),
    Solver(EXPLICIT, ADAPTIVE, "DOP853", compiled=True),
    Solver(RACE_IMPLICIT, ADAPTIVE, "Radau", implicit=True, compiled=True),
    Solver("bdf", ADAPTIVE, "BDF", implicit=True, compiled=True),
    Solver("lsoda", ADAPTIVE, "LSODA", implicit=True),
    Solver("verlet", FIXED, compiled=True, order=2, pairs=True),
    Solver("symplectic-euler", FIXED, compiled=True, order=1, pairs=True),
    Solver("rk4", FIXED, compiled=True, order=4),
)}
"""Every solver by name, in the order ``--solver`` lists them."""


def registered(name: str) -> Solver:
    """The registry row of ``name`` (a name of :data:`ALL_SOLVERS`)."""
    return REGISTRY[name]


SOLVERS = {s.name: s.scipy for s in REGISTRY.values() if s.kind == ADAPTIVE}
"""Adaptive solvers: springc name -> ``scipy.integrate`` class name."""
IMPLICIT_SOLVERS = frozenset(s.name for s in REGISTRY.values() if s.implicit)


def companion_solver(solver: str) -> str:
    """The method of the companion run that estimates the error of a run of the
    adaptive ``solver``: the same method for an implicit one (a stiff run), else
    :data:`EXPLICIT` (the full path's :mod:`.error_control` and the warm replay of
    :mod:`springc.launcher` both ask here)."""
    return solver if solver in IMPLICIT_SOLVERS else EXPLICIT


FIXED_STEP = tuple(s.name for s in REGISTRY.values() if s.fixed)
"""Fixed-step solvers; they need a step (``RunSettings.step``, ``--step H``)."""
ORDERS = {s.name: s.order for s in REGISTRY.values() if s.fixed}
"""The order of each fixed-step method (Richardson's gain ``2^q``)."""
RACE = "race"
"""Not a solver: the stiffness estimate's verdict "measure both" (``auto`` only)."""
DEFAULT_SOLVER = AUTO
ALL_SOLVERS = tuple(REGISTRY)
"""Every name ``--solver`` and ``springc.simulate(solver=...)`` accept."""

ENGINES = ("auto", "compiled", "scipy")
"""Step loops ``--engine`` accepts: ``compiled`` (:mod:`springc.integrate`, numba, no
Python per step), ``scipy`` (``scipy.integrate``'s solver classes stepped from Python),
or ``auto``: compiled where numba is importable and the solver has a compiled loop."""
DEFAULT_ENGINE = "auto"
ERROR_CONTROLS = ("tighten", "warn", "off")
"""What ``--error-control`` accepts (:mod:`springc.simulation.error_control`)."""
DEFAULT_ERROR_CONTROL = "tighten"
COMPILED_SOLVERS = tuple(s.name for s in REGISTRY.values() if s.compiled and s.name != AUTO)
"""Solvers with a compiled loop (``auto`` too: it finishes on :data:`EXPLICIT` or
:data:`RACE_IMPLICIT` compiled)."""
