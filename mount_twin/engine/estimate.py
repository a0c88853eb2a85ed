"""The live error estimate's figures: their layout, and what they say (pure Python).

The core's loop fills the figures (`follow` in src/core/engine/kernel.hpp, which has the slots
as `mt::Figure`: test/test_core_contract.py holds them equal); the health window and the engine
read them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

FORCE_ERROR, ATTITUDE_ERROR, FORCE_SCALE, FAILURES, N_FIGURES = range(5)
"""Slots of the figures: largest |ΔF| (N), largest |Δα|, |Δγ|, |Δδ| (rad), largest |F|
component (N), companion failures (re-synchronisations)."""
WARN_FORCE_ERROR_REL = 0.01
"""An estimated mount-force error above this share of the largest force is a WARN: the results
are not to be trusted to the percent (tighten integration.rtol)."""


@dataclass(frozen=True)
class ErrorEstimate:
    """The estimated error of the published outputs over a stretch of the run.

    Attributes:
        force_error_rel: largest |ΔF| over samples, mounts and force components, relative to the
            largest |F| component (the definition of `analysis.accuracy.Accuracy.force_error`).
        force_error_n: that largest |ΔF|, N.
        attitude_error_rad: largest |Δα|, |Δγ|, |Δδ|, rad.
        resyncs: intervals where the companion failed and was re-synchronised to the twin
            (the estimate then misses what it had carried).
    """

    force_error_rel: float
    force_error_n: float
    attitude_error_rad: float
    resyncs: int

    @classmethod
    def of(cls, figures: np.ndarray) -> ErrorEstimate:
        """From figures as the companion keeps them (N_FIGURES slots)."""
        scale = figures[FORCE_SCALE]
        return cls(
            float(figures[FORCE_ERROR] / scale) if scale > 0.0 else 0.0,
            float(figures[FORCE_ERROR]),
            float(figures[ATTITUDE_ERROR]),
            int(figures[FAILURES]),
        )


def accumulate(total: np.ndarray, figures: np.ndarray) -> None:
    """Fold figures (as the companion keeps them) into `total`: maxima, and failures added."""
    np.maximum(total[:FAILURES], figures[:FAILURES], out=total[:FAILURES])
    total[FAILURES] += figures[FAILURES]
