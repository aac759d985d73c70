// `import uphill`: the Python module over uphill's libraries (docs/python.md).
#include "bindings.hpp"
#include "model/vector_kernel.hpp"

PYBIND11_MODULE(uphill, m) {
  namespace py = pybind11;
  m.doc() = R"(uphill: experiment analysis for the rolling-uphill rail apparatus, from Python.

The same library as the `uphill` program: scenes and bodies, the batch converter over NumPy arrays
with uncertainties, the rest band, the five fits with their reports, the rolling motion, experiment
folders, track CSVs, calibration files and video tracking. Numbers are SI (metres, radians,
seconds) everywhere; where the program accepts a unit ("45 mm", "10 deg"), so does the module.
Arrays are float64 (nothing is cast silently); bad input raises uphill.InputError, a ValueError
with the attributes quantity, rule and row. See docs/python.md.)";
  m.attr("__version__") = UPHILL_VERSION;
  m.def("kernel", [] { return std::string(uphill::VectorKernelName()); },
        "The batch kernels in use: \"avx2+fma (libmvec)\" or \"scalar (libm)\" (chosen at run time).");
  uphill::python::RegisterErrors(m);
  uphill::python::BindUnits(m);
  uphill::python::BindModel(m);
  uphill::python::BindConvert(m);
  uphill::python::BindFit(m);
  uphill::python::BindMotion(m);
  uphill::python::BindFiles(m);
  uphill::python::BindVision(m);
}
