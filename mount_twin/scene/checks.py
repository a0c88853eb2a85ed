"""Load-time checks of a whole scene: what no single key shows, from its small-motion statics
(`mount_twin.scene.statics`) under the nominal weight m·input.g.

Errors (SceneError naming the key path):
- a mount's nominal stiffness beyond STIFFNESS_LIMIT;
- mounts too soft to carry the weight at all (the static sag overflows);
- a body so compact (a principal radius of gyration √(I/m) below GYRATION_MIN_M, with a
  rotation free) that its rotational modes lie beyond what the restraint check and the
  integrators resolve beside its translational ones (it was refused as "no mount holds x, y,
  z": a tolerance relative to 1e15 rad²/s² hid the translations' 1e3);
- a free DOF that nothing holds (zero stiffness, the weight's geometric stiffness included),
  when the twin starts at equilibrium (`initial_state.mode: equilibrium`) and the caller asks
  (`refuse_unheld`: scene files and parameter sets do): the body would drift along it under
  any input (0.51 m in 2 s, as reported). Reduced scenes only need their free DOFs held. A
  scene built in code (tests of one mount's law, of the model's own refusal) gets a warning,
  and `model.assemble.static_equilibrium` refuses it at the start.

Warnings (SceneWarning, kept on `Scene.warnings`): values that load but are likely mistakes.
- a free DOF nothing holds, when it is not refused: from a given start
  (`initial_state.mode: given`) a free body is what torque-free and free-flight studies want;
- a DOF the weight overturns (negative stiffness: a CG high above soft mounts);
- a static sag of the CG or of a mount's attachment point beyond SAG_WARN_M (stiffness in N/mm
  sags a thousand times more), and a mount's static load or deflection beyond its rated values
  (where these statics are not the start the twin takes, the assembly judges the ratings at
  that start instead, `rated_at_start`, `model.ratings`: a given start, at its pose and
  velocity, and a start at equilibrium that it solves with non-linear mount laws — a softening
  force table, cubic terms, snubbers, hysteretic mounts on their loading curves, clearances);
  a shear key's allowable force and a bolted joint's yield and ultimate force (`limits`) are
  judged at that start only, whichever it is (`model.ratings`);
- a mount, the body IMU or the deck IMU farther from the CG than FAR_FACTOR times the body's
  largest radius of gyration, and a radius of gyration beyond GYRATION_WARN_M (positions in
  mm, inertia in kg·mm²);
- an Imu input declared without gravity: sensor_msgs/Imu linear_acceleration is specific force.
- `integration.method: exprb32` where the body's stiff modes are not its linear mounts' alone
  (`scene.statics.linear_stiffness`): `auto` does not take it there, where it is slow and far
  off.

Angles beyond 2π are refused when read (`geometry_reading.ANGLE_LIMIT_RAD`), not warned of: no
orientation needs more than a turn, a value in degrees corrupts every output without any other
sign, and the fix is one edit.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from mount_twin.errors import SceneError
from mount_twin.integrate.methods import EXPONENTIAL, METHODS
from mount_twin.kinds.bolted_joint import BoltedJoint
from mount_twin.kinds.elastomer import Elastomer, hysteretic
from mount_twin.kinds.shear_key import ShearKey
from mount_twin.scene.description import LinearMount, Mount, Scene, SceneWarning, Vec3
from mount_twin.scene.statics import (
    AXES,
    Statics,
    linear_stiffness,
    loose_dofs,
    piecewise_mounts,
    statics,
)

STIFFNESS_LIMIT = 1.0e13
"""Largest nominal stiffness of a mount, N/m or N·m/rad: a steel block 1 m² in section and
20 mm thick (bolted steel joints are ~1e9 N/m); more is a unit error."""
SAG_WARN_M = 0.1
"""Static sag under the weight, m, past which a scene is implausible: mounts sag millimetres
(a 1.6 Hz bounce sags 0.1 m)."""
FAR_FACTOR = 10.0
"""A mount farther from the CG than this many radii of gyration lies outside the body."""
GYRATION_WARN_M = 30.0
"""Largest plausible radius of gyration √(I/m) of a machine on mounts, m."""
GYRATION_MIN_M = 1.0e-4
"""Smallest principal radius of gyration √(I/m), m, of a body whose rotation is free: a
machine, or a lab specimen of a few grams, is far larger; less is a unit error."""
INPUT_IMU = "sensor_msgs/msg/Imu"
UNITS_OR_MOUNT = "stiffness or mass in the wrong units, or the wrong mount?"
"""What a mount's static load or deflection past its rating likely means."""


