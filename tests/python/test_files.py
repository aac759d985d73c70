"""Experiment folders, track CSVs, calibration files and tracking from Python. Truths: the files'
own contents (data/series2-fixed-L as written by tools/make_samples, read independently with the
csv module), a synthetic clip's exact ground truth (tools/make_video renders it), and the program
run on the same files."""
import csv
import json
import os
import subprocess

import numpy as np
import pytest

import uphill
from conftest import SOURCE, run_cli

MAKE_VIDEO = os.environ.get("UPHILL_MAKE_VIDEO", "make_video")


def test_read_experiment_matches_the_csv():
    folder = SOURCE / "data" / "series2-fixed-L"
    exp = uphill.read_experiment(str(folder))
    with open(folder / "measurements.csv") as f:
        table = list(csv.DictReader(f))
    assert len(exp.rows) == len(table) and not exp.errors
    for row, line in zip(exp.rows, table):
        assert row["trial"] == line["trial"]
        assert row["Y"] == pytest.approx(float(line["Y_mm"]) / 1000, rel=1e-15)
        assert row["configuration"]["D"]["value"] == pytest.approx(float(line["D_mm"]) / 1000, rel=1e-15)
        assert row["configuration"]["H"]["value"] == pytest.approx(0.3, rel=1e-15)
        assert row["u_Y"] == pytest.approx(0.0005, rel=1e-15)
    assert exp.metadata["format"] == "uphill-experiment/1"
    assert len(exp.scenes) == len(table)
    assert exp.scenes[0].body.kind == "spheroid"


def test_a_bad_row_is_kept_with_its_error(tmp_path):
    folder = tmp_path / "exp"
    folder.mkdir()
    source = SOURCE / "data" / "series2-fixed-L"
    (folder / "experiment.json").write_text((source / "experiment.json").read_text())
    lines = (source / "measurements.csv").read_text().splitlines()
    lines[3] = lines[3].replace("110.3", "-110.3")
    (folder / "measurements.csv").write_text("\n".join(lines) + "\n")
    exp = uphill.read_experiment(str(folder))
    bad = [r for r in exp.rows if r["error"]]
    assert len(bad) == 1 and bad[0]["row"] == 4 and "D_mm" in bad[0]["error"]
    analysis = uphill.analyse_experiment(exp, mc_trials=1000)
    assert len(analysis.y) == len(lines) - 2 and analysis.row_errors


def test_an_excluded_row_is_analysed_but_fitted_as_if_deleted(tmp_path):
    """measurements.csv's `excluded` column (data/README.md): the row keeps its reason and its
    X, and every fit equals the fit of the file without that row (the truth: the row deleted);
    `uphill fit --json` agrees."""
    source = SOURCE / "data" / "series2-fixed-L"
    lines = (source / "measurements.csv").read_text().splitlines()
    folders = {}
    for name in ("excluded", "deleted"):
        folders[name] = tmp_path / name
        folders[name].mkdir()
        (folders[name] / "experiment.json").write_text((source / "experiment.json").read_text())
    slip = "s2-5,s2,1165.1,130.1,45.24,"  # Y typed in cm
    rows = [slip if line.startswith("s2-5,") else line for line in lines]
    marked = [rows[0] + ",excluded"] + [r + (",Y typed in cm" if r == slip else ",") for r in rows[1:]]
    (folders["excluded"] / "measurements.csv").write_text("\n".join(marked) + "\n")
    (folders["deleted"] / "measurements.csv").write_text(
        "\n".join(line for line in lines if not line.startswith("s2-5,")) + "\n")
    exp = uphill.read_experiment(str(folders["excluded"]))
    assert [r["excluded"] for r in exp.rows if r["excluded"]] == ["Y typed in cm"]
    excluded = uphill.analyse_experiment(exp, mc_trials=1000)
    deleted = uphill.analyse_experiment(str(folders["deleted"]), mc_trials=1000)
    assert [e["trial"] for e in excluded.excluded] == ["s2-5"]
    assert excluded.excluded[0]["reason"] == "Y typed in cm" and excluded.excluded[0]["y"] == pytest.approx(0.04524)
    assert "s2-5" not in excluded.trials and len(excluded.y) == len(deleted.y) == 23
    for method, fit in deleted.fits.items():
        assert [(p.name, p.value, p.se_unscaled) for p in excluded.fits[method].parameters] == \
            [(p.name, p.value, p.se_unscaled) for p in fit.parameters], method
        assert excluded.fits[method].chi2 == fit.chi2, method
    assert excluded.summary["excluded"] == ["trial s2-5 (row 6): Y typed in cm"]
    assert excluded.summary["preferred"] == deleted.summary["preferred"] == "friction"
    status, out, err = run_cli("fit", folders["excluded"], "--json", "--mc-trials", "1000")
    assert status == 0, err
    result = json.loads(out)
    assert [r["trial"] for r in result["excluded_rows"]] == ["s2-5"]
    assert result["fits"]["york"]["slope"] == deleted.fits["york"].slope


