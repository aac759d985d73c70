"""Bad input from Python: a clear exception naming the argument, the element and the rule;
never a crash, never a silent cast or NaN. uphill.InputError is a ValueError."""
import pickle

import numpy as np
import pytest

import uphill

L = np.array([1.165, 1.165, 1.165])
H = np.array([0.3, 0.3, 0.3])
D = np.array([0.045, 0.1, 0.2])
A, B = 0.015875, 0.0254


def test_input_error_is_a_value_error_with_quantity_row_and_rule():
    with pytest.raises(uphill.InputError) as e:
        uphill.convert_apparatus(L, H, np.array([0.045, -0.1, 0.2]), A, B)
    err = e.value
    assert isinstance(err, ValueError)
    assert err.quantity == "D" and err.row == 1
    assert "> 0" in err.rule and "-0.1" in err.rule
    assert str(err).startswith("D, element 1: ")
    again = pickle.loads(pickle.dumps(err))
    assert (again.quantity, again.rule, again.row) == (err.quantity, err.rule, err.row)


@pytest.mark.parametrize("bad, name, row", [
    (dict(D=np.array([0.045, np.nan, 0.2])), "D", 1),
    (dict(L=np.array([1.165, 1.165, np.inf])), "L", 2),
    (dict(H=np.array([-0.1, 0.3, 0.3])), "H", 0),
])
def test_nan_inf_and_negative_lengths_name_the_element(bad, name, row):
    args = dict(L=L, H=H, D=D)
    args.update(bad)
    for call in (lambda: uphill.convert_apparatus(args["L"], args["H"], args["D"], A, B),
                 lambda: uphill.convert("spheroid", a=A, b=B, **args)):
        with pytest.raises(uphill.InputError) as e:
            call()
        assert (e.value.quantity, e.value.row) == (name, row), str(e.value)


def test_mismatched_lengths():
    with pytest.raises(uphill.InputError) as e:
        uphill.convert_apparatus(L, H, D[:2], A, B)
    assert e.value.quantity == "D" and "shape" in e.value.rule
    with pytest.raises(uphill.InputError) as e:
        uphill.fit_wls(np.arange(5.0), np.arange(5.0), np.ones(4))
    assert "u(Y)" in str(e.value)


@pytest.mark.parametrize("dtype", [np.float32, np.int64, np.int32, object, np.complex128])
def test_other_dtypes_are_refused_not_cast(dtype):
    # An InputError (a ValueError naming the argument and the rule) that is also a TypeError.
    with pytest.raises(uphill.InputTypeError, match="float64") as e:
        uphill.convert_apparatus(L, H, D.astype(dtype), A, B)
    assert isinstance(e.value, ValueError) and isinstance(e.value, TypeError)
    assert e.value.quantity == "D" and e.value.row is None
    assert np.dtype(dtype).name in e.value.rule and "dtype=np.float64" in e.value.rule
    with pytest.raises(uphill.InputTypeError, match="float64") as e:
        uphill.fit_ols(np.arange(5).astype(dtype), np.arange(5.0))
    assert e.value.quantity == "X"
    with pytest.raises(uphill.InputTypeError):
        uphill.convert("sphere", L=L, H=H, D=D, R=np.full(3, 0.0127, dtype=dtype))


def test_wrong_python_types_are_input_type_errors():
    for call, quantity in ((lambda: uphill.convert_apparatus(L, H, D, A, [0.0254]), "b"),
                           (lambda: uphill.convert_apparatus(L, H, {"D": 1}, A, B), "D"),
                           (lambda: uphill.convert_apparatus(L, H, True, A, B), "D"),
                           (lambda: uphill.Body.sphere(None), "R"),
                           (lambda: uphill.convert_setting(body="sphere", R=[1.0], L="1165mm"), "R")):
        with pytest.raises(uphill.InputTypeError) as e:
            call()
        assert e.value.quantity == quantity, str(e.value)


