"""The equations of a compiled model for notebooks: LaTeX in Jupyter, text elsewhere.

:meth:`springc.pipeline.CompiledModel.equations` gives the simplified system (in
evaluation order), :meth:`~springc.pipeline.CompiledModel.flat_equations` the flat model;
both render through :mod:`springc.ir.latex` (``_repr_latex_`` of the IR objects).
"""

from __future__ import annotations

from dataclasses import dataclass

from ..ir import flat, ode


@dataclass(frozen=True)
class Equations:
    """Equations to show: ``system`` is the simplified ODE or the flat model.

    In Jupyter they render as aligned LaTeX (as text past
    :data:`springc.ir.latex.NOTEBOOK_ROWS` equations); ``str`` gives the text form of
    ``springc simplify`` / ``springc flatten``, :meth:`latex` the ``--latex`` form.
    """

    system: ode.ODE | flat.FlatModel

    def latex(self) -> str:
        """The equations in a LaTeX ``align`` environment."""
        if isinstance(self.system, ode.ODE):
            return ode.format_ode_latex(self.system)
        return flat.format_flat_latex(self.system)

    def _repr_latex_(self) -> str | None:
        return self.system._repr_latex_()

    def __str__(self) -> str:
        if isinstance(self.system, ode.ODE):
            return ode.format_ode(self.system)
        return flat.format_flat(self.system)

    def __repr__(self) -> str:
        return str(self)
