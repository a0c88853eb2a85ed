"""Cost of one right-hand-side evaluation and of one output evaluation, per scene.

    python3 bench/bench_rhs.py

Times `dynamics.rhs` and `dynamics.evaluate` in a compiled loop (no Python call per
evaluation) for the default linear scene and the bolted, keyed genset: the linear scene must
not pay for the mount kinds it does not use.
"""

from __future__ import annotations

import time

import numpy as np
from numba import njit

from mount_twin.commands.common import share_dir
from mount_twin.model.assemble import assemble, gravity_input, initial_state
from mount_twin.physics.dynamics import evaluate, rhs
from mount_twin.scene.loader import load_scene_file

SCENES = ("pump_8_mounts.scene.yaml", "genset_bolted_keyed.scene.yaml")
CALLS = 200_000


@njit
def _rhs_loop(n, y, m, s, u, dydt):
    acc = 0.0
    for _ in range(n):
        y[0] += 1e-12  # a new state each call: nothing to hoist out of the loop
        rhs(0.0, y, m, s, u, dydt)
        acc += dydt[-1]
    return acc


@njit
def _evaluate_loop(n, y, m, s, pose, wrenches):
    acc = 0.0
    for _ in range(n):
        y[0] += 1e-12
        acc += evaluate(y, m, s, pose, wrenches)
    return acc


def main() -> None:
    """Print µs per call for each scene."""
    for name in SCENES:
        model = assemble(load_scene_file(share_dir() / "config" / name))
        g = np.array([0.0, 0.0, model.scene.input.g])
        y = initial_state(model, g)
        s, u, dydt = model.new_scratch(), gravity_input(0.0, g), np.zeros(model.n_state)
        pose, wrenches = np.zeros(10), np.zeros((model.n_mounts, 6))
        _rhs_loop(10, y, model.arrays, s, u, dydt)
        _evaluate_loop(10, y, model.arrays, s, pose, wrenches)
        t0 = time.perf_counter()
        _rhs_loop(CALLS, y, model.arrays, s, u, dydt)
        t1 = time.perf_counter()
        _evaluate_loop(CALLS, y, model.arrays, s, pose, wrenches)
        t2 = time.perf_counter()
        print(
            f"{model.scene.name}: {model.n_mounts} mounts, {model.n_state} states: "
            f"rhs {(t1 - t0) / CALLS * 1e6:.2f} µs, evaluate {(t2 - t1) / CALLS * 1e6:.2f} µs"
        )


if __name__ == "__main__":
    main()