def test_a_list_of_floats_is_accepted_a_list_of_ints_is_not():
    theta, alpha, x_eq = uphill.convert_apparatus(list(L), list(H), list(D), A, B)
    assert x_eq.shape == (3,)
    with pytest.raises(TypeError):
        uphill.convert_apparatus([1, 2, 3], H, D, A, B)


def test_non_contiguous_input_gives_the_same_numbers():
    big = np.stack([L, H, D, D])  # rows are contiguous, columns are strided
    strided = np.asfortranarray(big)[2]
    assert not strided.flags.c_contiguous
    np.testing.assert_array_equal(uphill.convert_apparatus(L, H, strided, A, B)[2],
                                  uphill.convert_apparatus(L, H, D, A, B)[2])


def test_bad_body_and_bad_scene():
    with pytest.raises(uphill.InputError) as e:
        uphill.Body.spheroid(-1, 2)
    assert e.value.quantity == "a" and e.value.row is None
    with pytest.raises(uphill.InputError):
        uphill.Rails.from_angles("10 deg", "190 deg")
    with pytest.raises(uphill.InputError) as e:
        uphill.Body.sphere("12.7")  # a number without a unit, as on the command line
    assert "unit" in e.value.rule
    scene = uphill.Scene(uphill.Body.sphere(0.0127), uphill.Rails.from_angles("10 deg", "30 deg"))
    with pytest.raises(uphill.InputError) as e:
        scene.at(np.array([0.01, 0.02, 99.0]))
    assert e.value.row == 2


def test_fit_names_the_row_with_a_nan():
    y = np.arange(6.0)
    y[4] = np.nan
    with pytest.raises(uphill.InputError) as e:
        uphill.fit_ols(np.arange(6.0), y)
    assert (e.value.quantity, e.value.row) == ("Y", 4)


def test_out_arrays_are_written_in_place_and_checked():
    theta, alpha, x_eq = np.empty(3), np.empty(3), np.empty(3)
    r = uphill.convert_apparatus(L, H, D, A, B, theta=theta, alpha=alpha, x_eq=x_eq)
    assert r[2] is x_eq and np.all(np.isfinite(x_eq))
    with pytest.raises(uphill.InputTypeError) as e:
        uphill.convert_apparatus(L, H, D, A, B, x_eq=np.empty(3, dtype=np.float32))
    assert e.value.quantity == "x_eq"
    with pytest.raises(uphill.InputError):
        uphill.convert_apparatus(L, H, D, A, B, x_eq=np.empty(4))


def test_empty_and_scalar_inputs():
    t, a, x = uphill.convert_apparatus(np.empty(0), np.empty(0), np.empty(0), A, B)
    assert x.shape == (0,)
    t, a, x = uphill.convert_apparatus(1.165, 0.3, 0.045, A, B)
    assert x.shape == () and float(x) > 0
    grid = uphill.convert("sphere", L=1.165, H=0.3, D=np.linspace(0.05, 0.2, 12).reshape(3, 4), R=0.0127)
    assert grid["x_eq"].shape == (3, 4)


def test_unknown_keyword_and_missing_dimensions():
    with pytest.raises(TypeError):
        uphill.convert("sphere", L=L, H=H, D=D, R=0.0127, u_Q=0.1)
    with pytest.raises(uphill.InputError) as e:
        uphill.convert("spheroid", L=L, H=H, D=D, a=A)
    assert e.value.quantity == "b"
    with pytest.raises(uphill.InputError):
        uphill.convert("sphere", L=L, H=H, theta=0.1, R=0.0127)


def test_experiment_folder_errors_name_the_file(tmp_path):
    with pytest.raises(uphill.InputError) as e:
        uphill.read_experiment(str(tmp_path / "missing"))
    assert "missing" in str(e.value)
    with pytest.raises(uphill.InputError):
        uphill.parse_quantity("12.7", "length")
    assert uphill.parse_quantity("1 in", "length") == 0.0254

