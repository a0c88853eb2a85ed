// The live global error estimate: local errors measured on a sample of the input intervals,
// carried forward by the linearised dynamics (engine/estimator.py holds the method, its
// figures and who owns which array; this is the per-interval step the loop calls).
#pragma once

#include <cmath>

#include "../constants.hpp"
#include "../integrate/control.hpp"
#include "../integrate/fd_jacobian.hpp"
#include "../integrate/stepper.hpp"
#include "../linalg.hpp"
#include "../model.hpp"
#include "../numeric.hpp"
#include "../physics/dynamics.hpp"
#include "integrator.hpp"

namespace mt::engine {

/// Slots of the estimator's small state vector (engine/estimator.py: the same names): its
/// settings (CHECK_EVERY, LINEARISE_EVERY, LINEARISE_MAX, JACOBIAN_KEEP, OUTPUT_TURN, set
/// once), then what it keeps between intervals.
enum EstimatorSlot : int {
  CHECK_EVERY = 0,    // a measured interval counts for at most this many
  LINEARISE_EVERY,    // check periods (CHECK_EVERY intervals) between linearisations, at first
  LINEARISE_MAX,      // ... and at most, doubled from LINEARISE_EVERY while the propagator holds
  JACOBIAN_KEEP,      // the propagator is kept while the Jacobian moves less than this share
  OUTPUT_TURN,        // rad: the fastest mode's turn between foldings of the outputs' errors
  LINEARISE_SPAN,     // check periods between linearisations now (0: LINEARISE_EVERY)
  OUTPUT_PENDING,     // intervals since the outputs' errors were last folded into the figures
  PENDING,            // intervals not measured since the last check
  PENDING_NORM,       // the twin's error norms of those intervals, summed
  PROPAGATOR_STEP,    // s, the interval the propagator is for (0: none held)
  FASTEST_RATE,       // rad/s, a bound on the fastest mode's rate where the propagator came from
  ERROR_NORM_MEAN,    // running mean of the twin's error norm
  SINCE_LINEARISED,   // check periods the regular checks since the last one stood for
  N_CARRIED,          // states carried (their indices: `carried`)
  CHECKS,             // intervals measured since the start
  LINEARISATIONS,     // linearisations (Jacobians taken) since the start
  EXPONENTIALS,       // propagators computed since the start
  BORROWED,           // checks that took the exponential twin's linearisation
  N_ESTIMATOR_SLOTS
};

/// What the mounts' watch saw at a sample (engine/kernel.hpp log_crossings), as bits: a mount
/// switched or an event function changed sign over the interval (CHANGED); an event function is
/// at or above zero, a mount's event under way (ENGAGED: in contact, slipping, open).
enum Watched : int { CHANGED = 1, ENGAGED = 2 };

/// While a mount is ENGAGED its stiffness moves with the state (a Hertzian contact, a slipping
/// face): a regular check comes every ENGAGED_CHECK_EVERY intervals, and linearises again.
constexpr double ENGAGED_CHECK_EVERY = 4.0;

/// A regular check stands for this share of the fastest mode's period at most
/// (`period_spacing`): beyond it local errors no longer add up in phase (engine/estimator.py
/// says what was measured) ...
constexpr double PERIOD_SHARE = 1.0;
/// ... and this share where the twin's steps are bound by its tolerance (more than one step in
/// the interval): their local errors keep their phase over fewer intervals.
constexpr double BOUND_PERIOD_SHARE = 0.25;

/// The twin's error norm of an interval is a spike (the interval is checked on its own) above
/// this multiple of its running mean.
constexpr double SPIKE_RATIO = 4.0;
/// The propagator held serves an interval whose length is within this share of its own.
constexpr double STEP_MATCH = 1e-6;
/// Weight of the newest interval in the running mean of the twin's error norm.
constexpr double MEAN_WEIGHT = 0.1;
/// The most intervals from one folding of the outputs' estimated errors to the next.
constexpr double OUTPUT_STRIDE_MAX = 8.0;

/// The estimator's arrays (engine/estimator.py Estimator). n states; at most np_max carried:
/// the body's and the internal states that move where it last linearised (`carried`).
struct Estimator {
  Integrator integ;  // the checking stepper (the twin's method at tighter tolerances)
  Vec y;             // (n,) the check's state; the Jacobian's trial states
  Scratch s;         // its scratch
  Vec y_start;       // (n,) the twin's state at the interval's start
  Vec y_end;         // (n,) the twin's state after its step, before the mounts' switches
  Vec e;             // (n,) the estimated global error of the twin's state
  Vec carried;       // (np_max,) indices into y of the carried states (first N_CARRIED)
  Vec jac;           // (np_max²,) ∂f/∂y over the carried states (row-major, N_CARRIED²)
  Vec prop;          // (np_max²,) exp(h·jac), the error's propagator over an interval of h,
                     // transposed (linalg::matvec_t)
  Vec decay;         // ((n_body/2)²,) exp(h/2·∂v̇/∂v): how an interval damps the body's
                     // modes (`decay_per_interval`), held with the propagator
  Vec work;          // (2·np_max²,): a linearisation's fresh Jacobian, the exponentials' work
  Vec sens;          // (np_max·(3·nm + 3),) ∂(mount forces, α γ δ)/∂(carried states),
                     // transposed: a carried state's row of outputs (linalg::matvec_t)
  Vec f0, f1;        // (n,)
  Vec out0, out1;    // (3·nm + 3,)
  Vec ec, pc;        // (np_max,) the carried error, gathered; its propagation
  M6 wrenches;       // (nm, 6)
  Vec state;         // (N_ESTIMATOR_SLOTS,)
  Vec figures;       // (N_FIGURES,)
  idx n_body;        // the body's states (2 × free coordinates): always carried first
};

/// Square n×n view on the first n² entries of a buffer.
inline Mat square(Vec buffer, idx n) { return Mat{buffer.d, n, n}; }

/// The estimated outputs at y (s holding its body motion): every mount's force components
/// (N, mount axes), then α, γ, δ (rad).
inline void estimated_outputs(Vec y, const Model& m, Scratch& s, M6 wrenches, Vec out) {
  physics::mount_wrenches(y, m, s, wrenches);
  const idx nm = wrenches.rows;
  for (idx a = 0; a < nm; ++a) {
    for (int b = 0; b < 3; ++b) out[3 * a + b] = wrenches(a, b);
  }
  for (int i = 0; i < 3; ++i) out[3 * nm + i] = s.q[3 + i];
}

/// The most free coordinates of the body (three translations, three rotations).
constexpr idx MAX_FREE = 6;

/// est.decay = exp(h/2·J_vv), J_vv the body's velocity block of the Jacobian held (−M⁻¹C, the
/// damping, and the gyroscopic terms): a lightly damped mode of rate ω and damping ratio ζ
/// keeps e^(−ζωh) of its amplitude, position and velocity alike, over an interval of h
/// (modally, where the damping is, J_vv/2 has the eigenvalues −ζω; `add_local_error`).
/// False if it is not finite.
inline bool decay_per_interval(Estimator& est, double h) {
  const idx nc = static_cast<idx>(est.state[N_CARRIED]), nf = est.n_body / 2;
  const Mat jac = square(est.jac, nc), jvv{est.work.d, nf, nf};
  const Mat w0{est.work.d + nf * nf, nf, nf}, w1{est.work.d + 2 * nf * nf, nf, nf};
  for (idx r = 0; r < nf; ++r) {
    for (idx c = 0; c < nf; ++c) jvv(r, c) = jac(nf + r, nf + c);
  }
  return linalg::expm(jvv, 0.5 * h, square(est.decay, nf), w0, w1);
}

/// A bound on the body's fastest mode's rate (rad/s) from a Jacobian jac (jac(r, c) = ∂f_r/∂y_c;
/// first the body's nf free coordinates, then their rates): the square root of the ∞-norm of
/// ∂v̇/∂q, which bounds its spectral radius, ω² of the fastest mode (on the pump, 157 rad/s for
/// its 122).
inline double fastest_rate(const Mat jac, idx nf) {
  double norm = 0.0;
  for (idx r = 0; r < nf; ++r) {
    double row = 0.0;
    for (idx c = 0; c < nf; ++c) row += std::fabs(jac(nf + r, c));
    norm = py_max(norm, row);
  }
  return std::sqrt(norm);
}

/// The most intervals a regular check stands for: `share` of the fastest mode's period
/// (FASTEST_RATE) in intervals of h, at least 1; no limit where that period is shorter than an
/// interval (ωh > 2π, as the stiff scene's 33): a mode the samples do not resolve loses most of
/// its error within the few intervals the damped count gives it, in phase or not.
inline double period_spacing(const Vec st, double h, double share) {
  const double period = 2.0 * M_PI / (st[FASTEST_RATE] * h);
  if (!(period >= 1.0)) return INFINITY;
  return py_max(1.0, std::floor(share * period));
}

/// Intervals of h from one folding of the outputs' estimated errors into the figures to the
/// next (an interval whose local error was measured is folded besides): as many as the fastest
/// mode (FASTEST_RATE, the propagator's bound) takes to turn by OUTPUT_TURN rad, at least 1, at
/// most OUTPUT_STRIDE_MAX; 1 where no propagator is held. Between checks the estimated error is
/// the free motion of the linearised modes, none faster than that bound, so a peak lies within
/// half a stride of a folded interval and is read at cos(OUTPUT_TURN/2) of its size at least
/// (0.97 at 0.5 rad: a signal of no frequency above ω keeps cos(ωτ) of a peak τ from it); a
/// run's last intervals are folded as it ends (`close_run`). Those products and maxima were
/// half the estimate's cost on the pump, whose stride is 3 at 1 kHz.
inline double output_stride(const Vec st, double h) {
  if (!(st[PROPAGATOR_STEP] > 0.0)) return 1.0;
  const double stride = std::floor(st[OUTPUT_TURN] / (h * st[FASTEST_RATE]));
  return py_min(py_max(1.0, stride), OUTPUT_STRIDE_MAX);
}

/// The propagator over an interval of h from the Jacobian held, and the decay with it; false
/// if either is not finite.
inline bool propagator(Estimator& est, double h) {
  const idx nc = static_cast<idx>(est.state[N_CARRIED]);
  const Mat w0{est.work.d, nc, nc}, w1{est.work.d + nc * nc, nc, nc};
  est.state[EXPONENTIALS] += 1.0;
  if (!linalg::expm(square(est.jac, nc), h, square(est.prop, nc), w0, w1)) return false;
  linalg::transpose(square(est.prop, nc));
  if (!decay_per_interval(est, h)) return false;
  est.state[FASTEST_RATE] =
      fastest_rate(square(est.jac, static_cast<idx>(est.state[N_CARRIED])), est.n_body / 2);
  est.state[PROPAGATOR_STEP] = h;
  return true;
}

/// Choose the carried states at est.y (f0 = f there): the body's, then each internal state
/// whose rate is not zero (a Bouc–Wen z under motion, a slip while slipping; not a stuck
/// joint, a fracture flag), up to np_max; returns how many moving ones did not fit, and in
/// `same` whether they are the ones carried before.
inline idx choose_carried(Estimator& est, bool& same) {
  const idx n = est.y.n, np_max = est.carried.n;
  idx nc = 0, left_out = 0;
  same = true;
  for (idx i = 0; i < n; ++i) {
    if (i >= est.n_body && est.f0[i] == 0.0) continue;
    if (nc < np_max) {
      const double index = static_cast<double>(i);
      same = same && nc < est.state[N_CARRIED] && est.carried[nc] == index;
      est.carried[nc++] = index;
    } else {
      ++left_out;
    }
  }
  same = same && static_cast<double>(nc) == est.state[N_CARRIED];
  est.state[N_CARRIED] = static_cast<double>(nc);
  return left_out;
}

/// Check periods of regular checks from one linearisation to the next: LINEARISE_SPAN, or
/// LINEARISE_EVERY before the first (`linearise_at` sets it). Where the Jacobian barely moves
/// (the pump under ship motion: 1.6e-5–1.0e-4 of itself between linearisations two periods
/// apart) its differences were a fifth of the estimate's cost, and each found the propagator
/// held; a Jacobian that moved past JACOBIAN_KEEP since the propagator's came from brings the
/// span back to LINEARISE_EVERY (engine/estimator.py LINEARISE_MAX says what it read).
inline double linearise_span(const Vec st) {
  return py_max(st[LINEARISE_SPAN], st[LINEARISE_EVERY]);
}

/// Whether the propagator held serves a fresh Jacobian `fresh` (nc², over the same carried
/// states) for an interval of h: it is for h (STEP_MATCH), and the Jacobian it came from
/// (est.jac) is within JACOBIAN_KEEP of `fresh` (Frobenius norms). A relative change δ of the
/// Jacobian moves a mode's frequency by about δ/2: with δ = 1e-3, and a lightly damped mode's
/// error kept over 1/(ζωh) intervals, its phase by 5e-3 rad at ζ = 0.1, nothing an estimate
/// within a factor 2 would feel; on the pump under ship motion the Jacobian moved 1.6e-5 to
/// 1.0e-4 between linearisations.
inline bool propagator_holds(const Estimator& est, const Mat fresh, double h) {
  const double held_h = est.state[PROPAGATOR_STEP];
  if (!(held_h > 0.0) || std::fabs(h - held_h) > STEP_MATCH * h) return false;
  const idx nc = fresh.rows;
  const Mat jac = square(est.jac, nc);
  double change = 0.0, size = 0.0;
  for (idx r = 0; r < nc; ++r) {
    for (idx c = 0; c < nc; ++c) {
      const double d = fresh(r, c) - jac(r, c);
      change += d * d;
      size += jac(r, c) * jac(r, c);
    }
  }
  const double keep = est.state[JACOBIAN_KEEP];
  return change <= keep * keep * size;
}

/// Jacobian and output sensitivities at (t, est.y) by forward differences (the steppers'
/// JAC_STEP) over the carried states, chosen afresh, then the propagator over h, unless the
/// one held serves (`propagator_holds`: the Jacobian, differenced into est.work, then stays
/// the one the propagator came from, and the span to the next linearisation doubles, up to
/// LINEARISE_MAX check periods; where it does not, the span is LINEARISE_EVERY again). False
/// if an evaluation failed (off the chart).
inline bool linearise_at(const Model& m, Estimator& est, Vec u, double t, double h) {
  Scratch& s = est.s;
  const Vec y = est.y;
  const idx n_out = est.out0.n;
  if (physics::rhs(t, y, m, s, u, est.f0) != OK) return false;
  estimated_outputs(y, m, s, est.wrenches, est.out0);
  bool same = false;
  est.figures[UNCARRIED] = py_max(est.figures[UNCARRIED],
                                  static_cast<double>(choose_carried(est, same)));
  const idx nc = static_cast<idx>(est.state[N_CARRIED]);
  const Mat fresh = square(est.work, nc), sens_t{est.sens.d, nc, n_out};
  const Vec set = est.integ.settings;
  const double typical = py_min(py_max(set[ATOL] / set[RTOL], 1e-6), 1.0);
  for (idx c = 0; c < nc; ++c) {
    const idx col = static_cast<idx>(est.carried[c]);
    const double keep = y[col];
    y[col] = keep + integrate::JAC_STEP * py_max(std::fabs(keep), typical);
    const double d = y[col] - keep;
    const bool bad = physics::rhs(t, y, m, s, u, est.f1) != OK;
    if (!bad) estimated_outputs(y, m, s, est.wrenches, est.out1);
    y[col] = keep;
    if (bad) return false;
    for (idx r = 0; r < nc; ++r) {
      const idx row = static_cast<idx>(est.carried[r]);
      fresh(r, c) = (est.f1[row] - est.f0[row]) / d;
    }
    for (idx r = 0; r < n_out; ++r) sens_t(c, r) = (est.out1[r] - est.out0[r]) / d;
  }
  const Vec st = est.state;
  st[SINCE_LINEARISED] = 0.0;
  st[LINEARISATIONS] += 1.0;
  if (same && propagator_holds(est, fresh, h)) {
    st[LINEARISE_SPAN] = py_min(2.0 * linearise_span(st), st[LINEARISE_MAX]);
    return true;
  }
  st[LINEARISE_SPAN] = st[LINEARISE_EVERY];
  for (idx i = 0; i < nc * nc; ++i) est.jac[i] = est.work[i];
  return propagator(est, h);
}

/// Whether the check of an interval of h can take the exponential twin's linearisation: the
/// twin took the interval in one step, none rejected, from a Jacobian taken at its start (what
/// the check's own would be: the same differences at the same state and input) and kept the
/// φ functions of half the step, the check's two steps (exprb32.hpp HALF).
inline bool twin_linearisation_fits(const Integrator& twin, const Estimator& est, double h) {
  namespace x = integrate::exprb32;
  return twin.method == EXPRB32 && est.integ.method == EXPRB32 && twin.result[1] == 1.0 &&
         twin.result[2] == 0.0 && twin.settings[JACOBIAN_AGE] == 1.0 &&
         twin.work2d(x::HALF, 0) == 0.5 * h && est.integ.settings[MIN_STEPS] == 2.0;
}

/// Give the check the twin's Jacobian and half-step φ functions (`twin_linearisation_fits`):
/// the check then computes neither (most of its cost: the φ functions' squarings) and
/// takes the same steps it would have taken with its own.
inline void borrow_linearisation(const Integrator& twin, const Integrator& check, idx n,
                                 double h) {
  namespace x = integrate::exprb32;
  for (idx r = 0; r < n; ++r) {
    for (idx c = 0; c < n; ++c) {
      check.work2d(x::J0 + r, c) = twin.work2d(x::J0 + r, c);
      for (idx b = 0; b < 3; ++b) {
        check.work2d(x::J0 + (1 + b) * n + r, c) = twin.work2d(x::J0 + (x::HALF_P1 + b) * n + r, c);
      }
    }
  }
  check.settings[JACOBIAN_AGE] = 1.0;  // held from this state: not renewed at the start
  check.settings[PHI_STEP] = 0.5 * h;
}

/// The twin's local error over [t0, t1]: est.y_end less the checking stepper's solution from
/// est.y_start under the same input u (with the twin's linearisation where it fits); false
/// (nothing measured) if the check failed.
inline bool local_error(const Model& m, Estimator& est, Vec u, double t0, double t1,
                        const Integrator& twin) {
  const Integrator& c = est.integ;
  copy(est.y_start, est.y);
  c.settings[CHAINED] = 0.0;  // the state jumped: no last stage, no Jacobian held (the step
  c.settings[JACOBIAN_AGE] = 0.0;  // proposal is kept: it suits the next check)
  c.settings[PHI_STEP] = 0.0;
  if (twin_linearisation_fits(twin, est, t1 - t0)) {
    borrow_linearisation(twin, c, est.y.n, t1 - t0);
    est.state[BORROWED] += 1.0;
  }
  est.state[CHECKS] += 1.0;
  const int status = integrate::advance(c.method, est.y, t0, t1, c.settings, m, est.s, u,
                                        c.work2d, c.work1d, c.result);
  if (status != SUCCESS) integrate::forget(c.settings);
  return status == SUCCESS;
}

/// How many intervals a regular check's local error stands for: the `pending` ones (itself
/// included) in proportion to the twin's error norms, their sum `pending_norm` over its own
/// `norm` (a ratio estimate: ℓ follows the norm as the motion's envelope changes, so a shock's
/// onset after quiet intervals is not counted as many loud ones), within 1 and `pending` (a
/// quiet check does not stand for more than the intervals it follows: the loud ones among
/// them were spikes, measured on their own).
inline double stands_for(double pending, double pending_norm, double norm) {
  if (!(norm > 0.0)) return pending;
  return py_min(py_max(pending_norm / norm, 1.0), pending);
}

/// e += the local error ℓ = y_end − y measured at a check, standing for `weight` intervals
/// (`stands_for`; 1 for a special interval) that each committed as much, in phase. On the
/// body's states, with a propagator held (`decayed`), their sum as it stands now:
/// Σ_{j<weight} Dʲ·ℓ (D: `decay`, the last term's share the fraction of weight), each interval's
/// error damped by the intervals since; a mode the damping takes out within a few intervals (a
/// kHz mode on stiff mounts at a 1 kHz sample rate loses a third to two thirds of its error an
/// interval) counts for those few, as it does in the error itself, not for all. Elsewhere, and
/// on the mounts' internal states, weight·ℓ.
inline void add_local_error(Estimator& est, double weight, bool decayed) {
  const Vec e = est.e;
  const idx nf = decayed ? est.n_body / 2 : 0, n = e.n;
  for (idx i = 2 * nf; i < n; ++i) e[i] += weight * (est.y_end[i] - est.y[i]);
  if (nf == 0) return;
  const Mat d = square(est.decay, nf);
  double t[MAX_FREE][2], next[MAX_FREE][2], sum[MAX_FREE][2];  // (position, velocity) pairs
  for (idx i = 0; i < nf; ++i) {
    for (idx part = 0; part < 2; ++part) {
      t[i][part] = est.y_end[part * nf + i] - est.y[part * nf + i];
      sum[i][part] = 0.0;
    }
  }
  const double whole = std::floor(weight), share = weight - whole;
  const idx count = static_cast<idx>(whole);
  for (idx j = 0; j < count; ++j) {
    for (idx i = 0; i < nf; ++i) {
      sum[i][0] += t[i][0];
      sum[i][1] += t[i][1];
    }
    if (j + 1 == count && share == 0.0) break;
    for (idx r = 0; r < nf; ++r) {
      double a0 = 0.0, a1 = 0.0;
      for (idx c = 0; c < nf; ++c) {
        a0 += d(r, c) * t[c][0];
        a1 += d(r, c) * t[c][1];
      }
      next[r][0] = a0;
      next[r][1] = a1;
    }
    for (idx i = 0; i < nf; ++i) {
      t[i][0] = next[i][0];
      t[i][1] = next[i][1];
    }
  }
  for (idx i = 0; i < nf; ++i) {
    e[i] += sum[i][0] + share * t[i][0];
    e[nf + i] += sum[i][1] + share * t[i][1];
  }
}

/// e ← propagator · e over the carried states (the others are held).
inline void carry(Estimator& est) {
  const idx nc = static_cast<idx>(est.state[N_CARRIED]);
  for (idx c = 0; c < nc; ++c) est.ec[c] = est.e[static_cast<idx>(est.carried[c])];
  linalg::matvec_t(square(est.prop, nc), est.ec.d, est.pc.d);
  for (idx c = 0; c < nc; ++c) est.e[static_cast<idx>(est.carried[c])] = est.pc[c];
}

/// The outputs' estimated errors, ∂(forces, α γ δ)/∂y · e over the carried states, folded
/// into the figures' running maxima (N, rad); none pending after.
inline void fold_outputs(Estimator& est) {
  const Vec st = est.state, fig = est.figures;
  const idx nc = static_cast<idx>(st[N_CARRIED]), n_out = est.out1.n, n_forces = n_out - 3;
  st[OUTPUT_PENDING] = 0.0;
  for (idx c = 0; c < nc; ++c) est.ec[c] = est.e[static_cast<idx>(est.carried[c])];
  linalg::matvec_t(Mat{est.sens.d, nc, n_out}, est.ec.d, est.out1.d);
  double force = fig[FORCE_ERROR], attitude = fig[ATTITUDE_ERROR];
  for (idx i = 0; i < n_forces; ++i) force = py_max(force, std::fabs(est.out1[i]));
  for (idx i = n_forces; i < n_out; ++i) attitude = py_max(attitude, std::fabs(est.out1[i]));
  fig[FORCE_ERROR] = force;
  fig[ATTITUDE_ERROR] = attitude;
}

/// One input interval [t0, t1] of the estimate, after the twin's step: carry the error over
/// it; measure the twin's local error where the interval is special (`watched` CHANGED, or the
/// twin rejected a step, or its error norm spiked) or where CHECK_EVERY intervals are pending
/// (ENGAGED_CHECK_EVERY while a mount is engaged, a share of the fastest mode's period:
/// `period_spacing`; it then counts for them); linearise again at
/// the twin's state y after a mount's event, at every check while one is engaged, and every
/// `linearise_span` check periods of regular checks (CHECK_EVERY intervals each: an early check
/// counts for its share); fold the estimated errors of the outputs into the figures every
/// `output_stride` intervals and at a measured one (the twin's largest force, every interval).
/// A regular check may come early, from a quarter of CHECK_EVERY pending, where it can take the
/// exponential twin's linearisation (`twin_linearisation_fits`: the twin renews its Jacobian
/// every 20 intervals at most, so one such interval falls in every window of that length).
/// twin: the twin's stepper after its step (result: [error norm, accepted, rejected]);
/// wrenches: the twin's at t1.
inline void estimate_interval(const Model& m, Estimator& est, Vec u, double t0, double t1,
                              int watched, const Integrator& twin, M6 wrenches, Vec y) {
  const Vec twin_result = twin.result;
  const bool changed = (watched & CHANGED) != 0, engaged = (watched & ENGAGED) != 0;
  const Vec st = est.state, fig = est.figures;
  const idx nm = wrenches.rows;
  const double h = t1 - t0;
  bool linearised = st[PROPAGATOR_STEP] > 0.0;
  if (linearised && std::fabs(h - st[PROPAGATOR_STEP]) > STEP_MATCH * h) {
    linearised = propagator(est, h);
  }
  if (linearised) carry(est);
  const double err = twin_result[0];
  const bool spike = err > SPIKE_RATIO * st[ERROR_NORM_MEAN];
  st[ERROR_NORM_MEAN] += MEAN_WEIGHT * (err - st[ERROR_NORM_MEAN]);
  const bool special = changed || twin_result[2] > 0.0 || spike;
  st[PENDING] += 1.0;
  if (!special) st[PENDING_NORM] += err;
  double every = engaged ? py_min(st[CHECK_EVERY], ENGAGED_CHECK_EVERY) : st[CHECK_EVERY];
  if (linearised) {
    const double share = twin_result[1] > 1.0 ? BOUND_PERIOD_SHARE : PERIOD_SHARE;
    every = py_min(every, period_spacing(st, h, share));
  }
  const bool cheap = st[PENDING] >= 0.25 * every && twin_linearisation_fits(twin, est, h);
  const bool regular = !special && (st[PENDING] >= every || cheap);
  const bool measured = special || regular || !linearised;
  if (measured) {
    if (local_error(m, est, u, t0, t1, twin)) {
      const double weight = special ? 1.0 : stands_for(st[PENDING], st[PENDING_NORM], err);
      add_local_error(est, weight, linearised);
    } else {
      fig[FAILURES] += 1.0;
    }
    if (regular) st[SINCE_LINEARISED] += st[PENDING] / every;  // an early check, its share
    st[PENDING] = special ? st[PENDING] - 1.0 : 0.0;
    if (!special) st[PENDING_NORM] = 0.0;
    if (changed || engaged || !linearised || st[SINCE_LINEARISED] >= linearise_span(st)) {
      copy(y, est.y);
      if (!linearise_at(m, est, u, t1, h)) st[PROPAGATOR_STEP] = 0.0;
    }
  }
  double scale = fig[FORCE_SCALE];
  for (idx a = 0; a < nm; ++a) {
    for (int b = 0; b < 3; ++b) scale = py_max(scale, std::fabs(wrenches(a, b)));
  }
  fig[FORCE_SCALE] = scale;
  st[OUTPUT_PENDING] += 1.0;
  if (measured || st[OUTPUT_PENDING] >= output_stride(st, h)) fold_outputs(est);
}

/// A run ends (a restart follows, or the stream ends): the intervals since the outputs'
/// errors were last folded are folded now, at the run's last state, so that a peak there is
/// read at cos(OUTPUT_TURN/2) of its size at least, as everywhere else (`output_stride`).
/// The run's end is where the input puts it, not where a batch of it ends: the figures do not
/// depend on how the input is batched.
inline void close_run(Estimator& est) {
  if (est.state[OUTPUT_PENDING] > 0.0) fold_outputs(est);
}

}  // namespace mt::engine
