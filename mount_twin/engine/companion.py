"""The live error estimate where the model has non-linear mounts: a companion solution of the
twin of a smaller error (models of linear mounts take the cheaper `engine.estimator`, which is
not cheaper here: on the bolted genset at rtol 1e-6 it read 0.92 of the true error at 2.8–3.3×
the engine's time; see there).

Richardson's global error estimate (Hairer, Nørsett & Wanner, *Solving Ordinary Differential
Equations I*, §II.4 and §II.12): the published solution y and a companion ŷ of smaller error;
y − ŷ is the published solution's error, not a bound on a local error norm (which is what the
stepper's `error_norm` is: it tracks rtol, not the error).

**Carried** (src/core/engine/kernel.hpp `carry_interval`). The companion is kept as the twin's
state plus its error e, and e is carried interval by interval, eₙ₊₁ = Φₙ(eₙ) + ℓₙ (the "Lady
Windermere's fan", *ibid.* §II.3), instead of integrated a second time:

- Φₙ by symplectic Euler through one right-hand side of the non-linear law itself: the rates'
  and internal states' errors are kicked by h·(f(t₀, y + e) − f(t₀, y)), then the body's
  position errors drift by h·(their rates' errors). f(t₀, y) is the twin's first stage
  (free); f(t₀, y + e) is taken at the end of the interval before in one pass with the
  companion's outputs (src/core/physics/dynamics.hpp `rhs_with_wrenches`), moved to the new
  input's Ω′ as the twin's chain moves its stage: one pass over the mounts an interval, where a
  kick at t₁ took a right-hand side and an evaluation of the outputs (256 Bouc–Wen mounts
  1.30× → 1.22× the engine's time). It is a difference of the law, not a linearisation: a
  snubber met or a key closed in the companion and not in the twin is in it, with no Jacobian
  and no switch rule. Symplectic Euler keeps a free mode's error amplitude where h·ω < 2; an
  interval is carried only where h times the body's fastest mode on its mounts' tangents
  (`Model.tangent_rate`, KICK_RATE) is within KICK_LIMIT = 1 (the bolted genset at 10 kHz:
  0.36; at 1 kHz, 3.6, carried it read 1e6 times its true error);
- a kind's rate-independent states are not kicked but returned by the kind's `carry` (a bolted
  joint's stick point onto its friction bound, its bolt's plastic elongation onto its yield
  line, where the twin's is there or the companion's passes it): kicked, a sliding face's
  stick point, whose rate turns with e as μ·F_K/k_τ goes to 0, read the genset 18.6 and 1090
  times its true error at rtol 1e-6 and 1e-8. The carry is taken in the pass of the outputs,
  before each mount's load, from its deflection there and the twin's in the twin's own pass
  (src/core/physics/dynamics.hpp `KindCarry`), where a pass of its own took both bodies'
  motions and two local motions a joint again;
- ℓₙ measured, not modelled: one step of the companion's stepper (below) from the twin's start
  state (its first stage the twin's, which the kick holds: one right-hand side less a check; 256
  Bouc–Wen mounts 1.20× against 1.22–1.24×, within an hour's noise) less the twin's end state,
  at every special interval (a rejected step, an error norm over SPIKE_RATIO times its running
  mean, the first after a restart; an interval in which an event function changes sign is
  integrated, below) and every half period of the body's fastest tangent mode, at most
  CARRY_CHECK_EVERY = 32 intervals apart (the genset at 10 kHz: 8); the intervals between add
  the last measured ℓ scaled by the twin's error norms (at most SPIKE_RATIO times; an interval's
  norm is its largest accepted one times its accepted steps). A check a rejection or a spike
  called for adds its own ℓ but is not the one scaled after it, nor does it put the next regular
  check off: at such an event (a Bouc–Wen mount turning, a contact) ℓ is tens of times what a
  smooth interval's norm predicts, and scaled onto the smooth ones after it 4 and 16 Bouc–Wen
  mounts under ship motion read 7.1 and 5.6 times their true error at rtol 1e-9 (1.05 and 0.93
  so; with the norm of the largest step alone, 64 mounts still 2.0). Checked every 32 intervals
  instead of 8, the genset under the bundled half-sine read 0.49 of its true error (every 17:
  0.53; every 8: 1.25 and 0.87 at rtol 1e-6 and 1e-8). Where the twin took one step over the
  interval, none rejected, the check is the stepper's fewest steps, every one taken
  (`integrate.stepper.advance_fixed`): a step of Verner's 6th order as long as the twin's
  accepted 5th-order one, or two of the twin's own method half as long (error 1/64 of the
  twin's), the same argument as one integrated step an interval below; two of the twin's own
  half as long where a mount's law has kinks no event marks (a Bouc–Wen state's rate turns with
  |ẋ|: there one Verner step's own error is no small share of the twin's, KINKED_CHECK). Held to
  its tolerance (rtol/8 on its 5th-order estimate, not on the error it has), the check took 4
  steps a check on 256 Bouc–Wen mounts, 169 of its 523 rejected, and cost the estimate 0.15× of
  the engine's time (1.44× → 1.30×). Added where it is committed, ℓ is then carried by Φ like
  the rest, damped and turned as the motion damps and turns it. Counting the skipped intervals
  into the next measured ℓ instead, in phase, read 0.46–0.53 of the true error under the real
  47 g record at rtol 1e-3 and 1e-5 (checks 8 and 32 apart), by their number 1.8–9.3 times it.

Where the twin runs a linearising method, where the interval is too long for the kick, where
the kick meets a stiffness past its reach on some coordinate k of the body (h²·|Δaₖ| over
KICK_LIMIT²·|eₖ|, the core's `in_reach`: a snubber driven far past its gap stiffens the body
beyond the open tangents KICK_RATE is taken on), over an interval in which an event function
changes sign (a contact closing or opening inside it, which a kick from its start does not
see: snubbers of 1e10 and 1e11 N/m^1.5 at 1 kHz read 1.2e5 and 1e35 times their true error
carried, 0.92–1.19 at rtol 1e-3 and 1e-6 integrated there), where y + e is off the α/γ/δ
chart, and over an interval that starts with an event holding that its kind does not carry
through (its EVENT_COMPANION, `kinds.COMPANION_TREATMENTS`; `treatments`: any of a bolted
joint's, flowing, open, slipping or broken, and a snubber in contact), the companion is
integrated over the interval as below, from the twin's state plus e, and carried again after
it. A Hertzian snubber in contact stiffens through the interval past the kick taken at its
start, which the reach at the start cannot see: carried there, rubber on snubbers of 1e9
N/m^1.5 at 1 kHz read 2.22, 0.20 and 19.6 times its true force error at rtol 1e-3, 3e-4 and
1e-5 (attitude 48 times at 1e-5), and 1e10 N/m^1.5 5.0 at 3e-5; integrated, 0.89–1.03 and
0.80–1.23 at rtol 7e-4 … 1e-7, the 10 kHz rubber on snubbers and the real shock at 1.17–1.27×
the engine's time (1.10–1.17× carried).
The companion's own events are seen after the kick: where one of its event functions changed
sign over a carried interval (its snubber met inside it, where the twin's was not: the
monitors at the interval's start see neither), the interval is taken again from the
companion's start, integrated, its steps halved as over the twin's crossings. Carried across,
rubber on 1e10 N/m^1.5 snubbers at 1 kHz, its twin 32–33 % off in force at rtol 1e-3 and
looser, read 3.17 and 2.68 times its true attitude error at rtol 3e-3 and 1e-3 (the companion
integrated at every interval read 0.99 and 1.01); 0.96 and 0.95 so, and 0.72–1.10 for the
snubbers of 1e9, 1e10 and 1e11 N/m^1.5 at rtol 3e-3 … 1e-8 (force 0.60–1.15).

The sign matters where the two meet: e is the companion less the twin, so ℓ is added as the
check's end state less the twin's. Added the other way round (until 2026-11-28), the carried
companion was the twin's mirror image, its error the true one with the sign turned, which the
estimate's magnitudes do not see while Φ is linear; integrated from the mirror over an
interval, the mirrored error and the new local one half cancelled (rubber on snubbers read
0.50 of its true error so).

Measured against a reference (`python3 bench/error_estimate.py`; docs/scene.md "Error estimate" and
docs/benchmarks.md have the table), it reads 0.67–1.73 of the true force error on the genset (under
its shock bag and two synthesised 30 g shocks), rubber on snubbers (at 10 kHz, and at 1 kHz on
snubbers of 1e9 to 1e11 N/m^1.5), hysteresis with snubbers under the real shock and 4 to 256
Bouc–Wen elastomers at rtol 1e-3 … 1e-9 (2026-11-28 evening; the 1 kHz snubbers from 3e-3 to
1e-8), at 1.0–2.6× the engine's time (1.1–1.7× at rtol 1e-6), where the
companion integrated at every interval read 0.69–1.08 at 1.4–2.1×: its work an interval is one pass
over the mounts (a right-hand side with the outputs) and, at a special interval or every half
period, one step of the check, where the integrated companion's was 8 right-hand sides at least,
more across the joints' switches. On the genset most of what is left is the intervals it is
integrated over: 305 of 2 499 under its shock, 0.42 of the twin's right-hand sides, 0.22 in the
58 whose crossings are halved (below; an instrumented build, docs/benchmarks.md).

**Integrated** (over the intervals above): the same model integrated beside the twin with rtol and
atol divided by TOLERANCE_DIVISOR = 8. Where the twin's steps are set by the samples, not its
tolerance (one step an interval), one step of the twin's own method would be the twin again (the
estimate 0): where the twin runs Dormand–Prince 5(4) the companion runs Verner's 6(5) pair
(`integrate.verner65`) at least one step an interval (a 6th-order step of the same length: its
error a small share of the twin's; 8 new right-hand sides a step); where the twin runs a
linearising method it runs that method at least MIN_STEPS = 2 steps an interval (HIGHER,
`own_method`; `switch` follows the twin), but beside the Rosenbrock on a scene whose stiff
modes are its linear mounts' (`Model.linear_stiffness`), where it runs the exponential method at
one step (EXACT_ON_LINEAR: the Rosenbrock damps the stiff modes, its own companion too). On
other scenes beside the Rosenbrock it runs the exponential method at one step over an interval
whose twin steps were longer than 2/ω of the body's fastest mode on the twin's Jacobian
(`exact_method`, kernel.hpp `stepped_over`, Stepping EXACT; its Jacobian and φ functions kept
over consecutive such intervals): there the Rosenbrock damps that mode (|R(2i)| = 0.88 a step),
and its own companion's steps, shorter but damping too, left the error of it out. 10 kg on four
1e9 N/m Bouc–Wen elastomers of strong hysteresis under 1 kHz ship motion read 0.29, 0.08 and
0.64 of its true force error at rtol 1e-3, 1e-4 and 1e-5 by the Rosenbrock's own companion
(at twelve steps an interval still 0.17), 1.08–1.09 so, at 1.34–1.40× the engine's time
against 1.44–2.18×; the stiff scene beside a snubbed elastomer 0.28, 0.18 and 0.76, and 1.00
so, at 0.92–1.07× (docs/scene.md has the table). Beside a stiff key or snubber no interval is
stepped over, so nothing changes there. This stepper is also the carried error's check.
Where a joint's faces switch inside the steps (an interval that starts with a joint's event
holding, its treatment "switching", over which the twin's tolerance bound its steps: more than
one, or one rejected), the companion runs the twin's own method at MIN_STEPS steps at least
instead (`switching_method`):
there a step's error jumps with its length whatever its order, so a higher order saves few
steps, and a step costs what its stages cost, 6 new right-hand sides where Verner's take 8. On the
genset under its shock the intervals integrated with a joint's event holding took 9 840
right-hand sides by Verner's pair, 6 332 so (the twin's whole run 18 609), and the estimate's
cost went from 1.67–1.68× to 1.53–1.54× (best of 5 at rtol 1e-6, alternating with the tree
before), its estimate 0.89–0.99 of the true force error at rtol 1e-3 … 1e-9 (0.90–1.01 before),
its attitude 0.86–1.12.
Taken wherever the twin's tolerance bound its steps, snubbers, contacts and all, the rubber on
snubbers of 1e9 N/m^1.5 at 1 kHz read 0.42 of its true error at rtol 1e-6 (attitude 0.32 at
1e-3): beside the twin's own method the companion's errors follow the twin's where a contact,
not a friction bound, sets the steps. So a snubber in contact is "integrated", by the
companion's own method: as "switching", 1e10 N/m^1.5 read 0.54 at rtol 1e-5 (0.97 so).
Over an integrated interval in which an event function changes sign (a joint opening or a face
starting to slip inside it; a carried interval over which one of the companion's own changed
sign, taken again) the companion takes twice its fewest steps (kernel.hpp `halved`), whatever
holds: a step across the switch misjudges its error, so the companion's one step there erred as
the twin's did, and the difference missed it. The genset under a vertical shock synthesised to
60 g at 300 Hz (`mount-twin synthesize`, seed 0) read 0.44 and 0.28 of its true force error at
rtol 1e-3 and 1e-5 (integrated throughout by the old rule, 0.52 and 0.35; by the switching
method at its 2 steps, 0.66 and 0.28), 0.69 and 0.89 by Verner's pair at 2 steps; its cost
under its own shock bag 1.52–1.54× → 1.65–1.69× (best of 5 at rtol 1e-6, alternating with a
tree of 17db827), its real-time factor 22.7× → 20.9×. Where the event is a joint's (its
treatment "switching"), the twice is of the switching method's steps (`switching_method`,
Dormand–Prince at 4 steps at least beside Dormand–Prince): across its faces' switches, as where
they switch inside the steps, a step's error falls about as its length whatever its order, so
a step costs what its stages cost. Over the genset's 58 halved intervals under its shock
Verner's pair took 528 steps and had 431 rejected, 7 672 right-hand sides (46 % of the
companion's); now Dormand–Prince 408 and 189 over the 55 where a joint's event crossed, 3 582,
and Verner's pair 432 over the other 3 (an instrumented build). The estimate's cost went from
1.64–1.70× to 1.50–1.56× (as shipped, `bench/bench_engine.py`, three rounds alternating with a
tree of bad7234), the genset's real-time factor from 17.1–18.1× to 19.4–20.0×; the synthesised
shock read 0.60–0.87 of its true force error at rtol 3e-3 … 2e-9 (attitude 0.62–0.88; seed 1
0.84–1.04), the genset under its shock 0.76–0.98 (attitude 0.73–1.37), under the half-sine
0.88–1.24 (2026-11-29). Elsewhere (a contact) it is of the companion's own method's steps:
halved by Dormand–Prince too, rubber on snubbers of 1e10 N/m^1.5 at 1 kHz read 0.59 and 0.55 of
its true force error at rtol 1e-4 and 1e-5 (0.88 and 0.91 so), as a contact "switching" read
above. A carried interval over which the twin's event function changed sign is integrated from
the carried state at the companion's fewest steps still: halved too it read the same and cost
more.

Right after a rejected step the companion grows no step (`integrate.settings` HOLD_AFTER_REJECT,
the rule of Hairer, Nørsett & Wanner's DOPRI5 code): on the bolted genset under its shock the
joints' faces between sticking and sliding make the error of a step jump with its length, and a
step grown at once from one accepted with a tiny error was rejected again, and again. Verner's
"most efficient" 6(5) pair was tried first and dropped: its weights of ±176 on stages 0.05 % of a
step apart make its error estimate's rounding, ε·176·|f|·h, dominate at tight tolerances. With
Verner's pair a divisor of 4 reads 0.71 of the true error at rtol 1e-3 on the genset (8: 0.89), 2
reads 0.57 (docs/benchmarks.md).

Both read the same held input, take the same discrete mount switches between samples, and
restart with the twin. `integration.error_estimate: false` turns the estimate off. It never
touches the twin's state: the published numbers are identical with it on or off
(test/test_error_estimate.py).

Its figures, kept as `engine.estimate` lays them out, are running maxima since the engine last
read them: the largest |ΔF| over mounts and force components (N, mount axes), the largest
|Δα|, |Δγ|, |Δδ| (rad), the largest |F| component of the twin (N: the scale of a relative
error), and the intervals where the companion's own stepper (or its check) failed (FAILURES: it
is then re-synchronised to the twin, the error carried until then is lost, and the estimate
counts it); it carries every state (UNCARRIED stays 0).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from mount_twin import _core
from mount_twin.engine.estimate import (
    N_FIGURES,
)
from mount_twin.integrate.methods import AUTO, DOPRI54, EXPRB32, METHODS, ROS34PW2, VERNER65
from mount_twin.integrate.settings import MAX_SUBSTEPS
from mount_twin.integrate.settings import MIN_STEPS as MIN_STEPS_SLOT
from mount_twin.integrate.stepper import forget, tighter_arrays
from mount_twin.physics.dynamics import Scratch

TOLERANCE_DIVISOR = 8.0
"""The companion's rtol and atol are the twin's over this (see the module docstring)."""
MIN_STEPS = 2
"""The companion's fewest steps per input interval where it runs the twin's own method."""
KINKED_CHECK = (DOPRI54, 2)
"""A carried interval's check (method id, equal steps) where the twin took the interval in one
step and a mount's law has kinks no event marks (`Model.kinked`: a Bouc–Wen state's rate turns
with |ẋ| wherever a hysteretic axis's deflection rate turns): two of the twin's own steps of
half the length. One Verner step as long as the twin's, elsewhere the check, is not there the
small share of the twin's error its order promises, and the local error it measures falls
short: 16 and 64 Bouc–Wen elastomers under ship motion (β = 120, γ = 80) read 0.67 of their
true force error and 0.57 of their attitude error at rtol 1e-6, and 16 with β = 200, γ = 0 (the
|ẋ| term alone) 0.54 of the attitude error, where the companion integrated at every interval
read 0.94–1.08 and 0.97–1.12. Two Dormand–Prince half steps (error a quarter of the twin's
across a kink, 1/32 of it elsewhere) read 0.93, 0.98 and 1.14 there; over 4 to 256
elastomers and five β, γ settings 0.93–1.52 of the force error and 0.98–1.39 of the attitude
error, where one Verner step read 0.66–1.20 and 0.54–1.16, two Verner half steps 0.85–1.27 and
0.93–1.28 (16 right-hand sides a check, where these take 12 and one Verner step 8; 2026-11-29,
docs/benchmarks.md). Scenes without such a law keep Verner's one step (on the genset two would
add 1.3 ms to its core)."""
(
    Y_START,
    ERROR,
    TRIAL,
    RATE,
    TWIN_RATE,
    CHECK,
    LOCAL,
    N_ERROR_ROWS,
) = _core.ERROR_ROWS
"""Rows of `Companion.error_rows` (src/core/engine/kernel.hpp ErrorRow says what each holds)."""
(
    CARRYING,
    SINCE_CHECK,
    CHECK_NORM,
    NORM_MEAN,
    INTERVALS,
    KICK_RATE,
    RATED,
    TWIN_RATED,
    EXACT_HELD,
    N_CARRY_SLOTS,
) = _core.CARRY_SLOTS
"""Slots of `Companion.carry` (src/core/engine/kernel.hpp CarrySlot)."""
HIGHER = {DOPRI54: VERNER65}
"""The companion's method where the twin's is a key (ids): one step of it an interval is a
different solution of a smaller error, where one of the twin's own would be the twin again."""
EXACT_ON_LINEAR = {ROS34PW2: EXPRB32}
"""The companion's method where the twin's is a key (ids) on a scene whose stiff modes are its
linear mounts' (`Model.linear_stiffness`: no mount's law has pieces, the non-linear mounts
soft), at one step an interval: the Rosenbrock steps over the stiff modes by damping them, and
a companion by the Rosenbrock damps them too; the exponential method is exact on the linear
part. On 10 kg on 4 × 1e9 N/m beside a soft Bouc–Wen elastomer under 1 kHz ship motion the
Rosenbrock's own companion read 0.28, 0.88 and 0.85 of the true force error at rtol 1e-3, 1e-6
and 1e-9; this one 1.00, 1.00, 1.00 (2026-11-29). Where a law has pieces it is the worst method
there is as the companion throughout: beside a 1e9 N/m key or snubber at 1 kHz it read 17–381
times the true error (docs/scene.md), so the Rosenbrock's own it stays, but over an interval
whose twin steps passed over the body's fastest mode, where the Rosenbrock's own reads a
fraction of the error (`exact_method`)."""


