"""Dormand–Prince 5(4) with error control, advancing across one input-sample interval.

The method is its coefficient table (src/core/integrate/dopri54.hpp holds the same) over the
core's one explicit step (src/core/integrate/explicit_rk.hpp, scipy `integrate/_ivp` shape),
which calls the model's right-hand side directly. The state advances with the 5th-order
solution; the embedded 4th-order one estimates the local error. Error norm: RMS of
err / (atol + rtol·|y|).
"""

from __future__ import annotations

import numpy as np

from mount_twin import _core

C = np.array([0.0, 1 / 5, 3 / 10, 4 / 5, 8 / 9, 1.0, 1.0])
A = np.array(
    [
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [1 / 5, 0.0, 0.0, 0.0, 0.0, 0.0],
        [3 / 40, 9 / 40, 0.0, 0.0, 0.0, 0.0],
        [44 / 45, -56 / 15, 32 / 9, 0.0, 0.0, 0.0],
        [19372 / 6561, -25360 / 2187, 64448 / 6561, -212 / 729, 0.0, 0.0],
        [9017 / 3168, -355 / 33, 46732 / 5247, 49 / 176, -5103 / 18656, 0.0],
        [35 / 384, 0.0, 500 / 1113, 125 / 192, -2187 / 6784, 11 / 84],
    ]
)
B = A[6].copy()
E = np.array([71 / 57600, 0.0, -71 / 16695, 71 / 1920, -17253 / 339200, 22 / 525, -1 / 40])
"""5th-order weights minus the embedded 4th-order weights (the last stage is FSAL)."""
FSAL = True
"""The last stage is evaluated at (t + h, y_new): it is the next step's first."""
ORDER = 4
"""Order of the error estimate (the step-size controller's exponent is −1/(ORDER + 1))."""
MAX_FACTOR = 10.0


advance = _core.dopri54_advance
"""advance(y, t0, t1, settings, m, s, u, k, y_new, result) -> status: Dormand–Prince across one
input interval (src/core/integrate/dopri54.hpp: this table, the same operations in the same
order); y in place, t0, t1 in s, k (7, n) stages, y_new (n,), result [largest accepted error
norm, accepted, rejected substeps]. On success k[0] holds dy/dt at (t1, y) and
settings[CHAINED] is 1."""
