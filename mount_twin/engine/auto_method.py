"""`integration.method: auto`: the method a scene takes, chosen at the first sample interval and
looked at again after mount events.

The rule is `integrate.methods.choose`: ρ·Δt, the spectral radius of the Jacobian (rad/s) times
the sample interval (s), against what an explicit method can step, and whether the mounts
switch. Before the first interval ρ is the larger of the Jacobian's at the nominal start state
and the rate of the mounts' nominal tangents (`scene.statics`: a shear key counts as bearing,
however wide its clearance), so a light body beside a stiff key starts on the method the key
needs when it closes, not on the one its open clearance allows (5 kg beside a 1e9 N/m key at
1 kHz: 9.8e-4 of the largest force by ros34pw2 from the start, 2.3e-2 by Dormand–Prince until
the key had closed). ρ is taken again at the state of a sample that logged an event that may
stiffen the scene beyond that (a snubber touching: its Hertzian contact has no tangent until it
is pressed), at most once per REEXAMINE_S of record time. The compiled loop ends a run at such
a sample (`engine.kernel.AT_EVENT`), so a live node pushing one sample at a time and a replay
pushing thousands make the same choices at the same samples.
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


TANGENT_MARGIN = 1.05
"""The status names the keys when the tangents' rate is this much above the Jacobian's (on
linear mounts the two differ by the weight's geometric stiffness, a few 1e-3)."""


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


def at_start(model: Model, rho_start: float, rho_tangent: float, interval_s: float) -> Choice:
    """The choice at the first sample interval (s), from ρ at the nominal start and the rate
    of the nominal tangents (rad/s, `Model.tangent_rate`): the larger of the two."""
    rho_dt = max(rho_start, rho_tangent) * interval_s
    bearing = rho_tangent > TANGENT_MARGIN * rho_start
    why = f"ρ·Δt = {rho_dt:.3g}" + (", keys bearing" if bearing else "")
    return Choice(choose(rho_dt, smooth=model.arrays.nl is None), why)


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
