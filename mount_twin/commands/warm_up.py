"""`mount-twin warm-up`: compile and cache the kernels now, not at the first replay or start.

numba compiles the twin's kernels on first use (20–60 s on a small machine) and caches them
beside the sources. `colcon build` runs this after installing (setup.py), so the installed
package starts warm; after `pip install` run it once by hand, or let the first run compile.
"""

from __future__ import annotations

import argparse
import dataclasses
import time

NAME = "warm-up"
HELP = "compile and cache the kernels (colcon build does it; after pip install, optional)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument(
        "scenes",
        nargs="*",
        help="scene YAML files to warm for (default: the bundled scenes, which cover the "
        "kernels' variants: linear mounts only, and with non-linear kinds; each with and "
        "without the error estimate)",
    )


def run(args: argparse.Namespace) -> int:
    from mount_twin.commands.common import load_scene, share_dir
    from mount_twin.replay import kernels_loading
    from mount_twin.stream import TwinStream

    scenes = args.scenes or sorted(str(p) for p in (share_dir() / "config").glob("*.scene.yaml"))
    start = time.perf_counter()
    for path in scenes:
        scene = load_scene(path)
        for estimate in (True, False):  # integration.error_estimate compiles its own variant
            integ = dataclasses.replace(scene.integration, error_estimate=estimate)
            with kernels_loading():  # building the engine loads (or compiles) its kernels
                TwinStream(dataclasses.replace(scene, integration=integ))
        print(f"kernels ready for {path} (with and without the error estimate)")
    print(f"warm-up done in {time.perf_counter() - start:.1f} s")
    return 0
