"""The MSL's table external objects, evaluated natively while flattening (``tables``), with
their interpolants as expressions (``interpolation``)."""

from __future__ import annotations

from .tables import is_external_object, native_call, native_function, table_object

__all__ = ["is_external_object", "native_call", "native_function", "table_object"]
