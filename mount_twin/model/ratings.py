"""The load-time rating check at the start the twin uses, where tangent statics miss it.

`scene.checks` judges each mount's static load and deflection against its ratings by the
statics of the nominal stiffness under the weight: exact for linear mounts at equilibrium, and
for a non-linear one at zero load only. A new machine's start at equilibrium is solved with the
mounts' own laws (`model.assemble.static_equilibrium`: force tables, cubic terms, snubbers,
clearances, bolted joints, and hysteretic mounts set down along their loading curves,
`model.loading`), and a law that softens as it loads starts past its tangent's sag: 400 kg on
four elastomers whose force table softens from 1e5 N/m start 14.4 mm down where the tangent
says 9.8, past a rated 12 mm that the tangent statics found unreached (on four Bouc–Wen mounts
of k₀ = 1e5 N/m, a = 0.3, β + γ = 200: 21.2 mm), and every mount was then an ERROR from the
first report without a word at load; one that stiffens (cubic terms, a snubber) was warned of
where it starts within. A given start (`initial_state.mode: given`) is its pose and velocity,
not the weight's equilibrium, whatever the mounts: a pose given past a rating was an ERROR from
the first report without a word, and one given at the reference (the mounts unstressed) was
warned of a load it does not start under. For such a scene (`scene.checks.tangent_misjudges`)
the loader leaves the ratings to this check, which takes every rated mount's deflection and
force (a linear mount's damping force at the given velocity too) at the start state the
assembly solved or was given, and says what it finds as the loader's warnings do
(`Scene.warnings`).

A shear key's allowable force and a bolted joint's yield and ultimate force
(`scene.checks.limits`) are judged here only, at that start, whichever it is: a machine whose
weight (with its bolts' preload) already put a key past its allowable force or a bolt past its
yield, or that was given a pose that did, read ERROR from the first report without a word at
load. The force judged is the one its utilisation divides, read back from the utilisation the
mounts' monitors give at the start (`physics.dynamics.mount_monitors`, as the engine's first
report takes it), so the warned ratio is that report's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from mount_twin.kinds import N_EVENTS
from mount_twin.kinds.elastomer import Elastomer, hysteretic
from mount_twin.physics.dynamics import (
    ModelArrays,
    Scratch,
    body_motion,
    mount_monitors,
    mount_wrenches,
    new_scratch,
)
from mount_twin.physics.rotations import point_displacements, rpy_matrices
from mount_twin.scene.checks import (
    UNITS_OR_MOUNT,
    limits,
    more_mounts,
    past_limit,
    rated_at_start,
    rating_warnings,
    tangent_misjudges,
)
from mount_twin.scene.description import Scene, SceneWarning

AT_START = "at the start (the weight's equilibrium on the mounts' own force laws{})"
"""Where the figures of a start at equilibrium are taken, for the warnings' messages ({}:
LOADING_CURVES where a mount is hysteretic)."""
LOADING_CURVES = ", hysteretic ones set down along their loading curves"
AT_GIVEN = "at the given start (initial_state.pose and velocity, not the weight's equilibrium)"
"""Where the figures of a given start are taken, for the warnings' messages (hysteretic states
start at 0 there)."""
PAST_1 = "its utilisation is past 1 from the first report (ERROR); "
"""What such a mount means: utilisation counts from the start; then what it likely means."""
POSE_OR_MOUNT = "initial_state.pose or stiffness in the wrong units, or the wrong mount?"
"""What a mount past its rating at a given start likely means (the mass plays no part there)."""
ELASTIC = (
    ", the bolt taken as elastic there (its plastic elongation starts at 0; one that yielded on "
    "its way there would have stretched and lost preload)"
)
"""What the start is for a bolt past its yield force."""
BOLT_FORCE = "the bolt force F_S (its preload and its share of the load)"
LIMITED = {
    "allowable_force": ("the key's force", "its allowable force", "", ""),
    "yield_force": (BOLT_FORCE, "its yield force", ELASTIC, ""),
    "ultimate_force": (
        BOLT_FORCE,
        "its ultimate force",
        ELASTIC,
        "it breaks at the start (bolt_fractured), and ",
    ),
}
"""Each limit key (`scene.checks.limits`): what its force is, what the limit is, what the start
is, and what passing it means beside `Basis.means`, for the warnings' messages."""


