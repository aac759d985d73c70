"""A property test of the Python module: its public functions called with random arguments, most
plausible and some extreme (0, ±denormals, ±1e308, the largest double, inf, NaN, negative values,
ints too large for a double, lengths just outside 1 nm … 1000 km). Whatever the arguments, each
call either returns only finite numbers or raises uphill.InputError (the module's contract,
docs/python.md "Errors", and the ranges of model/input_ranges.hpp) — never another exception,
never inf or NaN. Documented sentinels are the exception: Motion.end_time and time_at are +inf for
a motion that never ends or a position never reached (never NaN, never -inf).

Reproducible: UPHILL_PYTHON_PROPERTY_SEED=<n> draws other values (the seed is printed, and named
in a failure); UPHILL_PYTHON_PROPERTY_DRAWS sets the number of calls (default 12000)."""
import math
import os
import random

import numpy as np

import uphill

DEFAULT_SEED = 20261129
EXTREMES = [0.0, -0.0, 5e-324, -5e-324, 2.2250738585072014e-308, -1e-310, 1e-300, 1e308, -1e308,
            1.7976931348623157e308, math.inf, -math.inf, math.nan, -1.0, -1e-3, 10**400, -10**400, 2**64,
            -2**63, 1e-9, 9.9e-10, 1e6, 1.0000001e6, 1e20, 1e-20]


class Draw:
    def __init__(self, seed):
        self.rng = random.Random(seed)
        self.last = ""  # the call being made, for a failure's message

    def chance(self, p):
        return self.rng.random() < p

    def extreme(self):
        return self.rng.choice(EXTREMES)

    def value(self, lo, hi, p_extreme=0.2):
        """A plausible value in [lo, hi], or an extreme one."""
        return self.extreme() if self.chance(p_extreme) else self.rng.uniform(lo, hi)

    def real(self, lo, hi, p_extreme=0.2):
        """value() as a float, for arithmetic in the test itself (an int too large is ±inf)."""
        v = self.value(lo, hi, p_extreme)
        if isinstance(v, int) and abs(v) >= 2**1024:
            return math.inf if v > 0 else -math.inf
        return float(v)

    def array(self, lo, hi, n):
        """A float64 array of n plausible values, sometimes with an extreme element."""
        a = np.array([self.rng.uniform(lo, hi) for _ in range(n)])
        if n and self.chance(0.3):
            a[self.rng.randrange(n)] = self.real(lo, hi, 1.0)
        return a

    def count(self, lo, hi):
        return self.rng.randint(lo, hi) if self.chance(0.8) else self.rng.choice(
            [0, -1, 1, 99, 10**8 + 1, 2**64, -2**70, 10**400])

    def body(self):
        kind = self.rng.choice(["sphere", "spheroid", "double_cone"])
        if kind == "sphere":
            return uphill.Body.sphere(self.value(0.005, 0.05))
        if kind == "spheroid":
            return uphill.Body.spheroid(self.value(0.01, 0.03), self.value(0.01, 0.04))
        return uphill.Body.double_cone(self.value(0.02, 0.06), self.value(0.04, 0.12))

    def rails(self):
        if self.chance(0.6):
            return uphill.Rails.from_apparatus(self.value(0.3, 2.0), self.value(0.01, 0.4), self.value(0.02, 0.3),
                                               along_rail=self.chance(0.1))
        return uphill.Rails.from_angles(self.value(0.003, 0.5), self.value(0.1, 2.5))

    def scene(self):
        rod = self.value(0.001, 0.01) if self.chance(0.15) else None
        return uphill.Scene(self.body(), self.rails(), rod_radius=rod)


def path_x(d, scene):
    """A position on the path mostly, or anywhere."""
    lo, hi = scene.x_low, scene.x_max
    return d.real(lo + 1e-3 * (hi - lo), hi - 1e-3 * (hi - lo), 0.15)


# ---- the calls: each returns (a description, the result) --------------------------------------

def call_body_rails_scene(d):
    scene = d.scene()
    return "Scene", [scene.x_eq, scene.z_eq, scene.x_max, scene.x_low, scene.theta0, scene.theta0_fixed_phi,
                     scene.rails.theta, scene.rails.alpha, scene.rails.phi, scene.rails.tan_theta,
                     scene.rails.tan_half_alpha, scene.body.across, scene.body.along, scene.rolls_up]


