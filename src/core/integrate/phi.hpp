// The φ functions of a matrix, φ_k(hJ) for k = 1, 2, 3, allocation-free: what the exponential
// integrator multiplies by (integrate/phi.py: balancing, scaling, Taylor series, modified
// squaring, unbalancing; the same operations in the same order).
#pragma once

#include <cmath>
#include <algorithm>
#include <cstdint>

#include "../numeric.hpp"
#include "../views.hpp"

namespace mt::integrate::phi {

/// Largest 1-norm of the scaled matrix summed by Taylor series.
constexpr double THETA = 1.0;
/// Taylor terms z^0 … z^18.
constexpr int TERMS = 19;
/// Sweeps of the balancing at most.
constexpr int MAX_BALANCE_SWEEPS = 64;

/// First rows of the n-row blocks of a work array the φ functions use (phi.py Blocks): j the
/// matrix J (read); p1 φ_1, φ_2, φ_3 of hJ in three consecutive blocks (written); z four
/// consecutive work blocks; scale one row for the balancing's diagonal.
struct Blocks {
  idx j, p1, z, scale;
};

/// k[out:out+n] = k[a:a+n] @ k[b:b+n] (out distinct from a and b).
inline void matmul(Mat k, idx a, idx b, idx out, idx n) {
  for (idx r = 0; r < n; ++r) {
    for (idx c = 0; c < n; ++c) k(out + r, c) = 0.0;
    for (idx q = 0; q < n; ++q) {
      const double x = k(a + r, q);
      if (x != 0.0) {
        for (idx c = 0; c < n; ++c) k(out + r, c) += x * k(b + q, c);
      }
    }
  }
}

/// Balance k[z:z+n] in place by a diagonal similarity D⁻¹ A D of powers of two; D's diagonal
/// into k[sc].
inline void balance(Mat k, idx z, idx sc, idx n) {
  for (idx i = 0; i < n; ++i) k(sc, i) = 1.0;
  for (int sweep = 0; sweep < MAX_BALANCE_SWEEPS; ++sweep) {
    bool done = true;
    for (idx i = 0; i < n; ++i) {
      double c = 0.0, r = 0.0;
      for (idx j = 0; j < n; ++j) {
        if (j != i) {
          c += std::fabs(k(z + j, i));
          r += std::fabs(k(z + i, j));
        }
      }
      if (c == 0.0 || r == 0.0) continue;
      const double total = c + r;
      double f = 1.0;
      while (c < r / 2.0) {
        f *= 2.0;
        c *= 4.0;
      }
      while (c > r * 2.0) {
        f /= 2.0;
        c /= 4.0;
      }
      if ((c + r) / f < 0.95 * total) {
        done = false;
        k(sc, i) *= f;
        for (idx j = 0; j < n; ++j) {
          k(z + i, j) /= f;
          k(z + j, i) *= f;
        }
      }
    }
    if (done) return;
  }
}

/// numba's float ** int (numbers.py int_power): binary powering, a negative exponent by 1/x^|b|.
inline double int_power(double a, std::int64_t b) {
  double r = 1.0;
  const bool invert = b < 0;
  std::int64_t e = invert ? -b : b;
  if (e > 0x10000) return std::pow(a, static_cast<double>(b));
  while (e != 0) {
    if (e & 1) r *= a;
    e >>= 1;
    a *= a;
  }
  return invert ? 1.0 / r : r;
}

/// Copy the three φ blocks from row `from` to row `to` (3n rows).
inline void copy_phis(Mat k, idx from, idx to, idx n) {
  for (idx r = 0; r < 3 * n; ++r) {
    for (idx c = 0; c < n; ++c) k(to + r, c) = k(from + r, c);
  }
}

/// φ_1, φ_2, φ_3 of h·J (h in s, J in 1/s) into the blocks from b.p1 (J at b.j); false if they
/// are not finite (J with NaN or inf). With `half` ≥ 0 and at least one doubling, also φ_1,
/// φ_2, φ_3 of (h/2)·J into the three blocks from row `half`: the doubling's last iterate but
/// one, what `phi_functions(k, n, h / 2, b)` computes (the same balancing, the same scaled
/// matrix, one doubling fewer); *halved says whether it did.
inline bool phi_functions(Mat k, idx n, double h, Blocks b, idx half = -1,
                          bool* halved = nullptr) {
  const idx z = b.z, pw = b.z + n, tmp = b.z + 2 * n, e = b.z + 3 * n, sc = b.scale;
  const idx p1 = b.p1, p2 = b.p1 + n, p3 = b.p1 + 2 * n;
  for (idx r = 0; r < n; ++r) {
    for (idx c = 0; c < n; ++c) k(z + r, c) = h * k(b.j + r, c);
  }
  balance(k, z, sc, n);
  double norm = 0.0;
  for (idx c = 0; c < n; ++c) {
    double col = 0.0;
    for (idx r = 0; r < n; ++r) col += std::fabs(k(z + r, c));
    norm = py_max(norm, col);
  }
  if (!std::isfinite(norm)) return false;
  // math.ceil returns an int (fptosi of the float ceiling)
  const std::int64_t squarings =
      norm > THETA
          ? std::max<std::int64_t>(
                0, static_cast<std::int64_t>(std::ceil(std::log2(norm / THETA))))
          : 0;
  const double shrink = int_power(2.0, -squarings);
  for (idx r = 0; r < n; ++r) {
    for (idx c = 0; c < n; ++c) {
      k(z + r, c) *= shrink;
      k(pw + r, c) = r == c ? 1.0 : 0.0;  // z^0
      k(e + r, c) = 0.0;
      k(p1 + r, c) = 0.0;
      k(p2 + r, c) = 0.0;
      k(p3 + r, c) = 0.0;
    }
  }
  // Taylor: term i adds z^i/i!, z^i/(i+1)!, z^i/(i+2)!, z^i/(i+3)!
  double fact = 1.0;  // i!
  for (int i = 0; i < TERMS; ++i) {
    if (i > 0) {
      fact *= static_cast<double>(i);
      matmul(k, pw, z, tmp, n);
      for (idx r = 0; r < n; ++r) {
        for (idx c = 0; c < n; ++c) k(pw + r, c) = k(tmp + r, c);
      }
    }
    const double w0 = 1.0 / fact;
    const double w1 = w0 / static_cast<double>(i + 1);
    const double w2 = w1 / static_cast<double>(i + 2);
    const double w3 = w2 / static_cast<double>(i + 3);
    for (idx r = 0; r < n; ++r) {
      for (idx c = 0; c < n; ++c) {
        const double x = k(pw + r, c);
        k(e + r, c) += w0 * x;
        k(p1 + r, c) += w1 * x;
        k(p2 + r, c) += w2 * x;
        k(p3 + r, c) += w3 * x;
      }
    }
  }
  // square back: each doubling uses the old φ_1, φ_2 in the higher ones, so φ_3 goes first
  const bool keep_half = half >= 0 && squarings >= 1;
  if (halved != nullptr) *halved = keep_half;
  if (keep_half && squarings == 1) copy_phis(k, p1, half, n);
  for (std::int64_t q = 0; q < squarings; ++q) {
    matmul(k, e, p3, tmp, n);
    for (idx r = 0; r < n; ++r) {
      for (idx c = 0; c < n; ++c) {
        k(p3 + r, c) = (k(tmp + r, c) + 0.5 * k(p1 + r, c) + k(p2 + r, c) + k(p3 + r, c)) / 8.0;
      }
    }
    matmul(k, e, p2, tmp, n);
    for (idx r = 0; r < n; ++r) {
      for (idx c = 0; c < n; ++c) k(p2 + r, c) = (k(tmp + r, c) + k(p1 + r, c) + k(p2 + r, c)) / 4.0;
    }
    matmul(k, e, p1, tmp, n);
    for (idx r = 0; r < n; ++r) {
      for (idx c = 0; c < n; ++c) k(p1 + r, c) = (k(tmp + r, c) + k(p1 + r, c)) / 2.0;
    }
    matmul(k, e, e, tmp, n);
    for (idx r = 0; r < n; ++r) {
      for (idx c = 0; c < n; ++c) k(e + r, c) = k(tmp + r, c);
    }
    if (keep_half && q + 2 == squarings) copy_phis(k, p1, half, n);
  }
  bool finite = true;
  for (idx r = 0; r < n; ++r) {  // undo the balancing: φ(A) = D φ(D⁻¹AD) D⁻¹
    for (idx c = 0; c < n; ++c) {
      const double ratio = k(sc, r) / k(sc, c);
      k(p1 + r, c) *= ratio;
      k(p2 + r, c) *= ratio;
      k(p3 + r, c) *= ratio;
      finite = finite && std::isfinite(k(p3 + r, c)) && std::isfinite(k(p1 + r, c));
      if (keep_half) {
        for (idx block = 0; block < 3; ++block) k(half + block * n + r, c) *= ratio;
      }
    }
  }
  return finite;
}

}  // namespace mt::integrate::phi
