// Small dense linear algebra on row-major square views: products, a 3×3 inverse (the model's
// inertia) and the matrix exponential (the error estimate's propagator,
// engine/estimator.hpp). No allocation: callers pass work.
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

/// out = a·x from a_t = aᵀ (a: a_t.cols × a_t.rows; out distinct from x), column by column:
/// each row's sum still runs over the columns in order from 0.0 (the bits of a row-by-row dot
/// product), but the rows' sums advance side by side, so the compiler fills vector registers
/// with them instead of waiting an addition's latency per term (the estimate's two products
/// per interval took 0.07 of the pump's engine time row by row, four rows at a time).
inline void matvec_t(Mat a_t, const double* x, double* out) {
  const idx rows = a_t.cols;
  for (idx r = 0; r < rows; ++r) out[r] = 0.0;
  for (idx c = 0; c < a_t.rows; ++c) {
    const double xc = x[c];
    const double* col = &a_t(c, 0);
    for (idx r = 0; r < rows; ++r) out[r] += col[r] * xc;
  }
}

/// a ← aᵀ (square).
inline void transpose(Mat a) {
  for (idx i = 0; i < a.rows; ++i) {
    for (idx j = 0; j < i; ++j) {
      const double keep = a(i, j);
      a(i, j) = a(j, i);
      a(j, i) = keep;
    }
  }
}

/// inv = a⁻¹ of an invertible 3×3 matrix, the adjugate over the determinant (the model's
/// inertia, which the scene loader holds positive definite).
inline void invert_3x3(MatC<3> a, double (&inv)[3][3]) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {  // cofactor of a(j, i): the adjugate's (i, j)
      const int r0 = (j + 1) % 3, r1 = (j + 2) % 3, c0 = (i + 1) % 3, c1 = (i + 2) % 3;
      inv[i][j] = a(r0, c0) * a(r1, c1) - a(r0, c1) * a(r1, c0);
    }
  }
  const double det = a(0, 0) * inv[0][0] + a(0, 1) * inv[1][0] + a(0, 2) * inv[2][0];
  for (auto& row : inv) {
    for (double& x : row) x /= det;
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
