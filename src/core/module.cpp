// mount_twin._core_ext: the compiled hot path (C++17), built ahead of time by setup.py, imported
// through mount_twin/_core.py (which checks SOURCE_SHA256 against the sources beside it).
#include "bind.hpp"
#include "constants.hpp"

PYBIND11_MODULE(_core_ext, m) {
  m.doc() = "mount_twin's compiled core: mount laws, equations of motion, steppers, the loop";
  m.attr("SETTING_SLOTS") = pybind11::make_tuple(
      int(mt::STEP), int(mt::RTOL), int(mt::ATOL), int(mt::MAX_SUBSTEPS), int(mt::CHAINED),
      int(mt::MIN_STEPS), int(mt::JACOBIAN_AGE), int(mt::PHI_STEP), int(mt::HOLD_AFTER_REJECT),
      int(mt::N_SETTINGS));
  m.attr("STATUSES") = pybind11::make_tuple(
      int(mt::SUCCESS), int(mt::TOO_MANY_STEPS), int(mt::STEP_TOO_SMALL), int(mt::LEFT_CHART),
      int(mt::NOT_FINITE), int(mt::UNKNOWN_METHOD));
  m.attr("METHOD_IDS") = pybind11::make_tuple(int(mt::DOPRI54), int(mt::ROS34PW2),
                                              int(mt::EXPRB32), int(mt::VERNER65));
  m.attr("POSE_ROW") = pybind11::make_tuple(mt::pose_row::POSITION, mt::pose_row::QUATERNION,
                                            mt::pose_row::ANGLES, mt::pose_row::WIDTH);
  m.attr("FIGURE_SLOTS") = pybind11::make_tuple(int(mt::FORCE_ERROR), int(mt::ATTITUDE_ERROR),
                                                int(mt::FORCE_SCALE), int(mt::FAILURES),
                                                int(mt::UNCARRIED), int(mt::N_FIGURES));
  m.attr("AT_EVENT") = mt::AT_EVENT;
  m.attr("SOURCE_SHA256") = MT_SOURCE_SHA256;
  m.attr("INPUT_SIZE") = mt::INPUT_SIZE;
  mt::bind_kinds(m);
  mt::bind_physics(m);
  mt::bind_integrate(m);
  mt::bind_engine(m);
}
