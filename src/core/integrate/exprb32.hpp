// EXPRB32: an exponential Rosenbrock method for stiff scenes, exact on their linear part
// (Hochbruck, Ostermann & Schweitzer, SIAM J. Numer. Anal. 47 (2009) 786–803; integrate/
// exprb32.py: the work layout and the step logic, the same operations in the same order).
// With J = ∂f/∂y, v = ∂f/∂t (at the interval's start) and f0 = f(t, y) at the step's start:
//   U = y + h·φ1(hJ)·f0 + h²·φ2(hJ)·v
//   D = f(t + h, U) − f0 − J·(U − y) − h·v
//   y1 = U + 2h·φ3(hJ)·D,   error estimate 2h·φ3(hJ)·D
#pragma once

#include <cmath>
#include <cstdint>

#include "../constants.hpp"
#include "../model.hpp"
#include "../numeric.hpp"
#include "../physics/dynamics_api.hpp"
#include "../views.hpp"
#include "control.hpp"
#include "fd_jacobian.hpp"
#include "linearised_loop.hpp"
#include "phi.hpp"

namespace mt::integrate::exprb32 {

/// Order of the error estimate (the controller's exponent is −1/(ORDER + 1)).
constexpr int ORDER = 2;
constexpr double MAX_FACTOR = 6.0;
/// Input intervals a Jacobian (and its φ functions) serves at most.
constexpr double JACOBIAN_MAX_AGE = 20.0;
/// φ functions computed for a step within this fraction of the one taken are used for it.
constexpr double PHI_REUSE = 1e-9;
/// The magnitude (m, rad, m/s, rad/s) below which a Jacobian column is differenced over
/// JAC_STEP·TYPICAL.
constexpr double TYPICAL = 1.0;
/// Rows of the work array: f0, v = ∂f/∂t, a right-hand side's scratch, the stage state U, the
/// remainder's change D, the balancing's diagonal, HALF (its first entry: the step, s, the
/// half-step φ functions held are for; 0: none); then the blocks from J0.
constexpr idx F = 0, FT = 1, FTMP = 2, U = 3, DIFF = 4, SCALE = 5, HALF = 6;
constexpr idx ROWS = 7;
constexpr idx J0 = ROWS;
/// J, φ1, φ2, φ3, the φ functions' four work blocks, then φ1, φ2, φ3 of half the step (the
/// doubling's last iterate but one: what a check of the interval in two steps takes,
/// engine/estimator.hpp), n rows each.
constexpr idx BLOCKS = 11;
constexpr idx HALF_P1 = 8;  // the first half-step block, in blocks from J0

/// Rows of n of the work array for n states.
inline idx work_rows(idx n) { return ROWS + BLOCKS * n; }

/// Advance y (in place) from t0 to t1 s with input u held over the interval: the signature and
/// statuses of explicit_rk::advance (k: work_rows(n) × n; settings[PHI_STEP]: the step, s, the φ
/// functions held were computed for, 0 for none; settings[CHAINED] is left at 0), by the
/// linearising methods' loop (`advance_linearised`).
inline int advance(Vec y, double t0, double t1, Vec settings, const Model& m, Scratch& s, Vec u,
                   Mat k, Vec y_new, Vec result) {
  const Interval iv = interval(settings, t0, t1);
  const double rtol = iv.rtol, atol = iv.atol;
  const idx n = y.n;
  const phi::Blocks blocks{J0, J0 + n, J0 + 4 * n, SCALE};
  const idx p1 = blocks.p1, p2 = blocks.p1 + n, p3 = blocks.p1 + 2 * n;
  const auto try_step = [&](double t, double h) -> StepTry {
    // the rest of the interval in equal steps no longer than the proposal: one set of φ
    // functions serves them all (math.ceil gives an int: fptosi of the float ceiling)
    const double rest = t1 - t;
    const double count = py_max(
        1.0, static_cast<double>(static_cast<std::int64_t>(
                 std::ceil(rest / py_min(h, iv.h_max) * (1.0 - 1e-12)))));
    const bool last = count == 1.0;
    const double step = last ? rest : on_grid(t, rest / count);
    if (std::fabs(step - settings[PHI_STEP]) > PHI_REUSE * step) {
      bool halved = false;
      const bool ok = phi::phi_functions(k, n, step, blocks, J0 + HALF_P1 * n, &halved);
      settings[PHI_STEP] = ok ? step : 0.0;
      k(HALF, 0) = ok && halved ? 0.5 * step : 0.0;
      if (!ok) return {step, last, Tried::NOT_FINITE, INFINITY};
    }
    for (idx r = 0; r < n; ++r) {
      double acc = y[r];
      for (idx c = 0; c < n; ++c) {
        acc += step * k(p1 + r, c) * k(F, c) + step * step * k(p2 + r, c) * k(FT, c);
      }
      k(U, r) = acc;
    }
    if (physics::rhs(t + step, k.row(U), m, s, u, k.row(FTMP)) != 0) {
      return {step, last, Tried::OFF_CHART, INFINITY};
    }
    for (idx r = 0; r < n; ++r) {
      double acc = k(FTMP, r) - k(F, r) - step * k(FT, r);
      for (idx c = 0; c < n; ++c) acc -= k(J0 + r, c) * (k(U, c) - y[c]);
      k(DIFF, r) = acc;
    }
    double err = 0.0;
    for (idx r = 0; r < n; ++r) {
      double e = 0.0;
      for (idx c = 0; c < n; ++c) e += k(p3 + r, c) * k(DIFF, c);
      e *= 2.0 * step;
      y_new[r] = k(U, r) + e;
      const double scale = atol + rtol * py_max(std::fabs(y[r]), std::fabs(y_new[r]));
      const double x = e / scale;
      err += x * x;  // numba's x ** 2 (a literal integer exponent): x·x
    }
    return {step, last, Tried::TRIED, std::sqrt(err / static_cast<double>(n))};
  };
  return advance_linearised(iv, {{F, FTMP, FT, J0}, TYPICAL, JACOBIAN_MAX_AGE, ORDER, MAX_FACTOR},
                            y, t0, t1, settings, m, s, u, k, y_new, result, try_step);
}

}  // namespace mt::integrate::exprb32
