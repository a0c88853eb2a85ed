"""Sweep throughput: cases per minute through `mount-twin sweep` on a local Dask cluster with one
and with two workers, against a loop of `mount-twin replay` processes over the same cases.

    python3 bench/bench_sweep.py [--cases-cli 4]

The sweep: the bundled pump, mount stiffness × 0.5 … 2 (8 values) × mass 1000 … 1387.5 kg (32),
against the bundled 0.4 s, 10 kHz half-sine bag: 256 cases. The CLI loop replays the first
`--cases-cli` of them, each from its own scene file, writing its output bag as `replay` does.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml
from dask.distributed import LocalCluster

from mount_twin.commands.common import share_dir
from mount_twin.sweeps.cases import apply, check
from mount_twin.sweeps.runner import run_sweep
from mount_twin.sweeps.spec import load_sweep

SCALES = [0.5, 0.6, 0.75, 0.9, 1.1, 1.3, 1.6, 2.0]
MASSES = [1000.0 + 12.5 * k for k in range(32)]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--cases-cli", type=int, default=4)
    args = parser.parse_args()
    share = share_dir()
    bag = share / "bags" / "half_sine_shock_10khz"
    with tempfile.TemporaryDirectory(prefix="bench_sweep_") as tmp_name:
        tmp = Path(tmp_name)
        sweep_file = tmp / "sweep.yaml"
        sweep_file.write_text(
            yaml.safe_dump(
                {
                    "base": str(share / "config" / "pump_8_mounts.scene.yaml"),
                    "vary": [
                        {"key": "mounts[*].stiffness", "scale": SCALES},
                        {"key": "body.mass", "values": MASSES},
                    ],
                    "inputs": [{"bag": str(bag)}],
                }
            ),
            encoding="utf-8",
        )
        spec = load_sweep(sweep_file)
        cases = check(spec)
        t0 = time.perf_counter()
        for i, case in enumerate(cases[: args.cases_cli]):
            scene = tmp / f"case{i}.scene.yaml"
            scene.write_text(yaml.safe_dump(apply(spec.base, case.settings)), encoding="utf-8")
            cmd = [
                "mount-twin",
                "replay",
                str(bag),
                "--scene",
                str(scene),
                "-o",
                str(tmp / f"o{i}"),
            ]
            subprocess.run([*cmd, "--no-progress"], check=True, capture_output=True)
        cli = (time.perf_counter() - t0) / args.cases_cli
        print(f"{len(cases)} cases; CLI loop: {cli:.2f} s per case ({60 / cli:.1f} cases/min)")
        per_worker = {}
        for workers in (1, 2):
            t0 = time.perf_counter()
            with LocalCluster(
                n_workers=workers, threads_per_worker=1, processes=True, dashboard_address=None
            ) as cluster:
                started = time.perf_counter()
                rows = run_sweep(
                    spec, tmp / f"r{workers}.csv", scheduler=cluster.scheduler_address
                )
                wall = time.perf_counter() - started
            total = time.perf_counter() - t0
            assert len(rows) == len(cases)
            per_worker[workers] = wall
            print(
                f"sweep, {workers} worker(s): {wall:.2f} s for {len(cases)} cases "
                f"({60 * len(cases) / wall:.0f} cases/min, {cli * len(cases) / wall:.1f}× the "
                f"CLI loop); with the cluster's start and stop {total:.2f} s "
                f"({cli * len(cases) / total:.1f}×)"
            )
        print(f"one → two workers: {per_worker[1] / per_worker[2]:.2f}× faster")


if __name__ == "__main__":
    sys.exit(main())
