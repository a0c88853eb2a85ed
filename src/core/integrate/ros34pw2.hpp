// ROS34PW2: a linearly implicit (Rosenbrock–Wanner) method for stiff scenes, L-stable (Rang &
// Angermann, BIT 45 (2005) 761–787): 4 stages, order 3 with an embedded order-2 estimate
// (integrate/ros34pw2.py: the table, the work layout and the step logic, the same operations
// in the same order). Each step solves, for its four stages,
// (I − hγJ)·k_i = h·f(t + α_i h, y + Σ α_ij k_j) + h·J·Σ γ_ij k_j + h²·γ_i·∂f/∂t
// through one LU factorisation (partial pivoting, in place).
#pragma once

#include <cmath>

#include "../constants.hpp"
#include "../model.hpp"
#include "../numeric.hpp"
#include "../physics/dynamics_api.hpp"
#include "../views.hpp"
#include "control.hpp"
#include "fd_jacobian.hpp"
#include "linearised_loop.hpp"

namespace mt::integrate::ros34pw2 {

constexpr double GAMMA = 0.435866521508459;
/// α_ij, j < i: the stage states y + Σ α_ij k_j.
constexpr double ALPHA[4][3] = {
    {0.0, 0.0, 0.0},
    {0.87173304301691801, 0.0, 0.0},
    {0.84457060015369423, -0.11299064236484185, 0.0},
    {0.0, 0.0, 1.0},
};
/// γ_ij, j < i (γ_ii = GAMMA).
constexpr double GAMMAS[4][3] = {
    {0.0, 0.0, 0.0},
    {-0.87173304301691801, 0.0, 0.0},
    {-0.90338057013044082, 0.054180672388095326, 0.0},
    {0.24212380706095346, -1.2232505839045147, 0.54526025533510214},
};
constexpr double B[4] = {0.24212380706095346, -1.2232505839045147, 1.5452602553351020, GAMMA};
constexpr double B_HAT[4] = {0.37810903145819369, -0.096042292212423178, 0.5,
                             0.2179332607542295};
/// α_i = Σ_j α_ij (numpy's ALPHA.sum(axis=1); every grouping gives the same bits here).
constexpr double C[4] = {
    (ALPHA[0][0] + ALPHA[0][1]) + ALPHA[0][2],
    (ALPHA[1][0] + ALPHA[1][1]) + ALPHA[1][2],
    (ALPHA[2][0] + ALPHA[2][1]) + ALPHA[2][2],
    (ALPHA[3][0] + ALPHA[3][1]) + ALPHA[3][2],
};
/// γ_i = γ + Σ_j γ_ij: the weights of h²·∂f/∂t (GAMMA + GAMMAS.sum(axis=1)).
constexpr double D[4] = {
    GAMMA + ((GAMMAS[0][0] + GAMMAS[0][1]) + GAMMAS[0][2]),
    GAMMA + ((GAMMAS[1][0] + GAMMAS[1][1]) + GAMMAS[1][2]),
    GAMMA + ((GAMMAS[2][0] + GAMMAS[2][1]) + GAMMAS[2][2]),
    GAMMA + ((GAMMAS[3][0] + GAMMAS[3][1]) + GAMMAS[3][2]),
};
/// Order of the error estimate (the controller's exponent is −1/(ORDER + 1)).
constexpr int ORDER = 2;
constexpr int STAGES = 4;
constexpr double MAX_FACTOR = 6.0;
/// Input intervals a Jacobian serves at most (a W-method keeps its order with a stale one).
constexpr double JACOBIAN_MAX_AGE = 20.0;
/// Rows of the work array after the stages: f at the step's start, the stage state, Σ γ_ij k_j,
/// ∂f/∂t, the pivots (as floats), a right-hand side's scratch row; then J and LU (n rows each).
constexpr idx F = STAGES, YS = STAGES + 1, ACC = STAGES + 2, FT = STAGES + 3, PIV = STAGES + 4,
              FTMP = STAGES + 5;
constexpr idx J0 = FTMP + 1;

/// Rows of n of the work array for n states.
inline idx work_rows(idx n) { return J0 + 2 * n; }

/// LU with partial pivoting of the n×n block of `a` starting at row `first`, in place; pivot
/// indices (as floats) in piv_row. False if singular.
inline bool lu_factor(Mat a, idx first, idx n, Vec piv_row) {
  for (idx c = 0; c < n; ++c) {
    idx p = c;
    double best = std::fabs(a(first + c, c));
    for (idx r = c + 1; r < n; ++r) {
      const double v = std::fabs(a(first + r, c));
      if (v > best) {
        p = r;
        best = v;
      }
    }
    piv_row[c] = static_cast<double>(p);
    if (best == 0.0 || !std::isfinite(best)) return false;
    if (p != c) {
      for (idx j = 0; j < n; ++j) {
        const double tmp = a(first + c, j);
        a(first + c, j) = a(first + p, j);
        a(first + p, j) = tmp;
      }
    }
    const double inv = 1.0 / a(first + c, c);
    for (idx r = c + 1; r < n; ++r) {
      const double f = a(first + r, c) * inv;
      a(first + r, c) = f;
      if (f != 0.0) {
        for (idx j = c + 1; j < n; ++j) a(first + r, j) -= f * a(first + c, j);
      }
    }
  }
  return true;
}

/// Whether the n×n block of `a` starting at row `first` is finite.
inline bool all_finite(Mat a, idx first, idx n) {
  for (idx r = 0; r < n; ++r) {
    for (idx c = 0; c < n; ++c) {
      if (!std::isfinite(a(first + r, c))) return false;
    }
  }
  return true;
}

/// Solve (LU)·x = b in place (b overwritten by x).
inline void lu_solve(Mat a, idx first, idx n, Vec piv_row, Vec b) {
  for (idx c = 0; c < n; ++c) {
    const idx p = static_cast<idx>(piv_row[c]);
    if (p != c) {
      const double tmp = b[c];
      b[c] = b[p];
      b[p] = tmp;
    }
  }
  for (idx r = 0; r < n; ++r) {
    double acc = b[r];
    for (idx j = 0; j < r; ++j) acc -= a(first + r, j) * b[j];
    b[r] = acc;
  }
  for (idx r = n - 1; r >= 0; --r) {
    double acc = b[r];
    for (idx j = r + 1; j < n; ++j) acc -= a(first + r, j) * b[j];
    b[r] = acc / a(first + r, r);
  }
}

/// Advance y (in place) from t0 to t1 s with input u held over the interval: the signature and
/// statuses of explicit_rk::advance (k: work_rows(n) × n; settings[CHAINED] is left at 0), by
/// the linearising methods' loop (`advance_linearised`).
inline int advance(Vec y, double t0, double t1, Vec settings, const Model& m, Scratch& s, Vec u,
                   Mat k, Vec y_new, Vec result) {
  const Interval iv = interval(settings, t0, t1);
  const double rtol = iv.rtol, atol = iv.atol;
  const idx n = y.n;
  const idx lu0 = J0 + n;
  const double typical = py_min(py_max(atol / rtol, 1e-6), 1.0);  // where rtol and atol meet
  const Vec piv = k.row(PIV);
  const auto try_step = [&](double t, double h) -> StepTry {
    const Trial trial = trial_step(t, t1, h, iv.h_max, iv.span);
    const double step = trial.step;
    for (idx r = 0; r < n; ++r) {  // W = I − hγJ
      for (idx c = 0; c < n; ++c) k(lu0 + r, c) = -step * GAMMA * k(J0 + r, c);
      k(lu0 + r, r) += 1.0;
    }
    // LU failed: J is not finite (a NaN in the state), else W is singular at this step, which
    // a shorter one is not (W → I)
    if (!lu_factor(k, lu0, n, piv)) {
      return {step, trial.last, all_finite(k, J0, n) ? Tried::OFF_CHART : Tried::NOT_FINITE,
              INFINITY};
    }
    for (int stage = 0; stage < STAGES; ++stage) {
      for (idx r = 0; r < n; ++r) {
        double ys = y[r], acc = 0.0;
        for (int j = 0; j < stage; ++j) {
          ys += ALPHA[stage][j] * k(j, r);
          acc += GAMMAS[stage][j] * k(j, r);
        }
        k(YS, r) = ys;
        k(ACC, r) = acc;
      }
      if (stage == 0) {
        for (idx r = 0; r < n; ++r) k(FTMP, r) = k(F, r);
      } else if (physics::rhs(t + C[stage] * step, k.row(YS), m, s, u, k.row(FTMP)) != 0) {
        return {step, trial.last, Tried::OFF_CHART, INFINITY};
      }
      for (idx r = 0; r < n; ++r) {
        double jacc = 0.0;
        for (idx c = 0; c < n; ++c) jacc += k(J0 + r, c) * k(ACC, c);
        k(stage, r) = step * (k(FTMP, r) + jacc + step * D[stage] * k(FT, r));
      }
      lu_solve(k, lu0, n, piv, k.row(stage));
    }
    double err = 0.0;
    for (idx r = 0; r < n; ++r) {
      double yn = y[r], e = 0.0;
      for (int j = 0; j < STAGES; ++j) {
        yn += B[j] * k(j, r);
        e += (B[j] - B_HAT[j]) * k(j, r);
      }
      y_new[r] = yn;
      const double scale = atol + rtol * py_max(std::fabs(y[r]), std::fabs(yn));
      const double x = e / scale;
      err += x * x;  // numba's x ** 2 (a literal integer exponent): x·x
    }
    return {step, trial.last, Tried::TRIED, std::sqrt(err / static_cast<double>(n))};
  };
  return advance_linearised(iv, {{F, FTMP, FT, J0}, typical, JACOBIAN_MAX_AGE, ORDER, MAX_FACTOR},
                            y, t0, t1, settings, m, s, u, k, y_new, result, try_step);
}

}  // namespace mt::integrate::ros34pw2
