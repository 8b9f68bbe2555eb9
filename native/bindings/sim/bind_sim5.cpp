// Scaffolding: filled in by the bind_sim5 work (see native/include/tmm/sim/).
#include <pybind11/pybind11.h>

namespace py = pybind11;

void bind_sim5(py::module_& m) { (void)m; }
