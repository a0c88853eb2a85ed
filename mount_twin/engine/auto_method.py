"""`integration.method: auto`: the method a scene takes, chosen at the first sample interval and
looked at again after mount events.

The rule is `integrate.methods.choose`: ρ·Δt, the spectral radius of the Jacobian (rad/s) times
the sample interval (s), against what an explicit method can step, and whether the mounts
switch. ρ is taken at the nominal start state before the first interval, and again at the
state of a sample that logged a mount event (a key closing, a joint opening, a bolt breaking:
the scene's stiffness changes with them), at most once per REEXAMINE_S of record time. The
compiled loop ends a run at such a sample (`engine.kernel.AT_EVENT`), so a live node pushing one
sample at a time and a replay pushing thousands make the same choices at the same samples.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from mount_twin.engine.batch import MountEvent
from mount_twin.errors import ModelError
from mount_twin.integrate.methods import choose
from mount_twin.model.assemble import Model
from mount_twin.model.stiffness import spectral_radius

REEXAMINE_S = 0.01
"""Record time (s) after a look at the scene before a mount event prompts the next: a joint
slipping in stick–slip logs events at the sample rate, and each look costs an eigenproblem."""


@dataclass(frozen=True)
class Choice:
    """A method for the scene (a name of `integrate.methods.METHODS`) and why, as the
    integration status says it."""

    method: str
    why: str

    @property
    def status(self) -> str:
        """e.g. `exprb32 (auto: ρ·Δt = 31.6)`."""
        return f"{self.method} (auto: {self.why})"


def at_start(model: Model, rho_start: float, interval_s: float) -> Choice:
    """The choice at the first sample interval (s), from ρ at the nominal start (rad/s)."""
    rho_dt = rho_start * interval_s
    return Choice(choose(rho_dt, smooth=model.arrays.nl is None), f"ρ·Δt = {rho_dt:.3g}")


def after_event(
    model: Model, y: np.ndarray, specific_force: np.ndarray, interval_s: float, event: MountEvent
) -> Choice | None:
    """The choice at state y under the sample's specific force (m/s², F) after `event`; None
    where ρ cannot be taken (the state at the α/γ/δ chart's edge): the method stays."""
    try:
        rho = spectral_radius(model, y, specific_force)
    except ModelError:
        return None
    if not math.isfinite(rho):
        return None
    rho_dt = rho * interval_s
    method = choose(rho_dt, smooth=model.arrays.nl is None)
    return Choice(method, f"ρ·Δt = {rho_dt:.3g} after {event.event} of {event.mount}")
