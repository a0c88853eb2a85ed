// The Jacobian ∂f/∂y and ∂f/∂t of the right-hand side by forward differences, into rows of a
// stepper's work array, and how long one is held (integrate/fd_jacobian.py: the same
// operations in the same order). The rows are passed by index (f, scratch, ∂f/∂t, first row
// of J), so each method keeps its own layout.
#pragma once

#include <cmath>

#include "../constants.hpp"
#include "../model.hpp"
#include "../numeric.hpp"
#include "../physics/dynamics_api.hpp"
#include "../views.hpp"

namespace mt::integrate {

/// √ε: the relative finite-difference step of the Jacobian columns (relative to |y_c|, or to
/// the caller's typical magnitude where y_c is smaller).
constexpr double JAC_STEP = 1.4901161193847656e-08;

/// The rows of the work array the linearisation uses: f(t, y) (filled by `linearise`, read by
/// the others), a right-hand side's scratch, ∂f/∂t, and the first of J's n rows.
struct JacRows {
  idx f, tmp, ft, j0;
};

/// k[ft] = ∂f/∂t at (t, y) (1/s times the state's units) by a forward difference; k[f] holds
/// f(t, y) on entry, k[tmp] is scratch. False if the evaluation failed.
inline bool time_derivative(Vec y, double t, const Model& m, Scratch& s, Vec u, Mat k,
                            idx f_row, idx tmp_row, idx ft_row) {
  const idx n = y.n;
  const double dt = JAC_STEP * py_max(std::fabs(t), 1.0);
  if (physics::rhs(t + dt, y, m, s, u, k.row(tmp_row)) != 0) return false;
  for (idx r = 0; r < n; ++r) k(ft_row, r) = (k(tmp_row, r) - k(f_row, r)) / dt;
  return true;
}

/// k[j0 : j0 + n] = ∂f/∂y at (t, y), then `time_derivative` into k[ft_row]; k[f_row] holds
/// f(t, y) on entry, k[tmp_row] is scratch; column c is differenced over JAC_STEP·max(|y_c|,
/// typical) (state units). y is restored. False if an evaluation failed (off the chart).
inline bool jacobian(Vec y, double t, const Model& m, Scratch& s, Vec u, Mat k, double typical,
                     idx f_row, idx tmp_row, idx ft_row, idx j0) {
  const idx n = y.n;
  for (idx c = 0; c < n; ++c) {
    const double keep = y[c];
    double d = JAC_STEP * py_max(std::fabs(keep), typical);
    y[c] = keep + d;
    d = y[c] - keep;  // the step actually taken
    const bool bad = physics::rhs(t, y, m, s, u, k.row(tmp_row)) != 0;
    y[c] = keep;
    if (bad) return false;
    for (idx r = 0; r < n; ++r) k(j0 + r, c) = (k(tmp_row, r) - k(f_row, r)) / d;
  }
  return time_derivative(y, t, m, s, u, k, f_row, tmp_row, ft_row);
}

/// At an interval's start: f(t, y) into k[rows.f], then J afresh if none is held or the one
/// held has served `max_age` intervals, else only ∂f/∂t; the one held is aged
/// (settings[JACOBIAN_AGE]; a fresh one forgets settings[PHI_STEP]). False if an evaluation
/// failed (off the chart).
inline bool linearise(Vec y, double t, const Model& m, Scratch& s, Vec u, Mat k, double typical,
                      JacRows rows, Vec settings, double max_age) {
  const double age = settings[JACOBIAN_AGE];
  const bool fresh = age == 0.0 || age >= max_age;
  if (physics::rhs(t, y, m, s, u, k.row(rows.f)) != 0) return false;
  if (fresh) {
    if (!jacobian(y, t, m, s, u, k, typical, rows.f, rows.tmp, rows.ft, rows.j0)) return false;
    settings[PHI_STEP] = 0.0;
  } else if (!time_derivative(y, t, m, s, u, k, rows.f, rows.tmp, rows.ft)) {
    return false;
  }
  settings[JACOBIAN_AGE] = fresh ? 1.0 : age + 1.0;
  return true;
}

/// After a rejected step (y unchanged, k[rows.f] = f(t, y)): a Jacobian held from an earlier
/// interval is taken afresh at (t, y).
inline void renew_if_stale(Vec y, double t, const Model& m, Scratch& s, Vec u, Mat k,
                           double typical, JacRows rows, Vec settings) {
  if (settings[JACOBIAN_AGE] > 1.0 &&
      jacobian(y, t, m, s, u, k, typical, rows.f, rows.tmp, rows.ft, rows.j0)) {
    settings[JACOBIAN_AGE] = 1.0;
    settings[PHI_STEP] = 0.0;
  }
}

}  // namespace mt::integrate
