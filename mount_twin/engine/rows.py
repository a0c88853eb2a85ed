"""Output rows of a push: where the compiled loop writes the poses and wrenches it publishes."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from mount_twin.physics import pose_row


class Rows(NamedTuple):
    """Published rows: positions of their samples in the pushed batch, poses, wrenches; and
    where the compiled loop gave them, their largest |wrench component| per mount and smallest
    cos θ (`kernel.Published`)."""

    sample: np.ndarray
    pose: np.ndarray
    wrenches: np.ndarray
    peaks: tuple[np.ndarray, float] | None = None


class Tail(NamedTuple):
    """A run's last sample, which decimation had not published, published at the run's end
    (a restart, the stream's end) so that its peaks are not lost: its position among all the
    samples pushed (`TwinEngine.pending_ids`), stamp (s), pose row (1, WIDTH) and wrenches
    (1, n_mounts, 6), each component's largest magnitude since the row before."""

    stream_id: int
    stamp: float
    pose: np.ndarray
    wrenches: np.ndarray


Part = Rows | Tail
"""What a push publishes comes in parts, in the order the twin gave them."""


class BatchRows:
    """Output rows for a pushed batch, one per sample (row r + 1 holds sample r's; row 0 is
    before the batch): a start and a run over consecutive samples write theirs in place, so a
    push whose published rows are consecutive returns views of these rather than a
    concatenation of each run's (0.5 ms of the genset's 2,500-sample shock record)."""

    def __init__(self, n: int, n_mounts: int) -> None:
        self.pose = np.empty((n + 1, pose_row.WIDTH))
        self.wrenches = np.empty((n + 1, n_mounts, 6))

    def of_run(self, index: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """A run's buffers (row 0: the sample before index[0]) where its samples are
        consecutive; None else."""
        first, n = int(index[0]), index.shape[0] + 1
        if int(index[-1]) - first != n - 2:
            return None
        return self.pose[first : first + n], self.wrenches[first : first + n]

    def put(self, i: int, pose: np.ndarray, wrenches: np.ndarray) -> Rows:
        """Sample i's outputs (one pose row, its (n_mounts, 6) wrenches), written in place."""
        self.pose[i + 1], self.wrenches[i + 1] = pose, wrenches
        return Rows(np.array([i]), self.pose[i + 1 : i + 2], self.wrenches[i + 1 : i + 2])

    def gather(self, parts: list[Rows]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The parts' samples, poses and wrenches, in order."""
        sample = np.concatenate([r.sample for r in parts])
        n = sample.shape[0]
        if (
            n
            and int(sample[-1]) - int(sample[0]) == n - 1
            and all(np.may_share_memory(r.pose, self.pose) for r in parts)
        ):  # consecutive rows of these buffers, in place
            rows = slice(int(sample[0]) + 1, int(sample[-1]) + 2)
            return sample, self.pose[rows], self.wrenches[rows]
        return (
            sample,
            np.concatenate([r.pose for r in parts]),
            np.concatenate([r.wrenches for r in parts]),
        )
