// Python bindings of the core's kinds (mount_twin._core.kind_load, kind_monitor, kind_update,
// kind_carry, KIND_NAMES, N_PAR, N_EVENTS): the dispatchers of dispatch.hpp on numpy float64
// arrays, for mount_twin.kinds.check_dispatch and the tests. Every array is checked (dtype,
// contiguity, length) and every index the law will use is checked to lie inside its array, so
// a wrong argument raises TypeError/ValueError naming it instead of reaching the law.
#include <pybind11/pybind11.h>

#include <string>

#include "../bind.hpp"
#include "../convert.hpp"
#include "dispatch.hpp"

namespace mt {

namespace kinds_bind {

namespace py = pybind11;

/// The parameter row: at least N_PAR entries, and nothing in it that would make the kind's law
/// index outside it.
inline Vec par(py::handle obj, idx code) {
  const Vec p = convert::vec(obj, "p");
  if (p.n < kinds::N_PAR) {
    throw py::value_error("p: length " + std::to_string(p.n) + " where at least " +
                          std::to_string(kinds::N_PAR) + " (N_PAR) is needed");
  }
  if (const char* why = kinds::kind_invalid(code, p.d)) {
    throw py::value_error(std::string("p: ") + why);
  }
  return p;
}

/// The state y and the offset o of the mount's states in it: −1 ≤ o < len(y), and the kind's
/// states (o .. o + its count) inside y.
inline Vec state(py::handle obj, idx code, const Vec& p, idx o) {
  const Vec y = convert::vec(obj, "y");
  if (o < -1 || o >= y.n) {
    throw py::value_error("o: offset " + std::to_string(o) + " outside y (length " +
                          std::to_string(y.n) + "; -1: no states)");
  }
  const idx ns = kinds::kind_states(code, p.d);
  if (ns > 0 && (o < 0 || o + ns > y.n)) {
    throw py::value_error("o: the kind's " + std::to_string(ns) + " states from offset " +
                          std::to_string(o) + " do not lie inside y (length " +
                          std::to_string(y.n) + ")");
  }
  return y;
}

inline const double* vec3(py::handle obj, const char* what) {
  return convert::vec(obj, what, 3).d;
}

inline void load(idx code, py::handle p_, py::handle y_, idx o, py::handle d_, py::handle v_,
                 py::handle phi_, py::handle w_, py::handle dydt_, py::handle f_,
                 py::handle c_) {
  const Vec p = par(p_, code);
  const Vec y = state(y_, code, p, o);
  const double* d = vec3(d_, "d");
  const double* v = vec3(v_, "v");
  const double* phi = vec3(phi_, "phi");
  const double* w = vec3(w_, "w");
  const Vec dydt = convert::vec(dydt_, "dydt", y.n);
  double* f = convert::vec(f_, "f", 3).d;
  double* c = convert::vec(c_, "c", 3).d;
  kinds::kind_load(code, p.d, y, o, d, v, phi, w, dydt, f, c);
}

inline double monitor(idx code, py::handle p_, py::handle y_, py::handle y0_, idx o,
                      py::handle d_, py::handle v_, py::handle g_) {
  const Vec p = par(p_, code);
  const Vec y = state(y_, code, p, o);
  const Vec y0 = convert::vec(y0_, "y0", y.n);
  const double* d = vec3(d_, "d");
  const double* v = vec3(v_, "v");
  const Vec g = convert::vec(g_, "g");
  const int ne = kinds::kind_events(code);
  if (g.n < ne) {
    throw py::value_error("g: length " + std::to_string(g.n) + " where the kind has " +
                          std::to_string(ne) + " event functions (N_EVENTS: " +
                          std::to_string(kinds::N_EVENTS) + ")");
  }
  return kinds::kind_monitor(code, p.d, y, y0, o, d, v, g);
}

inline bool update(idx code, py::handle p_, py::handle y_, idx o, py::handle d_) {
  const Vec p = par(p_, code);
  const Vec y = state(y_, code, p, o);
  if (kinds::kind_states(code, p.d) < 0 && y.n == 0) {
    throw py::value_error("y: empty, where an unknown kind code writes NaN into y[max(o, 0)]");
  }
  const double* d = vec3(d_, "d");
  return kinds::kind_update(code, p.d, y, o, d);
}

inline void carry(idx code, py::handle p_, py::handle y_, py::handle y0_, py::handle yt_, idx o,
                  py::handle d_, py::handle dt_) {
  const Vec p = par(p_, code);
  const Vec y = state(y_, code, p, o);
  if (kinds::kind_states(code, p.d) < 0 && y.n == 0) {
    throw py::value_error("y: empty, where an unknown kind code writes NaN into y[max(o, 0)]");
  }
  const Vec y0 = convert::vec(y0_, "y0", y.n);
  const Vec yt = convert::vec(yt_, "yt", y.n);
  kinds::kind_carry(code, p.d, y, y0, yt, o, vec3(d_, "d"), vec3(dt_, "dt"));
}

}  // namespace kinds_bind

void bind_kinds(pybind11::module_& m) {
  namespace py = pybind11;
  using namespace py::literals;
  py::tuple names(kinds::N_KINDS);
  for (int i = 0; i < kinds::N_KINDS; ++i) names[i] = py::str(kinds::KIND_NAMES[i]);
  m.attr("KIND_NAMES") = names;
  m.attr("N_PAR") = kinds::N_PAR;
  m.attr("N_EVENTS") = kinds::N_EVENTS;

  m.def("kind_load", &kinds_bind::load, "code"_a, "p"_a, "y"_a, "o"_a, "d"_a, "v"_a, "phi"_a,
        "w"_a, "dydt"_a, "f"_a, "c"_a,
        R"doc(The load of a mount of kind `code` (its index in mount_twin.kinds.KINDS), in the mount's
local axes. All arrays float64, C-contiguous, writeable.

p: (>= N_PAR,) the mount's parameter row (SI units, columns as the kind's module names them).
y: (n,) state vector; o: offset of the mount's internal states in y (-1: none).
d: (3,) local deflection, m; v: (3,) its rate, m/s.
phi: (3,) local rotation vector, rad; w: (3,) its rate, rad/s (NaN for a kind that is not
    ROTATIONAL: it does not read them).
Out: f (3,) force on the body, N; c (3,) generalized couple conjugate to phi, N·m;
    dydt (n,) the kind's internal state rates at o.. (e.g. m/s), other entries untouched.
An unknown code writes NaN into f and c.)doc");

