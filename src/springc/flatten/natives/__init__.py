"""The MSL's table external objects, evaluated natively while flattening (``tables``), with
their interpolants as expressions (``interpolation``); calls of external functions, the
ModelicaStrings ones evaluated, the others a located error (``externals``)."""

from __future__ import annotations

from .externals import external_value, is_external, skipped_call
from .tables import is_external_object, native_call, table_object

__all__ = ["external_value", "is_external", "is_external_object", "native_call",
           "skipped_call", "table_object"]
