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

from mount_twin import _core

STEP = _core.CENTRAL_STEP
"""Central-difference step, relative to max(1, |y_c|) (1e-7)."""


central_columns = _core.central_columns
"""central_columns(y, t, m, s, u, plus, minus, jac) -> bool: jac[:, c] = ∂(dy/dt)/∂y_c at
(t, y) under the input u, for the first jac.shape[1] columns c, by central differences of step
STEP·max(1, |y_c|); plus, minus: (n,) work. y is left as it was. False if an evaluation failed
(the α/γ/δ chart's edge): jac is then incomplete."""
