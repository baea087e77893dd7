"""The solver names springc offers, in one place (the CLI, the API and tradeoff read them).

- :data:`SOLVERS`: the adaptive ``scipy.integrate`` methods, by springc name -> scipy
  class name; :data:`IMPLICIT_SOLVERS` among them get the analytic Jacobian.
- :data:`FIXED_STEP`: the fixed-step scene integrators (:mod:`springc.simulation.integrators`);
  they need a step (``--step H``).
- :data:`AUTO`: ``dop853``, or ``radau`` where a race says it is cheaper
  (:mod:`springc.simulation.race`): :data:`EXPLICIT` and :data:`RACE_IMPLICIT`.
- :data:`ALL_SOLVERS`: every name ``--solver`` accepts.

This module imports nothing, so that the CLI can build its options without loading numpy.
"""

from __future__ import annotations

SOLVERS = {"rk45": "RK45", "dop853": "DOP853", "radau": "Radau", "bdf": "BDF",
           "lsoda": "LSODA"}
"""Adaptive solvers: springc name -> ``scipy.integrate`` class name."""
IMPLICIT_SOLVERS = frozenset({"radau", "bdf", "lsoda"})
FIXED_STEP = ("verlet", "symplectic-euler", "rk4")
"""Fixed-step solvers; they need ``SimulationOptions.step`` (``--step H``)."""
AUTO = "auto"
EXPLICIT = "dop853"
"""``auto``'s explicit method: an 8th-order Runge-Kutta method (the spring-mass scenes
are oscillatory and mostly non-stiff, where it takes far fewer steps than rk45 at
tight tolerances); also the method of the switching driver for non-scipy choices."""
RACE_IMPLICIT = "radau"
"""``auto``'s implicit method, raced against :data:`EXPLICIT` on stiff runs."""
RACE = "race"
"""Not a solver: the stiffness estimate's verdict "measure both" (``auto`` only)."""
DEFAULT_SOLVER = AUTO
ALL_SOLVERS = (AUTO, *SOLVERS, *FIXED_STEP)
"""Every name ``--solver`` and ``springc.simulate(solver=...)`` accept."""

ENGINES = ("auto", "compiled", "scipy")
"""Step loops ``--engine`` accepts: ``compiled`` (:mod:`springc.integrate`, numba, no
Python per step), ``scipy`` (``scipy.integrate``'s solver classes stepped from Python),
or ``auto``: compiled where numba is importable and the solver has a compiled loop."""
DEFAULT_ENGINE = "auto"
ERROR_CONTROLS = ("tighten", "warn", "off")
"""What ``--error-control`` accepts (:mod:`springc.simulation.error_control`)."""
DEFAULT_ERROR_CONTROL = "tighten"
COMPILED_SOLVERS = ("rk45", EXPLICIT, RACE_IMPLICIT, "bdf", *FIXED_STEP)
"""Solvers with a compiled loop (``auto`` too: it finishes on :data:`EXPLICIT` or
:data:`RACE_IMPLICIT` compiled)."""
