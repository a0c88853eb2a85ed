"""The layout of a pose row, the one place that says it: the compiled `dynamics.outputs` writes
rows in it and every reader (engine, encoders, replay, plots) takes its columns from here.

A row holds the CG position in F (m), the quaternion (x, y, z, w) of R (body → F) and the chart
angles (α, γ, δ) rad. The core writes rows in it (`mt::pose_row` in src/core/constants.hpp:
test/test_core_contract.py holds the two equal).
"""

from __future__ import annotations

POSITION, QUATERNION, ANGLES, WIDTH = 0, 3, 7, 10
"""First column of each part, and the row's width."""

POSITION_COLS = slice(POSITION, POSITION + 3)
QUATERNION_COLS = slice(QUATERNION, QUATERNION + 4)
ANGLES_COLS = slice(ANGLES, ANGLES + 3)
POSE_COLS = slice(POSITION, QUATERNION + 4)
"""Position and quaternion together: a geometry_msgs/Pose or a Transform."""

assert ANGLES + 3 == WIDTH and QUATERNION + 4 == ANGLES and POSITION + 3 == QUATERNION
