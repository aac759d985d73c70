"""The ranges of model/input_ranges.hpp through the Python module: what the command line refuses,
the module refuses too, as uphill.InputError naming the argument, the value with its unit and the
range; nothing outside them comes back as inf or NaN, and no internal RuntimeError escapes.
Truth: the ranges' contract (model/input_ranges.hpp) and the command line's answers to the same
values (docs/exit-codes.md: exit 2 naming the flag)."""
import math

import numpy as np
import pytest

import uphill
from conftest import run_cli

L, H, D = 1.165, 0.300, 0.120
A, B = 0.015875, 0.0254


def sphere_scene(**rails):
    return uphill.Scene(uphill.Body.sphere(0.0127), uphill.Rails.from_apparatus(**(dict(L=L, H=H, D=D) | rails)))


# Guards: D = 5e-324 and a = 1e308 gave x_eq = inf.
@pytest.mark.parametrize("args, name", [
    (dict(D=np.array([0.1, 5e-324])), "D"),
    (dict(L=np.array([1e308, 1.0])), "L"),
    (dict(H=np.array([0.3, 1e-320])), "H"),
])
def test_convert_apparatus_refuses_lengths_outside_the_range(args, name):
    arrays = dict(L=np.full(2, L), H=np.full(2, H), D=np.full(2, D)) | args
    with pytest.raises(uphill.InputError) as e:
        uphill.convert_apparatus(arrays["L"], arrays["H"], arrays["D"], A, B)
    assert e.value.quantity == name and "between 1 nm and 1000 km" in e.value.rule, str(e.value)
    assert " m)" in e.value.rule  # the value with its unit


@pytest.mark.parametrize("a, b", [(1e308, B), (A, 5e-324), ("1e308 mm", B)])
def test_convert_apparatus_refuses_a_body_outside_the_range(a, b):
    with pytest.raises(uphill.InputError) as e:
        uphill.convert_apparatus(L, H, D, a, b)
    assert e.value.quantity in ("a", "b") and "1000 km" in e.value.rule


def test_the_range_ends_at_1000_km_in_the_vector_check_and_the_scalar_one():
    # 1000 km is in; the next double above it is out, element by element, in a block long enough
    # for the vectorised check.
    top = np.full(9, 1e6)
    theta, alpha, x_eq = uphill.convert_apparatus(top, top, top, A, B)
    np.testing.assert_array_equal(theta, np.full(9, np.arctan(1.0)))
    assert np.all(np.isfinite(x_eq))
    top[7] = np.nextafter(1e6, 2e6)
    with pytest.raises(uphill.InputError) as e:
        uphill.convert_apparatus(top, np.full(9, H), np.full(9, D), A, B)
    assert (e.value.quantity, e.value.row) == ("L", 7)


# Guards: convert(R=1e308) gave inf; u_D = 1e308 and mc_trials = -1 were not refused alike.
@pytest.mark.parametrize("extra, name", [
    (dict(R=1e308), "R"), (dict(R=np.array([0.01, 1e-320])), "R"), (dict(rod_radius=1e308), "rod_radius"),
    (dict(u_D=1e308), "u_D"), (dict(u_theta=10.0), "u_theta"), (dict(mc_trials=-1), "mc_trials"),
    (dict(mc_trials=5), "mc_trials"), (dict(seed=2**64), "seed"),
])
def test_convert_refuses_values_outside_the_ranges(extra, name):
    args = dict(L=L, H=H, D=D, R=0.0127) | extra
    if "u_theta" in extra:
        args = dict(theta=0.1, alpha=0.5, R=0.0127) | extra
    with pytest.raises(uphill.InputError) as e:
        uphill.convert("sphere", **args)
    assert e.value.quantity == name, str(e.value)


# Guards: Scene(... from_apparatus(1e308, ...)) gave nan or inf, and fit_friction on such scenes
# raised an internal RuntimeError.
def test_scenes_outside_the_ranges_are_refused_before_any_fit():
    with pytest.raises(uphill.InputError) as e:
        sphere_scene(L=1e308)
    assert e.value.quantity == "L"
    with pytest.raises(uphill.InputError):
        uphill.fit_friction([sphere_scene(L=1e308)] * 3, np.full(3, 0.5), np.full(3, 1e-3))
    with pytest.raises(uphill.InputError):  # a divergence of 5e-324 rad: X overflows
        uphill.Scene(uphill.Body.sphere(0.0127), uphill.Rails.from_angles(0.1, 5e-324))


def test_a_path_point_where_the_path_turns_vertical_is_refused_not_infinite():
    scene = sphere_scene()
    with pytest.raises(uphill.InputError) as e:
        scene.at(np.array([scene.x_eq, scene.x_max]))
    assert e.value.row == 1 and "dz/dx" in e.value.rule


