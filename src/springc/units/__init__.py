"""Units: the SI algebra of Modelica's ``unit`` strings and the check of a flat model's
equations against it (flat.FlatModel -> unit mismatches, warnings unless
``--strict-units``)."""

from .algebra import Unit, UnitSyntaxError, canonical, parse_unit
from .check import check_units

__all__ = ["Unit", "UnitSyntaxError", "canonical", "check_units", "parse_unit"]
