"""Unit strings -> :class:`Unit`: the SI unit algebra of Modelica's ``unit`` attribute.

The syntax is Modelica 3.6, section 19.1 ("Unit Expressions"): factors joined by
``.`` (``N.m``), one ``/`` (``m/s``, ``W/(m2.K)``), integer exponents written after
the symbol (``s2``, ``s-1``), ``1`` for dimensionless, and SI prefixes (``mm``,
``kN``, ``ms``; a symbol is tried before a prefixed symbol, so ``m`` is the metre and
``min`` the minute). A :class:`Unit` is a vector of exponents of the seven SI base
units and a scale factor: ``N`` and ``kg.m/s2`` are the same unit, ``mm`` and ``m``
are not. Angles (``rad``, ``sr``, ``deg``) are dimensionless; temperatures in ``degC``
count as kelvin (their differences are, and an offset is not a unit).
"""

from __future__ import annotations

import functools
import math
import re
from dataclasses import dataclass, field
from fractions import Fraction

BASE = ("kg", "m", "s", "A", "K", "mol", "cd")
"""The SI base units, in the order of :attr:`Unit.dims`."""

STEP = 60
"""Exponents are kept as integer multiples of 1/STEP (halves, thirds, quarters, fifths
and sixths are exact; integer arithmetic keeps the check of a large model fast)."""

Dims = tuple[int, ...]


def _dims(**exponents: int) -> Dims:
    return tuple(STEP * exponents.get(b, 0) for b in BASE)


@dataclass(frozen=True)
class Unit:
    """A unit: exponents of the SI base units (:data:`BASE`, in steps of 1/:data:`STEP`)
    and a scale factor (``mm``: metre, 0.001). ``text`` is how it is shown (the unit
    string it was written as, or a canonical form) and takes no part in comparisons."""

    dims: Dims
    scale: float = 1.0
    text: str = field(default="", compare=False)

    def __str__(self) -> str:
        return self.text or canonical(self)

    def same(self, other: Unit) -> bool:
        """The same unit (dimensions and scale; the text does not matter)."""
        return self.dims == other.dims and math.isclose(self.scale, other.scale,
                                                        rel_tol=1e-9)

    @property
    def dimensionless(self) -> bool:
        return not any(self.dims)

    @property
    def exponents(self) -> tuple[Fraction, ...]:
        """The exponent of each base unit of :data:`BASE`."""
        return tuple(Fraction(d, STEP) for d in self.dims)

    def __mul__(self, other: Unit) -> Unit:
        return Unit(tuple(a + b for a, b in zip(self.dims, other.dims)),
                    self.scale * other.scale)

    def __truediv__(self, other: Unit) -> Unit:
        return Unit(tuple(a - b for a, b in zip(self.dims, other.dims)),
                    self.scale / other.scale)

    def power(self, exponent: Fraction) -> Unit | None:
        """The unit raised to ``exponent``; ``None`` where an exponent would not be a
        multiple of 1/:data:`STEP`."""
        dims = tuple(d * exponent for d in self.dims)
        if any(d.denominator != 1 for d in dims):
            return None
        return Unit(tuple(int(d) for d in dims), self.scale ** float(exponent))


ONE = Unit(_dims(), 1.0, "1")
SECOND = Unit(_dims(s=1), 1.0, "s")


def _derived(scale: float, **exponents: int) -> tuple[float, Dims]:
    return scale, _dims(**exponents)


SYMBOLS: dict[str, tuple[float, Dims]] = {
    "m": _derived(1, m=1), "s": _derived(1, s=1), "A": _derived(1, A=1),
    "K": _derived(1, K=1), "mol": _derived(1, mol=1), "cd": _derived(1, cd=1),
    "g": _derived(1e-3, kg=1), "rad": _derived(1), "sr": _derived(1),
    "Hz": _derived(1, s=-1), "N": _derived(1, kg=1, m=1, s=-2),
    "Pa": _derived(1, kg=1, m=-1, s=-2), "J": _derived(1, kg=1, m=2, s=-2),
    "W": _derived(1, kg=1, m=2, s=-3), "C": _derived(1, s=1, A=1),
    "V": _derived(1, kg=1, m=2, s=-3, A=-1), "F": _derived(1, kg=-1, m=-2, s=4, A=2),
    "Ohm": _derived(1, kg=1, m=2, s=-3, A=-2), "S": _derived(1, kg=-1, m=-2, s=3, A=2),
    "Wb": _derived(1, kg=1, m=2, s=-2, A=-1), "T": _derived(1, kg=1, s=-2, A=-1),
    "H": _derived(1, kg=1, m=2, s=-2, A=-2), "lm": _derived(1, cd=1),
    "lx": _derived(1, m=-2, cd=1), "Bq": _derived(1, s=-1), "Gy": _derived(1, m=2, s=-2),
    "Sv": _derived(1, m=2, s=-2), "kat": _derived(1, s=-1, mol=1),
    # Outside the SI, accepted with it (and used by the Modelica Standard Library).
    "min": _derived(60, s=1), "h": _derived(3600, s=1), "d": _derived(86400, s=1),
    "l": _derived(1e-3, m=3), "L": _derived(1e-3, m=3), "bar": _derived(1e5, kg=1, m=-1,
                                                                        s=-2),
    "deg": _derived(math.pi / 180), "rev": _derived(2 * math.pi),
    "degC": _derived(1, K=1), "eV": _derived(1.602176634e-19, kg=1, m=2, s=-2),
}