@dataclass(frozen=True)
class Basis:
    """Where a start's figures are taken, and what a mount past a limit there means, for the
    warnings' messages.

    Attributes:
        where: the start ("at the given start (…)").
        means: utilisation past 1 from the first report, and what that likely means.
        static: whether the start is at rest in equilibrium (its loads static ones).
    """

    where: str
    means: str
    static: bool


def start_basis(scene: Scene) -> Basis:
    """The `Basis` of the start `scene` takes: its given pose and velocity, or the weight's
    equilibrium on the mounts' own laws (hysteretic ones on their loading curves)."""
    if scene.initial.mode == "given":
        return Basis(AT_GIVEN, PAST_1 + POSE_OR_MOUNT, static=False)
    loading = any(isinstance(mt, Elastomer) and hysteretic(mt) for mt in scene.mounts)
    return Basis(AT_START.format(LOADING_CURVES if loading else ""), PAST_1 + UNITS_OR_MOUNT, True)


def start_ratings(scene: Scene, m: ModelArrays, y: np.ndarray) -> tuple[SceneWarning, ...]:
    """Warnings of the mounts loaded or deflected past their ratings, and of the keys and bolts
    past their force limits, at the start state `y` (the nominal one of `m`: at rest on the
    chart, or the given pose and velocity); none for a scene whose start the loader judges
    (`rated_at_start`), and no ratings where it judges those (`tangent_misjudges`)."""
    if not rated_at_start(scene):
        return ()
    s = new_scratch(y.shape[0])
    body_motion(y, m, s)  # the start's motion: s.q (its frozen DOFs too) and s.rot, body → F
    paths = [scene.mount_path(i) for i in range(len(scene.mounts))]
    basis = start_basis(scene)
    found = []
    if tangent_misjudges(scene):
        wrenches = np.zeros((len(scene.mounts), 6))
        mount_wrenches(y, m, s, wrenches)  # at y's velocity too: a linear mount's damping
        arm = np.array([mt.position for mt in scene.mounts]) - np.array(scene.body.cg)
        shift = point_displacements(s.q[None, :3], s.rot[None], arm)[0]  # each attachment point's
        axes = rpy_matrices([mt.orientation_rpy for mt in scene.mounts])
        deflection = np.einsum("nji,nj->ni", axes, shift)
        found = rating_warnings(
            scene, paths, deflection, wrenches[:, :3], basis.where, basis.means, basis.static
        )
    return (*found, *limit_warnings(scene, m, y, s, paths, basis))


def limit_warnings(
    scene: Scene, m: ModelArrays, y: np.ndarray, s: Scratch, paths: list[str], basis: Basis
) -> list[SceneWarning]:
    """Each key's and bolt's force at state `y` (s holding its body motion) against its force
    limits (`scene.checks.limits`): one warning per limit key, at the mount most past it.

    The force is its utilisation there (the mounts' monitors, `mount_monitors`, on a copy of y:
    a bolt past its ultimate force breaks in it) times the limit the utilisation divides (the
    first of `limits`), so the warned ratio to that limit is the utilisation itself.

    Args:
        scene, m: the scene and its core arrays.
        paths: key path of each mount, for messages.
        basis: where the state is taken and what passing a limit there means, for messages.
    """
    nl = m.nl
    if nl is None:
        return []
    util = np.zeros(nl.slot.shape[0])
    mount_monitors(y.copy(), y, nl, s, np.zeros((util.shape[0], N_EVENTS)), util)
    over: dict[str, list[tuple[float, int, float, float]]] = {}
    for row, i in enumerate(nl.slot.tolist()):
        own = limits(scene.mounts[i])
        for key, limit in own:
            ratio = float(util[row]) * (own[0][1] / limit)
            if ratio > 1.0:
                over.setdefault(key, []).append((ratio, i, float(util[row]) * own[0][1], limit))
    found = []
    for key, cases in over.items():
        _, i, force, limit = max(cases)
        what, of, start, means = LIMITED[key]
        found.append(
            SceneWarning(
                scene.source,
                f"{paths[i]}.{key}",
                f"{what} {basis.where}, {force:.4g} N, is {past_limit(force, limit, 'N')} "
                f"{of} {limit:.4g} N"
                f"{more_mounts(len(cases) - 1)}{start}: {means}{basis.means}",
            )
        )
    return found
