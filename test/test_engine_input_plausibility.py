"""Input plausibility: readings at the sensor's full scale (saturated) and exactly repeated
readings beyond 2 g (a clipped or stuck sensor) are counted per period and flagged WARN."""

from __future__ import annotations

import numpy as np
import pytest
from io_helpers import batch, engine_for, scene_with, split

from mount_twin.engine.batch import OK, WARN

G = 9.80665
N, RATE = 600, 10_000.0
T = 1.0 + np.arange(N) / RATE
PULSE = np.where((T >= 1.01) & (T <= 1.03), 400.0 * np.sin(np.pi * (T - 1.01) / 0.02), 0.0)


def _accel(clip: float | None) -> np.ndarray:
    up = G + PULSE
    if clip is not None:
        up = np.minimum(up, clip)
    return np.column_stack([np.zeros(N), np.zeros(N), up])


def _run(accel: np.ndarray, sizes: list[int] | None = None, **inp: float):
    engine = engine_for(scene_with(input=inp) if inp else None)
    for part in split(batch(T, accel), sizes or [N]):
        engine.push(part)
    (report,) = engine.flush().health
    (status,) = [s for s in report.statuses if s.name == "mount_twin: input"]
    return engine.counts, status


def test_a_clean_shock_is_neither_saturated_nor_a_plateau() -> None:
    counts, status = _run(_accel(None), accel_range_m_s2=500.0)
    assert (counts["saturated"], counts["plateau"], status.level) == (0, 0, OK)


def test_readings_at_the_full_scale_are_counted_as_saturated() -> None:
    """A ±300 m/s² accelerometer clips the 409.8 m/s² peak: every clipped sample counts."""
    accel = _accel(300.0)
    clipped = int((G + PULSE >= 300.0).sum())
    counts, status = _run(accel, accel_range_m_s2=300.0)
    assert counts["saturated"] == clipped > 10
    assert status.level == WARN
    assert f"{clipped} samples at the sensor's range (300 m/s²): clipped" in status.message


def test_a_clipped_top_without_a_declared_range_shows_as_a_plateau() -> None:
    """The same clip, range not declared: the flat top repeats one value exactly (run length
    r gives r − 1 repeats)."""
    clipped = int((G + PULSE >= 300.0).sum())
    counts, status = _run(_accel(300.0))
    assert counts["plateau"] == clipped - 1
    assert counts["saturated"] == 0
    assert status.level == WARN and "repeated exactly" in status.message


@pytest.mark.parametrize("sizes", [[1] * N, [150, 1, 1, 7, 300], [120, 80]])
def test_the_counts_do_not_depend_on_batching(sizes: list[int]) -> None:
    accel = _accel(300.0)
    whole, _ = _run(accel, accel_range_m_s2=300.0)
    parted, _ = _run(accel, sizes, accel_range_m_s2=300.0)
    assert (parted["saturated"], parted["plateau"]) == (whole["saturated"], whole["plateau"])


def test_a_saturated_sample_held_back_at_a_stamp_jump_counts_once() -> None:
    """The one clipped sample arrives last in its push after a 10 ms stamp jump, so it is held
    until the next push confirms the jump: it is one sample at the full scale, counted once
    (not also in the push that held it)."""
    stamps = 1.0 + np.arange(20) / RATE
    stamps[10:] += 0.01  # a jump into sample 10, which the next samples confirm
    accel = np.tile([0.0, 0.0, G], (20, 1))
    accel[10, 2] = 300.0
    engine = engine_for(scene_with(input={"accel_range_m_s2": 300.0}))
    first, rest = split(batch(stamps, accel), [11])
    engine.push(first)
    assert engine.holding  # the jump to confirm: the clipped sample waits
    engine.push(rest)
    engine.flush()
    assert engine.counts["saturated"] == 1