# Guards: propagate(trials=0) returned NaN for the Monte Carlo entries.
def test_propagate_without_monte_carlo_returns_none_not_nan():
    out = uphill.propagate(uphill.Body.sphere(0.0127), L=L, H=H, D=D, u_D=2e-4, trials=0)
    x_eq = out["x_eq"]
    assert x_eq["u_monte_carlo"] is None and x_eq["mc_mean"] is None and x_eq["coverage_interval"] is None
    assert math.isfinite(x_eq["u_first_order"]) and x_eq["u_first_order"] > 0
    for bad, name in [(dict(trials=-1), "trials"), (dict(trials=10**30), "trials"), (dict(trials=50), "trials"),
                      (dict(u_D=1e308), "u(D)"), (dict(L=1e308), "L")]:
        with pytest.raises(uphill.InputError) as e:
            uphill.propagate(uphill.Body.sphere(0.0127), **(dict(L=L, H=H, D=D, u_D=2e-4, trials=0) | bad))
        assert e.value.quantity == name, str(e.value)


# Guards: Motion(g=1e-308).end_time was inf; Motion(v0=1e300, method="ode") raised RuntimeError.
@pytest.mark.parametrize("options, name", [
    (dict(g=1e-308), "g"), (dict(g=1e308), "g"), (dict(g=10**400), "g"),
    (dict(v0=1e300, method="ode"), "v0"), (dict(v0=-1e4, method="ode"), "v0"),
    (dict(mu=1e308, method="ode"), "mu"), (dict(mu=float("nan"), method="ode"), "mu"),
    (dict(tolerance=0.0), "tolerance"),
])
def test_motion_refuses_options_outside_the_ranges(options, name):
    scene = sphere_scene()
    with pytest.raises(uphill.InputError) as e:
        uphill.Motion(scene, scene.x_eq * 1.01, **options)
    assert e.value.quantity == name, str(e.value)


def test_motion_at_the_ends_of_the_ranges_is_finite():
    scene = sphere_scene()
    for options in [dict(g=1e-3), dict(g=1e3), dict(v0=1e3, method="ode"), dict(v0=-1e3, method="ode"),
                    dict(mu=10.0, v0=1.0, method="ode")]:
        motion = uphill.Motion(scene, scene.x_eq * 1.01, **options)
        end = motion.events[-1][1]  # falls off, reaches O, or comes to rest
        assert math.isfinite(end), options
        states = motion.at(np.linspace(0, end, 7))
        assert all(np.all(np.isfinite(v)) for v in states.values()), options


def test_release_times_refuses_g_outside_the_range():
    scene = sphere_scene()
    with pytest.raises(uphill.InputError) as e:
        uphill.release_times(scene, scene.x_eq * 1.01, np.array([scene.x_max]), g=1e-308)
    assert e.value.quantity == "g"


# The same values on the command line: refused there as here (one set of checks).
@pytest.mark.parametrize("flags, name", [
    (["--D", "1e308mm"], "--D"), (["--D", "1e-320mm"], "--D"), (["--u-D", "1e308mm"], "--u-D"),
    (["--mu", "1e308"], "--mu"), (["--u-D", "0.2mm", "--mc-trials", "5"], "--mc-trials"),
])
def test_the_command_line_refuses_the_same_values(flags, name):
    setting = {"--body": "sphere", "--R": "12.7mm", "--L": "1165mm", "--H": "300mm", "--D": "120mm"}
    given = dict(zip(flags[::2], flags[1::2]))
    status, out, err = run_cli("convert", *[w for f, v in (setting | given).items() for w in (f, v)])
    assert status == 2 and err.startswith("uphill: " + name + ": must"), err
    assert "inf" not in out and "nan" not in out


@pytest.mark.parametrize("call", [
    lambda: uphill.Body.sphere(10**400), lambda: uphill.to_unit(10**400, "length", "mm"),
    lambda: uphill.to_unit(1e308, "length", "um"), lambda: uphill.convert_setting(
        body="sphere", R="12.7mm", L="1165mm", H="300mm", D="120mm", u_D="0.2mm", mc_trials=-1),
    lambda: uphill.fit_ols(np.arange(5.0), np.arange(5.0), outlier_threshold=10**400),
])
def test_huge_ints_and_overflowing_values_are_input_errors(call):
    with pytest.raises(uphill.InputError):
        call()


# Guards: a divergence of 1e-300 rad put x_max at 1e297 m, where Motion's ODE never finished (an
# internal RuntimeError); found by test_property.py.
def test_a_scene_whose_positions_lie_beyond_1000_km_is_refused():
    with pytest.raises(uphill.InputError) as e:
        uphill.Scene(uphill.Body.spheroid(0.018, 0.015), uphill.Rails.from_angles(0.355, 1e-300))
    assert e.value.quantity == "the setting" and "1000 km" in e.value.rule, str(e.value)


# Guards: fit_friction with u(Y) = 5e-324 or Y = 1e306 raised Ceres' internal RuntimeError; found
# by test_property.py. Y and u(Y) are held to the lengths' ranges, as `uphill fit` holds them.
@pytest.mark.parametrize("y, u_y, name", [(0.2664, 5e-324, "u(Y)"), (1.165e306, 6e-4, "Y")])
def test_fit_friction_refuses_positions_and_uncertainties_outside_the_ranges(y, u_y, name):
    scene = uphill.Scene(uphill.Body.spheroid(0.0198, 0.0197), uphill.Rails.from_angles(0.2045, 0.1429))
    with pytest.raises(uphill.InputError) as e:
        uphill.fit_friction([scene], np.array([y]), np.array([u_y]))
    assert (e.value.quantity, e.value.row) == (name, 0), str(e.value)
