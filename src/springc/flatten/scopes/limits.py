"""Resource limits of one flattening run: the size of the flat model and the work of
its loops.

A model of a few lines can ask for ``Real x[1000000000]`` or a loop of 10^10 iterations;
without a cap springc would exhaust memory or run for hours before saying anything. The
cap (:data:`DEFAULT_MAX_SIZE`, 2 million) bounds both the scalar variables and arrays
that flattening creates and the iterations of ``for`` loops, ranges and array
constructors; ``springc --max-size N``, ``flatten(..., max_size=N)`` or the environment
variable ``SPRINGC_MAX_SIZE`` raises it.
"""

from __future__ import annotations

import math
import os

from ...errors import FlattenError, Span

__all__ = ["DEFAULT_MAX_SIZE", "ENVIRONMENT_VARIABLE", "Limits", "max_size_setting"]

#: 2 million: 2.7 times the largest benchmark model (the 100x100 cloth: 517,400 flat
#: equations, 736,829 scalar variables and components, 60,299 loop iterations).
#: Flattening costs 20-40 us per equation or iteration, so a model at the cap fails
#: within about a minute instead of running for hours or exhausting memory.
DEFAULT_MAX_SIZE = 2_000_000
ENVIRONMENT_VARIABLE = "SPRINGC_MAX_SIZE"
#: One run of a ``while`` loop may take a hundredth of the cap (20,000 iterations by
#: default, under a second): a loop whose condition never becomes false fails fast,
#: where the cap for all loops together would let it run for about 100 s.
WHILE_SHARE = 100


def max_size_setting(max_size: int | None = None) -> int:
    """The cap to use: ``max_size`` if given, else ``$SPRINGC_MAX_SIZE``, else the default."""
    if max_size is not None:
        if isinstance(max_size, bool) or not isinstance(max_size, int) or max_size < 1:
            raise FlattenError(f"max_size must be a positive integer, found {max_size!r}")
        return max_size
    text = os.environ.get(ENVIRONMENT_VARIABLE, "").strip()
    if not text:
        return DEFAULT_MAX_SIZE
    try:
        value = int(text)
    except ValueError:
        value = 0
    if value < 1:
        raise FlattenError(f"{ENVIRONMENT_VARIABLE} must be a positive integer, "
                           f"found '{text}'", hint=f"unset it to use the default cap of "
                           f"{DEFAULT_MAX_SIZE}")
    return value


class Limits:
    """The cap of one run and what has been spent of it: scalar variables (and
    elements of arrays of components) created, and loop iterations run."""

    def __init__(self, max_size: int) -> None:
        self.max_size = max_size
        self.scalars = 0
        self.iterations = 0
        # The error raised when a running count crossed the cap; raised again (the same
        # object, so that it is reported once) by every later addition.
        self.exceeded: FlattenError | None = None

    @property
    def hint(self) -> str:
        return (f"springc caps the flat model and its loops at {self.max_size} elements; "
                f"if this model really needs more, raise the cap with "
                f"springc --max-size N, {ENVIRONMENT_VARIABLE}=N or flatten(..., max_size=N)")

    def check_size(self, count: float, what: str, span: Span | None,
                   unit: str = "elements") -> None:
        """One array (or range, or loop) of ``count`` elements: refused past the cap,
        before any memory or time is spent on it."""
        if count > self.max_size:
            raise FlattenError(f"{what} has {_number(count)} {unit}, more than the limit "
                               f"of {self.max_size}", span, hint=self.hint)

    def add_scalars(self, count: int, name: str, span: Span | None) -> None:
        """``count`` more scalar variables or components (``name``) in the flat model."""
        self.check_size(count, f"'{name}'", span)
        self.scalars += count
        if self.exceeded is None and self.scalars > self.max_size:
            self.exceeded = FlattenError(
                f"the flat model has more than {self.max_size} scalar variables and "
                "components (this declaration crosses the limit)", span, hint=self.hint)
        if self.exceeded is not None:
            raise self.exceeded

    def while_iteration(self, done: int, span: Span | None) -> None:
        """One more iteration of a ``while`` loop that has run ``done`` iterations."""
        bound = max(1000, self.max_size // WHILE_SHARE)
        if done >= bound:
            raise FlattenError(
                f"this while loop did not end within {bound} iterations",
                span, hint=f"springc runs a while loop while it flattens the model and "
                f"stops it after 1/{WHILE_SHARE} of its cap of {self.max_size} elements; "
                f"check that the loop's condition becomes false; if the loop really "
                f"needs more iterations, raise the cap with springc --max-size N, "
                f"{ENVIRONMENT_VARIABLE}=N or flatten(..., max_size=N)")
        self.add_iterations(1, span)

    def add_iterations(self, count: float, span: Span | None) -> None:
        """``count`` more loop iterations (``for`` equations and statements, array
        constructors with iterators)."""
        self.check_size(count, "this loop", span, "iterations")
        self.iterations += int(count)
        if self.exceeded is None and self.iterations > self.max_size:
            self.exceeded = FlattenError(
                f"the loops of this model run more than {self.max_size} iterations in all "
                "(this loop crosses the limit)", span, hint=self.hint)
        if self.exceeded is not None:
            raise self.exceeded


def _number(count: float) -> str:
    """``1000000000`` or ``about 1e+300`` for counts too large to write out."""
    if math.isfinite(count) and count < 1e15:
        return str(int(count))
    return f"about {count:.3g}"
