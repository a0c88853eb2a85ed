"""Data crossing the engine boundary: input samples in, outputs and health reports out."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from itertools import repeat

import numpy as np

from mount_twin.physics import pose_row

OK, WARN, ERROR = 0, 1, 2
"""Health levels, as diagnostic_msgs/DiagnosticStatus uses them."""
LEVEL_NAMES = ("OK", "WARN", "ERROR")
"""Each health level's name, by its value."""
FAILED = "FAILED"
"""The verdict of a run worse than any health level: the integration failed (the twin then
restarted or stopped following, so its figures are not the machine's), or a sweep case that
raised."""


@dataclass
class SampleBatch:
    """Input samples in arrival order, in the sensor frame.

    Attributes:
        stamps: (n,) header stamps, s.
        accel: (n, 3) acceleration, m/s², sensor frame (specific force if it includes gravity).
        gyro: (n, 3) angular velocity, rad/s, sensor frame.
        frame_ids: header.frame_id of each sample.
        unprovided: (n, 2) bool, where a sample's message marks its acceleration, its angular
            velocity not provided (REP-145); None: every reading is provided.
    """

    stamps: np.ndarray
    accel: np.ndarray
    gyro: np.ndarray
    frame_ids: list[str]
    unprovided: np.ndarray | None = None

    def __post_init__(self) -> None:
        """Arrays of float64 whatever holds the numbers (lists, float32, integers; no copy of
        float64 arrays) and a list of frame ids: what the engine reads (a list kept as the
        last reading broke every later push; float32 cast the reading limit to inf). What
        holds no numbers is left for `check` to name."""
        for name in ("stamps", "accel", "gyro"):
            value = np.asarray(getattr(self, name))
            if value.dtype.kind in "fiu" and value.dtype != np.float64:
                value = value.astype(np.float64)
            setattr(self, name, value)
        if not isinstance(self.frame_ids, list):
            self.frame_ids = list(self.frame_ids)

    def __len__(self) -> int:
        """n (stamps of another shape count 1: not empty, so `push` checks and names them)."""
        return int(self.stamps.shape[0]) if self.stamps.ndim == 1 else 1

    def check(self) -> None:
        """Raise ValueError naming the field unless this is a batch of n samples: stamps (n,),
        accel and gyro (n, 3) of real numbers, n frame ids (strings). Values are not judged here
        (NaN, a stamp going back: the engine counts and reports those per sample)."""
        stamps, accel, gyro = (np.asarray(a) for a in (self.stamps, self.accel, self.gyro))
        if stamps.ndim != 1:
            msg = f"SampleBatch.stamps: shape {stamps.shape}, expected (n,) seconds"
            raise ValueError(msg)
        n = stamps.shape[0]
        for name, a in (("stamps", stamps), ("accel", accel), ("gyro", gyro)):
            if a.dtype.kind not in "fiu":
                msg = f"SampleBatch.{name}: dtype {a.dtype}, expected real numbers"
                raise ValueError(msg)
        for name, a in (("accel", accel), ("gyro", gyro)):
            if a.shape != (n, 3):
                msg = f"SampleBatch.{name}: shape {a.shape}, expected ({n}, 3) for {n} stamps"
                raise ValueError(msg)
        if len(self.frame_ids) != n:
            msg = f"SampleBatch.frame_ids: {len(self.frame_ids)} entries, expected {n} strings"
            raise ValueError(msg)
        if not _all_strings(self.frame_ids):
            i, bad = next((i, f) for i, f in enumerate(self.frame_ids) if not isinstance(f, str))
            msg = f"SampleBatch.frame_ids: expected {n} strings, [{i}] is a {type(bad).__name__}"
            raise ValueError(msg)

    def part(self, keep: slice) -> SampleBatch:
        """The samples at the positions `keep` takes (views of the arrays where numpy gives
        them)."""
        unset = None if self.unprovided is None else self.unprovided[keep]
        return SampleBatch(
            self.stamps[keep], self.accel[keep], self.gyro[keep], self.frame_ids[keep], unset
        )

    @classmethod
    def concat(cls, parts: list[SampleBatch]) -> SampleBatch:
        """One batch of several, in order (of none, an empty one)."""
        if not parts:
            return cls(np.zeros(0), np.zeros((0, 3)), np.zeros((0, 3)), [])
        return cls(
            np.concatenate([p.stamps for p in parts]),
            np.concatenate([p.accel for p in parts]).reshape(-1, 3),
            np.concatenate([p.gyro for p in parts]).reshape(-1, 3),
            [fid for p in parts for fid in p.frame_ids],
            None
            if all(p.unprovided is None for p in parts)
            else np.concatenate(
                [
                    np.zeros((len(p), 2), bool) if p.unprovided is None else p.unprovided
                    for p in parts
                ]
            ),
        )


