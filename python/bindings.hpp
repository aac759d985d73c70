// What the binding files of the Python module share: arrays from and to NumPy, quantities with
// units, errors, JSON. The bindings only translate: every number is computed by the library.
//
// Arrays in. A NumPy array (or a list of floats) of dtype float64, any shape; the array
// arguments of one call must have the same shape (a scalar stands for every element). Nothing is
// cast silently: another dtype is uphill.InputTypeError (an InputError, so a ValueError, and a
// TypeError) that names the argument and says how to convert it.
// A C-contiguous array is read in place (no copy); another layout is copied once.
// Arrays out. New float64 arrays of the inputs' shape, written by the library's kernels in place,
// or (where a function takes `out=`) the caller's own arrays, so that repeated calls allocate
// nothing.
// Errors. uphill::InputError becomes uphill.InputError (a ValueError) with the attributes
// quantity, rule and row: row is the element's index (flat, C order) for array arguments, the
// file's row where the library names one, else None. An argument of the wrong type or dtype is
// uphill.InputTypeError, a subclass of both InputError and TypeError (as NumPy's AxisError is
// both a ValueError and an IndexError): `except ValueError` and `except TypeError` both see it.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "io/units.hpp"
#include "model/input_error.hpp"
#include "model/input_ranges.hpp"

namespace uphill::python {

namespace py = pybind11;

// An InputError about one element of an array argument (or one row of a file).
class RowInputError : public InputError {
 public:
  RowInputError(const InputError& error, std::size_t row) : InputError(error), row_(row) {}
  std::size_t row() const { return row_; }

 private:
  std::size_t row_;
};

// f(), with an InputError it throws made element i's (RowInputError) — unless `whole`: the
// argument is a scalar, and the error is about it as a whole.
template <typename F>
auto ForElement(std::size_t i, F&& f, bool whole = false) {
  try {
    return f();
  } catch (const InputError& e) {
    if (whole) throw;
    throw RowInputError(e, i);
  }
}

// An argument of the wrong Python type or NumPy dtype (never cast): uphill.InputTypeError.
class ArgumentTypeError : public InputError {
 public:
  using InputError::InputError;
};

// Registers uphill.InputError, uphill.InputTypeError and the translation of InputError,
// RowInputError and ArgumentTypeError.
void RegisterErrors(py::module_& m);

// A float64 argument: a scalar, or an array read in place when C-contiguous.
class Float64Argument {
 public:
  // Throws ArgumentTypeError for anything but a real number or a float64 array/list.
  Float64Argument(const py::handle& value, std::string name);
  const std::string& name() const { return name_; }
  bool is_scalar() const { return !array_.has_value(); }
  std::size_t size() const { return size_; }
  const std::vector<py::ssize_t>& shape() const { return shape_; }
  const double* data() const { return array_ ? static_cast<const double*>(array_->data()) : &scalar_; }
  // Element i (the scalar for every i).
  double operator[](std::size_t i) const { return array_ ? data()[i] : scalar_; }

 private:
  std::string name_;
  std::optional<py::array> array_;  // the C-contiguous data (the caller's array, or a copy)
  double scalar_ = 0.0;
  std::size_t size_ = 1;
  std::vector<py::ssize_t> shape_;
};

// The common shape of the array arguments (an empty shape when all are scalars). InputError
// (quantity: the later argument's name) when two arrays differ in shape.
std::vector<py::ssize_t> CommonShape(const std::vector<const Float64Argument*>& arguments);
std::size_t ElementCount(const std::vector<py::ssize_t>& shape);

// A new float64 array of `shape` (a 0-d array for an empty shape).
py::array_t<double> NewArray(const std::vector<py::ssize_t>& shape);
// The caller's `out=` array for `name`, checked: float64, C-contiguous, writeable, of `shape`
// (ArgumentTypeError / InputError naming it); or a new array when `out` is None.
py::array_t<double> OutputArray(const py::object& out, const std::string& name, const std::vector<py::ssize_t>& shape);
double* MutableData(py::array_t<double>& array);

// A quantity given as a number (SI) or as text with its unit, as on the command line ("45 mm",
// "10 deg"): uphill's own unit parser (io/units.hpp) reads the text. Finite, else InputError.
double Quantity(const py::handle& value, Dimension dimension, const std::string& name);
std::optional<double> OptionalQuantity(const py::object& value, Dimension dimension, const std::string& name);
// A length (a number in m, or text with its unit) in the model's range (model/input_ranges.hpp).
double Length(const py::handle& value, const std::string& name);
// A plain real number (a Python int or float): ArgumentTypeError for another type, InputError for
// NaN, the infinities, or an int too large for a double.
double Number(const py::handle& value, const std::string& name);
// A whole number in [0, 2^64) (a seed): ArgumentTypeError for another type, InputError outside.
std::uint64_t Count(const py::handle& value, const std::string& name);
// Monte Carlo trials: 0 (none) or within model/input_ranges.hpp's range.
std::uint64_t Trials(const py::handle& value, const std::string& name);

// nlohmann JSON (the CLI's own JSON of a result) to Python dicts, lists and numbers.
py::object ToPython(const nlohmann::ordered_json& value);
py::object ToPython(const nlohmann::json& value);

// A NumPy array over a std::vector<T> that a Python object keeps alive (`owner`): no copy.
template <typename T>
py::array_t<T> ArrayView(const std::vector<T>& values, const py::handle& owner) {
  return py::array_t<T>({static_cast<py::ssize_t>(values.size())}, {static_cast<py::ssize_t>(sizeof(T))},
                        values.data(), owner);
}

// The binding files: each adds its part of the module.
void BindUnits(py::module_& m);
void BindModel(py::module_& m);
void BindConvert(py::module_& m);
void BindFit(py::module_& m);
void BindMotion(py::module_& m);
void BindFiles(py::module_& m);
void BindVision(py::module_& m);

}  // namespace uphill::python
