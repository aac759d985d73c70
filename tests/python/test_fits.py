"""The five fits from Python against certified and published values: NIST StRD Norris (OLS,
certified), Pearson's data with York's weights (York et al. 2004, published), and properties
that must hold whatever the data (a straight line through exact points, invariances)."""
import numpy as np
import pytest

import uphill
from conftest import SOURCE


def load(name):
    return np.loadtxt(SOURCE / "tests" / "data" / name, comments="#")


def rel(a, b):
    return abs(a - b) / abs(b)


def test_norris_certified_values():
    data = load("nist_norris.dat")
    y, x = data[:, 0].copy(), data[:, 1].copy()
    fit = uphill.fit_ols(x, y)
    # NIST's certified values (tests/data/nist_norris.dat header), to the digits binary64 keeps.
    assert rel(fit.intercept, -0.262323073774029) < 1e-12
    assert rel(fit.slope, 1.00211681802045) < 1e-13
    assert rel(fit.parameter("c").se_scaled, 0.232818234301152) < 1e-12
    assert rel(fit.parameter("k").se_scaled, 0.429796848199937e-3) < 1e-12
    assert rel(np.sqrt(fit.reduced_chi2), 0.884796396144373) < 1e-12
    assert rel(fit.chi2, 26.6173985294224) < 1e-12
    assert rel(fit.r_squared, 0.999993745883712) < 1e-14
    assert fit.dof == 34 and fit.n == 36 and fit.primary_scaling == "scaled"
    assert fit.p_value is None
    # The per-row results: a read-only structured view, residual = y - fitted.
    rows = fit.rows
    assert rows.shape == (36,) and not rows.flags.writeable
    np.testing.assert_array_equal(rows["row"], np.arange(36))
    assert np.max(np.abs(fit.residuals - (y - fit.fitted))) < 1e-12 * np.max(np.abs(y))


def test_fit_xy_is_the_per_method_functions_by_name():
    # One use case (app/fit_xy.hpp) behind both: the same numbers, and the command's refusal.
    data = load("pearson_york.dat")
    x, w_x, y, w_y = (data[:, i].copy() for i in range(4))
    u_x, u_y = 1 / np.sqrt(w_x), 1 / np.sqrt(w_y)
    pairs = [(uphill.fit_xy(x, y), uphill.fit_ols(x, y)),
             (uphill.fit_xy(x, y, None, u_y, method="wls"), uphill.fit_wls(x, y, u_y)),
             (uphill.fit_xy(x, y, u_x, u_y, method="york"), uphill.fit_york(x, y, u_x, u_y)),
             (uphill.fit_xy(x, y, None, u_y, method="robust"), uphill.fit_robust(x, y, u_y))]
    for by_name, direct in pairs:
        a, b = by_name.to_json(), direct.to_json()
        del a["solver"]["seconds"], b["solver"]["seconds"]  # wall-clock time, not a result
        assert a == b
    with pytest.raises(uphill.InputError, match=r"^method: must be ols, wls, york or robust \(got 'lsq'\)$"):
        uphill.fit_xy(x, y, method="lsq")


def test_york_pearson_published_values():
    data = load("pearson_york.dat")
    x, wx, y, wy = (data[:, k].copy() for k in range(4))
    fit = uphill.fit_york(x, y, 1 / np.sqrt(wx), 1 / np.sqrt(wy))
    # York et al. (2004) solution as published (bfsl; Williamson's values in the kmpfit docs).
    assert rel(fit.slope, -0.48053340745) < 1e-9
    assert rel(fit.intercept, 5.47991022403) < 1e-9
    assert rel(fit.parameter("k").se_unscaled, 0.0579850090) < 1e-8
    assert rel(fit.parameter("c").se_unscaled, 0.294970735) < 1e-8
    assert rel(fit.reduced_chi2, 1.483294149) < 1e-8
    assert fit.covariance.shape == (2, 2)
    assert abs(fit.correlation[0, 0] - 1) < 1e-15
    assert 0 < fit.p_value < 1


def test_exact_line_through_exact_points():
    # Truth: points on y = 2x + 1 exactly (binary64 integers), every method must give that line.
    x = np.arange(10.0)
    y = 2 * x + 1
    u = np.full(10, 0.5)
    for fit in (uphill.fit_ols(x, y), uphill.fit_wls(x, y, u), uphill.fit_york(x, y, u, u),
                uphill.fit_robust(x, y, u)):
        assert fit.slope == pytest.approx(2, abs=1e-14), fit.method
        assert fit.intercept == pytest.approx(1, abs=1e-13), fit.method
        assert fit.chi2 == pytest.approx(0, abs=1e-20), fit.method


def test_robust_fit_names_the_gross_error():
    rng = np.random.default_rng(7)
    x = np.linspace(0, 10, 50)
    y = 3 * x - 2 + rng.normal(0, 0.1, 50)
    y[17] += 25  # a gross error
    fit = uphill.fit_robust(x, y)
    assert 17 in [row for row, weight, normalised in fit.downweighted]
    assert fit.slope == pytest.approx(3, abs=0.02)
    assert uphill.fit_ols(x, y).slope != pytest.approx(3, abs=0.02)  # the plain fit is dragged


def test_friction_fit_recovers_mu_of_synthetic_rest_positions():
    # Truth: Y generated as x_rest(mu = 0.02) of each scene (the model itself, exactly).
    body = uphill.Body.spheroid(0.015875, 0.0254)
    scenes = [uphill.Scene(body, uphill.Rails.from_apparatus(1.165, 0.3, d)) for d in np.linspace(0.05, 0.2, 12)]
    y = np.array([s.rest(0.02)[1] for s in scenes])
    fit = uphill.fit_friction(scenes, y, np.full(12, 1e-3))
    assert fit.parameter("mu").value == pytest.approx(0.02, rel=1e-9)
    assert fit.method == "friction"


def test_to_json_is_the_report():
    x = np.arange(5.0)
    y = np.array([0.1, 2.0, 3.9, 6.1, 8.0])
    fit = uphill.fit_ols(x, y)
    j = fit.to_json()
    assert j["method"] == "ols"
    assert j["slope"] == fit.slope and j["intercept"] == fit.intercept
    assert j["n"] == 5 and j["dof"] == 3
