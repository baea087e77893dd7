"""Checks of a hybrid model after state selection: flat.FlatModel + ode.ODE -> None
or a located SimplifyError."""

from __future__ import annotations

from ..errors import Note, SimplifyError
from ..ir import flat, ode


def check_reinits(model: flat.FlatModel, system: ode.ODE) -> None:
    """Every ``reinit`` names a state of ``system`` (a variable that index reduction or
    alias elimination did not select as a state cannot restart)."""
    states = {s.name for s in system.states}
    for clause in model.whens:
        for branch in clause.branches:
            for r in branch.reinits:
                if r.name not in states:
                    chosen = ", ".join(sorted(states)[:6]) or "none"
                    raise SimplifyError(
                        f"reinit({r.name}, ...): '{r.name}' is not a state of the "
                        "simplified system", r.span,
                        [Note(f"the states are: {chosen}")],
                        hint=f"reinit a variable whose derivative appears in the equations "
                        f"(der({r.name})), or give it stateSelect = StateSelect.always")
