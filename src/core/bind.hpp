// The parts of the `mount_twin._core` extension module, one per area of the core.
#pragma once

#include <pybind11/pybind11.h>

namespace mt {
void bind_kinds(pybind11::module_& m);      // kinds/bind.cpp
void bind_physics(pybind11::module_& m);    // physics/bind.cpp
void bind_integrate(pybind11::module_& m);  // integrate/bind.cpp
void bind_engine(pybind11::module_& m);     // engine/bind.cpp
}  // namespace mt
