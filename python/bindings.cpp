#include "bindings.hpp"

#include <pybind11/eval.h>

#include <cmath>
#include <cstring>

namespace uphill::python {

namespace {

// uphill.InputError, defined in Python so that it is an ordinary ValueError subclass with
// attributes (pickles, prints and compares like any exception).
constexpr const char* kInputErrorSource = R"py(
class InputError(ValueError):
    """Bad input: a value outside the model's domain, a malformed file, arrays that do not match.

    Attributes:
        quantity: what is wrong, as the command line would name it ("D", "u(Y)", a file and column).
        rule: the rule broken, in words ("must be > 0 (got -0.003)").
        row: the index of the offending element of an array argument (flat, C order), or the
            file's row, or None when the error is not about one row.
    """

    def __init__(self, quantity, rule, row=None):
        where = quantity if row is None else f"{quantity}, element {row}"
        super().__init__(f"{where}: {rule}")
        self.quantity = quantity
        self.rule = rule
        self.row = row

    def __reduce__(self):
        return (type(self), (self.quantity, self.rule, self.row))


class InputTypeError(InputError, TypeError):
    """An argument of the wrong type or dtype (uphill casts nothing silently): an InputError (so a
    ValueError) with quantity, rule and row, and a TypeError, as Python reports wrong types."""
)py";

py::object& InputErrorType() {
  static py::object type;  // set once at import; lives as long as the module
  return type;
}

py::object& InputTypeErrorType() {
  static py::object type;
  return type;
}

// A Python value for a message: its str, cut short (an int may have thousands of digits).
std::string Shown(const py::handle& value) {
  std::string text = py::str(value);
  return text.size() > 24 ? text.substr(0, 20) + "..." : text;
}

// A Python int or float as a double: InputError for an int too large for one (Python raises
// OverflowError) and for NaN and the infinities.
double ToDouble(const py::handle& value, const std::string& name) {
  const double v = PyFloat_AsDouble(value.ptr());
  if (v == -1.0 && PyErr_Occurred()) {
    PyErr_Clear();
    throw InputError(name, "must be a finite number (got " + Shown(value) + ", too large for a double)");
  }
  return v;
}

double Finite(const py::handle& value, const std::string& name) {
  const double v = ToDouble(value, name);
  if (!std::isfinite(v)) throw InputError(name, "must be a finite number (got " + Shown(value) + ")");
  return v;
}

void Raise(const py::object& type, const InputError& e, const py::object& row) {
  py::object error = type(e.quantity(), e.rule(), row);
  PyErr_SetObject(type.ptr(), error.ptr());
}

}  // namespace

void RegisterErrors(py::module_& m) {
  py::dict scope;
  scope["__name__"] = "uphill";
  py::exec(kInputErrorSource, scope);
  InputErrorType() = scope["InputError"];
  InputTypeErrorType() = scope["InputTypeError"];
  m.attr("InputError") = InputErrorType();
  m.attr("InputTypeError") = InputTypeErrorType();
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const RowInputError& e) {
      Raise(InputErrorType(), e, py::int_(e.row()));
    } catch (const ArgumentTypeError& e) {
      Raise(InputTypeErrorType(), e, py::none());
    } catch (const InputError& e) {
      Raise(InputErrorType(), e, py::none());
    }
  });
}

Float64Argument::Float64Argument(const py::handle& value, std::string name) : name_(std::move(name)) {
  if (py::isinstance<py::bool_>(value))
    throw ArgumentTypeError(name_, "expected a number or a float64 array, got a bool");
  if (py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value)) {
    scalar_ = ToDouble(value, name_);
    return;
  }
  py::array array;
  if (py::isinstance<py::array>(value)) {
    array = py::reinterpret_borrow<py::array>(value);
  } else if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    array = py::array::ensure(value);  // NumPy's own conversion; its dtype is checked below
  } else {
    throw ArgumentTypeError(name_, "expected a number or a float64 array, got " +
                                       std::string(py::str(py::type::of(value).attr("__name__"))));
  }
  if (!array || !array.dtype().is(py::dtype::of<double>()))
    throw ArgumentTypeError(name_, "expected float64, got " +
                                       (array ? std::string(py::str(array.dtype())) : std::string("a list of mixed types")) +
                                       " (uphill casts nothing silently: pass np.asarray(" + name_ +
                                       ", dtype=np.float64))");
  if (array.ndim() == 0) {
    scalar_ = *static_cast<const double*>(array.data());
    return;
  }
  if (!(array.flags() & py::array::c_style)) array = py::array_t<double, py::array::c_style>::ensure(array);
  shape_.assign(array.shape(), array.shape() + array.ndim());
  size_ = static_cast<std::size_t>(array.size());
  array_ = std::move(array);
}

std::size_t ElementCount(const std::vector<py::ssize_t>& shape) {
  std::size_t n = 1;
  for (py::ssize_t d : shape) n *= static_cast<std::size_t>(d);
  return n;
}