PREFIXES = {
    "Y": 1e24, "Z": 1e21, "E": 1e18, "P": 1e15, "T": 1e12, "G": 1e9, "M": 1e6,
    "k": 1e3, "h": 1e2, "da": 1e1, "d": 1e-1, "c": 1e-2, "m": 1e-3, "u": 1e-6,
    "\u00b5": 1e-6, "n": 1e-9, "p": 1e-12, "f": 1e-15, "a": 1e-18, "z": 1e-21, "y": 1e-24,
}

_TOKEN = re.compile(r"\s*(?:(?P<op>[./()])|(?P<word>[^\W\d_]+)(?P<exp>[+-]?\d+)?"
                    r"|(?P<one>1)(?![\d]))")


class UnitSyntaxError(ValueError):
    """A unit string springc cannot read (its variables are then left unchecked)."""


@functools.lru_cache(maxsize=4096)
def parse_unit(text: str) -> Unit | None:
    """The unit written as ``text`` (``None`` for ``""``: no unit given);
    :class:`UnitSyntaxError` when it is not a unit expression springc knows."""
    if not text.strip():
        return None
    tokens = _tokens(text)
    unit, rest = _expression(tokens)
    if rest:
        raise UnitSyntaxError(f"unexpected '{rest[0][1]}' in unit '{text}'")
    return Unit(unit.dims, unit.scale, text.strip())


def _tokens(text: str) -> list[tuple[str, str, int]]:
    out: list[tuple[str, str, int]] = []
    pos = 0
    text = text.rstrip()
    while pos < len(text):
        match = _TOKEN.match(text, pos)
        if match is None:
            raise UnitSyntaxError(f"unexpected '{text[pos:].strip()[:1]}' in unit '{text}'")
        if match["op"]:
            out.append(("op", match["op"], 1))
        elif match["word"]:
            out.append(("word", match["word"], int(match["exp"] or 1)))
        else:
            out.append(("one", "1", 1))
        pos = match.end()
    return out


Tokens = list[tuple[str, str, int]]


def _expression(tokens: Tokens) -> tuple[Unit, Tokens]:
    unit, tokens = _product(tokens)
    while tokens and tokens[0][1] == "/":
        divisor, tokens = _factor(tokens[1:])
        unit = unit / divisor
    return unit, tokens


def _product(tokens: Tokens) -> tuple[Unit, Tokens]:
    unit, tokens = _factor(tokens)
    while tokens and tokens[0][1] == ".":
        factor, tokens = _factor(tokens[1:])
        unit = unit * factor
    return unit, tokens


def _factor(tokens: Tokens) -> tuple[Unit, Tokens]:
    if not tokens:
        raise UnitSyntaxError("a unit factor is missing")
    kind, value, exponent = tokens[0]
    if kind == "one":
        return ONE, tokens[1:]
    if value == "(":
        unit, rest = _expression(tokens[1:])
        if not rest or rest[0][1] != ")":
            raise UnitSyntaxError("a ')' is missing")
        return unit, rest[1:]
    if kind != "word":
        raise UnitSyntaxError(f"unexpected '{value}'")
    powered = _operand(value).power(Fraction(exponent))
    assert powered is not None  # an integer power
    return powered, tokens[1:]


def _operand(word: str) -> Unit:
    """A unit symbol, or a prefix and a symbol (the symbol is tried first)."""
    if word in SYMBOLS:
        scale, dims = SYMBOLS[word]
        return Unit(dims, scale)
    for size in (2, 1):
        prefix, symbol = word[:size], word[size:]
        if prefix in PREFIXES and symbol in SYMBOLS:
            scale, dims = SYMBOLS[symbol]
            return Unit(dims, scale * PREFIXES[prefix])
    raise UnitSyntaxError(f"unknown unit symbol '{word}'")


def canonical(unit: Unit) -> str:
    """The unit in SI base units, as Modelica writes it: ``kg.m/s2``, ``1/s``, ``1``
    (a scale other than 1 is written before it: ``0.001*m``)."""
    top = [_power(b, e) for b, e in zip(BASE, unit.exponents) if e > 0]
    bottom = [_power(b, -e) for b, e in zip(BASE, unit.exponents) if e < 0]
    text = ".".join(top) or "1"
    if bottom:
        below = ".".join(bottom)
        text += f"/({below})" if len(bottom) > 1 else f"/{below}"
    if not math.isclose(unit.scale, 1.0, rel_tol=1e-9):
        text = f"{unit.scale:g}*{text}"
    return text


def _power(base: str, exponent: Fraction) -> str:
    if exponent == 1:
        return base
    if exponent.denominator == 1:
        return f"{base}{exponent.numerator}"
    return f"{base}({exponent})"
