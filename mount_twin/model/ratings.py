"""The load-time rating check at the start the twin uses, where tangent statics miss it.

`scene.checks` judges each mount's static load and deflection against its ratings by the
statics of the nominal stiffness: exact for linear mounts, and for a non-linear one at zero
load only. A new machine's start at equilibrium is solved with the mounts' own laws
(`model.assemble.static_equilibrium`: force tables, cubic terms, snubbers, clearances, bolted
joints, and hysteretic mounts set down along their loading curves, `model.loading`), and a
law that softens as it loads starts past its tangent's sag: 400 kg on four elastomers whose
force table softens from 1e5 N/m start 14.4 mm down where the tangent says 9.8, past a rated
12 mm that the tangent statics found unreached (on four Bouc–Wen mounts of k₀ = 1e5 N/m,
a = 0.3, β + γ = 200: 21.2 mm), and every mount was then an ERROR from the first report without
a word at load; one that stiffens (cubic terms, a snubber) was warned of where it starts
within. For such a scene (`scene.checks.rated_at_start`) the loader leaves the ratings to this
check, which takes every rated mount's deflection and force at the start state the assembly
solved, and says what it finds as the loader's warnings do (`Scene.warnings`).
"""

from __future__ import annotations

import numpy as np

from mount_twin.kinds.elastomer import Elastomer
from mount_twin.physics.dynamics import ModelArrays, body_motion, mount_wrenches, new_scratch
from mount_twin.physics.rotations import point_displacements, rpy_matrices
from mount_twin.scene.checks import UNITS_OR_MOUNT, rated_at_start, rating_warnings
from mount_twin.scene.description import Scene, SceneWarning

AT_START = "at the start (the weight's equilibrium on the mounts' own force laws{})"
"""Where the figures are taken, for the warnings' messages ({}: LOADING_CURVES where a mount is
hysteretic)."""
LOADING_CURVES = ", hysteretic ones set down along their loading curves"
FROM_THE_START = f"its utilisation is past 1 from the first report (ERROR); {UNITS_OR_MOUNT}"
"""What such a mount means: utilisation counts from the start."""


def start_ratings(scene: Scene, m: ModelArrays, y: np.ndarray) -> tuple[SceneWarning, ...]:
    """Warnings of the mounts loaded or deflected past their ratings at the start state `y`
    (the nominal one of `m`, at rest on the chart); none for a scene whose ratings the loader
    judges (`rated_at_start`)."""
    if not rated_at_start(scene):
        return ()
    s = new_scratch(y.shape[0])
    body_motion(y, m, s)  # the start's motion: s.q (its frozen DOFs too) and s.rot, body → F
    wrenches = np.zeros((len(scene.mounts), 6))
    mount_wrenches(y, m, s, wrenches)
    arm = np.array([mt.position for mt in scene.mounts]) - np.array(scene.body.cg)
    shift = point_displacements(s.q[None, :3], s.rot[None], arm)[0]  # each attachment point's
    axes = rpy_matrices([mt.orientation_rpy for mt in scene.mounts])
    deflection = np.einsum("nji,nj->ni", axes, shift)
    paths = [scene.mount_path(i) for i in range(len(scene.mounts))]
    hysteretic = any(
        isinstance(mt, Elastomer) and mt.hysteresis is not None and mt.hysteresis.axes
        for mt in scene.mounts
    )
    where = AT_START.format(LOADING_CURVES if hysteretic else "")
    found = rating_warnings(scene, paths, deflection, wrenches[:, :3], where, FROM_THE_START)
    return tuple(found)