ROW_CHECK_JSON = {"format": "uphill-experiment/1",
                  "body": {"type": "spheroid", "a": "15.875 mm", "b": "25.4 mm"},
                  "apparatus": {"H": "300 mm", "L_convention": "horizontal"},
                  "uncertainties": {"L": "1 mm", "H": "0.5 mm", "D": "0.2 mm", "Y": "0.5 mm"}}


def test_check_row_flags_as_fit_and_the_page_do(tmp_path):
    """The one row check (app/row_check.hpp) through Python, the analysis and `uphill fit --json`:
    the issue's Y below X (L = 906 mm, D = 165 mm: X = 274.9 mm by the closed form of
    docs/physics.md, "Lab shortcut"; Y = 270 mm) and a Y typed in cm, same codes and words."""
    folder = tmp_path / "exp"
    folder.mkdir()
    (folder / "experiment.json").write_text(json.dumps(ROW_CHECK_JSON))
    (folder / "measurements.csv").write_text("trial,L_mm,D_mm,Y_mm\nbelow,906,165,270\ncm,906,165,27.55\n")
    x = 906 * (2 * 25.4 / 165) / (1 + (15.875 * 165 / (2 * 25.4 * 300)) ** 2) ** 0.5
    below = uphill.check_row(str(folder), "below", unit="mm")
    assert below["x"] == pytest.approx(x, rel=1e-12)
    assert [f["code"] for f in below["flags"]] == ["y_below_x"]
    assert "the body cannot rest there" in below["flags"][0]["message"]
    cm = uphill.check_row(uphill.read_experiment(str(folder)), 1)
    assert [f["code"] for f in cm["flags"]] == ["unit_mixup"] and cm["flags"][0]["field"] == "Y"
    assert cm["x"] == pytest.approx(x / 1000, rel=1e-12)  # the default unit: m
    analysis = uphill.analyse_experiment(str(folder))  # as `uphill fit`: 10^5 Monte Carlo trials
    assert analysis.flags == [below["flags"], cm["flags"]]
    status, out, err = run_cli("fit", folder, "--json")
    assert status == 0, err
    assert [r["flags"] for r in json.loads(out)["rows"]] == [below["flags"], cm["flags"]]
    with pytest.raises(uphill.InputError, match="no row has the trial label 'nope'"):
        uphill.check_row(str(folder), "nope")
    with pytest.raises(uphill.InputError, match="row: must be an index"):
        uphill.check_row(str(folder), 2)


@pytest.fixture(scope="module")
def clip(tmp_path_factory):
    out = tmp_path_factory.mktemp("clip")
    subprocess.run([MAKE_VIDEO, str(out), "--frames", "24", "--boards", "0", "--lossless"], check=True,
                   capture_output=True)
    return out


def scene_of_clip():
    # make_video's default apparatus: a 2-inch ball on 8 mm rods, L = 1000 mm, H = 100 mm, D = 150 mm.
    return uphill.Scene(uphill.Body.sphere("25.4 mm"), uphill.Rails.from_apparatus("1000 mm", "100 mm", "150 mm"),
                        "4 mm")


