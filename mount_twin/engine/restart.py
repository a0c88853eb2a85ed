"""The state a (re)start begins from: the machine's own static equilibrium, damaged or not.

A restart (a gap, a stamp jumping back, a stepper failure) discards the motion but keeps the
mounts' damage: a broken bolt stays broken, a yielded one stretched. What it resets is the
kinds' `RESTUCK` states (a friction face's stick point, relative to the discarded pose), which
the start then settles at its own pose (`model.assemble.settle`: a face that slid there on its
friction bound). The machine as it is then starts at rest in its own equilibrium: under the
start specific force, else (a restart inside a shock) under nominal gravity. A damaged machine
may have none (nothing holds it any more, e.g. a machine hanging from bolts that broke): then
there is no state to start from, and the twin publishes nothing rather than a pose it is not
in.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mount_twin.errors import ModelError
from mount_twin.kinds import KINDS
from mount_twin.model.assemble import Model, initial_state


@dataclass(frozen=True)
class Start:
    """Where a start begins.

    Attributes:
        state: the start state; None where the machine has no static equilibrium.
        note: why it is not the equilibrium under the start specific force (a fallback on
            nominal gravity), or why there is none (state None); None: nothing to say.
    """

    state: np.ndarray | None
    note: str | None = None


def restuck(model: Model, internal: np.ndarray) -> np.ndarray:
    """`internal` (the mounts' internal states, in state order) with each kind's `RESTUCK`
    states set to zero."""
    offset = 2 * len(model.scene.dofs)
    out = internal.copy()
    index = {name: i - offset for i, name in enumerate(model.state_names)}
    for mount in model.scene.mounts:
        kind = KINDS.get(mount.kind)  # None: a linear mount, without states
        for state in kind.RESTUCK if kind else ():
            out[index[f"{mount.name}.{state}"]] = 0.0
    return out


def start_state(
    model: Model,
    nominal: np.ndarray,
    gravity_up: np.ndarray,
    f0: np.ndarray,
    w0: np.ndarray,
    internal: np.ndarray | None,
) -> Start:
    """The start state of `model` with the mounts' internal states `internal` (None: a new
    machine, whose nominal-gravity equilibrium is `nominal`), at rest under the start specific
    force f0 (m/s², F) turning at w0 (rad/s, F) where the scene starts at equilibrium under
    the first samples; else, or where no equilibrium holds under f0, under `gravity_up`."""
    init = model.scene.initial
    if init.mode == "given":  # the given motion, whatever the mounts' states
        return Start(initial_state(model, f0, w0, internal))
    kept = None if internal is None else restuck(model, internal)
    note = None
    if init.gravity == "first_sample":
        try:
            return Start(initial_state(model, f0, w0, kept))
        except ModelError as e:
            # Restarting inside a shock, or heeled past what the mounts hold: no equilibrium
            # holds under that load (why, and at which mounts, in e).
            note = (
                f"no static equilibrium under the start specific force "
                f"{np.linalg.norm(f0):.4g} m/s² ({e}): started from rest under nominal gravity"
            )
    if kept is None or not kept.any():
        return Start(nominal.copy(), note)
    try:
        return Start(initial_state(model, gravity_up, None, kept), note)
    except ModelError as e:
        return Start(None, f"the machine as damaged has no static equilibrium ({e})")