def check_scene(
    scene: Scene, mount_paths: Sequence[str], *, refuse_unheld: bool
) -> tuple[SceneWarning, ...]:
    """Raise SceneError for a scene that cannot work; return what looks mistaken in it.

    Args:
        scene: a scene whose every value passed its own checks.
        mount_paths: key path of each mount, for messages.
        refuse_unheld: a free DOF nothing holds is an error if the start is at equilibrium
            (else it is a warning).
    """
    _check_compactness(scene)
    _check_body_sensor(scene)
    _check_frames(scene, mount_paths)
    st = statics(scene)
    _check_stiffness_limits(scene, st, mount_paths)
    if not st.finite:
        raise SceneError(
            scene.source,
            "mounts",
            "the mounts are too soft to carry the weight: its static sag overflows (a "
            "stiffness near 1e-300?)",
        )
    geometry = _geometry(scene, mount_paths)
    try:
        restraint = _restraint(scene, st, refuse_unheld)
    except SceneError as err:  # a unit mistake breaks the restraint first: name it
        if not geometry:
            raise
        why = "; ".join(f"{w.path}: {w.message}" for w in geometry)
        raise SceneError(err.source, err.path, f"{err.message}; likely why: {why}") from err
    return (
        *restraint,
        *_sag(scene, st, mount_paths),
        *_ratings(scene, st, mount_paths),
        *geometry,
        *_gravity_convention(scene),
        *_exponential_method(scene, mount_paths),
    )


def _check_body_sensor(scene: Scene) -> None:
    if scene.ageing is not None and scene.body_sensor is None:
        raise SceneError(
            scene.source, "ageing", "tracks mounts from the body IMU: give the body_sensor"
        )
    if scene.body_sensor is not None and scene.body_sensor.topic == scene.input.topic:
        raise SceneError(
            scene.source,
            "body_sensor.topic",
            f"{scene.body_sensor.topic!r} is also input.topic: the body IMU is another sensor, "
            "on the machine, on its own topic",
        )
    if scene.body_sensor is not None and scene.outputs.decimation > 1:
        raise SceneError(
            scene.source,
            "outputs.decimation",
            f"{scene.outputs.decimation} with a body_sensor: its prediction needs every "
            "sample's mount forces (decimated rows hold each component's peak), so 1",
        )


def _check_frames(scene: Scene, mount_paths: Sequence[str]) -> None:
    """Every frame the twin publishes on /tf and /tf_static is its own: a body frame that is
    the foundation's is a transform to itself, and a mount frame that is the foundation's or
    the body's gets two parents."""
    frames = scene.frames
    if frames.body == frames.foundation:
        raise SceneError(
            scene.source,
            "frames.body",
            f"{frames.body!r} is also frames.foundation: /tf would hold a transform from the "
            "frame to itself",
        )
    taken = {frames.foundation: "frames.foundation", frames.body: "frames.body"}
    for mount, path in zip(scene.mounts, mount_paths, strict=True):
        frame = frames.mount_frame(mount.name)
        if frame in taken:
            raise SceneError(
                scene.source,
                f"{path}.name",
                f"its frame {frame!r} (frames.mount_prefix + name) is also {taken[frame]}: "
                "one frame id would be two frames on /tf and /tf_static",
            )


def _check_compactness(scene: Scene) -> None:
    if not {"alpha", "gamma", "delta"} & set(scene.dofs):
        return
    body = scene.body
    smallest = float(np.linalg.eigvalsh(np.array(body.inertia_tensor()))[0])
    gyration = math.sqrt(max(smallest, 0.0) / body.mass)
    if gyration < GYRATION_MIN_M:
        raise SceneError(
            scene.source,
            "body.inertia",
            f"the body's smallest radius of gyration √(I/m) is {gyration:.3g} m, below "
            f"{GYRATION_MIN_M:g} m: no body on mounts is that compact (its rotation would be "
            "orders of magnitude faster than its translation); inertia in t·m², or mass in g?",
        )


def _check_stiffness_limits(scene: Scene, st: Statics, mount_paths: Sequence[str]) -> None:
    for tangent, path in zip(st.tangents, mount_paths, strict=True):
        for k, key in zip(tangent.stiffness, tangent.keys, strict=True):
            if k > STIFFNESS_LIMIT:
                raise SceneError(
                    scene.source,
                    f"{path}.{key}",
                    f"nominal stiffness {k:.4g} is beyond {STIFFNESS_LIMIT:g} N/m (N·m/rad): "
                    "stiffer than a solid steel block; units?",
                )


