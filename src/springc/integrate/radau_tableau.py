"""Radau IIA of order 5 (3 stages): the published method data (plain data, no springc).

E. Hairer, G. Wanner, *Solving Ordinary Differential Equations II* (2nd ed., Sec. IV.8):
the collocation nodes ``C``, the eigenvalues of the inverse Runge-Kutta matrix (one real
``MU_REAL``, a complex pair ``MU_COMPLEX``), the transformation ``T`` (and its inverse
``TI``) that turns the 3n x 3n Newton system into one real and one complex n x n system,
the embedded error estimate ``E`` and the dense output ``P`` (the collocation polynomial
in powers of the step fraction). The values are those of ``radau5.f`` (and scipy's
``Radau``, which the tests compare).
"""

import numpy as np

S6 = 6 ** 0.5
C = np.array([(4 - S6) / 10, (4 + S6) / 10, 1.0])
E = np.array([-13 - 7 * S6, -13 + 7 * S6, -1.0]) / 3
MU_REAL = 3 + 3 ** (2 / 3) - 3 ** (1 / 3)
MU_COMPLEX = (3 + 0.5 * (3 ** (1 / 3) - 3 ** (2 / 3))
              - 0.5j * (3 ** (5 / 6) + 3 ** (7 / 6)))
T = np.array([
    [0.09443876248897524, -0.1412552950209542, 0.03002919410514742],
    [0.2502131229653333, 0.20412935229379994, -0.3829421127572619],
    [1.0, 1.0, 0.0]])
TI = np.array([
    [4.178718591551904, 0.32768282076106237, 0.5233764454994495],
    [-4.178718591551904, -0.32768282076106237, 0.47662355450055044],
    [0.5028726349457868, -2.571926949855605, 0.5960392048282249]])
TI_REAL = TI[0].copy()
TI_COMPLEX = TI[1] + 1j * TI[2]
P = np.array([
    [13 / 3 + 7 * S6 / 3, -23 / 3 - 22 * S6 / 3, 10 / 3 + 5 * S6],
    [13 / 3 - 7 * S6 / 3, -23 / 3 + 22 * S6 / 3, 10 / 3 - 5 * S6],
    [1 / 3, -8 / 3, 10 / 3]])
NEWTON_MAXITER = 6