def own_method(twin: int, linear_stiffness: bool) -> tuple[int, int]:
    """(method id, fewest steps per input interval) of the companion of a twin running the
    method `twin` (an id) on a scene whose stiff modes are its linear mounts' or not
    (`linear_stiffness`): a higher-order method at one step (HIGHER), where they are the one
    exact on the linear part at one step (EXACT_ON_LINEAR), else the twin's at MIN_STEPS."""
    if linear_stiffness and twin in EXACT_ON_LINEAR:
        return EXACT_ON_LINEAR[twin], 1
    return (HIGHER[twin], 1) if twin in HIGHER else (twin, MIN_STEPS)


def exact_method(twin: int, linear_stiffness: bool) -> int:
    """The method (an id) the companion of a twin running `twin` (an id) takes at one step over
    an interval whose twin steps were longer than the body's fastest mode allows (kernel.hpp
    `stepped_over`): EXACT_ON_LINEAR's, where that is not its own already (`own_method`); -1
    where there is none (an explicit twin's steps are bound to its fastest mode)."""
    exact = EXACT_ON_LINEAR.get(twin, -1)
    return -1 if exact == own_method(twin, linear_stiffness)[0] else exact


def fixed_check(kinked: bool) -> tuple[int, int]:
    """(method id, equal steps) of a carried interval's check where the twin took the interval
    in one step, on a scene whose mounts' laws have kinks no event marks or not (`kinked`,
    `Model.kinked`): KINKED_CHECK, else one step of Verner's 6th order (HIGHER's of the twin's
    Dormand–Prince, the only twin beside which the error is carried)."""
    return KINKED_CHECK if kinked else (HIGHER[DOPRI54], 1)