def test_track_recovers_the_rendered_truth(clip):
    video = next(p for p in clip.iterdir() if p.suffix in (".avi", ".mp4"))
    run = uphill.track(str(video), str(clip / "cam.json"), str(clip / "scene.json"), scene_of_clip())
    truth = np.genfromtxt(clip / "truth.csv", delimiter=",", names=True)
    assert run["found"].all() and not run["partial"]
    np.testing.assert_array_equal(run["frame"], truth["frame"].astype(int))
    rms_px = np.sqrt(np.mean((run["u"] - truth["u"]) ** 2 + (run["v"] - truth["v"]) ** 2))
    rms_mm = 1000 * np.sqrt(np.mean((run["x"] - truth["x"] / 1000) ** 2 + (run["z"] - truth["z"] / 1000) ** 2))
    assert rms_px <= 0.1, rms_px   # the tracker's tested accuracy on clean lossless clips
    assert rms_mm <= 0.5, rms_mm


def test_track_csv_of_the_program_reads_back(clip, tmp_path):
    video = next(p for p in clip.iterdir() if p.suffix in (".avi", ".mp4"))
    csv_path = tmp_path / "track.csv"
    status, _, err = run_cli("track", video, "--camera", clip / "cam.json", "--scene", clip / "scene.json",
                             "--body", "sphere", "--R", "25.4mm", "--L", "1000mm", "--H", "100mm", "--D", "150mm",
                             "--rod-diameter", "8mm", "-o", csv_path, "--quiet")
    assert status == 0, err
    from_cli = uphill.read_track(str(csv_path))
    run = uphill.track(str(video), str(clip / "cam.json"), str(clip / "scene.json"), scene_of_clip())
    np.testing.assert_array_equal(from_cli["frame"], run["frame"])
    np.testing.assert_array_equal(from_cli["found"], run["found"])
    # The CSV prints x, z in mm and pixels with a fixed number of decimals.
    assert np.max(np.abs(from_cli["x"] - run["x"])) < 1e-6
    assert np.max(np.abs(from_cli["u"] - run["u"])) < 1e-3
    # Every found position carries its standard uncertainty, the same from the CSV as from the call.
    assert (run["u_px"][run["found"]] > 0).all() and (run["u_x"][run["found"]] > 0).all()
    assert np.max(np.abs(from_cli["u_px"] - run["u_px"])) < 1e-4
    assert np.max(np.abs(from_cli["u_x"] - run["u_x"])) < 1e-7  # 4 decimals of a mm
    # The outline spread (NaN where the model measured the frame) likewise, to the CSV's 4 decimals.
    np.testing.assert_allclose(np.nan_to_num(from_cli["u_outline_px"]), np.nan_to_num(run["u_outline_px"]), atol=1e-4)
    camera = uphill.read_camera(str(clip / "cam.json"))
    pose = uphill.read_scene_calibration(str(clip / "scene.json"))
    assert camera["width"] == pose["camera"]["width"] and camera["fx"] == pytest.approx(pose["camera"]["fx"])
    rotation = pose["rotation"]
    np.testing.assert_allclose(rotation @ rotation.T, np.eye(3), atol=1e-12)
    np.testing.assert_allclose(pose["camera_centre"], -rotation.T @ pose["translation"], atol=1e-12)


def test_lost_frames_stay_missing(tmp_path):
    path = tmp_path / "track.csv"
    path.write_text("frame,t,u,v,radius_px,x,z,quality\n"
                    "0,0.0,100.5,200.25,20.0,300.0,40.0,0.9\n"
                    "1,0.04,,,,,,0\n"
                    "2,0.08,101.5,200.5,20.0,301.0,40.1,0.8\n")
    t = uphill.read_track(str(path))
    np.testing.assert_array_equal(t["found"], [True, False, True])
    assert np.isnan(t["x"][1]) and t["quality"][1] == 0
    assert t["x"][2] == pytest.approx(0.301) and t["t"][1] == 0.04
    assert np.isnan(t["u_px"]).all() and np.isnan(t["u_x"]).all()  # this track states no uncertainty
    assert np.isnan(t["u_outline_px"]).all()
