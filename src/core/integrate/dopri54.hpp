// Dormand–Prince 5(4): its table (integrate/dopri54.py holds the same, test_core_contract
// holds them equal) over the explicit step of explicit_rk.hpp. The state advances with the
// 5th-order solution; the embedded 4th-order one estimates the local error. Error norm: RMS of
// err / (atol + rtol·|y|).
#pragma once

namespace mt::integrate::dopri54 {

/// The table as explicit_rk::advance reads it, as dopri54.py writes it (Python's int/int true
/// division is the correctly rounded quotient, as these double divisions of exactly
/// representable integers are). The last row of A is the 5th-order weights (the last stage is
/// first-same-as-last); E the 5th-order weights minus the embedded 4th-order ones.
struct Table {
  /// Rows of the 2-D work array (the stages, the FSAL one included).
  static constexpr int STAGES = 7;
  /// Order of the error estimate (the controller's exponent is −1/(ORDER + 1)).
  static constexpr int ORDER = 4;
  static constexpr double MAX_FACTOR = 10.0;
  static constexpr bool FSAL = true;
  static constexpr double C[7] = {0.0, 1.0 / 5, 3.0 / 10, 4.0 / 5, 8.0 / 9, 1.0, 1.0};
  static constexpr double A[7][6] = {
      {0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
      {1.0 / 5, 0.0, 0.0, 0.0, 0.0, 0.0},
      {3.0 / 40, 9.0 / 40, 0.0, 0.0, 0.0, 0.0},
      {44.0 / 45, -56.0 / 15, 32.0 / 9, 0.0, 0.0, 0.0},
      {19372.0 / 6561, -25360.0 / 2187, 64448.0 / 6561, -212.0 / 729, 0.0, 0.0},
      {9017.0 / 3168, -355.0 / 33, 46732.0 / 5247, 49.0 / 176, -5103.0 / 18656, 0.0},
      {35.0 / 384, 0.0, 500.0 / 1113, 125.0 / 192, -2187.0 / 6784, 11.0 / 84},
  };
  static constexpr double E[7] = {71.0 / 57600,      0.0,        -71.0 / 16695, 71.0 / 1920,
                                  -17253.0 / 339200, 22.0 / 525, -1.0 / 40};
};

}  // namespace mt::integrate::dopri54
