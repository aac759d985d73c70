"""The module against the 60-digit reference values of tests/data/physics_reference.json, the
same truths the C++ tests use (tests/model_reference_test.cpp, motion_reference_test.cpp), with the
file's tolerance rule: max(1e-12, 16·cond·1.1e-16) relative (conftest.tolerance)."""
import math

import numpy as np
import pytest

import uphill
from conftest import assert_ref, ref, reference_file, tolerance

CASES = [c for c in reference_file()["cases"] if "sweep" not in c["rails"]]
SWEEPS = [c for c in reference_file()["cases"] if "sweep" in c["rails"]]


def body_of(case):
    b = case["body"]
    if b["type"] == "sphere":
        return uphill.Body.sphere(b["R"])
    if b["type"] == "spheroid":
        return uphill.Body.spheroid(b["a"], b["b"])
    return uphill.Body.double_cone(b["R"], b["h"])


def rails_of(case, along_rail=False):
    r = case["rails"]
    if "apparatus" in r:
        a = r["apparatus"]
        return uphill.Rails.from_apparatus(a["L"], a["H"], a["D"], along_rail)
    return uphill.Rails.from_angles(r["theta"], r["alpha"])


def scene_of(case, along_rail=False):
    return uphill.Scene(body_of(case), rails_of(case, along_rail), case.get("rod_radius") or None)


def cond(case, key, index=None, sub=None):
    c = (case.get("cond") or {}).get(key)
    if c is None:
        return 1.0
    if index is not None:
        c = c[index]
        if sub is not None:
            c = c.get(sub, 1.0) if isinstance(c, dict) else c
    return float(c)


@pytest.mark.parametrize("case", CASES, ids=[c["id"] for c in CASES])
def test_scene_matches_references(case):
    scene = scene_of(case)
    out = case["outputs"]
    rails = scene.rails
    assert_ref(rails.theta, out["theta"], what="theta")
    assert_ref(rails.alpha, out["alpha"], what="alpha")
    assert_ref(rails.phi, out["phi"], what="phi")
    if case["body"]["type"] == "double_cone":
        assert scene.x_eq is None
        assert_ref(scene.x_max, out["x_fall"], what="x_fall")
        assert_ref(scene.x_low, out["x_low"], what="x_low")
        assert_ref(scene.theta0, out["theta0"], cond(case, "theta0"), "theta0")
        assert_ref(scene.theta0_fixed_phi, out["theta0_fixed_phi"], what="theta0_fixed_phi")
        assert scene.rolls_up == out["rolls_up"]
        for r in out["rest"]:
            assert scene.rests_everywhere(r["mu"]) == r["rests_everywhere"]
            assert scene.rest(r["mu"]) is None
    else:
        assert_ref(scene.x_eq, out["x_eq"], cond(case, "x_eq"), "x_eq")
        assert_ref(scene.z_eq, out["z_eq"], what="z_eq")
        assert_ref(scene.x_max, out["x_max"], cond(case, "x_max"), "x_max")
        for i, r in enumerate(out["rest"]):
            low, high = scene.rest(r["mu"])
            assert_ref(high, r["x_rest"], cond(case, "x_rest", i), f"x_rest({r['mu']})")
            if "x_rest_low" in r:
                assert_ref(low, r["x_rest_low"], what=f"x_rest_low({r['mu']})")
    # The path, all points in one array call.
    xs = np.array([p["x"] for p in out["points"]])
    path = scene.at(xs)
    for i, p in enumerate(out["points"]):
        assert_ref(path["z"][i], p["z"], cond(case, "points", i, "z"), f"z at point {i}")
        assert_ref(path["dzdx"][i], p["dzdx"], cond(case, "points", i, "dzdx"), f"dzdx at point {i}")
        assert_ref(path["r_star"][i], p["R_star"], cond(case, "points", i, "R_star"), f"R_star at point {i}")
        assert_ref(path["x_contact"][i], p["x_M"], cond(case, "points", i, "x_M"), f"x_M at point {i}")


ALONG = [c for c in CASES if "along_rail_convention" in c["outputs"]]


@pytest.mark.parametrize("case", ALONG, ids=[c["id"] for c in ALONG])
def test_along_rail_convention(case):
    scene = scene_of(case, along_rail=True)
    out = case["outputs"]["along_rail_convention"]
    assert_ref(scene.rails.theta, out["theta"], what="theta")
    assert_ref(scene.rails.alpha, out["alpha"], what="alpha")
    assert_ref(scene.x_eq, out["x_eq"], cond(case, "x_eq"), "x_eq")
    assert_ref(scene.x_max, out["x_max"], cond(case, "x_max"), "x_max")


