// Slots and codes shared with the Python side. Python holds the names (integrate/settings.py,
// integrate/methods.py, physics/pose_row.py, engine/estimate.py); test/test_core_contract.py
// holds these values equal to them, so an edit on one side alone fails loudly.
#pragma once

namespace mt {

// A stepper's settings vector (integrate/settings.py).
enum Setting : int {
  STEP = 0, RTOL, ATOL, MAX_SUBSTEPS, CHAINED, MIN_STEPS, JACOBIAN_AGE, PHI_STEP,
  HOLD_AFTER_REJECT, N_SETTINGS
};

// A stepper's status (integrate/methods.py).
enum Status : int {
  SUCCESS = 0, TOO_MANY_STEPS = 1, STEP_TOO_SMALL = 2, LEFT_CHART = 3, NOT_FINITE = 4,
  UNKNOWN_METHOD = -1
};

// Method ids (integrate/methods.py METHODS[...].id).
enum Method : int { DOPRI54 = 0, ROS34PW2 = 1, EXPRB32 = 2, VERNER65 = 3, N_METHODS = 4 };

// Right-hand-side status (physics/dynamics.py).
enum RhsStatus : int { OK = 0, OFF_CHART = 1 };

// A pose row (physics/pose_row.py).
namespace pose_row {
constexpr int POSITION = 0, QUATERNION = 3, ANGLES = 7, WIDTH = 10;
}

// The error estimate's figures (engine/estimate.py).
enum Figure : int {
  FORCE_ERROR = 0, ATTITUDE_ERROR, FORCE_SCALE, FAILURES, UNCARRIED, N_FIGURES
};

// run_samples' status when it ended the run at an event that may stiffen the scene.
constexpr int AT_EVENT = -100;

constexpr int INPUT_SIZE = 13;  // u = [t0, f0, ḟ, Ω0, Ω̇]

}  // namespace mt
