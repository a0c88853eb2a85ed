"""How stiff a model is where it starts: the spectral radius of its Jacobian.

The Jacobian ∂f/∂y of the compiled right-hand side at a state and input, by forward
differences (√ε relative steps), and the largest |λ| of its eigenvalues (rad/s): the fastest
mode's rate. `integrate.methods.choose` compares ρ·Δt with an explicit method's stability.
"""

from __future__ import annotations

import numpy as np

from mount_twin.model.assemble import Model
from mount_twin.physics.dynamics import INPUT_SIZE, rhs

STEP = 1.4901161193847656e-08
"""√ε: the relative finite-difference step (of |y_i|, or of 1e-3 where y_i is smaller)."""


def jacobian(model: Model, y: np.ndarray, specific_force: np.ndarray) -> np.ndarray:
    """∂f/∂y (n × n) at state y under a constant specific force (m/s², F), foundation at rest
    otherwise. Raises ValueError off the α/γ/δ chart."""
    u = np.zeros(INPUT_SIZE)
    u[1:4] = specific_force
    n, scratch = y.shape[0], model.new_scratch()
    f0, f = np.zeros(n), np.zeros(n)
    if rhs(0.0, y, model.arrays, scratch, u, f0) != 0:
        msg = "the state is off the α/γ/δ chart: no Jacobian"
        raise ValueError(msg)
    jac = np.empty((n, n))
    for c in range(n):
        probe = y.copy()
        probe[c] += STEP * max(abs(y[c]), 1e-3)
        step = probe[c] - y[c]
        rhs(0.0, probe, model.arrays, scratch, u, f)
        jac[:, c] = (f - f0) / step
    return jac


def spectral_radius(model: Model, y: np.ndarray, specific_force: np.ndarray) -> float:
    """Largest |λ| of `jacobian` (rad/s): the rate of the model's fastest mode at y."""
    return float(np.abs(np.linalg.eigvals(jacobian(model, y, specific_force))).max())