def _named(shares: dict[str, float]) -> str:
    """'x, y, delta' for DOFs free alone, 'gamma (92 %), x (8 %)' for a coupled direction."""
    if all(s > 0.99 for s in shares.values()):
        return ", ".join(shares)
    return ", ".join(f"{d} ({s:.0%})" for d, s in shares.items())


def _restraint(scene: Scene, st: Statics, refuse_unheld: bool) -> list[SceneWarning]:
    zero, negative = loose_dofs(st, scene.dofs)
    found = []
    if zero:
        them = _named(zero)
        if refuse_unheld and scene.initial.mode == "equilibrium":
            raise SceneError(
                scene.source,
                "mounts",
                f"no mount holds {them}: the mounts' stiffness about the reference pose (with "
                "the weight's) has no component there, so the body would drift under any "
                f"input; give a mount stiffness there, or leave {them} out of `dofs`",
            )
        found.append(
            SceneWarning(
                scene.source,
                "mounts",
                f"no mount holds {them}: the body moves freely there (a start at "
                "equilibrium refuses it)",
            )
        )
    if negative:
        found.append(
            SceneWarning(
                scene.source,
                "body.cg",
                f"the weight overturns the body in {_named(negative)}: its moment on the CG's "
                "height above the mounts outweighs their rocking stiffness (the reference pose "
                "is unstable)",
            )
        )
    return found


def _sag(scene: Scene, st: Statics, mount_paths: Sequence[str]) -> list[SceneWarning]:
    cg = float(np.linalg.norm(st.sag[:3]))
    point = np.linalg.norm(st.deflection, axis=1)
    worst = int(np.argmax(point))
    if max(cg, float(point[worst])) <= SAG_WARN_M:
        return []
    weight = scene.body.mass * scene.input.g
    return [
        SceneWarning(
            scene.source,
            "mounts",
            f"under its weight ({weight:.4g} N) the CG sags {cg:.3g} m and {mount_paths[worst]} "
            f"deflects {point[worst]:.3g} m (statics of the nominal stiffness): more than "
            f"{SAG_WARN_M:g} m is implausible on mounts; stiffness in N/mm, or mass in g?",
        )
    ]


def _ratings(scene: Scene, st: Statics, mount_paths: Sequence[str]) -> list[SceneWarning]:
    """The ratings by the statics of the nominal stiffness, unless the model judges them at
    its start (`tangent_misjudges`)."""
    if tangent_misjudges(scene):
        return []
    return rating_warnings(
        scene, mount_paths, st.deflection, st.force, "under the weight", UNITS_OR_MOUNT
    )


def ratings(mount: Mount) -> tuple[tuple[str, tuple[float, ...]], ...]:
    """(key, rating per local axis, 0 where unrated) of each rated quantity of `mount`: a
    linear mount's rated_load (N) and rated_travel (m), an elastomer's rated_deflection (m).
    The force limits of keys and bolts are `limits`."""
    if isinstance(mount, LinearMount):
        return (("rated_load", mount.rated_load), ("rated_travel", mount.rated_travel))
    if isinstance(mount, Elastomer):
        return (("rated_deflection", mount.rated_deflection),)
    return ()


def limits(mount: Mount) -> tuple[tuple[str, float], ...]:
    """(key, N) of each force limit of `mount`, the first the one its utilisation divides (its
    kind's `monitor`): a shear key's allowable_force (utilisation: its force over it; none at
    0, not monitored), a bolted joint's yield_force (utilisation F_S/F_y) and ultimate_force.
    None for other kinds, whose ratings are `ratings`."""
    if isinstance(mount, ShearKey):
        return (("allowable_force", mount.allowable_force),) if mount.allowable_force else ()
    if isinstance(mount, BoltedJoint):
        return (("yield_force", mount.yield_force), ("ultimate_force", mount.ultimate_force))
    return ()


def rated_at_start(scene: Scene) -> bool:
    """Whether the load-time check needs the start the twin uses (`model.ratings`, at
    assembly): ratings the tangent statics misjudge there (`tangent_misjudges`: any at a given
    start) or a mount with a force limit (`limits`: a key's, a bolt's), which only the start's
    own mount laws give: a bolt's force is its preload and its share of the load, and it is the
    figure the utilisation of every report divides."""
    return any(limits(m) for m in scene.mounts) or tangent_misjudges(scene)


