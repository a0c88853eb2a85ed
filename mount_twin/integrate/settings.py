"""The slots of a stepper's `settings` vector, shared by every method's compiled `advance`, the
stepper holder and the engine's loop (the core's `mt::Setting` in src/core/constants.hpp:
test/test_core_contract.py holds the two equal)."""

from __future__ import annotations

(
    STEP,
    RTOL,
    ATOL,
    MAX_SUBSTEPS,
    CHAINED,
    MIN_STEPS,
    JACOBIAN_AGE,
    PHI_STEP,
    HOLD_AFTER_REJECT,
    N_SETTINGS,
) = range(10)
"""Slots of a stepper's `settings` vector: STEP the step size to try next (s; 0: none yet),
RTOL, ATOL (the state's units), MAX_SUBSTEPS per input interval, CHAINED: 1.0 after a
success, when work2d[0] holds dy/dt at the end state (FSAL); a caller that changes the input
between calls moves that stage to the new input and leaves the flag, or sets it to 0.0; and
MIN_STEPS, the fewest steps per input interval (no step longer than the interval / MIN_STEPS:
1 for the twin and for the error estimate's Verner companion, 2 for its checking
stepper and for a companion running the twin's own method); JACOBIAN_AGE, for methods that keep a
Jacobian: the input intervals it has served (0: none held); PHI_STEP, for the exponential
method: the step (s) its matrix functions of the Jacobian held were computed for (0: none);
HOLD_AFTER_REJECT, 1.0 where a step accepted right after a rejection may not propose a longer
one (the rule of Hairer's DOPRI5 code, Hairer, Nørsett & Wanner I, §II.4), 0.0 where it may
grow at once: the error estimate's companion holds (`engine.companion`), the twin does not."""
