// sin and cos of the body's chart angles α, γ, δ (rad): a few milliradians on their mounts, so
// by their series where |x| ≤ π/4 and by the C library beyond.
#pragma once

#include <cmath>

namespace mt::physics {

/// π/4: the reach of `sin_cos`'s series.
inline constexpr double SERIES_REACH = 0.7853981633974483;

/// The Taylor coefficients of (sin x − x)/x³ and (cos x − 1)/x² in x², the highest power first
/// (each (−1)ᵏ/n! rounded to the nearest double).
inline constexpr double SIN_SERIES[] = {
    2.8114572543455206e-15,  // 1/17!
    -7.647163731819816e-13,  1.6059043836821613e-10, -2.505210838544172e-08,
    2.7557319223985893e-06,  -0.0001984126984126984, 0.008333333333333333,
    -0.16666666666666666,  // −1/3!
};
inline constexpr double COS_SERIES[] = {
    -1.5619206968586225e-16,  // −1/18!
    4.779477332387385e-14,    -1.1470745597729725e-11, 2.08767569878681e-09,
    -2.755731922398589e-07,   2.48015873015873e-05,    -0.001388888888888889,
    0.041666666666666664,     -0.5,  // −1/2!
};

/// c[0]·zⁿ⁻¹ + c[1]·zⁿ⁻² + … + c[n − 1] in Horner's form.
template <int N>
inline double horner(const double (&c)[N], double z) {
  double p = c[0];
  for (int k = 1; k < N; ++k) p = p * z + c[k];
  return p;
}

/// s = sin x, c = cos x. Where |x| ≤ π/4, their Taylor series to x¹⁷ and x¹⁸ in Horner's form
/// in x² (the first term left out of each, x¹⁹/19! and x²⁰/20!, is below 1e-19 there: the
/// series' own error is the rounding of its last few operations, within 1.5 ulp of the
/// correctly rounded value: test_physics_kinematics.py finds 1.0 at worst); elsewhere (and for
/// NaN) the C library's.
/// The library's sincos, which reduces any x, was 7.5 % of the bundled genset's engine with its
/// estimate (perf); with these series its core took 11.6–11.8 ms, not 12.3 (bench_engine.py).
inline void sin_cos(double x, double& s, double& c) {
  if (!(std::fabs(x) <= SERIES_REACH)) {
    s = std::sin(x);
    c = std::cos(x);
    return;
  }
  const double z = x * x;
  s = x + (x * z) * horner(SIN_SERIES, z);
  c = 1.0 + z * horner(COS_SERIES, z);
}

}  // namespace mt::physics
