"""The twin's integrator against scipy's on the same model, side by side in one run.

For a scene and bag, a reference run (the twin at rtol 1e-12, or 1e-10, on the input refined
8×), then per tolerance the largest mount-force error relative to the largest force and the
wall time per simulated second of:

- the twin's engine (`auto` method, no error estimate), and
- scipy's `solve_ivp` (RK45, DOP853, Radau, LSODA) integrating the twin's own compiled
  right-hand side interval by interval (the held input is linear between samples, with a kink
  at each: restarting at each sample is how it is integrated exactly), with the mounts'
  discrete switches applied between samples as the twin does.

Same model, same input, same outputs: only the integration differs. scipy pays a Python call
per right-hand side and a restart per sample; that is the point of comparing.

    python3 bench/peers.py [--scene config/pump_8_mounts.scene.yaml --bag bags/ship_motion_1khz]
        [--seconds 2] [--rtol 1e-4 1e-6 1e-8] [--max-substeps 1000000]

MuJoCo is not here: it has no six-axis bushing (a mount would be three spatial tendons, whose
force follows their length, not the mount's axes, and no rotational stiffness), and no bolted
joint, slip or key clearance, so the bundled scenes cannot be posed to it as they are.
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.integrate import solve_ivp

from mount_twin.analysis.accuracy import conditioned, measure, reference_run
from mount_twin.engine.batch import SampleBatch
from mount_twin.io.input_samples import read_samples
from mount_twin.kinds import N_EVENTS
from mount_twin.model.assemble import assemble, initial_state
from mount_twin.physics import pose_row
from mount_twin.physics.dynamics import INPUT_SIZE, evaluate, mount_monitors, rhs
from mount_twin.scene.description import Scene
from mount_twin.scene.loader import load_scene_file


def scipy_run(scene: Scene, samples: SampleBatch, method: str, rtol: float) -> np.ndarray:
    """Mount wrenches (k, n_mounts, 6) at the samples, the twin's model integrated by scipy."""
    model = assemble(scene)
    arrays, scratch = model.arrays, model.new_scratch()
    t = samples.stamps
    f, w = samples.accel @ model.sensor_rotation.T, samples.gyro @ model.sensor_rotation.T
    if not scene.input.includes_gravity:
        f = f + np.array([0.0, 0.0, scene.input.g])
    y = initial_state(model, f[0], w[0])
    u = np.zeros(INPUT_SIZE)
    out = np.zeros(y.shape[0])
    wrenches = np.zeros((t.shape[0], model.n_mounts, 6))
    pose = np.zeros(pose_row.WIDTH)
    evaluate(y, arrays, scratch, pose, wrenches[0])
    nl = arrays.nl
    g = np.full((0 if nl is None else nl.kind.shape[0], N_EVENTS), -1.0)
    util = np.zeros(g.shape[0])
    if nl is not None:
        mount_monitors(y, y, nl, scratch, g, util)

    def f_rhs(time_s: float, state: np.ndarray) -> np.ndarray:
        rhs(time_s, state, arrays, scratch, u, out)
        return out.copy()

    for j in range(1, t.shape[0]):
        dt = t[j] - t[j - 1]
        u[0], u[1:4], u[4:7] = t[j - 1], f[j - 1], (f[j] - f[j - 1]) / dt
        u[7:10], u[10:13] = w[j - 1], (w[j] - w[j - 1]) / dt
        sol = solve_ivp(f_rhs, (t[j - 1], t[j]), y, method=method, rtol=rtol, atol=rtol * 1e-3)
        if not sol.success:
            msg = f"scipy {method} failed at {t[j]:.6f} s: {sol.message}"
            raise RuntimeError(msg)
        y_prev, y = y, sol.y[:, -1].copy()
        evaluate(y, arrays, scratch, pose, wrenches[j])
        if nl is not None:
            mount_monitors(y, y_prev, nl, scratch, g, util)
    return wrenches


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="config/pump_8_mounts.scene.yaml")
    parser.add_argument("--bag", default="bags/ship_motion_1khz")
    parser.add_argument("--seconds", type=float, default=2.0, help="of the record, from its start")
    parser.add_argument("--rtol", type=float, nargs="+", default=[1e-4, 1e-6, 1e-8])
    parser.add_argument("--methods", nargs="+", default=["RK45", "DOP853", "Radau", "LSODA"])
    parser.add_argument("--max-substeps", type=int, default=100_000)
    args = parser.parse_args()
    loaded = load_scene_file(args.scene)
    full = read_samples(args.bag, loaded.input)
    keep = full.stamps - full.stamps[0] <= args.seconds
    cut = SampleBatch(
        full.stamps[keep], full.accel[keep], full.gyro[keep], list(np.array(full.frame_ids)[keep])
    )
    scene, samples = conditioned(loaded, cut)
    duration = float(samples.stamps[-1] - samples.stamps[0])
    ref = reference_run(scene, samples, args.max_substeps)
    want = ref.out.wrenches[:, :, :3]
    scale = np.abs(want).max()
    print(f"{scene.name} on {args.bag}, {duration:.3f} s; reference at rtol {ref.rtol:g}")
    print(f"{'integrator':<16} {'rtol':>6} {'force err':>10} {'wall s/s':>9} {'vs twin':>8}")
    for rtol in args.rtol:
        twin = measure(scene, samples, rtol, args.max_substeps, ref)
        print(
            f"{'twin (auto)':<16} {rtol:>6.0e} {twin.force_error:>10.2e} "
            f"{twin.wall_s_per_sim_s:>9.4f} {1.0:>7.1f}×",
            flush=True,
        )
        for method in args.methods:
            t0 = time.perf_counter()
            got = scipy_run(scene, samples, method, rtol)
            wall = (time.perf_counter() - t0) / duration
            err = np.abs(got[:, :, :3] - want).max() / scale
            ratio = wall / twin.wall_s_per_sim_s
            print(
                f"{'scipy ' + method:<16} {rtol:>6.0e} {err:>10.2e} {wall:>9.4f} {ratio:>7.1f}×",
                flush=True,
            )


if __name__ == "__main__":
    main()