def switching_method(twin: int, linear_stiffness: bool) -> tuple[int, int]:
    """(method id, fewest steps per input interval) of the companion of a twin running the
    method `twin` (an id) over an interval where a bolted joint's faces switch inside the
    steps (an event holds that the companion is integrated over, and the twin's tolerance bound
    its steps), and at twice those steps over one in which an event function changes sign: the
    twin's own at MIN_STEPS (see the module docstring); where the stiff modes are the linear
    mounts' (no joint) the companion's own (`own_method`)."""
    if linear_stiffness and twin in EXACT_ON_LINEAR:
        return own_method(twin, linear_stiffness)
    return twin, MIN_STEPS


class Companion(NamedTuple):
    """The companion solution's stepper, state and work arrays (the core's loop advances it
    after the twin at every sample: `follow` in src/core/engine/kernel.hpp).

    method, settings, work2d, work1d, result: its stepper (`integrate.stepper.Stepper`).
    switching_method, switching_min_steps: the method (an id) and fewest steps it takes
    instead, with the same arrays, over an interval where a joint's faces switch, and at twice
    those steps across an event's crossing (`switching_method`).
    exact_method: the method (an id) it takes at one step, with the same arrays, over an
    interval whose twin steps passed over the body's fastest mode (`exact_method`; -1: none).
    check_method, check_steps: the method (an id, explicit) and equal steps, every one taken, of
    a carried interval's check where the twin took the interval in one step: Verner's at one,
    or KINKED_CHECK where a mount's law has kinks no event marks (`fixed_check`).
    y: (n_state,) its state; s: its scratch (its angles at the last sample: s.q[3:6]);
    y_prev, g, util: its mount monitors' arrays (its switches are taken with them); g_prev:
    g at a carried interval's start, while its end is monitored (the interval is integrated
    again where one of its event functions changed sign over it).
    wrenches: (n_mounts, 6): its mount wrenches at the last sample.
    figures: (N_FIGURES,) running maxima (see the module docstring), reset by the reader.
    error_rows: (N_ERROR_ROWS, n_state) the carried error's rows; carry: (N_CARRY_SLOTS,) its
    slots; treatments: (k, NE) how it takes an interval that starts with the event holding
    (in the twin's monitors or its own): the core's code of its kind's EVENT_COMPANION
    (`kinds.COMPANION_TREATMENTS`); twin_d: (k, 3) the twin's mount deflections (m, their
    axes) at the sample, from the twin's own pass over its mounts, where the kinds' carry reads
    them.
    linear_stiffness: whether the scene's stiff modes are its linear mounts'
    (`Model.linear_stiffness`: which method is its own, `own_method`).
    """

    method: int
    settings: np.ndarray
    work2d: np.ndarray
    work1d: np.ndarray
    result: np.ndarray
    switching_method: int
    switching_min_steps: int
    exact_method: int
    check_method: int
    check_steps: int
    y: np.ndarray
    s: Scratch
    y_prev: np.ndarray
    g: np.ndarray
    g_prev: np.ndarray
    util: np.ndarray
    wrenches: np.ndarray
    figures: np.ndarray
    error_rows: np.ndarray
    carry: np.ndarray
    treatments: np.ndarray
    twin_d: np.ndarray
    linear_stiffness: bool


