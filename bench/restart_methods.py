"""`auto` at a restart onto a pressed snubber: what it chooses, and the methods there.

The `heeled_onto_a_snubber` case of test/test_error_estimate.py: 5 kg on soft mounts beside a
snubber 1 mm off, at 100 Hz, upright, then after a gap (a restart) heeled onto the snubber,
which the restart's equilibrium presses (no contact is logged). Per snubber stiffness (N/m)
and rtol: the method `auto` chooses at the restart, then each method over the heeled part
alone (a fresh start there puts the twin in the restart's state: checked, the outputs the
same bit for bit), its mount-force error against a reference (the same twin at rtol 1e-12 on
the input refined 8×), its substeps per sample and real-time factor without the error
estimate. Before `auto` chose at restarts, the first start's method (`dopri54`, upright) went
on after the restart.

    python3 bench/restart_methods.py [--stiffness 1e7 1e8] [--rtol 1e-3 1e-6] [--seconds 3]
"""

from __future__ import annotations

import argparse
import dataclasses
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "test"))

from test_error_estimate import _heeled_onto_a_snubber

from mount_twin.analysis.accuracy import measure, reference_run
from mount_twin.engine.engine import TwinEngine
from mount_twin.model.assemble import assemble


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stiffness", type=float, nargs="+", default=[1e7, 1e8])
    parser.add_argument("--rtol", type=float, nargs="+", default=[1e-3, 1e-6])
    parser.add_argument("--seconds", type=float, default=3.0)
    args = parser.parse_args()
    for stiffness in args.stiffness:
        for rtol in args.rtol:
            scene, model, upright, heeled = _heeled_onto_a_snubber(
                "auto", stiffness, args.seconds, rtol
            )
            engine = TwinEngine(model)
            engine.push(upright)
            restarted = engine.push(heeled)
            fresh = TwinEngine(assemble(scene)).push(heeled)
            same = np.array_equal(restarted.wrenches, fresh.wrenches)
            print(
                f"snubber {stiffness:.0e} N/m, rtol {rtol:.0e}: auto at the restart "
                f"{engine.health.method}; a fresh start the same: {same}"
            )
            ref = reference_run(scene, heeled, 1_000_000)
            for method in ("dopri54", "ros34pw2"):
                integ = dataclasses.replace(scene.integration, method=method)
                a = measure(
                    dataclasses.replace(scene, integration=integ), heeled, rtol, 100_000, ref
                )
                print(
                    f"  {method:<9} force err {a.force_error:.2e}  substeps/sample "
                    f"{a.substeps_per_sample:6.1f}  x real {1 / a.wall_s_per_sim_s:6.1f}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