std::vector<py::ssize_t> CommonShape(const std::vector<const Float64Argument*>& arguments) {
  const Float64Argument* first = nullptr;
  for (const Float64Argument* a : arguments) {
    if (a == nullptr || a->is_scalar()) continue;
    if (first == nullptr) {
      first = a;
    } else if (a->shape() != first->shape()) {
      auto text = [](const std::vector<py::ssize_t>& s) {
        std::string t = "(";
        for (std::size_t i = 0; i < s.size(); ++i) t += (i ? ", " : "") + std::to_string(s[i]);
        return t + (s.size() == 1 ? ",)" : ")");
      };
      throw InputError(a->name(), "has shape " + text(a->shape()) + ", but " + first->name() + " has shape " +
                                      text(first->shape()) + " (array arguments must match element for element)");
    }
  }
  return first ? first->shape() : std::vector<py::ssize_t>{};
}

py::array_t<double> NewArray(const std::vector<py::ssize_t>& shape) { return py::array_t<double>(shape); }

py::array_t<double> OutputArray(const py::object& out, const std::string& name, const std::vector<py::ssize_t>& shape) {
  if (out.is_none()) return NewArray(shape);
  if (!py::isinstance<py::array>(out)) throw ArgumentTypeError(name, "out array must be a NumPy array");
  auto array = py::reinterpret_borrow<py::array>(out);
  if (!array.dtype().is(py::dtype::of<double>()))
    throw ArgumentTypeError(name, "out array must be float64, got " + std::string(py::str(array.dtype())));
  if (!(array.flags() & py::array::c_style) || !array.writeable())
    throw ArgumentTypeError(name, "out array must be C-contiguous and writeable");
  if (std::vector<py::ssize_t>(array.shape(), array.shape() + array.ndim()) != shape)
    throw InputError(name, "out array has the wrong shape (it must be the inputs' shape)");
  return py::reinterpret_borrow<py::array_t<double>>(out);
}

double* MutableData(py::array_t<double>& array) { return static_cast<double*>(array.mutable_data()); }

double Quantity(const py::handle& value, Dimension dimension, const std::string& name) {
  if (py::isinstance<py::str>(value)) return ParseQuantity(value.cast<std::string>(), dimension, name);
  if (py::isinstance<py::bool_>(value) || !(py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value)))
    throw ArgumentTypeError(name, "expected a number in SI units or a text with its unit (e.g. \"45 mm\")");
  return Finite(value, name);
}

double Length(const py::handle& value, const std::string& name) {
  const double v = Quantity(value, Dimension::kLength, name);
  RequireModelLength(name, v);
  return v;
}

double Number(const py::handle& value, const std::string& name) {
  if (py::isinstance<py::bool_>(value) || !(py::isinstance<py::float_>(value) || py::isinstance<py::int_>(value)))
    throw ArgumentTypeError(name, "expected a number, got " + std::string(py::str(py::type::of(value).attr("__name__"))));
  return Finite(value, name);
}

std::uint64_t Count(const py::handle& value, const std::string& name) {
  if (py::isinstance<py::bool_>(value) || !py::isinstance<py::int_>(value))
    throw ArgumentTypeError(name, "expected a whole number (int), got " +
                                      std::string(py::str(py::type::of(value).attr("__name__"))));
  const unsigned long long n = PyLong_AsUnsignedLongLong(value.ptr());
  if (n == static_cast<unsigned long long>(-1) && PyErr_Occurred()) {
    PyErr_Clear();
    throw InputError(name, "must be a whole number >= 0 and < 2^64 (got " + Shown(value) + ")");
  }
  return n;
}

std::uint64_t Trials(const py::handle& value, const std::string& name) {
  const std::uint64_t n = Count(value, name);
  if (n != 0) RequireMonteCarloTrials(name, static_cast<double>(n));
  return n;
}

std::optional<double> OptionalQuantity(const py::object& value, Dimension dimension, const std::string& name) {
  if (value.is_none()) return std::nullopt;
  return Quantity(value, dimension, name);
}

template <typename Json>
py::object JsonToPython(const Json& value) {
  switch (value.type()) {
    case nlohmann::json::value_t::null:
      return py::none();
    case nlohmann::json::value_t::boolean:
      return py::bool_(value.template get<bool>());
    case nlohmann::json::value_t::number_integer:
      return py::int_(value.template get<std::int64_t>());
    case nlohmann::json::value_t::number_unsigned:
      return py::int_(value.template get<std::uint64_t>());
    case nlohmann::json::value_t::number_float:
      return py::float_(value.template get<double>());
    case nlohmann::json::value_t::string:
      return py::str(value.template get<std::string>());
    case nlohmann::json::value_t::array: {
      py::list list;
      for (const auto& item : value) list.append(JsonToPython(item));
      return list;
    }
    case nlohmann::json::value_t::object: {
      py::dict dict;
      for (auto it = value.begin(); it != value.end(); ++it) dict[py::str(it.key())] = JsonToPython(it.value());
      return dict;
    }
    default:
      return py::none();  // binary and discarded values do not occur in uphill's JSON
  }
}

py::object ToPython(const nlohmann::ordered_json& value) { return JsonToPython(value); }
py::object ToPython(const nlohmann::json& value) { return JsonToPython(value); }

}  // namespace uphill::python