def new_companion(
    method: str,
    n: int,
    rtol: float,
    atol: float,
    max_substeps: int,
    scratch: Scratch,
    n_mounts: int,
    treatments: np.ndarray,
    kick_rate: float,
    *,
    linear_stiffness: bool,
    kinked: bool,
) -> Companion:
    """A companion of a twin of n states integrated by `method` (a name, or AUTO: then
    `switch` it with the twin) at the twin's tolerances rtol, atol; `scratch`: fresh work
    arrays of the model; treatments: (non-linear mounts, events), the shape of the twin's mount
    event functions, how the companion takes an interval that starts with the event holding
    (`Companion.treatments`); kick_rate: the body's fastest mode on its mounts' tangents (rad/s,
    `Model.tangent_rate`; 0 where unknown: then never carried); linear_stiffness: whether the
    scene's stiff modes are its linear mounts' (`Model.linear_stiffness`); kinked: whether a
    mount's law has kinks no event marks (`Model.kinked`: its checks, `fixed_check`)."""
    twin = METHODS["dopri54" if method == AUTO else method].id
    own, min_steps = own_method(twin, linear_stiffness)
    exact = exact_method(twin, linear_stiffness)
    # arrays that hold every method where it may take another than its own
    name = (
        AUTO
        if method == AUTO or exact >= 0
        else next(k for k, m in METHODS.items() if m.id == own)
    )
    arrays = tighter_arrays(
        name,
        n,
        rtol,
        atol,
        max_substeps,
        TOLERANCE_DIVISOR,
        min_steps,
        hold_after_reject=True,
    )
    carry = np.zeros(N_CARRY_SLOTS)
    carry[KICK_RATE] = kick_rate
    return Companion(
        own,
        *arrays[1:],
        *switching_method(twin, linear_stiffness),
        exact,
        *fixed_check(kinked),
        np.zeros(n),
        scratch,
        np.zeros(n),
        np.full(treatments.shape, -1.0),
        np.full(treatments.shape, -1.0),
        np.zeros(treatments.shape[0]),
        np.zeros((n_mounts, 6)),
        np.zeros(N_FIGURES),
        np.zeros((N_ERROR_ROWS, n)),
        _reset_carry(carry, own),
        np.array(treatments, dtype=float),
        np.zeros((treatments.shape[0], 3)),
        linear_stiffness,
    )


