"""A machine hung from one bolted joint: the scene the start's force-limit and start-switch tests
share (test_start_limits.py, test_start_switches.py write their truths for it).

MASS hangs from one bolted joint (local z down, along the bolt: the weight pulls the foot off
its face) and rests on four vertical springs K at the corners and a vertical key K_KEY under
the CG, all symmetric about the CG, so the body sinks straight down."""

from __future__ import annotations

import math
from typing import Any

from kinds_helpers import kind_mount
from physics_helpers import base_scene, mount

MASS, CG_Z = 400.0, 0.25  # kg, m
K, K_KEY = 2.0e5, 8.0e5  # N/m, each spring and the key along z
K_S, K_P = 1.0e6, 3.0e6  # N/m, the hanger's bolt and its clamped parts
CORNERS = ((0.4, 0.3), (-0.4, 0.3), (-0.4, -0.3), (0.4, -0.3))
BOLT = 5  # the bolt's index in the scene's mounts


def hung_scene(
    preload: float,
    yield_force: float,
    ultimate_force: float,
    key: dict[str, Any],
    rated_load: float = 0.0,
) -> dict[str, Any]:
    """The scene, its bolt preloaded `preload` (N) with those limits (N), the key's own
    settings `key` (clearance, allowable_force), the springs rated `rated_load` (N) along z (0:
    unrated)."""
    springs = [
        {
            **mount(f"s{i}", [x, y, 0.0], [1.0e5, 1.0e5, K, 0.0, 0.0, 0.0]),
            "rated_load": [0.0, 0.0, rated_load],
        }
        for i, (x, y) in enumerate(CORNERS)
    ]
    shear_key = kind_mount("shear_key", "key", stiffness=[0.0, 0.0, K_KEY], **key)
    bolt = kind_mount(
        "bolted_joint",
        "bolt",
        rpy=[math.pi, 0.0, 0.0],  # local z down: the foot lifts off as the body sinks
        bolt_stiffness=K_S,
        clamp_stiffness=K_P,
        preload=preload,
        yield_force=yield_force,
        ultimate_force=ultimate_force,
    )
    mounts = [*springs, shear_key, bolt]
    return base_scene(MASS, [0.0, 0.0, CG_Z], [30.0, 40.0, 50.0, 0, 0, 0], mounts)
