"""Round trips with the program's JSON: the module and `uphill ... --json` run the same library
code, so the same inputs must give the same numbers, key for key (the CLI's JSON prints every
double so that it parses back to the same bits)."""
import json

import numpy as np
import pytest

import uphill
from conftest import SOURCE, run_cli


def cli_json(*args):
    status, out, err = run_cli(*args, "--json")
    assert status == 0, err
    return json.loads(out)


def test_convert_one_setting_equals_the_cli():
    args = dict(body="spheroid", a="15.875mm", b="25.4mm", L="1165mm", H="300mm", D="120mm",
                u_D="0.2mm", u_L="1mm")
    cli = cli_json("convert", *[f"--{k.replace('_', '-')}={v}" for k, v in args.items()],
                   "--mu", "0.05", "--at-x", "480mm,490mm", "--mc-trials", "20000")
    py = uphill.convert_setting(**args, mu=0.05, at_x=["480mm", "490mm"], mc_trials=20000)
    assert py == cli
    # The same setting in SI numbers instead of text.
    py_si = uphill.convert_setting(body="spheroid", a=0.015875, b=0.0254, L=1.165, H=0.3, D=0.12,
                                   u_D=0.0002, u_L=0.001, mu=0.05, at_x=[0.48, 0.49], mc_trials=20000)
    assert py_si["x_eq"] == cli["x_eq"] and py_si["u_mc_x_eq"] == cli["u_mc_x_eq"]


def test_batch_file_equals_the_cli():
    path = SOURCE / "data" / "convert_batch.csv"
    cli = cli_json("convert", "--batch", path, "--mu", "0.005", "--mc-trials", "2000")
    py = uphill.convert_batch_file(str(path), mu=0.005, mc_trials=2000)
    assert py == cli
    # A flag as the default of a column the file does not have; exit status 2 only if a row failed.
    status, out, _ = run_cli("convert", "--batch", path, "--u-rod-diameter", "0.1mm", "--mc-trials", "2000", "--json")
    cli = json.loads(out)
    py = uphill.convert_batch_file(str(path), u_rod_diameter="0.1mm", mc_trials=2000)
    assert py == cli
    assert status == (2 if any("error" in r for r in py) else 0)


def test_batch_kernel_agrees_with_the_cli_batch(tmp_path):
    """uphill.convert (the vectorised kernel) against `uphill convert --batch --json` (the scalar
    model, Scene): within a few ulp (batch_convert.hpp's contract: <= 2.7e-15 relative)."""
    rng = np.random.default_rng(3)
    n = 200
    L = rng.uniform(0.8, 1.5, n)
    H = rng.uniform(0.05, 0.4, n)
    D = rng.uniform(0.03, 0.25, n)
    path = tmp_path / "batch.csv"
    with open(path, "w") as f:
        f.write("body,a_m,b_m,L_m,H_m,D_m\n")
        for row in zip(L, H, D):
            f.write("spheroid,0.015875,0.0254," + ",".join(repr(float(v)) for v in row) + "\n")
    cli = cli_json("convert", "--batch", path)
    got = uphill.convert("spheroid", L=L, H=H, D=D, a=0.015875, b=0.0254)
    fast = uphill.convert_apparatus(L, H, D, 0.015875, 0.0254)
    for key, index in (("theta", 0), ("alpha", 1), ("x_eq", 2)):
        expected = np.array([r[key] for r in cli])
        assert np.max(np.abs(got[key] / expected - 1)) <= 2.7e-15, key
        assert np.max(np.abs(fast[index] / expected - 1)) <= 2.7e-15, key
    expected = np.array([r["x_max"] for r in cli])
    assert np.max(np.abs(got["x_max"] / expected - 1)) <= 2.7e-15


def test_fit_xy_equals_the_cli(tmp_path):
    data = np.loadtxt(SOURCE / "tests" / "data" / "pearson_york.dat", comments="#")
    x, wx, y, wy = (data[:, k] for k in range(4))
    ux, uy = 1 / np.sqrt(wx), 1 / np.sqrt(wy)
    path = tmp_path / "xy.csv"
    with open(path, "w") as f:
        f.write("X,Y,uX,uY\n")
        for row in zip(x, y, ux, uy):
            f.write(",".join(repr(float(v)) for v in row) + "\n")
    table = uphill.read_xy(str(path))
    np.testing.assert_array_equal(table["x"], x)
    np.testing.assert_array_equal(table["u_y"], uy)
    for method, fit in (("ols", lambda: uphill.fit_ols(x, y, ux, uy)), ("wls", lambda: uphill.fit_wls(x, y, uy, u_x=ux)),
                        ("york", lambda: uphill.fit_york(x, y, ux, uy)), ("robust", lambda: uphill.fit_robust(x, y, uy, u_x=ux))):
        cli = cli_json("fit", "--xy", path, "--method", method)
        py = fit().to_json()
        py.pop("solver", None), cli.pop("solver", None)  # Ceres' own timing differs run to run
        assert py == cli, method


def test_analysis_of_the_sample_experiment_equals_the_cli():
    experiment = SOURCE / "data" / "series2-fixed-L"
    cli = cli_json("fit", experiment, "--mc-trials", "2000")
    analysis = uphill.analyse_experiment(str(experiment), mc_trials=2000)
    py = analysis.to_json()
    for fit in list(cli["fits"].values()) + list(py["fits"].values()):
        fit.pop("solver", None)
    assert py == cli
    # The arrays are the JSON's rows.
    np.testing.assert_array_equal(analysis.x_eq, [r["x_eq"] for r in cli["rows"]])
    np.testing.assert_array_equal(analysis.y, [r["y"] for r in cli["rows"]])
    assert set(analysis.fits) == {"ols", "wls", "york", "robust", "friction"}


def test_simulate_equals_motion():
    cli = cli_json("simulate", "--body", "spheroid", "--a", "20mm", "--b", "32mm", "--theta", "10deg",
                   "--alpha", "30deg", "--x0", "100mm", "--at-times", "0.1s,0.2s,0.3s")
    scene = uphill.Scene(uphill.Body.spheroid("20mm", "32mm"), uphill.Rails.from_angles("10deg", "30deg"))
    motion = uphill.Motion(scene, "100mm")
    states = motion.at(np.array([0.1, 0.2, 0.3]))
    for i, s in enumerate(cli["samples"]):
        for key in ("t", "x", "z", "v", "vx", "vz", "angle"):
            assert states[key][i] == s[key], key
    events = [(e["kind"], e["t"], e["x"]) for e in cli["events"] if e["kind"] != "position"]
    assert [tuple(e) for e in motion.events] == events