def call_scene_path(d):
    scene = d.scene()
    xs = np.array([path_x(d, scene) for _ in range(d.rng.randint(1, 4))], dtype=float)
    mu = d.value(0, 0.2)
    out = [scene.at(xs)]
    out.append(scene.rest(mu) if scene.x_eq is not None else scene.rests_everywhere(mu))
    out.append(scene.kinetic_factor(d.value(scene.x_low, scene.x_max)))
    return "Scene.at/rest/kinetic_factor", out


def call_convert(d):
    n = d.rng.randint(1, 5)
    body = d.rng.choice(["sphere", "spheroid", "double-cone"])
    args = {}
    if d.chance(0.6):
        args.update(L=d.array(0.3, 2.0, n), H=d.array(0.01, 0.4, n), D=d.array(0.02, 0.3, n))
        if d.chance(0.2):
            args.update(u_L=d.array(0, 0.002, n), u_D=d.value(0, 0.001))
    else:
        args.update(theta=d.array(0.003, 0.5, n), alpha=d.array(0.1, 2.5, n))
        if d.chance(0.2):
            args.update(u_theta=d.value(0, 0.01))
    if body == "spheroid":
        args.update(a=d.array(0.01, 0.03, n), b=d.value(0.01, 0.04))
    elif body == "sphere":
        args.update(R=d.array(0.005, 0.05, n))
        if d.chance(0.15):
            args.update(rod_radius=d.value(0.001, 0.01))
    else:
        args.update(R=d.value(0.02, 0.06), h=d.array(0.04, 0.12, n))
    if d.chance(0.3):
        args.update(mc_trials=d.count(100, 300), seed=d.count(0, 10**6))
    return f"convert({body!r}, {args})", uphill.convert(body, **args)


def call_convert_apparatus(d):
    n = d.rng.randint(1, 9)
    args = (d.array(0.3, 2.0, n), d.array(0.01, 0.4, n), d.array(0.02, 0.3, n), d.value(0.01, 0.03),
            d.value(0.01, 0.04))
    return f"convert_apparatus{args}", uphill.convert_apparatus(*args)


def call_propagate(d):
    body = d.body()
    args = dict(u_across=d.value(0, 1e-4), trials=d.rng.choice([0, 0, d.count(100, 300)]), seed=d.count(0, 10**6))
    if d.chance(0.6):
        args.update(L=d.value(0.3, 2.0), H=d.value(0.01, 0.4), D=d.value(0.02, 0.3), u_D=d.value(0, 0.001))
    else:
        args.update(theta=d.value(0.003, 0.5), alpha=d.value(0.1, 2.5), u_alpha=d.value(0, 0.01))
    return f"propagate({body!r}, {args})", uphill.propagate(body, **args)


def call_motion(d):
    scene = d.scene()
    method = d.rng.choice(["quadrature", "ode"])
    options = dict(v0=d.value(-1, 1, 0.2) if method == "ode" else 0.0, g=d.value(1, 20),
                   mu=d.value(0, 0.1) if method == "ode" else 0.0, method=method)
    x0 = path_x(d, scene)
    d.last = f"Motion({scene_text(scene)}, x0={x0!r}, {options})"
    motion = uphill.Motion(scene, x0, **options)
    end = motion.end_time
    assert end == math.inf or math.isfinite(end), f"end_time {end}"
    last = motion.events[-1][1] if motion.events else 0.0
    states = motion.at(np.array([0.0, last * d.rng.random(), last]))  # the ends of the motion included
    times = motion.time_at(np.array([path_x(d, scene)]))
    assert not np.any(np.isnan(times) | (times < 0)), f"time_at {times}"
    return f"Motion(x0={x0}, {options})", [states, motion.events, motion.x0, motion.direction]


def call_release_times(d):
    scene = uphill.Scene(uphill.Body.sphere(d.value(0.005, 0.05)), d.rails())
    x_eq, x_max = scene.x_eq, scene.x_max
    x0 = x_eq + (x_max - x_eq) * d.real(0.01, 0.5, 0.1)
    xs = np.sort(np.array([x0 + (x_max - x0) * d.rng.uniform(0.05, 1.0) for _ in range(4)]))
    options = dict(g=d.value(1, 20), tolerance=d.value(1e-13, 1e-6, 0.1))
    return f"release_times(x0={x0}, {options})", uphill.release_times(scene, x0, np.unique(xs), **options)


