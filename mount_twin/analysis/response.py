"""The twin's response as a record to take spectra of: the CG's specific force or a mount's
force, from an output bag's tables or from a replay in memory.

The CG's specific force needs no differentiation of the pose. The mounts are the only forces on
the body besides gravity, so Newton gives it exactly from the published wrenches:
m (a − g) = Σᵢ Qᵢ fᵢ, with fᵢ the force mount i exerts on the body in its local axes and Qᵢ
those axes in F (fixed in F, `docs/physics.md` §7). It is what an accelerometer at the CG reads
(specific force, +g up at rest), in the axes of F: the motion secondary equipment on the machine
feels, the input of a response spectrum as the deck's record is of the machine's. A DOF the
scene freezes is held by a constraint, not a mount: its axis is refused.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from mount_twin.engine.batch import OutputBatch, SampleBatch
from mount_twin.engine.engine import TwinEngine
from mount_twin.engine.sensor_reading import cg_specific_force
from mount_twin.io.output_tables import Table, integration_values
from mount_twin.io.output_topics import WRENCHES_OUTPUT
from mount_twin.model.assemble import Model, assemble
from mount_twin.scene.description import Scene

CG = "cg"
MOUNT_PREFIX = "mount:"
AXES = ("x", "y", "z")


@dataclass(frozen=True)
class Response:
    """A response record.

    Attributes:
        t: (k,) seconds from the first row.
        values: (k, 3) the CG's specific force in F (m/s²), or a mount's force in its local
            axes (N).
        unit: "m/s²" or "N".
        name: what it is, for titles.
    """

    t: np.ndarray
    values: np.ndarray
    unit: str
    name: str


def check_response(text: str, scene: Scene) -> str | None:
    """The mount named by `text` ("cg" or "mount:NAME") is one of the scene's; None for the
    CG. Raises ValueError naming what is wrong."""
    if text == CG:
        return None
    names = [m.name for m in scene.mounts]
    name = text.removeprefix(MOUNT_PREFIX)
    if not text.startswith(MOUNT_PREFIX) or name not in names:
        msg = (
            f"response {text!r} (srs --response): give cg or mount:NAME, NAME one of "
            f"{', '.join(names)}"
        )
        raise ValueError(msg)
    return name


def followed(scene: Scene, batch: SampleBatch, source: str) -> tuple[Model, OutputBatch]:
    """The scene's model and its twin's outputs on a whole record in memory, a row for every
    sample (whatever the scene's decimation: a response is simultaneous wrenches). A run whose
    integration failed, or that published fewer than 3 rows, is refused (ValueError naming
    `source`): its response is not the machine's."""
    every_sample = dataclasses.replace(scene.outputs, decimation=1)  # peaks are not one instant
    model = assemble(dataclasses.replace(scene, outputs=every_sample))
    engine = TwinEngine(model)
    out = engine.run(batch)
    if engine.failure_text or len(out) < 3:
        why = engine.failure_text or f"{len(out)} rows published ({dict(engine.counts)})"
        msg = f"{source}: the twin's run failed, its response is not the machine's: {why}"
        raise ValueError(msg)
    return model, out


def response_of(scene: Scene, stamps_s: np.ndarray, wrenches: np.ndarray, text: str) -> Response:
    """The response `text` ("cg" or "mount:NAME") of a run whose rows are at `stamps_s` (s)
    with (k, n, 6) `wrenches`."""
    mount = check_response(text, scene)
    t = stamps_s - stamps_s[0]
    if mount is not None:
        i = [m.name for m in scene.mounts].index(mount)
        return Response(t, wrenches[:, i, :3], "N", f"mount {mount} force (its axes)")
    frozen = [a for a in AXES if a not in scene.dofs]
    values = cg_specific_force(scene, wrenches)
    values[:, [AXES.index(a) for a in frozen]] = np.nan  # a constraint force is not published
    return Response(t, values, "m/s²", "CG specific force (F axes)")


def wrenches_of(tables: list[Table], scene: Scene, source: str) -> tuple[np.ndarray, np.ndarray]:
    """(stamps s, (k, n, 6) wrenches) from an output bag's tables (`io.output_tables`): every
    mount of the scene, on the same rows, of a run whose integration never failed. Raises
    ValueError naming `source` otherwise."""
    if scene.outputs.decimation > 1:
        msg = (
            f"{source}: written at outputs.decimation {scene.outputs.decimation}, its wrenches "
            "are each component's peak over the interval, not one instant: give the input bag "
            "(replayed at decimation 1)"
        )
        raise ValueError(msg)
    by_name = {t.name: t for t in tables}
    failures = integration_values(by_name.get("diagnostics")).get("failures_total", "0")
    if int(failures):  # its wrenches have holes where it failed, and a restart after each
        msg = (
            f"{source}: the twin's run failed, its response is not the machine's: integration "
            f"failed {failures} times"
        )
        raise ValueError(msg)
    names = [str(WRENCHES_OUTPUT.table).format(mount=m.name) for m in scene.mounts]
    missing = [n for n in names if n not in by_name]
    if missing:
        msg = f"{source}: no wrench table for {', '.join(missing)} (is it the scene's output?)"
        raise ValueError(msg)
    stamps = by_name[names[0]].columns["stamp_ns"]
    if any(not np.array_equal(by_name[n].columns["stamp_ns"], stamps) for n in names):
        msg = f"{source}: the mounts' wrenches are not on the same stamps"
        raise ValueError(msg)
    wrenches = np.stack(
        [
            np.stack([by_name[n].columns[c] for c in WRENCHES_OUTPUT.columns], axis=1)
            for n in names
        ],
        axis=1,
    )
    return (stamps - stamps[0]) * 1e-9, wrenches