def _all_strings(items: list[str]) -> bool:
    """Whether every item is a str: at once where they all equal the first, a str (one IMU's
    samples: list.count compares by identity first), else item by item."""
    if items and type(items[0]) is str and items.count(items[0]) == len(items):
        return True
    return all(map(isinstance, items, repeat(str)))


@dataclass
class HealthStatus:
    """One diagnostic status: name, level (OK/WARN/ERROR), message, key/value figures."""

    name: str
    level: int
    message: str
    values: dict[str, str] = field(default_factory=dict)


@dataclass(frozen=True)
class MountEvent:
    """A mount event: its interpolated time (s), mount, event name, mount force magnitude (N) at
    the sample that revealed it, and whether it is an ERROR (a limit passed) or a WARN."""

    stamp: float
    mount: str
    event: str
    force: float
    error: bool

    @property
    def level(self) -> str:
        """The level name: ERROR or WARN."""
        return event_level(self.error)


def event_level(error: bool) -> str:
    """The level name of a mount event that is an ERROR (`error`) or a WARN."""
    return LEVEL_NAMES[ERROR if error else WARN]


@dataclass
class HealthReport:
    """Diagnostics at one stamp (s), due once sample `sample` of the pushed batch is processed,
    published after the first `rows` output rows of its batch (with the gyro delay, rows of
    earlier samples may follow it)."""

    stamp: float
    sample: int
    statuses: list[HealthStatus]
    rows: int = 0


@dataclass
class OutputBatch:
    """Published outputs, one row per published sample.

    Attributes:
        stamps: (k,) input stamps the rows answer, s.
        sample: (k,) position of each row's sample in the pushed SampleBatch (so adapters can
            reuse the exact input stamps).
        pose: (k, pose_row.WIDTH) rows: CG position in F (m), quaternion (x, y, z, w) of R,
            (α, γ, δ) rad (`physics/pose_row.py`; `position`, `quaternion`, `angles`).
        wrenches: (k, n_mounts, 6) force (N) and couple (N·m) on the body in mount axes; with
            decimation, each component's largest magnitude since the previous row.
        health: diagnostics due in this batch.
    """

    stamps: np.ndarray
    sample: np.ndarray
    pose: np.ndarray
    wrenches: np.ndarray
    health: list[HealthReport] = field(default_factory=list)

    def __len__(self) -> int:
        return int(self.stamps.shape[0])

    @classmethod
    def empty(cls, n_mounts: int) -> OutputBatch:
        """No rows."""
        return cls(
            np.zeros(0),
            np.zeros(0, np.intp),
            np.zeros((0, pose_row.WIDTH)),
            np.zeros((0, n_mounts, 6)),
        )

    def then(self, later: OutputBatch, n: int) -> OutputBatch:
        """These rows and reports, then `later`'s, which count their samples (and rows) from
        the end of a batch of n samples (`TwinEngine.flush` after a push of n). Neither batch
        changes: `later`'s reports are moved in copies."""
        moved = [replace(r, sample=r.sample + n, rows=r.rows + len(self)) for r in later.health]
        return OutputBatch(
            np.concatenate([self.stamps, later.stamps]),
            np.concatenate([self.sample, later.sample + n]),
            np.concatenate([self.pose, later.pose]),
            np.concatenate([self.wrenches, later.wrenches]),
            [*self.health, *moved],
        )

    def select(self, keep: np.ndarray) -> OutputBatch:
        """The rows where `keep` (bool, one per row) is true, without the reports (which
        follow samples of the whole batch)."""
        return OutputBatch(
            self.stamps[keep], self.sample[keep], self.pose[keep], self.wrenches[keep]
        )

    @property
    def position(self) -> np.ndarray:
        """(k, 3) CG position in F, m."""
        return self.pose[:, pose_row.POSITION_COLS]

    @property
    def quaternion(self) -> np.ndarray:
        """(k, 4) quaternion (x, y, z, w) of R, body → F."""
        return self.pose[:, pose_row.QUATERNION_COLS]

    @property
    def angles(self) -> np.ndarray:
        """(k, 3) chart angles (α, γ, δ), rad."""
        return self.pose[:, pose_row.ANGLES_COLS]
