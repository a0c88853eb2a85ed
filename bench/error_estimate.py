"""The live error estimate against the true error, and its cost, per tolerance.

For the cases of test/test_error_estimate.py (a stiff, light body at its stability limit;
hysteretic rubber hitting its snubbers; the bundled pump under ship motion; the bundled bolted,
keyed genset under its 10 kHz shock bag), each rtol's true
mount-force error against a reference run (the same twin at rtol 1e-12 on the input refined
8×), the twin's own estimate of it, their ratio, the attitude errors, substeps per sample, and
the engine's wall time with the estimate over without it (side by side).

    python3 bench/error_estimate.py [--rtol 1e-3 1e-5 1e-7] [--cases NAME ...] [--sampled]
                                    [--repeats N]

Each case's first line gives what its reference resolves (`analysis.accuracy.resolution`); a
ratio marked * is of an error within RESOLVED times that: the reference's own error or
round-off, not the twin's, so no measure of the estimate.

The cost is one run each way; with `--repeats N`, the best of N runs each way, alternating
(short records move by ±0.1 from run to run).

`--sampled` gives every scene the sampled estimator (`engine.estimator`), the non-linear ones
included, which the engine gives the companion (`engine.companion`): how honest and how dear
the cheaper method is where mounts slip, open and hit their stops. `--integrated` has the
companion integrated at every interval, never carried: what the carried error's shortcuts
cost in honesty. The cases `hysteretic_N` (N = 4, 16, 64, 256 Bouc–Wen elastomers on a grid
under the same 200 kg body, together as stiff as four, 2 s of the pump's ship motion: how the
estimate's cost grows with the mounts; their hysteresis the test's, or `--hysteresis BETA
GAMMA`) are run only when named in `--cases`.
"""

from __future__ import annotations

import argparse
import math
import sys
from functools import partial
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "test"))

from test_error_estimate import CASES, _bouc_wen_grid

from mount_twin.analysis.accuracy import RESOLVED, measure, reference_run, resolution, run_at
from mount_twin.engine import companion, driver
from mount_twin.engine.companion import CARRYING, _reset_carry

HYSTERETIC_COUNTS = (4, 16, 64, 256)


def _integrated(carry, method):
    """`companion._reset_carry` with the companion never carried (`--integrated`)."""
    reset = _reset_carry(carry, method)
    reset[CARRYING] = 0.0
    return reset


def _sampled(model, n_watched):
    """The engine's estimate choice with the sampled estimator on every model."""
    return driver.sampled_estimator(model) if model.scene.integration.error_estimate else None


def _best_cost(scene, samples, rtol: float, repeats: int) -> float:
    """Engine wall time with the estimate over without: the best of `repeats` runs each,
    alternating."""
    without = with_it = math.inf
    for _ in range(repeats):
        without = min(without, run_at(scene, samples, rtol, 100_000, False).wall_s)
        with_it = min(with_it, run_at(scene, samples, rtol, 100_000, True).wall_s)
    return with_it / without


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rtol", type=float, nargs="+", default=[1e-3, 1e-4, 1e-5, 1e-6, 1e-7])
    parser.add_argument("--sampled", action="store_true", help="the sampled estimator on all")
    parser.add_argument(
        "--integrated", action="store_true", help="the companion integrated, never carried"
    )
    parser.add_argument(
        "--hysteresis",
        nargs=2,
        type=float,
        default=[],
        metavar=("BETA", "GAMMA"),
        help="Bouc–Wen β and γ of the hysteretic_N cases (default: the test's grid's)",
    )
    builds = {name: build for name, (build, _) in CASES.items()}
    names = [*builds, *(f"hysteretic_{n}" for n in HYSTERETIC_COUNTS)]
    parser.add_argument(
        "--cases",
        nargs="+",
        choices=names,
        metavar="NAME",
        help=f"case names (default: the test's cases): {', '.join(names)}",
    )
    parser.add_argument("--repeats", type=int, default=1, help="runs per cost figure (best)")
    args = parser.parse_args()
    for n in HYSTERETIC_COUNTS:
        builds[f"hysteretic_{n}"] = partial(_bouc_wen_grid, n, *args.hysteresis)
    if args.sampled:
        driver._new_estimator = _sampled  # a bench's what-if: the engine's choice replaced
    if args.integrated:
        companion._reset_carry = _integrated  # a bench's what-if: never carried
    print(
        f"{'case':<20} {'rtol':>6} {'force err':>10} {'estimate':>10} {'ratio':>6} "
        f"{'attitude rad':>12} {'estimate':>10} {'substeps':>8} {'cost':>6}"
    )
    for case in args.cases or list(CASES):
        scene, samples = builds[case]()
        ref = reference_run(scene, samples, 1_000_000)
        res = resolution(scene, samples, 1_000_000, ref)
        print(
            f"{case:<20} the reference resolves {res.force_error:.1e} of the force, "
            f"{res.attitude_error_rad:.1e} rad"
        )
        for rtol in args.rtol:
            a = measure(scene, samples, rtol, 100_000, ref)
            mark = "*" if a.force_error <= RESOLVED * res.force_error else " "
            cost = a.estimate_cost
            if args.repeats > 1:
                cost = _best_cost(scene, samples, rtol, args.repeats)
            print(
                f"{case:<20} {rtol:>6.0e} {a.force_error:>10.2e} {a.est_force_error:>10.2e} "
                f"{a.est_force_error / a.force_error:>6.2f}{mark}{a.attitude_error_rad:>12.2e} "
                f"{a.est_attitude_error_rad:>10.2e} {a.substeps_per_sample:>8.2f} "
                f"{cost:>5.2f}×",
                flush=True,
            )


if __name__ == "__main__":
    main()