def call_fits(d):
    n = d.rng.randint(0, 8)
    x, y = d.array(0.1, 1.0, n), d.array(0.1, 1.0, n)
    u_x, u_y = d.array(1e-4, 1e-2, n), d.array(1e-4, 1e-2, n)
    kind = d.rng.choice(["ols", "wls", "york", "robust"])
    fit = {"ols": lambda: uphill.fit_ols(x, y), "wls": lambda: uphill.fit_wls(x, y, u_y),
           "york": lambda: uphill.fit_york(x, y, u_x, u_y), "robust": lambda: uphill.fit_robust(x, y, u_y)}[kind]()
    return f"fit_{kind}", fit_numbers(fit)


def call_fit_friction(d):
    scenes, y = [], []
    for _ in range(d.rng.randint(1, 5)):
        scene = d.scene()
        if scene.x_eq is None:
            continue
        scenes.append(scene)
        y.append(scene.x_eq + (scene.x_max - scene.x_eq) * d.real(0.01, 0.9, 0.1))
    u_y = d.value(1e-4, 1e-3)
    d.last = f"fit_friction([{', '.join(scene_text(s) for s in scenes)}], y={y!r}, u_y={u_y!r})"
    fit = uphill.fit_friction(scenes, np.array(y, dtype=float), np.full(len(y), u_y))
    return "fit_friction", fit_numbers(fit)


def call_units(d):
    v = d.extreme() if d.chance(0.5) else d.rng.uniform(-1, 1)
    unit = d.rng.choice(["mm", "m", "km", "um", "in"])
    text = f"{v} {unit}" if not isinstance(v, int) or abs(v) < 10**30 else f"1e400 {unit}"
    return f"parse_quantity/to_unit({v!r}, {unit})", [uphill.parse_quantity(text, "length"),
                                                      uphill.to_unit(v, "length", unit)]


CALLS = [call_body_rails_scene, call_scene_path, call_convert, call_convert_apparatus, call_propagate, call_motion,
         call_release_times, call_fits, call_fit_friction, call_units]


def scene_text(scene):
    """A scene as the arguments that rebuild it, for a failure's message."""
    return (f"Scene(Body({scene.body.kind!r}, {scene.body.across!r}, {scene.body.along!r}), "
            f"Rails.from_angles({scene.rails.theta!r}, {scene.rails.alpha!r}), rod_radius={scene.rod_radius!r})")


def fit_numbers(fit):
    out = [[(p.value, p.se_unscaled, p.se_scaled) for p in fit.parameters], fit.chi2]
    return out


def non_finite(value, path="result"):
    """The first place in a result holding a non-finite number, or None."""
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return None
    if isinstance(value, (int, float, np.floating)):
        return None if math.isfinite(value) else f"{path} = {value}"
    if isinstance(value, np.ndarray):
        if value.dtype.kind == "f" and not np.all(np.isfinite(value)):
            return f"{path} = {value}"
        return None
    if isinstance(value, dict):
        items = value.items()
    elif isinstance(value, (list, tuple)):
        items = enumerate(value)
    else:
        return None
    for key, item in items:
        bad = non_finite(item, f"{path}[{key!r}]")
        if bad:
            return bad
    return None


def test_every_call_returns_finite_numbers_or_raises_input_error():
    seed = int(os.environ.get("UPHILL_PYTHON_PROPERTY_SEED", DEFAULT_SEED))
    draws = int(os.environ.get("UPHILL_PYTHON_PROPERTY_DRAWS", 12000))
    print(f"UPHILL_PYTHON_PROPERTY_SEED={seed} ({draws} draws; set it to draw other values)")
    d = Draw(seed)
    failures, refused = [], 0
    with np.errstate(all="ignore"):
        for i in range(draws):
            call = d.rng.choice(CALLS)
            d.last = ""
            try:
                what, result = call(d)
            except uphill.InputError:
                refused += 1
                continue
            except Exception as e:  # noqa: BLE001 - the property: nothing else may escape
                failures.append(f"draw {i} ({call.__name__}): {type(e).__name__}: {e} {d.last}")
                continue
            bad = non_finite(result)
            if bad:
                failures.append(f"draw {i}: {what}: {bad}")
    print(f"{draws - refused} calls returned, {refused} raised InputError")
    assert not failures, f"UPHILL_PYTHON_PROPERTY_SEED={seed}: {len(failures)} of {draws} draws broke the " \
                         f"property:\n" + "\n".join(failures[:20])
    assert refused < draws  # the draws are not all refused: most calls do their work