  m.def("kind_monitor", &kinds_bind::monitor, "code"_a, "p"_a, "y"_a, "y0"_a, "o"_a, "d"_a,
        "v"_a, "g"_a,
        R"doc(The event functions of a mount of kind `code` into g, in the order of the kind's EVENTS
(>= 0: the event is happening; units per event, e.g. m for a contact's penetration, 1 for a
force over its limit minus one); returns the mount's utilisation (dimensionless, 1 at its
limit).

p: (>= N_PAR,) parameter row; y, y0: (n,) state now and at the previous sample; o: offset of
the mount's states (-1: none); d: (3,) local deflection, m; v: (3,) its rate, m/s;
g: (>= the kind's event count,) out, entries past the kind's count untouched.
An unknown code writes NaN into all of g and returns NaN.)doc");

  m.def("kind_carries", &kinds::kind_carries, "code"_a,
        "Whether the kind's `kind_carry` returns anything (the companion calls it only then).");
  m.def("kind_carry", &kinds_bind::carry, "code"_a, "p"_a, "y"_a, "y0"_a, "yt"_a, "o"_a, "d"_a,
        "dt"_a,
        R"doc(The rate-independent states of a mount of kind `code` in the error estimate's companion,
after its carried error's kick (a bolted joint's plastic elongation and stick point, returned
onto the yield line and the friction bound where the twin's bolt flows or face is on its bound,
or the companion's passes them), in place in y's entries from o.

p: (>= N_PAR,) parameter row; y: (n,) the companion's state after the kick; y0: (n,) before
it; yt: (n,) the twin's state; o: offset of the mount's states (-1: none); d, dt: (3,) the
companion's and the twin's local deflections, m.
An unknown code writes NaN into y[max(o, 0)].)doc");

  m.def("kind_update", &kinds_bind::update, "code"_a, "p"_a, "y"_a, "o"_a, "d"_a,
        R"doc(Discrete switches of a mount of kind `code` between samples (e.g. a bolt that breaks), in
place in y's entries from o; returns whether one switched (the state jumped).

p: (>= N_PAR,) parameter row; y: (n,) state; o: offset of the mount's states (-1: none);
d: (3,) local deflection, m.
An unknown code writes NaN into y[max(o, 0)] and returns True.)doc");
}

}  // namespace mt
