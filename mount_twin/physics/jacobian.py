"""∂f/∂y of the compiled right-hand side by central differences, column by column, in one
compiled call: the model's stiffness (`model.stiffness`, `auto`'s spectral radius) and the start
equilibrium's Newton steps. From Python, each right-hand side was a call that unboxed the
model's and the scratch's arrays (~10 µs); the genset's 24 columns for `auto` took 0.3 ms.

The steppers' Jacobian (`integrate.fd_jacobian`) is another one on purpose: forward
differences, n + 1 evaluations with ∂f/∂t, into rows of a stepper's work array and taken at
every renewal; these are occasional, central (second-order accurate, for eigenvalues and the
equilibrium's Newton steps) and return a plain matrix.
"""

from __future__ import annotations

import numpy as np

from mount_twin.physics.compiled import kernel
from mount_twin.physics.dynamics import OK, ModelArrays, Scratch, rhs

STEP = 1.0e-7
"""Central-difference step, relative to max(1, |y_c|)."""


@kernel
def central_columns(
    y: np.ndarray,
    t: float,
    m: ModelArrays,
    s: Scratch,
    u: np.ndarray,
    plus: np.ndarray,
    minus: np.ndarray,
    jac: np.ndarray,
) -> bool:
    """jac[:, c] = ∂(dy/dt)/∂y_c at (t, y) under the input u, for the first jac.shape[1]
    columns c; plus, minus: (n,) work. y is left as it was. False if an evaluation failed (the
    α/γ/δ chart's edge): jac is then incomplete."""
    n = y.shape[0]
    for c in range(jac.shape[1]):
        keep = y[c]
        h = STEP * max(1.0, abs(keep))
        y[c] = keep + h
        up = y[c]
        ok = rhs(t, y, m, s, u, plus) == OK
        y[c] = keep - h
        down = y[c]
        ok = ok and rhs(t, y, m, s, u, minus) == OK
        y[c] = keep
        if not ok:
            return False
        for r in range(n):
            jac[r, c] = (plus[r] - minus[r]) / (up - down)
    return True
