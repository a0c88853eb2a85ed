"""Shock response spectrum speed: record seconds per wall second of `analysis.srs.srs`.

    python3 bench/bench_srs.py [--repeats 5]

10 s of white noise at 10 kHz and 100 natural frequencies from 10 Hz to 1 kHz (the size of a
long shock record's SRS), the best of `--repeats` runs; and the time per frequency, which a
filter per oscillator run over the whole record (the method) keeps flat as frequencies are
added.
"""

from __future__ import annotations

import argparse
import time

import numpy as np

from mount_twin.analysis.srs import srs

RATE_HZ, SECONDS = 10_000.0, 10.0


def best_time(record: np.ndarray, frequencies: np.ndarray, repeats: int) -> float:
    """The best wall time (s) of `repeats` SRS of `record` at `frequencies` (Hz)."""
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        srs(record, RATE_HZ, frequencies)
        best = min(best, time.perf_counter() - t0)
    return best


def main() -> None:
    """Print the speed for 25 and 100 frequencies."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=5, help="runs per figure (best)")
    args = parser.parse_args()
    record = np.random.default_rng(0).normal(size=int(RATE_HZ * SECONDS))
    for count in (25, 100):
        wall = best_time(record, np.geomspace(10.0, 1000.0, count), args.repeats)
        print(
            f"{count:4d} frequencies: {SECONDS / wall:8.1f}x real time "
            f"({wall * 1e3:.1f} ms, {wall / count * 1e3:.2f} ms per frequency)"
        )


if __name__ == "__main__":
    main()
