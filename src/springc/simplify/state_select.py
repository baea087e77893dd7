"""The ``stateSelect`` attribute honoured after state selection (Modelica 3.6, section
4.8.7.1): a variable declared ``StateSelect.never`` is not a state, one declared
``StateSelect.always`` is one (index reduction differentiates the equations that
determine it where its derivative does not appear:
:func:`springc.simplify.index_reduction.forced_derivatives`). Input: the unknowns of
the DAE and the names of the chosen states; output: nothing, or a located :class:`SimplifyError`.

Alias elimination runs first: a variable equal to another, or to a parameter, is no
longer an unknown here and is not checked.
"""

from __future__ import annotations

from collections.abc import Iterable

from ..errors import SimplifyError
from ..ir import dae

_RULE = " (Modelica 3.6, section 4.8.7.1)"


def check_state_select(unknowns: Iterable[dae.Unknown], states: set[str]) -> None:
    """Raise for the first unknown whose ``stateSelect`` the state choice contradicts."""
    for u in unknowns:
        if u.state_select == "never" and u.name in states:
            raise SimplifyError(
                f"'{u.name}' has stateSelect = StateSelect.never but must be a state: its "
                "derivative appears and no other variable can be integrated in its place",
                u.span, hint="StateSelect.never forbids a variable as a state; remove the "
                "attribute or give the model another variable to integrate" + _RULE)
        if u.state_select == "always" and u.name not in states:
            raise SimplifyError(
                f"'{u.name}' has stateSelect = StateSelect.always but cannot be a state: "
                "the equations determine it directly, and differentiated they leave no "
                "other variable to compute in its place",
                u.span, hint="StateSelect.always requires the variable to be a state; "
                "remove the attribute, or give the model another variable that these "
                "equations determine" + _RULE)