def tangent_misjudges(scene: Scene) -> bool:
    """Whether the scene's ratings (`ratings`) are judged at the start the twin uses
    (`model.ratings`, at assembly) rather than here, by the statics of the nominal tangent under
    the weight: a mount rated, and a start those statics are not.

    - A given start (`initial_state.mode: given`) is its pose and velocity, not the weight's
      equilibrium: 400 kg given 2 mm below the 4.9 mm sag of four linear 2e5 N/m mounts starts
      each at 1.4 times the load the weight gives it, and the first report's utilisation is
      that (a pose given at the reference, the mounts unstressed, starts them at zero).
    - A start at equilibrium that the assembly solves with a mount's own law where it is not
      its nominal tangent (`nonlinear_at_rest`): 400 kg on four elastomers whose force table
      softens from 1e5 N/m start 14.4 mm down where the tangent says 9.8 (a rated 12 mm passed
      unwarned), and on hysteretic ones set down along their loading curves (`model.loading`;
      k₀ = 1e5 N/m, a = 0.3, β + γ = 200) 21.2 mm; a stiffening law (cubic terms, a snubber)
      starts short of the tangent's sag."""
    rated = any(r > 0.0 for m in scene.mounts for _, limit in ratings(m) for r in limit)
    given = scene.initial.mode == "given"
    return rated and (given or any(nonlinear_at_rest(m) for m in scene.mounts))


def nonlinear_at_rest(mount: Mount) -> bool:
    """Whether `mount`'s static force law departs from its nominal tangent (`scene.statics`)
    under a load: an elastomer with a force table, cubic stiffness, a snubber or hysteresis; a
    shear key with a clearance or an engagement height; a bolted joint (it opens, and its
    face slips); any other kind. A linear mount, an elastomer of k₁ alone and a key that bears
    from zero are their tangents."""
    if isinstance(mount, LinearMount):
        return False
    if isinstance(mount, Elastomer):
        return bool(
            mount.force_table
            or any(k3 > 0.0 for k3 in mount.stiffness_cubic)
            or hysteretic(mount)
            or (mount.snubber is not None and mount.snubber.axes)
        )
    if isinstance(mount, ShearKey):
        return mount.clearance > 0.0 or mount.engagement_height > 0.0
    return True


def rating_warnings(
    scene: Scene,
    mount_paths: Sequence[str],
    deflection: np.ndarray,
    force: np.ndarray,
    basis: str,
    hint: str,
    static: bool = True,
) -> list[SceneWarning]:
    """Load and deflection of each mount against its rated values, where it has any: one
    warning per rated key, at the mount most over its rating.

    Args:
        scene: the scene.
        mount_paths: key path of each mount, for messages.
        deflection, force: (n, 3) each mount's deflection (m) and force (N) in its local axes.
        basis: where they are taken, for messages ("under the weight").
        hint: what a mount past its rating likely means, for messages.
        static: whether they are static ones (at rest in equilibrium), for messages.
    """
    over: dict[str, list[tuple[float, int, int, float, float]]] = {}
    for i, mount in enumerate(scene.mounts):
        for key, limit in ratings(mount):
            value = force[i] if key == "rated_load" else deflection[i]
            for j, (v, r) in enumerate(zip(value, limit, strict=True)):
                if abs(v) > r > 0.0:
                    over.setdefault(key, []).append((abs(v) / r, i, j, abs(v), r))
    found = []
    for key, cases in over.items():
        _, i, j, value, rating = max(cases)
        what, unit = ("load", "N") if key == "rated_load" else ("deflection", "m")
        found.append(
            SceneWarning(
                scene.source,
                f"{mount_paths[i]}.{key}",
                f"the {'static ' if static else ''}{what} {basis}, {value:.4g} {unit} along "
                f"local {AXES[j]}, is {past_limit(value, rating, unit)} the rated "
                f"{rating:.4g} {unit}"
                f"{more_mounts(len({c[1] for c in cases}) - 1)}: {hint}",
            )
        )
    return found


def past_limit(value: float, limit: float, unit: str) -> str:
    """How far `value` is past `limit` (0 < limit < value, both in `unit`), in the words that
    follow "is" and precede the limit: "1.23 times" to 3 significant figures, to 4 where 3 read
    1 ("1.002 times"), and where 4 do too, the excess ("0.00196 N past"; "just past" where a
    ratio judged past 1 is the limit to the last bit). A load-time warning had read "is 1
    times its allowable force": a force at its limit, not past it."""
    ratio = value / limit
    for digits in (3, 4):
        if float(text := f"{ratio:.{digits}g}") > 1.0:
            return f"{text} times"
    return f"{value - limit:.3g} {unit} past" if value > limit else "just past"


