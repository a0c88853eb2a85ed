"""mount_twin: real-time digital twin of a rigid body on compliant mounts.

The Python API, without ROS or bags: a scene (`load_scene_file`, `scene_from_dict`,
`scene_from_params`), assembled into a `Model` (`assemble`), drives a streaming `TwinEngine`
that takes `SampleBatch`es of foundation acceleration and returns `OutputBatch`es (pose, angles,
mount wrenches, health); `TwinStream` does the same on raw CDR messages and `replay_bag` on
bags; `sweep` runs a design sweep file (scene variants × inputs) on a Dask cluster.

    import numpy as np
    from mount_twin import SampleBatch, TwinEngine, assemble, load_scene_file

    engine = TwinEngine(assemble(load_scene_file("config/pump_8_mounts.scene.yaml")))
    t = np.arange(100) * 1e-3  # 0.1 s at 1 kHz, at rest: +g up along z
    accel = np.tile([0.0, 0.0, 9.80665], (t.size, 1))
    out = engine.run(SampleBatch(t, accel, np.zeros((t.size, 3)), ["deck_imu"] * t.size))
    print(out.wrenches[-1])  # (n_mounts, 6): force (N) and couple (N·m) in mount axes

Importing the package is cheap: each name below is imported on first use (PEP 562), so only
the names a program touches load numpy, scipy and the compiled core.
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any

from mount_twin.errors import BagError, ModelError, MountTwinError, SceneError

if TYPE_CHECKING:
    from mount_twin.engine.batch import (
        HealthReport,
        HealthStatus,
        MountEvent,
        OutputBatch,
        SampleBatch,
    )
    from mount_twin.engine.engine import TwinEngine
    from mount_twin.model.assemble import Model, assemble
    from mount_twin.replay import replay as replay_bag
    from mount_twin.replay_summary import ReplaySummary
    from mount_twin.scene.description import Scene
    from mount_twin.scene.loader import load_scene_file, scene_from_dict
    from mount_twin.scene.params import scene_from_params
    from mount_twin.stream import TwinStream
    from mount_twin.sweeps.runner import sweep

_LAZY = {
    "load_scene_file": "mount_twin.scene.loader",
    "scene_from_dict": "mount_twin.scene.loader",
    "scene_from_params": "mount_twin.scene.params",
    "Scene": "mount_twin.scene.description",
    "assemble": "mount_twin.model.assemble",
    "Model": "mount_twin.model.assemble",
    "TwinEngine": "mount_twin.engine.engine",
    "SampleBatch": "mount_twin.engine.batch",
    "OutputBatch": "mount_twin.engine.batch",
    "HealthReport": "mount_twin.engine.batch",
    "HealthStatus": "mount_twin.engine.batch",
    "MountEvent": "mount_twin.engine.batch",
    "TwinStream": "mount_twin.stream",
    "replay_bag": "mount_twin.replay:replay",
    "ReplaySummary": "mount_twin.replay_summary",
    "sweep": "mount_twin.sweeps.runner",
}
"""Exported name → module that defines it (`module:name` where the names differ: the function
`replay` is `replay_bag` here, since the submodule `mount_twin.replay` takes that attribute once
imported), imported on first access."""

__all__ = [
    "BagError",
    "HealthReport",
    "HealthStatus",
    "Model",
    "ModelError",
    "MountEvent",
    "MountTwinError",
    "OutputBatch",
    "ReplaySummary",
    "SampleBatch",
    "Scene",
    "SceneError",
    "TwinEngine",
    "TwinStream",
    "assemble",
    "load_scene_file",
    "replay_bag",
    "scene_from_dict",
    "scene_from_params",
    "sweep",
]


def __getattr__(name: str) -> Any:
    """Import an exported name's module on first access (PEP 562), then keep the name here. An
    entry of _LAZY whose module lacks the attribute is an ImportError naming the entry, not the
    AttributeError of an unknown name that `hasattr` and `from mount_twin import` would hide."""
    entry = _LAZY.get(name)
    if entry is None:
        msg = f"module {__name__!r} has no attribute {name!r}"
        raise AttributeError(msg)
    module, _, attribute = entry.partition(":")
    imported = import_module(module)
    if not hasattr(imported, attribute or name):
        msg = f"{__name__}._LAZY maps {name!r} to {entry!r}: {module} has no {attribute or name!r}"
        raise ImportError(msg, name=module)
    value = getattr(imported, attribute or name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The module's names, the lazy ones included."""
    return sorted({*globals(), *__all__})
