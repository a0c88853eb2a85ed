// Small numeric helpers with Python's semantics, so the core computes what the Python
// reference code says (NaN included).
#pragma once

namespace mt {

/// Python's max(a, b): a unless b > a (a NaN first argument stays; a NaN second is skipped).
inline double py_max(double a, double b) { return b > a ? b : a; }
/// Python's min(a, b): a unless b < a.
inline double py_min(double a, double b) { return b < a ? b : a; }

}  // namespace mt
