// Verner's "most robust" 6(5) pair (RKV65.IIIXb.Robust, nine stages, first-same-as-last):
// its table (integrate/verner65.py holds the same, test_core_contract holds them equal) over the
// explicit step of explicit_rk.hpp. The state advances with the 6th-order solution; the
// embedded 5th-order one estimates the local error. Error norm: RMS of err / (atol + rtol·|y|).
// The error estimate's companion runs it where the twin runs Dormand–Prince (engine/companion.py).
#pragma once

namespace mt::integrate::verner65 {

/// The table as explicit_rk::advance reads it, as verner65.py writes it: Verner's 40-digit
/// decimals (the nodes his decimals too, 1/6 as int/int), which the compiler and Python both
/// round correctly to the nearest double. The last row of A is the 6th-order weights (the last
/// stage is first-same-as-last); B_HAT the embedded 5th-order weights; E their difference
/// (double subtractions, as verner65.py's).
struct Table {
  /// Rows of the 2-D work array (the stages, the FSAL one included).
  static constexpr int STAGES = 9;
  /// Order of the error estimate (the controller's exponent is −1/(ORDER + 1)).
  static constexpr int ORDER = 5;
  static constexpr double MAX_FACTOR = 10.0;
  static constexpr bool FSAL = true;
  static constexpr double C[9] = {0.0, 0.18, 1.0 / 6, 0.25, 0.53, 0.6, 0.8, 1.0, 1.0};
  static constexpr double A[9][8] = {
      {0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
      {0.18, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
      {0.8950617283950617283950617283950617283951e-1, 0.7716049382716049382716049382716049382716e-1,
       0.0, 0.0, 0.0, 0.0, 0.0, 0.0},
      {0.625e-1, 0.0, 0.1875, 0.0, 0.0, 0.0, 0.0, 0.0},
      {0.316516, 0.0, -1.044948, 1.258432, 0.0, 0.0, 0.0, 0.0},
      {0.2723261273648562625722506556667430550251, 0.0, -0.8251336032388663967611336032388663967611,
       1.048091767881241565452091767881241565452, 0.1047157079927685687367911796908817762840, 0.0,
       0.0, 0.0},
      {-0.1669941859971651431432960727896179733320, 0.0, 0.6317085020242914979757085020242914979757,
       0.1746104455277387608214675883848816179643, -1.066535645908606612252519473401868067778,
       1.227210884353741496598639455782312925170, 0.0, 0.0},
      {0.3642375168690958164642375168690958164642, 0.0, -0.2040485829959514170040485829959514170040,
       -0.3488373781606864313631230924464007170774, 3.261932303285686744333360874714258172905,
       -2.755102040816326530612244897959183673469, 0.6818181818181818181818181818181818181818, 0.0},
      {0.7638888888888888888888888888888888888889e-1, 0.0, 0.0,
       0.3694083694083694083694083694083694083694, 0.0, 0.2480158730158730158730158730158730158730,
       0.2367424242424242424242424242424242424242, 0.6944444444444444444444444444444444444444e-1},
  };
  static constexpr double B_HAT[9] = {
      0.5870020964360587002096436058700209643606e-1, 0.0, 0.0,
      0.4807256235827664399092970521541950113379,
      -0.8534124207691908557883209486122831308356,
      1.204648526077097505668934240362811791383, 0.0,
      -0.5924237307216030620285939434875605088371e-1,
      0.1685804345378813463919846898570302825622};
  static constexpr double E[9] = {A[8][0] - B_HAT[0], A[8][1] - B_HAT[1], A[8][2] - B_HAT[2],
                                  A[8][3] - B_HAT[3], A[8][4] - B_HAT[4], A[8][5] - B_HAT[5],
                                  A[8][6] - B_HAT[6], A[8][7] - B_HAT[7], 0.0 - B_HAT[8]};
};

}  // namespace mt::integrate::verner65
