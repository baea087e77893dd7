"""springc: a compiler and simulator for spring-mass models written in a Modelica subset."""

from __future__ import annotations

from typing import Any

__all__ = ["AccuracyWarning", "compile_model", "export_fmu", "load_model_from_string",
           "simulate", "sweep"]


def __getattr__(name: str) -> Any:
    # Lazy: ``import springc`` stays fast; numpy/scipy load on first use.
    if name in __all__:
        from . import api

        return getattr(api, name)
    raise AttributeError(f"module 'springc' has no attribute {name!r}")