def _reset_carry(carry: np.ndarray, method: int) -> np.ndarray:
    """`carry` (returned) as a companion (re)started running `method` (an id) has it: carried
    where that is Verner's pair, the check of an explicit twin, and the body's fastest tangent
    mode is known (KICK_RATE > 0; the core carries only beside an explicit twin, and only over
    intervals short enough for it, whatever this says); no local error measured yet."""
    rate = carry[KICK_RATE]
    carry[:] = 0.0
    carry[CARRYING] = 1.0 if method == VERNER65 and rate > 0.0 else 0.0
    carry[CHECK_NORM] = -1.0
    carry[KICK_RATE] = rate
    return carry


def switch(c: Companion, method: int) -> Companion:
    """The companion of a twin now running `method` (an id; its work arrays were made for AUTO)
    afresh: its own method and fewest steps (`own_method`), at most MAX_SUBSTEPS of the twin's
    per step of its fewest, and its method where a joint's faces switch (`switching_method`)."""
    own, min_steps = own_method(method, c.linear_stiffness)
    settings = c.settings
    settings[MAX_SUBSTEPS] *= min_steps / settings[MIN_STEPS_SLOT]
    settings[MIN_STEPS_SLOT] = float(min_steps)
    forget(settings)
    _reset_carry(c.carry, own)
    switching, fewest = switching_method(method, c.linear_stiffness)
    return c._replace(
        method=own,
        switching_method=switching,
        switching_min_steps=fewest,
        exact_method=exact_method(method, c.linear_stiffness),
    )


def restart(c: Companion, y: np.ndarray) -> None:
    """Start the companion again from the twin's state y (a twin start or restart): its error
    zero, carried again where its method is the check of an explicit twin, its local error
    measured afresh."""
    c.y[:] = y
    c.y_prev[:] = y
    forget(c.settings)
    _reset_carry(c.carry, c.method)
