"""Past the chart's limit the twin never replays an old motion: a scene with a given initial
motion whose stepper fails stops following (no pose, angles or wrenches) and says so at ERROR in
every report, until the record restarts; a scene started at equilibrium restarts there."""

from __future__ import annotations

import numpy as np
from io_helpers import batch
from physics_helpers import free_body

from mount_twin.engine.batch import ERROR
from mount_twin.engine.engine import TwinEngine
from mount_twin.model.assemble import assemble
from mount_twin.scene.loader import scene_from_dict

OMEGA0 = np.array([4.0, 0.3, 0.5])  # rad/s in B, about the axis of least inertia: tips over


def _tumbling_engine() -> TwinEngine:
    data = free_body([2.0, 3.0, 4.0, 0.0, 0.0, 0.0], OMEGA0)
    data["outputs"] = {"diagnostics_period_s": 0.5}
    return TwinEngine(assemble(scene_from_dict(data, "<tumble>")))


def _integration_status(report):
    (s,) = [s for s in report.statuses if s.name == "mount_twin: integration"]
    return s


def test_a_given_motion_past_the_chart_stops_and_is_not_replayed() -> None:
    engine = _tumbling_engine()
    free_fall = np.zeros((2000, 3))  # specific force 0: torque-free
    out = engine.push(batch(1.0 + np.arange(2000) * 1e-3, free_fall, frame_ids=""))
    assert engine.counts["integration_failures"] == 1
    followed = len(out)
    assert 10 < followed < 2000
    tilt_end = np.degrees(
        np.arccos(1 - 2 * (out.quaternion[-1, 0] ** 2 + out.quaternion[-1, 1] ** 2))
    )
    assert tilt_end > 60.0, "it stopped while tipping over, not somewhere at rest"
    assert engine.counts["samples_not_followed"] == 2000 - followed - 1  # the failing sample
    assert engine.counts["restarts"] == 0 and not engine.running
    later = engine.push(batch(3.0 + np.arange(100) * 1e-3, np.zeros((100, 3)), frame_ids=""))
    assert len(later) == 0
    reports = [*out.health, *later.health]
    after = [r for r in reports if r.stamp > out.stamps[-1]]
    assert after and all(_integration_status(r).level == ERROR for r in after)
    assert all("not following since" in _integration_status(r).message for r in after)


def test_a_restart_of_the_record_follows_again() -> None:
    engine = _tumbling_engine()
    engine.push(batch(1.0 + np.arange(2000) * 1e-3, np.zeros((2000, 3)), frame_ids=""))
    again = engine.push(batch(1.0 + np.arange(50) * 1e-3, np.zeros((50, 3)), frame_ids=""))
    assert len(again) == 50 and engine.counts["reset_stamp_jumped_back"] == 1
