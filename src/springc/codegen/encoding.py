"""Python text of constant arrays and tuples in a generated module: literals when
short, compressed base64 when long (exact for floats; any string survives)."""

from __future__ import annotations

import base64
import json
import zlib
from collections.abc import Sequence

import numpy as np


def encode_floats(values: Sequence[float]) -> str:
    """Python text of a float64 array (exact): compressed base64."""
    data = base64.b64encode(zlib.compress(np.asarray(values, dtype=np.float64).tobytes(), 6))
    return (f"np.frombuffer(zlib.decompress(base64.b64decode({data.decode()!r})), "
            "dtype=np.float64).copy()")


def encode_strings(values: Sequence[str]) -> str:
    """Python text of a tuple of strings (compressed JSON when long: any character of a
    name survives, including newlines)."""
    if len(values) <= 32:
        return repr(tuple(values))
    data = base64.b64encode(zlib.compress(json.dumps(list(values)).encode(), 6))
    return f"tuple(json.loads(zlib.decompress(base64.b64decode({data.decode()!r}))))"


def encode_ints(values: Sequence[int]) -> str:
    """Python text of an int64 array: a literal when short, else compressed base64."""
    if len(values) <= 32:
        return f"np.array({list(values)!r}, dtype=np.int64)"
    data = base64.b64encode(zlib.compress(np.asarray(values, dtype=np.int64).tobytes(), 6))
    return (f"np.frombuffer(zlib.decompress(base64.b64decode({data.decode()!r})), "
            "dtype=np.int64).copy()")
