// The per-sample loop: integrate a run of accepted samples, evaluate the outputs, watch the
// mounts' events and step the live error estimate (engine/kernel.py and engine/estimator.py
// hold the Python side: the same fields, what they mean, who owns them).
#pragma once

#include <cmath>
#include <cstring>

#include "../constants.hpp"
#include "../integrate/control.hpp"
#include "../integrate/stepper.hpp"
#include "../model.hpp"
#include "../numeric.hpp"
#include "../physics/dynamics.hpp"
#include "estimator.hpp"
#include "integrator.hpp"

namespace mt::engine {

/// Event watch over the non-linear mounts (engine/kernel.py Watch).
struct Watch {
  Mat g_prev, g;
  Vec util, util_peak;
  Mat events;        // (cap, 4) [crossing time s, mount slot, event index, |force| N]
  idx* n_events;     // (1,) rows written (may exceed cap)
  Vec y_prev;
  const double* stop_after;  // (1,) s; inf: never
  Mat stiffens;      // (k, NE) 1.0 where an event may stiffen the scene
  idx* n_stiffening;  // (1,)
};

/// The input of one run: row 0 is the last sample already done (engine/kernel.py Samples).
struct Samples {
  Vec t;  // (n,) s
  M3 f;  // (n, 3) specific force, m/s², F
  M3 w;  // (n, 3) foundation Ω, rad/s, F
};

struct RunOptions {
  bool zero_order = false;
  idx decimation = 1;
  bool chain = false;
};

/// What a run publishes and the decimation's carried state (engine/kernel.py Published).
struct Published {
  idx* counter;
  M6 peak;       // (nm, 6)
  MatC<pose_row::WIDTH> pose;  // (n, WIDTH)
  StackC<6> wrenches;  // (n, nm, 6)
  bool* publish;  // (n,)
  Mat step_log;   // (n, 3)
  M6 wrench_abs_max;  // (nm, 6)
  double* cos_tilt_min;  // (1,)
  Vec lin_util;        // (n_lin,) running maxima of the linear mounts' utilisation
};

/// The error estimate's companion solution, where the model has non-linear mounts
/// (engine/companion.py Companion; engine/estimator.py says why).
struct Companion {
  Integrator integ;
  int switching_method;        // where a joint's faces switch inside the steps (`follow`) ...
  double switching_min_steps;  // ... this method, at least this many steps, in integ's arrays
  int exact_method;  // where the twin's steps passed over the body's fastest mode, this one at
                     // one step at least, in integ's arrays (-1: none; `stepped_over`)
  int check_method;     // a carried interval's check where the twin took one step: this
  double check_steps;   // explicit method at this many equal steps, every one taken
                        // (`add_local_error`), in integ's arrays
  Vec y;
  Scratch s;
  Vec y_prev;
  Mat g;
  Mat g_prev;  // g at the interval's start, while a carried interval's end is monitored
  Vec util;
  M6 wrenches;
  Vec figures;  // (N_FIGURES,)
  Mat error_rows;  // (N_ERROR_ROWS, n): the carried error's work rows (ErrorRow)
  Vec carry;    // (N_CARRY_SLOTS,): CarrySlot
  Mat treatments;  // (k, NE): how an interval that starts with the event holding is taken
  Mat twin_d;  // (k, 3) m: the twin's mount deflections at the sample, in their axes (the
               // kinds' carry reads them: `carry_interval`)
};

/// Rows of Companion.error_rows (engine/companion.py ERROR_ROWS).
enum ErrorRow : int {
  Y_START = 0,  // the twin's state at the interval's start
  ERROR,        // the companion's state less the twin's, e
  TRIAL,        // the twin's end state plus e before the kick (the kinds' carry reads it)
  RATE,         // the right-hand side at the companion's state (RATED)
  TWIN_RATE,    // the twin's at the interval's start: its first stage (TWIN_RATED)
  CHECK,        // the check's end state
  LOCAL,        // the last measured local error
  N_ERROR_ROWS
};

/// Slots of Companion.carry (engine/companion.py CARRY_SLOTS).
enum CarrySlot : int {
  CARRYING = 0,  // 1: the error may be carried (an explicit twin: `carries`); 0: integrated
  SINCE_CHECK,   // carried intervals since the local error was last measured
  CHECK_NORM,    // the twin's error norm at that interval (< 0: none measured since a restart)
  NORM_MEAN,     // running mean of the twin's error norms
  INTERVALS,     // carried intervals the mean has seen
  KICK_RATE,     // rad/s: the body's fastest mode on its mounts' tangents (model.tangent_rate)
  RATED,         // 1: RATE holds f at the companion's state, under the last interval's input
  TWIN_RATED,    // 1: TWIN_RATE holds the twin's f at the interval's start, under its input
  EXACT_HELD,    // 1: the stepper's settings hold exact_method's linearisation (`EXACT`)
  N_CARRY_SLOTS
};

/// A carried interval's local error is measured at least every CARRY_CHECK_EVERY intervals,
/// and every half period of the body's fastest tangent mode (engine/companion.py: between, the
/// last one scaled).
constexpr idx CARRY_CHECK_EVERY = 32;
/// h·ω of the fastest tangent mode above which an interval's error is not carried (the
/// companion is integrated over it): symplectic Euler is stable for h·ω < 2.
constexpr double KICK_LIMIT = 1.0;

/// After the mounts' monitors at a sample (`switched`: a discrete switch moved y): y into
/// y_prev; a switch clears the stepper's chain flag, its last stage not at this y. Returns
/// `switched`.
inline bool settle_switches(bool switched, Vec y, Vec y_prev, Vec settings) {
  if (switched) settings[CHAINED] = 0.0;
  copy(y, y_prev);
  return switched;
}

/// Whether an event function changed sign from g0 to g1: one of them below 0, the other not.
inline bool crossed(double g0, double g1) { return (g0 < 0.0) != (g1 < 0.0); }

/// Whether any event function changed sign from g0 to g (the same shape).
inline bool sign_changed(const Mat g0, const Mat g) {
  for (idx i = 0; i < g.rows * g.cols; ++i) {
    if (crossed(g0.d[i], g.d[i])) return true;
  }
  return false;
}

/// After the monitors at t1 (w.g, w.util; `switched` as `settle_switches` returns it), log
/// each upward zero crossing of an event function since t0 (located by linear interpolation).
/// Returns `Watched` bits.
inline int log_crossings(bool switched, const NonLinear& nl, Watch& w, double t0, double t1,
                         M6 wrenches) {
  bool changed = switched, engaged = false;
  for (idx i = 0; i < w.g.rows; ++i) {
    w.util_peak[i] = py_max(w.util_peak[i], w.util[i]);
    for (idx e = 0; e < w.g.cols; ++e) {
      const double g0 = w.g_prev(i, e), g1 = w.g(i, e);
      w.g_prev(i, e) = g1;
      changed = changed || crossed(g0, g1);
      engaged = engaged || g1 >= 0.0;
      if (g0 < 0.0 && 0.0 <= g1) {
        if (w.stiffens(i, e) > 0.0) *w.n_stiffening += 1;
        const idx k = *w.n_events;
        *w.n_events += 1;
        if (k < w.events.rows) {
          const idx slot = nl.slot[i];
          const double* r = &wrenches(slot, 0);
          w.events(k, 0) = t0 + (t1 - t0) * (-g0) / (g1 - g0);
          w.events(k, 1) = static_cast<double>(slot);
          w.events(k, 2) = static_cast<double>(e);
          w.events(k, 3) = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        }
      }
    }
  }
  return (changed ? CHANGED : 0) | (engaged ? ENGAGED : 0);
}

/// The companion's outputs (its wrenches, its angles q[3:6]) against the twin's (pose,
/// wrenches at the sample) into its running figures.
inline void fold_figures(Companion& c, const Vec q, Vec pose, M6 wrenches) {
  const Vec figures = c.figures;
  double force = figures[FORCE_ERROR], scale = figures[FORCE_SCALE];
  for (idx a = 0; a < wrenches.rows; ++a) {
    for (int b = 0; b < 3; ++b) {
      force = py_max(force, std::fabs(wrenches(a, b) - c.wrenches(a, b)));
      scale = py_max(scale, std::fabs(wrenches(a, b)));
    }
  }
  double attitude = figures[ATTITUDE_ERROR];
  for (int i = 0; i < 3; ++i) {
    const int k = pose_row::ANGLES + i;
    attitude = py_max(attitude, std::fabs(pose[k] - q[3 + i]));
  }
  figures[FORCE_ERROR] = force;
  figures[FORCE_SCALE] = scale;
  figures[ATTITUDE_ERROR] = attitude;
}

/// How the companion takes an interval that starts with an event holding (Companion.treatments;
/// the kinds name them, `kinds.COMPANION_TREATMENTS`, bound to these codes): its error carried
/// through; integrated by its own method; integrated by its switching method where the twin's
/// tolerance bound its steps. In this order: the interval takes the highest code holding.
enum Treatment : int { CARRIED_THROUGH = 0, INTEGRATED = 1, SWITCHING = 2 };

/// The treatment of the interval: the highest of the events holding at its start, in the twin's
/// monitors g or the companion's (none: CARRIED_THROUGH).
inline int holding_treatment(const Companion& c, const Mat g) {
  double treatment = CARRIED_THROUGH;
  for (idx i = 0; i < c.treatments.rows; ++i) {
    for (idx e = 0; e < c.treatments.cols; ++e) {
      const double code = c.treatments(i, e);
      if (code > treatment && (g(i, e) >= 0.0 || c.g(i, e) >= 0.0)) treatment = code;
    }
  }
  return static_cast<int>(treatment);
}

/// Whether the twin's tolerance bound its steps over the interval, not the samples: it took
/// more than one, or rejected one (twin_result: its stepper's [error norm, accepted, rejected]).
inline bool twin_bound(const Vec twin_result) {
  return twin_result[1] > 1.0 || twin_result[2] > 0.0;
}

/// How the companion steps over an integrated interval (`companion_advance`), or CARRIED.
enum Stepping : int {
  CARRIED = -1,  // not integrated: its error carried over the interval (`carry_interval`)
  OWN = 0,    // its own method at its fewest steps
  SWITCHED,   // c.switching_method at least c.switching_min_steps steps
  HALVED,     // its own method at twice its fewest steps
  SWITCHED_HALVED,  // c.switching_method at twice c.switching_min_steps steps
  EXACT,      // c.exact_method at one step at least (`stepped_over`)
};

/// The highest treatment of the events whose function changed sign from g0 to g (the same
/// shape as c.treatments; none: CARRIED_THROUGH).
inline int crossed_treatment(const Companion& c, const Mat g0, const Mat g) {
  double treatment = CARRIED_THROUGH;
  for (idx i = 0; i < g.rows; ++i) {
    for (idx e = 0; e < g.cols; ++e) {
      if (crossed(g0(i, e), g(i, e))) treatment = py_max(treatment, c.treatments(i, e));
    }
  }
  return static_cast<int>(treatment);
}

/// How the companion takes an interval across an event's crossing (`crossed_treatment`
/// `crossing`): halved, by the switching method where a joint's faces switched, else by its own
/// (engine/companion.py says why).
inline Stepping halved(int crossing) {
  return crossing == SWITCHING ? SWITCHED_HALVED : HALVED;
}

/// Advance the companion's stepper over [t0, t1] from y (in place) with error control, as
/// `stepping` says (engine/companion.py says why: where a joint's faces switch between sticking
/// and sliding inside the steps, a step costs what its stages cost, not what its order saves;
/// where an event function changes sign inside the interval, a step across the switch misjudges
/// its own error, and its error, shrinking with its length, then is the twin's own: halved).
/// Both methods are first-same-as-last: settings[CHAINED]'s stage holds for either.
inline int companion_advance(const Model& m, Companion& c, Vec y, double t0, double t1, Vec u,
                             Stepping stepping) {
  const Integrator& g = c.integ;
  const Vec settings = g.settings;
  const double min_steps = settings[MIN_STEPS], max_steps = settings[MAX_SUBSTEPS];
  int method = g.method;
  double fewest = min_steps;
  switch (stepping) {  // every Stepping (-Wswitch): one added is taken here or warned of
    case OWN:
      break;
    case SWITCHED:
      method = c.switching_method;
      fewest = c.switching_min_steps;
      break;
    case HALVED:
      fewest = 2.0 * min_steps;
      break;
    case SWITCHED_HALVED:
      method = c.switching_method;
      fewest = 2.0 * c.switching_min_steps;
      break;
    case EXACT:
      method = c.exact_method;
      fewest = 1.0;
      break;
    case CARRIED:  // a carried interval is not integrated: asked to, a caller's mistake, failed
      return UNKNOWN_METHOD;  // (`follow` resynchronises; the estimate counts the failure)
  }
  const double exact = stepping == EXACT ? 1.0 : 0.0;
  if (c.carry[EXACT_HELD] != exact) {  // the other method's Jacobian and φ functions: not ours
    settings[JACOBIAN_AGE] = 0.0;
    settings[PHI_STEP] = 0.0;
    settings[CHAINED] = 0.0;
    c.carry[EXACT_HELD] = exact;
  }
  if (method == g.method && fewest == min_steps) {  // its own stepping: nothing to set
    return integrate::advance(method, y, t0, t1, settings, m, c.s, u, g.work2d, g.work1d,
                              g.result);
  }
  settings[MIN_STEPS] = fewest;
  settings[MAX_SUBSTEPS] = max_steps * fewest / min_steps;
  const int status = integrate::advance(method, y, t0, t1, settings, m, c.s, u, g.work2d,
                                        g.work1d, g.result);
  settings[MIN_STEPS] = min_steps;
  settings[MAX_SUBSTEPS] = max_steps;
  return status;
}

/// The companion set back onto the twin's state y after a failure, which the estimate counts.
inline void resynchronise(Companion& c, Vec y) {
  copy(y, c.y);
  copy(y, c.y_prev);
  integrate::forget(c.integ.settings);
  c.figures[FAILURES] += 1.0;
}

/// A step of the Rosenbrock longer than this over the body's fastest mode's rate (rad/s) damps
/// that mode by more than a tenth (|R(2i)| = 0.88; R its stability function, L-stable).
constexpr double STEP_OVER = 2.0;

/// Whether the twin's steps over an interval of h (twin: its stepper after them) were longer
/// than STEP_OVER over the body's fastest mode on the Jacobian it holds (`fastest_rate`: a key
/// bearing and a snubber pressed count, not one open), where it runs the Rosenbrock and the
/// companion has an exact method (Companion.exact_method): the Rosenbrock damps such a mode
/// (L-stable) and its error estimate does not see it, so a companion by the Rosenbrock too
/// damps it as the twin does, and its error is in neither (engine/companion.py).
inline bool stepped_over(const Model& m, const Companion& c, const Integrator& twin, double h) {
  if (c.exact_method < 0 || twin.method != ROS34PW2) return false;
  const idx n = c.y.n, nf = m.free_trans.n + m.free_rot.n;
  const Mat jac{&twin.work2d(integrate::ros34pw2::J0, 0), n, n};
  return fastest_rate(jac, nf) * h > STEP_OVER * twin.result[1];
}

/// Advance the companion over [t0, t1] under the input u the twin just took
/// (`companion_advance`, as `stepping` says), take its mounts' switches, and fold the
/// differences of its outputs from the twin's (pose, wrenches at t1; y the twin's state): its
/// wrenches and angles, what the estimate compares (no pose row).
inline void follow(const Model& m, Companion& c, Vec u, double t0, double t1, bool chain,
                   Stepping stepping, Vec d_wdot, Vec pose, M6 wrenches, Vec y) {
  const Vec settings = c.integ.settings;
  if (chain && settings[CHAINED] == 1.0) {
    physics::rhs_after_rate_step(m, c.s, d_wdot, c.integ.work2d.row(0));
  } else {
    settings[CHAINED] = 0.0;
  }
  if (companion_advance(m, c, c.y, t0, t1, u, stepping) != 0) {
    resynchronise(c, y);
    return;
  }
  // the body's motion at c.y: its last rhs; the monitors in the wrenches' pass
  physics::MonitorRows mon{c.y_prev, c.g, c.util};
  physics::mount_wrenches(c.y, m, c.s, c.wrenches, m.has_nl ? &mon : nullptr);
  if (m.has_nl) settle_switches(mon.switched, c.y, c.y_prev, settings);
  fold_figures(c, c.s.q, pose, wrenches);
}

/// Whether the companion carries its error over [t0, t1]: it says so (CARRYING), the twin's
/// method is explicit (a linearising twin's stiff modes would put the explicit kick out of its
/// stable range), the interval times the fastest rate of the body on its mounts' tangents
/// (KICK_RATE, rad/s) is within KICK_LIMIT, and no event its kind does not carry through holds
/// at t0 (`holding`: `holding_treatment` is not CARRIED_THROUGH).
inline bool carries(const Companion& c, int twin_method, double t0, double t1, bool holding) {
  return c.carry[CARRYING] == 1.0 && (twin_method == DOPRI54 || twin_method == VERNER65) &&
         (t1 - t0) * c.carry[KICK_RATE] <= KICK_LIMIT && !holding;
}

/// The local error the twin committed over the interval, added to e (the companion less the
/// twin, so the check's end state less the twin's: added the other way round, the companion
/// was the twin's mirror image, its error the twin's with the sign turned, which only a linear
/// carry leaves alone; where it was integrated next, from the mirror, the two halves cancelled,
/// docs/benchmarks.md): measured (c.check_method at c.check_steps steps, or the companion's
/// stepper at its tolerance where the twin's was bound by it, from the twin's start state, less
/// the twin's end state y) where the interval is special (the twin rejected a step,
/// its error norm passed SPIKE_RATIO times its running mean, or none was measured since a
/// restart), and every CARRY_CHECK_EVERY intervals or half a period of the fastest tangent
/// mode (KICK_RATE), whichever is fewer; between, the last measured one scaled by the twin's
/// error norms (at most SPIKE_RATIO times). The norm of an interval is the twin's largest
/// accepted one times its accepted steps (their errors add). A check the twin's rejection or
/// spike called for adds its own error but is not what the intervals after it scale, nor does it
/// put the next regular check off: there the error's ratio to the norm is the event's (a
/// Bouc–Wen mount turning, a contact), tens of times a smooth interval's (4 Bouc–Wen mounts
/// under ship motion at rtol 1e-9: 7.1 times the true error; docs/benchmarks.md). Returns false
/// where the measurement failed (nothing added).
inline bool add_local_error(const Model& m, Companion& c, Vec u, double t0, double t1,
                            const Vec twin_result, Vec y) {
  const Vec carry = c.carry, e = c.error_rows.row(ERROR), local = c.error_rows.row(LOCAL);
  const double norm = twin_result[0] * twin_result[1];
  carry[INTERVALS] += 1.0;
  const double mean = carry[NORM_MEAN], last = carry[CHECK_NORM];
  const bool spike = carry[INTERVALS] > 1.0 && norm > SPIKE_RATIO * mean;
  carry[NORM_MEAN] += (norm - mean) / py_min(carry[INTERVALS], 64.0);
  const bool by_event = twin_result[2] > 0.0 || spike;  // a rejection, or a spike
  const bool special = by_event || last < 0.0;
  carry[SINCE_CHECK] += 1.0;
  const double every = py_min(static_cast<double>(CARRY_CHECK_EVERY),
                              py_max(1.0, std::floor(M_PI / ((t1 - t0) * carry[KICK_RATE]))));
  if (special || carry[SINCE_CHECK] >= every) {
    const Vec check = c.error_rows.row(CHECK), settings = c.integ.settings;
    copy(c.error_rows.row(Y_START), check);
    // from the twin's start state under its input: its first stage is the twin's (TWIN_RATE,
    // which `carry_interval` holds before it comes here), one right-hand side a check saved
    copy(c.error_rows.row(TWIN_RATE), c.integ.work2d.row(0));
    settings[CHAINED] = 1.0;
    // the twin took one step over the interval, none rejected: c.check_method's c.check_steps
    // equal steps, every one taken (one of a higher order, or two of the twin's own half as long
    // where a law has kinks no event marks: engine/companion.py says why); else its stepper at
    // its tolerance
    const double min_steps = settings[MIN_STEPS];
    const bool bound = twin_bound(twin_result);
    if (!bound) settings[MIN_STEPS] = c.check_steps;
    const int status =
        bound ? integrate::advance(c.integ.method, check, t0, t1, settings, m, c.s, u,
                                   c.integ.work2d, c.integ.work1d, c.integ.result)
              : integrate::advance_fixed(c.check_method, check, t0, t1, settings, m, c.s, u,
                                         c.integ.work2d, c.integ.work1d, c.integ.result);
    settings[MIN_STEPS] = min_steps;
    if (status != 0) return false;
    if (by_event && last >= 0.0) {  // its own error, not the scaled one's template
      for (idx i = 0; i < y.n; ++i) e[i] += check[i] - y[i];
      return true;
    }
    for (idx i = 0; i < y.n; ++i) local[i] = check[i] - y[i];
    carry[CHECK_NORM] = norm;
    carry[SINCE_CHECK] = 0.0;
    for (idx i = 0; i < y.n; ++i) e[i] += local[i];
    return true;
  }
  // at most SPIKE_RATIO times what was measured; both norms 0: nothing committed
  const double scale = last > 0.0 ? py_min(norm / last, SPIKE_RATIO) : 0.0;
  for (idx i = 0; i < y.n; ++i) e[i] += scale * local[i];
  return true;
}

/// Whether a kick over h s is in symplectic Euler's reach on every free coordinate k of the
/// body: h²·|Δaₖ| within KICK_LIMIT²·|eₖ|, Δa the body's accelerations at the companion's state
/// less the twin's (`rate` less `twin_rate` in rows nf.., nf the free coordinates), e its
/// position error (e's first nf). h·ω squared along each coordinate, where a snubber driven far
/// past its gap or a key closed stiffens the body beyond the open tangents KICK_RATE was taken
/// on (rubber on snubbers of 1e10 N/m^1.5 at 1 kHz: carried past it, the estimate read 1.2e5
/// times the true error at rtol 1e-3). Taken over all coordinates at once, h²·|Δa|/|e|, the
/// snubber's axis hid behind the others' errors: 14 times the true error at rtol 1e-6, its
/// attitude 26 times. A coordinate coupled to a stiff one reads stiff too: integrated, safe.
inline bool in_reach(idx nf, double h, const Vec rate, const Vec twin_rate, const Vec e) {
  for (idx k = 0; k < nf; ++k) {
    const double a = std::fabs(rate[nf + k] - twin_rate[nf + k]);
    if (h * h * a > KICK_LIMIT * KICK_LIMIT * std::fabs(e[k])) return false;
  }
  return true;
}

/// The companion over [t0, t1] as the twin's state plus its error e, carried: eₙ₊₁ = Φ(eₙ) +
/// ℓₙ (engine/companion.py says why and what it read). Φ by symplectic Euler through one
/// right-hand side of the non-linear law itself, at the interval's start: the rates' and the
/// internal states' errors are kicked by h·(f(t₀, y + e) − f(t₀, y)), then the body's position
/// errors drift by h·(their rates' errors); the kinds' carry returns their rate-independent
/// states. ℓ by `add_local_error`. f(t₀, y) is the twin's first stage (TWIN_RATE, taken before
/// its step); f(t₀, y + e) the right-hand side taken with the companion's outputs at the end of
/// the interval before (RATE), moved to this interval's input as the twin's chain moves its
/// stage (d_wdot; `chain`), so that the interval takes one right-hand side in all. Where a
/// state is off the α/γ/δ chart, the kick is out of its reach (`in_reach`) or an event
/// function changed sign over the interval, the twin's or, after the kick, the companion's
/// own, the companion is to be integrated over it from c.y (`follow`, its stepper's chain
/// broken): returns how (a Stepping), else CARRIED.
inline Stepping carry_interval(const Model& m, Companion& c, Vec u, double t0, double t1,
                               bool chain, const Vec twin_result, int watched, Vec d_wdot,
                               Vec pose, M6 wrenches, Vec y) {
  const idx n = y.n, nf = m.free_trans.n + m.free_rot.n;
  const double h = t1 - t0;
  const Mat rows = c.error_rows;
  const Vec e = rows.row(ERROR), trial = rows.row(TRIAL), rate = rows.row(RATE);
  const Vec y_start = rows.row(Y_START), twin_rate = rows.row(TWIN_RATE);
  const Vec carry = c.carry;
  bool rated = chain && carry[RATED] == 1.0;
  if (rated) {
    physics::rhs_after_rate_step(m, c.s, d_wdot, rate);  // c.s: the companion's, from then
  } else {
    rated = physics::rhs(t0, c.y, m, c.s, u, rate) == OK;
  }
  if (rated && carry[TWIN_RATED] != 1.0) {
    rated = physics::rhs(t0, y_start, m, c.s, u, twin_rate) == OK;
  }
  carry[RATED] = 0.0;
  for (idx i = 0; i < n; ++i) e[i] = c.y[i] - y_start[i];
  // integrated where the kick is out of its reach, and where a mount switched or an event
  // function changed sign over the interval (a contact the kick from t₀ does not see)
  if (!(rated && in_reach(nf, h, rate, twin_rate, e)) || (watched & CHANGED) != 0) {
    c.integ.settings[CHAINED] = 0.0;
    return OWN;
  }
  for (idx i = 0; i < n; ++i) trial[i] = y[i] + e[i];
  for (idx i = nf; i < n; ++i) e[i] += h * (rate[i] - twin_rate[i]);
  for (idx k = 0; k < nf; ++k) e[k] += h * e[nf + k];
  if (!add_local_error(m, c, u, t0, t1, twin_result, y)) {
    resynchronise(c, y);
    return CARRIED;
  }
  for (idx i = 0; i < n; ++i) c.y[i] = y[i] + e[i];
  // the kinds' carry and the monitors in the outputs' pass (c.y_prev the state before: at the
  // interval's start; the twin's deflections from its own pass at y: c.twin_d)
  if (m.has_nl) copy(c.g.flat(), c.g_prev.flat());
  physics::MonitorRows mon{c.y_prev, c.g, c.util};
  const physics::KindCarry kinds_carry{trial, y, c.twin_d};
  if (physics::rhs_with_wrenches(t1, c.y, m, c.s, u, rate, c.wrenches,
                                 m.has_nl ? &mon : nullptr,
                                 m.has_nl ? &kinds_carry : nullptr) != OK) {
    if (m.has_nl) copy(c.g_prev.flat(), c.g.flat());  // as before the pass
    resynchronise(c, y);
    return CARRIED;
  }
  const bool switched = mon.switched;
  if (m.has_nl) {
    if (sign_changed(c.g_prev, c.g)) {
      // an event function of its own changed sign over the interval (a snubber met inside
      // it, which the kick from t₀ does not see: rubber on snubbers of 1e10 N/m^1.5 at 1 kHz
      // read 2.3–3.2 times its true attitude error at rtol 1e-3 and looser carried across,
      // 0.95–0.99 so): taken again, integrated from its start (y_prev, which the monitors
      // read as the state before), its steps halved as over the twin's crossings
      const Stepping stepping = halved(crossed_treatment(c, c.g_prev, c.g));
      copy(c.y_prev, c.y);
      copy(c.g_prev.flat(), c.g.flat());
      c.integ.settings[CHAINED] = 0.0;  // the check's stages are at the twin's state
      return stepping;
    }
    copy(c.y, c.y_prev);
  }
  carry[RATED] = switched ? 0.0 : 1.0;  // a switch moved c.y off the rate taken there
  c.integ.settings[CHAINED] = 0.0;     // its stepper's stages are not at c.y
  fold_figures(c, c.s.q, pose, wrenches);
  return CARRIED;
}

/// run_samples' result: the index of the last sample done and the status (0 all done;
/// AT_EVENT ended at an event that may stiffen the scene; else the stepper's failure).
struct RunResult {
  idx done;
  int status;
};

/// Advance y through samples 1..n−1; sample 0 is the last one already done
/// (engine/kernel.py run_samples says what each argument holds). The watch is read only
/// where the model has non-linear mounts; the error estimate is `estimator` or `companion`
/// (null: none).
inline RunResult run_samples(Integrator& integ, const Model& m, Scratch& s, Vec u, Vec y,
                             const Samples& smp, const RunOptions& opts, Published& out,
                             Watch& watch, Estimator* estimator, Companion* companion) {
  const idx n = smp.t.n, nm = out.peak.rows;
  const double hold = opts.zero_order ? 0.0 : 1.0;
  const Vec d_wdot = s.rate_step, settings = integ.settings;
  for (idx j = 1; j < n; ++j) {
    const double dt = smp.t[j] - smp.t[j - 1];
    u[0] = smp.t[j - 1];
    for (int i = 0; i < 3; ++i) {
      u[1 + i] = smp.f(j - 1, i);
      u[4 + i] = hold * (smp.f(j, i) - smp.f(j - 1, i)) / dt;
      u[7 + i] = smp.w(j - 1, i);
      const double w_dot = hold * (smp.w(j, i) - smp.w(j - 1, i)) / dt;
      d_wdot[i] = w_dot - u[10 + i];
      u[10 + i] = w_dot;
    }
    if (opts.chain && settings[CHAINED] == 1.0) {
      // First-order hold: only Ω' jumps at the sample; the last stage moves to it.
      physics::rhs_after_rate_step(m, s, d_wdot, integ.work2d.row(0));
    } else {
      settings[CHAINED] = 0.0;
    }
    if (estimator != nullptr) copy(y, estimator->y_start);
    // at the interval's start, as the twin's monitors and the companion's stand
    const int holding =
        companion != nullptr ? holding_treatment(*companion, watch.g) : CARRIED_THROUGH;
    const bool carried = companion != nullptr && carries(*companion, integ.method, smp.t[j - 1],
                                                         smp.t[j], holding != CARRIED_THROUGH);
    if (carried) {  // the twin's start: its state and, chained, its first stage
      copy(y, companion->error_rows.row(Y_START));
      companion->carry[TWIN_RATED] = settings[CHAINED];
      if (settings[CHAINED] == 1.0) {
        copy(integ.work2d.row(0), companion->error_rows.row(TWIN_RATE));
      }
    } else if (companion != nullptr) {
      companion->carry[RATED] = 0.0;  // integrated: its rate is not kept
    }
    const int status = integrate::advance(integ.method, y, smp.t[j - 1], smp.t[j], settings, m,
                                          s, u, integ.work2d, integ.work1d, integ.result);
    if (status != 0) return {j - 1, status};
    if (estimator != nullptr) copy(y, estimator->y_end);
    const idx stiffening = *watch.n_stiffening;
    for (int k = 0; k < 3; ++k) out.step_log(j, k) = integ.result[k];
    const M6 wrenches_j = out.wrenches.mat(j);
    // the monitors in the outputs' pass over the mounts (and, carried, the deflections the
    // companion's carry reads)
    physics::MonitorRows mon{watch.y_prev, watch.g, watch.util};
    if (carried) mon.d = companion->twin_d;
    physics::outputs(y, m, s, out.pose.row(j), wrenches_j, m.has_nl ? &mon : nullptr);
    physics::linear_utilisation(m, s, wrenches_j, out.lin_util);
    int watched = 0, crossing = CARRIED_THROUGH;
    if (m.has_nl) {
      const bool switched = settle_switches(mon.switched, y, watch.y_prev, settings);
      if (companion != nullptr && !carried) {  // before the log moves g_prev on
        crossing = crossed_treatment(*companion, watch.g_prev, watch.g);
      }
      watched = log_crossings(switched, m.nl, watch, smp.t[j - 1], smp.t[j], wrenches_j);
    }
    if (estimator != nullptr) {
      estimate_interval(m, *estimator, u, smp.t[j - 1], smp.t[j], watched, integ, wrenches_j,
                        y);
    }
    if (companion != nullptr) {
      Stepping stepping = CARRIED;
      if (carried) {
        stepping = carry_interval(m, *companion, u, smp.t[j - 1], smp.t[j], opts.chain,
                                  integ.result, watched, d_wdot, out.pose.row(j), wrenches_j, y);
      } else if ((watched & CHANGED) != 0) {
        // an event function changed sign inside the interval: halved (a joint's faces opening
        // or slipping in the genset under a synthesised 30 g shock read 0.28 of the true error
        // at rtol 1e-5 across it by one step, by the switching method's two steps too)
        stepping = halved(crossing);
      } else {
        // where the twin's tolerance bound its steps while an event holds that switches the
        // law inside the steps (a joint's faces between sticking and sliding): switched
        stepping = holding == SWITCHING && twin_bound(integ.result) ? SWITCHED : OWN;
      }
      if (stepping != CARRIED && stepped_over(m, *companion, integ, smp.t[j] - smp.t[j - 1])) {
        stepping = EXACT;
      }
      if (stepping != CARRIED) {
        follow(m, *companion, u, smp.t[j - 1], smp.t[j], opts.chain, stepping, d_wdot,
               out.pose.row(j), wrenches_j, y);
      }
    }
    *out.counter += 1;
    for (idx a = 0; a < nm; ++a) {
      for (int b = 0; b < 6; ++b) {
        if (std::fabs(wrenches_j(a, b)) > std::fabs(out.peak(a, b))) {
          out.peak(a, b) = wrenches_j(a, b);
        }
      }
    }
    out.publish[j] = *out.counter >= opts.decimation;
    if (out.publish[j]) {
      for (idx a = 0; a < nm; ++a) {
        for (int b = 0; b < 6; ++b) {
          wrenches_j(a, b) = out.peak(a, b);
          out.wrench_abs_max(a, b) = py_max(out.wrench_abs_max(a, b), std::fabs(out.peak(a, b)));
          out.peak(a, b) = 0.0;
        }
      }
      *out.counter = 0;
      *out.cos_tilt_min = py_min(*out.cos_tilt_min, s.rot(2, 2));
    }
    if (*watch.n_stiffening > stiffening && smp.t[j] > *watch.stop_after) {
      return {j, AT_EVENT};
    }
  }
  return {n - 1, 0};
}

/// Lanes of doubles side by side (GCC's and clang's vector extension), each lane's arithmetic
/// IEEE as written: Pair is SSE2 on x86-64 and NEON on arm64; Quad is AVX2's width, taken
/// only inside functions built for it (`fir_rows`).
using Pair = double __attribute__((vector_size(16)));
using Quad = double __attribute__((vector_size(32)));

/// The lanes at p (any alignment) into v (an out-parameter: a vector wider than the baseline's
/// returned by value is an ABI question the compiler warns of, inlined or not).
template <class V>
__attribute__((always_inline)) inline void load_lanes(V& v, const double* p) {
  std::memcpy(&v, p, sizeof v);
}

/// Each lane of v set to x.
template <class V>
__attribute__((always_inline)) inline void splat(V& v, double x) {
  for (idx l = 0; l < static_cast<idx>(sizeof(V) / sizeof(double)); ++l) v[l] = x;
}

/// `fir_rows` on 4 × W outputs from c (W the lanes of V): their sums held in registers over all
/// j (a loop over j outside the outputs stored and reloaded each output at every tap). Every
/// lane adds its terms in `fir_rows`'s order: the same bits at any width.
template <class V>
__attribute__((always_inline)) inline void fir_block(const double* h, idx n, const double* c,
                                                     double* o) {
  constexpr idx w = sizeof(V) / sizeof(double);
  V hj, s[4], lo, hi;
  splat(hj, h[0]);
  for (idx b = 0; b < 4; ++b) {
    load_lanes(lo, c + b * w);
    s[b] = hj * lo;
  }
  for (idx j = 1; j <= n; ++j) {
    splat(hj, h[j]);
    for (idx b = 0; b < 4; ++b) {
      load_lanes(lo, c - j + b * w);
      load_lanes(hi, c + j + b * w);
      s[b] += hj * (lo + hi);
    }
  }
  std::memcpy(o, s, sizeof s);
}

/// `fir_rows` of one row's m outputs: blocks of V's, then of pairs, then one at a time.
template <class V>
__attribute__((always_inline)) inline void fir_row(const double* h, idx n, const double* r,
                                                   double* o, idx m) {
  constexpr idx block = 4 * sizeof(V) / sizeof(double);
  idx k = 0;
  for (; k + block <= m; k += block) fir_block<V>(h, n, r + k, o + k);
  for (; k + 8 <= m; k += 8) fir_block<Pair>(h, n, r + k, o + k);
  for (; k < m; ++k) {
    double sum = h[0] * r[k];
    for (idx j = 1; j <= n; ++j) sum += h[j] * (r[k - j] + r[k + j]);
    o[k] = sum;
  }
}

#if defined(__x86_64__) && defined(__GNUC__)
/// `fir_row` in AVX2's lanes (no fused multiply-adds: -ffp-contract=off holds here too).
__attribute__((target("avx2"))) inline void fir_row_avx2(const double* h, idx n,
                                                          const double* r, double* o, idx m) {
  fir_row<Quad>(h, n, r, o, m);
}
#endif

/// out[i, k] = h[N]·raw[i, k + N] + Σ_j h[N + j]·(raw[i, k + N − j] + raw[i, k + N + j]),
/// j = 1..N in that order (engine/gyro_filter.py fir_rows: any batching, the same bits; any
/// lane width too). AVX2's four lanes where the processor has them: 1.6× faster than SSE2's
/// pairs (0.40 → 0.25 ms for 2500 samples at 10 kHz, N = 375; AVX-512's eight lanes were no
/// faster: the loads bound it); else SSE2's or NEON's pairs.
inline void fir_rows(Mat raw, Vec half, Mat out) {
  const idx n = half.n - 1, m = out.cols;
  const double* h = half.d;
#if defined(__x86_64__) && defined(__GNUC__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
#endif
  for (idx i = 0; i < 3; ++i) {
    const double* r = &raw(i, n);  // r[k]: the sample of output k
    double* o = out.row(i).d;
#if defined(__x86_64__) && defined(__GNUC__)
    if (avx2) {
      fir_row_avx2(h, n, r, o, m);
      continue;
    }
#endif
    fir_row<Pair>(h, n, r, o, m);
  }
}

}  // namespace mt::engine
