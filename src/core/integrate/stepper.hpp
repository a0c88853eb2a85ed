// Steppers behind one interface: advance the state across one input interval
// (integrate/stepper.py `advance`: the switch on the method id of integrate/methods.py).
#pragma once

#include "../constants.hpp"
#include "../model.hpp"
#include "../views.hpp"
#include "control.hpp"
#include "dopri54.hpp"
#include "explicit_rk.hpp"
#include "exprb32.hpp"
#include "ros34pw2.hpp"
#include "verner65.hpp"

namespace mt::integrate {

/// Rows of n of a method's work array for n states (methods.py Method.work_rows); −1 for an
/// unknown method.
inline idx work_rows(int method, idx n) {
  switch (method) {
    case DOPRI54: return dopri54::Table::STAGES;
    case ROS34PW2: return ros34pw2::work_rows(n);
    case EXPRB32: return exprb32::work_rows(n);
    case VERNER65: return verner65::Table::STAGES;
    default: return -1;
  }
}

/// Advance y from t0 to t1 (s) with the stepper `method` (a Method id); returns its Status
/// (SUCCESS = 0), UNKNOWN_METHOD for an id no method has (nothing touched).
inline int advance(int method, Vec y, double t0, double t1, Vec settings, const Model& m,
                   Scratch& s, Vec u, Mat work2d, Vec work1d, Vec result) {
  if (method == DOPRI54) {
    return explicit_rk::advance<dopri54::Table>(y, t0, t1, settings, m, s, u, work2d, work1d,
                                               result);
  }
  if (method == ROS34PW2) {
    return ros34pw2::advance(y, t0, t1, settings, m, s, u, work2d, work1d, result);
  }
  if (method == EXPRB32) {
    return exprb32::advance(y, t0, t1, settings, m, s, u, work2d, work1d, result);
  }
  if (method == VERNER65) {
    return explicit_rk::advance<verner65::Table>(y, t0, t1, settings, m, s, u, work2d, work1d,
                                                result);
  }
  return UNKNOWN_METHOD;
}

/// Advance y from t0 to t1 (s) by settings[MIN_STEPS] equal steps of the explicit method
/// `method`, no error control (explicit_rk::advance_fixed); UNKNOWN_METHOD for an id that is not
/// an explicit method's (nothing touched).
inline int advance_fixed(int method, Vec y, double t0, double t1, Vec settings, const Model& m,
                         Scratch& s, Vec u, Mat work2d, Vec work1d, Vec result) {
  if (method == DOPRI54) {
    return explicit_rk::advance_fixed<dopri54::Table>(y, t0, t1, settings, m, s, u, work2d,
                                                     work1d, result);
  }
  if (method == VERNER65) {
    return explicit_rk::advance_fixed<verner65::Table>(y, t0, t1, settings, m, s, u, work2d,
                                                      work1d, result);
  }
  return UNKNOWN_METHOD;
}

}  // namespace mt::integrate
