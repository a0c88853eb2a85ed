// Small dense linear algebra on row-major square views: products and the matrix exponential
// (the error estimate's propagator, engine/estimator.hpp). No allocation: callers pass work.
#pragma once

#include <cmath>

#include "numeric.hpp"
#include "views.hpp"

namespace mt::linalg {

/// c = a·b (n×n; c distinct from a and b).
inline void matmul(Mat a, Mat b, Mat c) {
  const idx n = a.rows;
  for (idx i = 0; i < n; ++i) {
    double* ci = &c(i, 0);
    for (idx j = 0; j < n; ++j) ci[j] = 0.0;
    for (idx k = 0; k < n; ++k) {
      const double aik = a(i, k);
      const double* bk = &b(k, 0);
      for (idx j = 0; j < n; ++j) ci[j] += aik * bk[j];
    }
  }
}

/// out = a·x (a: rows × x.n; out distinct from x). Each row's sum runs over j in order; four
/// rows at a time, so four independent sums fill the adder's pipeline (one row's sum alone
/// waits an addition's latency per term: the estimate's two products took a tenth of the
/// pump's engine time).
inline void matvec(Mat a, const double* x, double* out) {
  const idx n = a.cols;
  idx i = 0;
  for (; i + 4 <= a.rows; i += 4) {
    const double *a0 = &a(i, 0), *a1 = a0 + n, *a2 = a1 + n, *a3 = a2 + n;
    double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;
    for (idx j = 0; j < n; ++j) {
      const double xj = x[j];
      s0 += a0[j] * xj;
      s1 += a1[j] * xj;
      s2 += a2[j] * xj;
      s3 += a3[j] * xj;
    }
    out[i] = s0;
    out[i + 1] = s1;
    out[i + 2] = s2;
    out[i + 3] = s3;
  }
  for (; i < a.rows; ++i) {
    const double* ai = &a(i, 0);
    double sum = 0.0;
    for (idx j = 0; j < n; ++j) sum += ai[j] * x[j];
    out[i] = sum;
  }
}

/// Largest absolute column sum.
inline double norm1(Mat a) {
  double best = 0.0;
  for (idx j = 0; j < a.cols; ++j) {
    double sum = 0.0;
    for (idx i = 0; i < a.rows; ++i) sum += std::fabs(a(i, j));
    best = py_max(best, sum);
  }
  return best;
}

/// Terms of the Taylor polynomial of exp after scaling ‖A/2^s‖₁ ≤ EXPM_SCALED_NORM: the
/// truncation is below 0.5⁹/9! ≈ 5e-9 relative, 2^s times that after the squarings (the error
/// estimate's propagator needs three digits).
constexpr int EXPM_TERMS = 8;
constexpr double EXPM_SCALED_NORM = 0.5;

/// out = exp(scale·a) by scaling and squaring of a Taylor polynomial (Moler & Van Loan's
/// method 3); w0, w1: n×n work. Returns false if a holds a non-finite value.
inline bool expm(Mat a, double scale, Mat out, Mat w0, Mat w1) {
  const idx n = a.rows;
  const double norm = std::fabs(scale) * norm1(a);
  if (!std::isfinite(norm)) return false;
  int squarings = 0;
  while (norm * std::ldexp(1.0, -squarings) > EXPM_SCALED_NORM) ++squarings;
  const double factor = std::ldexp(scale, -squarings);
  // Horner: T = I + A/1 (I + A/2 (I + … (I + A/K))), A = factor·a.
  for (idx i = 0; i < n; ++i) {
    for (idx j = 0; j < n; ++j) out(i, j) = (i == j) ? 1.0 : 0.0;
  }
  for (int k = EXPM_TERMS; k >= 1; --k) {
    matmul(a, out, w0);
    const double c = factor / k;
    for (idx i = 0; i < n; ++i) {
      for (idx j = 0; j < n; ++j) out(i, j) = c * w0(i, j) + ((i == j) ? 1.0 : 0.0);
    }
  }
  for (int q = 0; q < squarings; ++q) {
    matmul(out, out, w1);
    for (idx i = 0; i < n * n; ++i) out.d[i] = w1.d[i];
  }
  return true;
}

}  // namespace mt::linalg
