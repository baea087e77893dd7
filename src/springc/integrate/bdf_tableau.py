"""BDF's method data (plain data, no springc, no numba): the NDF coefficients ``KAPPA``
of Shampine and Reichelt's ``ode15s`` (scipy's ``BDF``), the sums ``GAMMA`` of
``1 / j``, ``ALPHA`` and the error constants of the orders 1-5. The compiled hooks
(:mod:`.bdf_steps`) and the C loop (:mod:`.native_loop`) read these values.
"""

import numpy as np

MAX_ORDER = 5
NEWTON_MAXITER = 4
KAPPA = np.array([0.0, -0.1850, -1 / 9, -0.0823, -0.0415, 0.0])
GAMMA = np.concatenate((np.zeros(1), np.cumsum(1 / np.arange(1, MAX_ORDER + 1))))
ALPHA = (1 - KAPPA) * GAMMA
ERROR_CONST = KAPPA * GAMMA + 1 / np.arange(1, MAX_ORDER + 2)
