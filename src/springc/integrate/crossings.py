"""Zero crossings against held signs, compiled (shared by the kernels of every method).

A model's zero-crossing function ``g(t, x, p, z) -> float64[::1]`` has one indicator per
relation. The caller holds a sign per indicator (``signs[i]`` = +1 or -1, the side the
model currently assumes) and a direction filter (``directions[i]``: +1 rising only, -1
falling only, 0 both). Indicator ``i`` crosses over an interval when it starts on its held
side or on zero (``signs[i] * g_start[i] >= 0``) and ends strictly on the other
(``signs[i] * g_end[i] < 0``), in an allowed direction. An indicator that starts on the
wrong side (rounding at the restart after an event, ``g = -1e-17`` held +1) therefore
fires only once it has come back to its held side and left it again.
"""

import numpy as np

from .arrays import internal

#: the located crossing time is the right end of a bracket at most this wide, relative
#: to max(|t|, step)
EVENT_TIME_TOLERANCE = 1e-12


@internal
def crossings(g_start: np.ndarray, g_end: np.ndarray, signs: np.ndarray,
              directions: np.ndarray, fired: np.ndarray) -> bool:
    """Whether some indicator crossed from ``g_start`` to ``g_end``; ``fired[i]`` is set
    to the direction of indicator ``i``'s crossing (+1 rising, -1 falling) or 0."""
    any_fired = False
    for i in range(signs.size):
        s = signs[i]
        fired[i] = 0
        if s * g_start[i] >= 0.0 and s * g_end[i] < 0.0 \
                and (directions[i] == 0.0 or directions[i] == -s):
            fired[i] = 1 if s < 0 else -1
            any_fired = True
    return any_fired


@internal
def time_tolerance(t: float, t_new: float) -> float:
    """The bracket width at which a crossing between ``t`` and ``t_new`` counts as located."""
    width = EVENT_TIME_TOLERANCE * max(abs(t), abs(t_new), t_new - t)
    ulp: float = np.nextafter(abs(t_new), np.inf) - abs(t_new)
    return max(width, 4.0 * ulp)