def more_mounts(n: int) -> str:
    """' (and n more mounts)', or '' for none."""
    return f" (and {n} more mounts)" if n else ""


def _geometry(scene: Scene, mount_paths: Sequence[str]) -> list[SceneWarning]:
    """Mount positions against the body's size as its inertia tells it."""
    body = scene.body
    gyration = math.sqrt(max(body.inertia[:3]) / body.mass)
    found = []
    if gyration > GYRATION_WARN_M:
        found.append(
            SceneWarning(
                scene.source,
                "body.inertia",
                f"the body's radius of gyration √(I/m) is {gyration:.3g} m: implausible for a "
                "machine on mounts; inertia in kg·mm², or mass in t?",
            )
        )
    mounts = [
        (f"{path}.position", m.position) for path, m in zip(mount_paths, scene.mounts, strict=True)
    ]
    found += _farthest(scene, gyration, mounts, "outside the body")
    if scene.body_sensor is not None:
        on_body = [("body_sensor.position", scene.body_sensor.position)]
        found += _farthest(scene, gyration, on_body, "outside the body")
    deck = [("input.sensor_position", scene.input.sensor_position)]
    rigid = "the twin takes the deck as rigid between them"
    return found + _farthest(scene, gyration, deck, rigid)


def _farthest(
    scene: Scene, gyration: float, points: Sequence[tuple[str, Vec3]], meaning: str
) -> list[SceneWarning]:
    """A warning for the farthest of `points` (key path, position m in F) that lies more than
    FAR_FACTOR radii of gyration (m) from the CG, counting the others that do too."""
    arms = np.linalg.norm(np.array([p for _, p in points]) - scene.body.cg, axis=1)
    far = np.flatnonzero(arms > FAR_FACTOR * gyration)
    if not far.size:
        return []
    i = int(far[np.argmax(arms[far])])
    return [
        SceneWarning(
            scene.source,
            points[i][0],
            f"{arms[i]:.4g} m from the CG{more_mounts(far.size - 1)}, {arms[i] / gyration:.3g} "
            f"times the body's largest radius of gyration ({gyration:.3g} m): {meaning}; "
            "positions in millimetres?",
        )
    ]


def _exponential_method(scene: Scene, mount_paths: Sequence[str]) -> list[SceneWarning]:
    """`integration.method` an exponential one where the body's stiff modes are not its linear
    mounts' alone (`linear_stiffness`), where `auto` does not take it: there it is slow and far
    off, its estimate at times blind to it (`python3 bench/stiff_methods.py --case key --methods
    exprb32 ros34pw2 --rtol 1e-6`, and `--case stiff_bouc_wen --rtol 1e-3`, 2026-11-29)."""
    method = METHODS.get(scene.integration.method)
    if method is None or method.family != EXPONENTIAL or linear_stiffness(scene):
        return []
    pieces = [mount_paths[i] for i in piecewise_mounts(scene)]
    why = (
        f"the law of {pieces[0]}{more_mounts(len(pieces) - 1)} has pieces"
        if pieces
        else "its non-linear mounts are stiff"
    )
    return [
        SceneWarning(
            scene.source,
            "integration.method",
            f"{method.name} is exact on linear mounts, and {why}: on such scenes it is slow and "
            "far off, its error estimate at times blind to it (beside a 1e9 N/m shear key at "
            "rtol 1e-6, 0.31 of the largest force off at 125 substeps a sample, where ros34pw2 "
            "is 9.4e-4 off at 10; on four stiff Bouc–Wen elastomers at rtol 1e-3 its estimate "
            "read 0.06 of its error); `auto` takes ros34pw2 where such a scene is stiff, "
            "dopri54 where explicit steps suffice (docs/scene.md, Integration methods)",
        )
    ]


def _gravity_convention(scene: Scene) -> list[SceneWarning]:
    spec = scene.input
    if spec.msg_type != INPUT_IMU or spec.includes_gravity:
        return []
    return [
        SceneWarning(
            scene.source,
            "input.includes_gravity",
            "false for a sensor_msgs/Imu input, whose linear_acceleration is specific force "
            "(gravity included, +g up at rest): the twin adds g again unless this driver "
            "removes it",
        )
    ]