def test_batch_convert_matches_references_in_one_call():
    """Every line-rails sphere/spheroid case through uphill.convert at once (the batch kernel),
    angles and apparatus inputs separately, per element against the references."""
    for given in ("angles", "apparatus"):
        cases = [c for c in CASES if c["body"]["type"] != "double_cone" and not c.get("rod_radius")
                 and ("apparatus" in c["rails"]) == (given == "apparatus")]
        assert cases
        a = np.array([c["body"].get("a", c["body"].get("R")) for c in cases])
        b = np.array([c["body"].get("b", c["body"].get("R")) for c in cases])
        if given == "apparatus":
            L, H, D = (np.array([c["rails"]["apparatus"][k] for c in cases]) for k in "LHD")
            got = uphill.convert("spheroid", L=L, H=H, D=D, a=a, b=b)
            # The fast path takes one body per call: one call per body, each element in place.
            x_eq = np.empty(len(cases))
            for body in {(x, y) for x, y in zip(a, b)}:
                same = (a == body[0]) & (b == body[1])
                x_eq[same] = uphill.convert_apparatus(L[same], H[same], D[same], *body)[2]
        else:
            th = np.array([c["rails"]["theta"] for c in cases])
            al = np.array([c["rails"]["alpha"] for c in cases])
            got = uphill.convert("spheroid", theta=th, alpha=al, a=a, b=b)
            x_eq = None
        for i, c in enumerate(cases):
            out = c["outputs"]
            # The batch kernel is within a few ulp of the scalar model: the same tolerance.
            assert_ref(got["theta"][i], out["theta"], what=c["id"] + " theta")
            assert_ref(got["alpha"][i], out["alpha"], what=c["id"] + " alpha")
            assert_ref(got["phi"][i], out["phi"], what=c["id"] + " phi")
            assert_ref(got["x_eq"][i], out["x_eq"], cond(c, "x_eq"), c["id"] + " x_eq")
            assert_ref(got["x_max"][i], out["x_max"], cond(c, "x_max"), c["id"] + " x_max")
            if x_eq is not None:
                assert_ref(x_eq[i], out["x_eq"], cond(c, "x_eq"), c["id"] + " x_eq (convert_apparatus)")


@pytest.mark.parametrize("case", SWEEPS, ids=[c["id"] for c in SWEEPS])
def test_sweeps_through_the_batch_kernel(case):
    rows = case["outputs"]["sweep"]
    theta = np.array([r["theta"] for r in rows])
    alpha = np.array([r["alpha"] for r in rows])
    got = uphill.convert("spheroid", theta=theta, alpha=alpha, a=case["body"]["a"], b=case["body"]["b"])
    for i, r in enumerate(rows):
        assert_ref(got["phi"][i], r["phi"], what="phi")
        assert_ref(got["x_eq"][i], r["x_eq"], what="x_eq")
        assert_ref(got["x_max"][i], r["x_max"], what="x_max")


def test_cones_through_the_batch_kernel():
    cases = [c for c in CASES if c["body"]["type"] == "double_cone"]
    got = uphill.convert("double-cone",
                         theta=np.array([c["rails"]["theta"] for c in cases]),
                         alpha=np.array([c["rails"]["alpha"] for c in cases]),
                         R=np.array([c["body"]["R"] for c in cases]), h=np.array([c["body"]["h"] for c in cases]))
    for i, c in enumerate(cases):
        assert_ref(got["x_fall"][i], c["outputs"]["x_fall"], what="x_fall")
        assert_ref(got["theta0"][i], c["outputs"]["theta0"], cond(c, "theta0"), "theta0")


RELEASES = [c for c in CASES if "release" in c["outputs"]]


@pytest.mark.parametrize("method", ["quadrature", "ode"])
@pytest.mark.parametrize("case", RELEASES, ids=[c["id"] for c in RELEASES])
def test_motion_matches_release_references(case, method):
    """Motion(...).time_at(x) and .at(t) against the 25-digit release references, with the
    tolerance of motion.hpp: max(1e-10, 16·cond·1.1e-16) relative."""
    rel = case["outputs"]["release"]
    scene = scene_of(case)
    motion = uphill.Motion(scene, rel["x0"], g=rel["g"], method=method)
    conds = (case.get("cond") or {})

    def check(actual, value, c):
        r = ref(value)
        assert abs(actual - r) <= abs(r) * max(1e-10, 16.0 * float(c) * 1.1e-16), f"{actual!r} vs {r!r}"

    t = motion.time_at(np.array([p["x"] for p in rel["t_at_x"]]))
    for i, p in enumerate(rel["t_at_x"]):
        check(t[i], p["t"], conds.get("t_at_x", ["1"] * 10)[i])
    states = motion.at(np.array([p["t"] for p in rel["x_at_t"]]))
    for i, p in enumerate(rel["x_at_t"]):
        check(states["x"][i], p["x"], conds.get("x_at_t", ["1"] * 10)[i])


def test_release_times_fast_path_matches_the_quadrature():
    case = next(c for c in RELEASES if c["id"] == "lab_exp2_L1165_H300_D100")
    rel = case["outputs"]["release"]
    scene = scene_of(case)
    xs = np.array([p["x"] for p in rel["t_at_x"]])
    t = uphill.release_times(scene, rel["x0"], xs, g=rel["g"], tolerance=1e-13)
    for i, p in enumerate(rel["t_at_x"]):
        r = ref(p["t"])
        assert abs(t[i] - r) <= abs(r) * max(1e-10, 16.0 * float(case["cond"]["t_at_x"][i]) * 1.1e-16)


def test_propagation_first_order_is_the_derivative_of_the_model():
    """u(x_eq) at first order equals |dX/dD|·u(D), the derivative taken here by a central
    difference of Scene (an independent route to the same number)."""
    L, H, D, a, b = 1.165, 0.300, 0.100, 0.015875, 0.0254
    uD = 2e-4
    body = uphill.Body.spheroid(a, b)
    res = uphill.propagate(body, L=L, H=H, D=D, u_D=uD, trials=0)
    h = 1e-6
    x = lambda d: uphill.Scene(body, uphill.Rails.from_apparatus(L, H, d)).x_eq
    derivative = (x(D + h) - x(D - h)) / (2 * h)
    assert res["x_eq"]["u_first_order"] == pytest.approx(abs(derivative) * uD, rel=1e-7)
    assert res["x_eq"]["sensitivity"]["D"] == pytest.approx(derivative, rel=1e-7)
    assert res["x_eq"]["value"] == x(D)
