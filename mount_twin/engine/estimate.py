"""The live error estimate's figures: their layout, and what they say (pure Python).

The core's loop fills the figures (`estimate_interval` in src/core/engine/estimator.hpp, which
has the slots as `mt::Figure`: test/test_core_contract.py holds them equal); the health window
and the engine read them.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

FORCE_ERROR, ATTITUDE_ERROR, FORCE_SCALE, FAILURES, UNCARRIED, N_FIGURES = range(6)
"""Slots of the figures: largest |ΔF| (N), largest |Δα|, |Δγ|, |Δδ| (rad), largest |F|
component (N), failed checks (intervals whose local error could not be measured), states the
estimate does not carry (`engine.estimator.DENSE_MAX`)."""
NOT_INTEGRATED = "none (no input interval was integrated)"
"""The estimated error of a run where nothing was estimated (`ErrorEstimate.estimated` false)."""
WARN_FORCE_ERROR_REL = 0.01
"""An estimated mount-force error above this share of the largest force is a WARN: the results
are not to be trusted to the percent (tighten integration.rtol)."""


@dataclass(frozen=True)
class ErrorEstimate:
    """The estimated error of the published outputs over a stretch of the run.

    Attributes:
        force_error_rel: largest |ΔF| over samples, mounts and force components, relative to the
            largest |F| component (the definition of `analysis.accuracy.Accuracy.force_error`);
            NaN where no interval was integrated (a run that accepted no sample, or one, or
            failed at every sample: nothing was estimated, and 0.0 would read as exact), and
            where no mount carried a force (a body tumbling free: nothing to relate it to).
        force_error_n: that largest |ΔF|, N (NaN where no interval was integrated).
        attitude_error_rad: largest |Δα|, |Δγ|, |Δδ|, rad (NaN where no interval was
            integrated).
        failed_checks: intervals whose local error could not be measured (the checking
            stepper failed: the estimate misses what they committed).
        uncarried_states: the model's states whose error the estimate does not carry from
            interval to interval (a model of more than `engine.estimator.DENSE_MAX` states:
            its mounts' internal states).
    """

    force_error_rel: float
    force_error_n: float
    attitude_error_rad: float
    failed_checks: int
    uncarried_states: int

    @property
    def estimated(self) -> bool:
        """Whether any interval was estimated (attitude_error_rad is a number)."""
        return not math.isnan(self.attitude_error_rad)

    def as_dict(self) -> dict[str, float | int | None]:
        """The fields for JSON: NaN as None (strict JSON has no NaN)."""
        return {
            k: None if isinstance(v, float) and math.isnan(v) else v
            for k, v in dataclasses.asdict(self).items()
        }

    @property
    def lower_bound(self) -> bool:
        """Whether the figures may be short of the error (failed checks, uncarried states)."""
        return self.failed_checks > 0 or self.uncarried_states > 0

    @classmethod
    def of(cls, figures: np.ndarray, intervals: int) -> ErrorEstimate:
        """From figures as the core keeps them (N_FIGURES slots) over `intervals` integrated
        input intervals: with none, nothing was estimated and the errors are NaN (their slots'
        0 is no measurement). The force scale cannot tell: a body tumbling free on mounts that
        carry no force has one of 0 and an attitude error estimated at every interval."""
        scale, estimated = figures[FORCE_SCALE], intervals > 0
        return cls(
            float(figures[FORCE_ERROR] / scale) if estimated and scale > 0.0 else math.nan,
            float(figures[FORCE_ERROR]) if estimated else math.nan,
            float(figures[ATTITUDE_ERROR]) if estimated else math.nan,
            int(figures[FAILURES]),
            int(figures[UNCARRIED]),
        )


def accumulate(total: np.ndarray, figures: np.ndarray) -> None:
    """Fold figures (as the core keeps them) into `total`: failures added, the rest maxima."""
    failures = total[FAILURES] + figures[FAILURES]
    np.maximum(total, figures, out=total)
    total[FAILURES] = failures
