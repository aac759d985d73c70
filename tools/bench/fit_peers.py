#!/usr/bin/python3
"""NumPy/SciPy peers of `uphill bench fit`: the same straight-line fits on the very same numbers.

Run by `uphill bench fit` as a subprocess (also usable by hand):

  fit_peers.py IN.f64 [--repeats K] [--no-odr] [--no-rlm]
      IN.f64: raw little-endian float64 array of shape (4, n), C order, holding X, Y, u(X), u(Y) (rows of the fit).

Fits, each timed (thread CPU time like the C++ side, best of K repeats):
  lstsq       numpy.linalg.lstsq of [X, 1] against Y (OLS, LAPACK's SVD-based gelsd)
  polyfit     numpy.polyfit(X, Y, 1) (OLS; scales the Vandermonde columns, then lstsq)
  wls_lstsq   numpy.linalg.lstsq of [X/u(Y), 1/u(Y)] against Y/u(Y) (WLS)
  york        York et al. (2004) iteration, vectorised (below), to |Δk| ≤ 1e-15·|k|
  odr         scipy.odr: ODR(RealData(X, Y, sx=u(X), sy=u(Y)), unilinear), started at OLS,
              ODRPACK's default tolerances (how it is normally used)
  rlm         statsmodels RLM with HuberT(t = 1.345) on the rows divided by u(Y) (design
              [X/u, 1/u], response Y/u) with the scale fixed at 1: it minimises
              Σ ρ_H((Y − c − kX)/u(Y)), ρ_H(z) = z²/2 for |z| ≤ t, t|z| − t²/2 beyond - half of
              uphill's Huber objective with σ_i = u(Y_i) and δ = 1.345, the same minimiser; IRLS
              with its default tolerance (1e-8 on the deviance)
  rlm_mad     statsmodels RLM with HuberT(1.345) and its default scale, 1.4826·MAD of the residuals
              (scale_est = "mad", center 0) updated every iteration: the fixed point of uphill's
              robust fit without u(Y)

Prints one JSON object on stdout: python/numpy/scipy versions and, per fit, seconds, peak_bytes
(peak resident memory, peak_memory.py), slope, intercept (floats print with repr, so they
round-trip exactly), for york the iterations, for odr ODRPACK's stop reason.

Written as a fair, tuned NumPy baseline: float64 throughout, the York iteration on data centred
once at their mean (so X near 1e9 does not cancel inside the loop: that is the textbook
algorithm's own weakness, not NumPy's, and uphill centres too), in-place ufuncs with out= into
arrays allocated once, one pass of sums per iteration. lstsq/polyfit are used as is: that they
lose digits for X far from 0 is what the 1e9-offset case of the benchmark shows.
"""
import argparse
import json
import sys

import numpy as np

from peak_memory import measure


def fit_lstsq(x, y):
    a = np.empty((x.size, 2))
    a[:, 0] = x
    a[:, 1] = 1.0
    (k, c), *_ = np.linalg.lstsq(a, y, rcond=None)
    return float(k), float(c)


def fit_polyfit(x, y):
    k, c = np.polyfit(x, y, 1)
    return float(k), float(c)


def fit_wls_lstsq(x, y, uy):
    w = 1.0 / uy
    a = np.empty((x.size, 2))
    np.multiply(x, w, out=a[:, 0])
    a[:, 1] = w
    (k, c), *_ = np.linalg.lstsq(a, y * w, rcond=None)
    return float(k), float(c)


class York:
    """York, Evensen, Martínez López & De Basabe Delgado (2004), Am. J. Phys. 72, 367, section III
    with r_i = 0: W_i = ω(X_i)ω(Y_i)/(ω(X_i) + k²ω(Y_i)), ω = 1/u², X̄ = ΣW X/ΣW,
    β_i = W_i(U_i/ω(Y_i) + k·V_i/ω(X_i)), U = X − X̄, V = Y − Ȳ, k = ΣW β V/ΣW β U, iterated.
    Written with u² instead of ω (W = 1/(u(Y)² + k²u(X)²), β = W(u(X)²·k·V + u(Y)²·U)... the same
    algebra) and on data centred once at their plain mean."""

    def __init__(self, x, y, ux, uy):
        n = x.size
        self.x0, self.y0 = x.mean(), y.mean()
        self.x = x - self.x0
        self.y = y - self.y0
        self.ux2 = ux * ux
        self.uy2 = uy * uy
        self.w = np.empty(n)
        self.u = np.empty(n)
        self.v = np.empty(n)
        self.b = np.empty(n)
        self.t = np.empty(n)

    def slope_ols(self):
        return float(np.dot(self.x, self.y) / np.dot(self.x, self.x))

    def __call__(self, tol=1e-15, max_iter=200):
        k = self.slope_ols()
        w, u, v, b, t = self.w, self.u, self.v, self.b, self.t
        for it in range(1, max_iter + 1):
            np.multiply(self.ux2, k * k, out=w)
            w += self.uy2
            np.reciprocal(w, out=w)                 # W = 1/(uy² + k²ux²)
            sw = w.sum()
            xbar = np.dot(w, self.x) / sw
            ybar = np.dot(w, self.y) / sw
            np.subtract(self.x, xbar, out=u)        # U
            np.subtract(self.y, ybar, out=v)        # V
            # β = W·(U·uy² + k·V·ux²)  (York's β_i with ω = 1/u²)
            np.multiply(u, self.uy2, out=b)
            np.multiply(v, self.ux2, out=t)
            t *= k
            b += t
            b *= w
            np.multiply(w, b, out=t)                # W·β
            k_new = float(np.dot(t, v) / np.dot(t, u))
            done = abs(k_new - k) <= tol * abs(k_new)
            k = k_new
            if done:
                break
        # Intercept at the final weights (York's eq. 11 with the converged W).
        np.multiply(self.ux2, k * k, out=w)
        w += self.uy2
        np.reciprocal(w, out=w)
        sw = w.sum()
        xbar = np.dot(w, self.x) / sw
        ybar = np.dot(w, self.y) / sw
        c_centred = ybar - k * xbar
        return k, float(self.y0 + c_centred - k * self.x0), it


def fit_rlm(x, y, uy):
    import statsmodels.api as sm
    from statsmodels.robust.norms import HuberT
    design = np.empty((x.size, 2))
    np.divide(x, uy, out=design[:, 0])
    np.divide(1.0, uy, out=design[:, 1])
    model = sm.RLM(y / uy, design, M=HuberT(t=1.345))
    model.scale = 1.0  # init (truthy) keeps this scale; update_scale=False holds it
    result = model.fit(init="fixed", update_scale=False)
    return float(result.params[0]), float(result.params[1])


def fit_rlm_mad(x, y):
    import statsmodels.api as sm
    from statsmodels.robust.norms import HuberT
    design = np.empty((x.size, 2))
    design[:, 0] = x
    design[:, 1] = 1.0
    result = sm.RLM(y, design, M=HuberT(t=1.345)).fit()
    return float(result.params[0]), float(result.params[1])


def fit_odr(x, y, ux, uy):
    from scipy import odr
    beta0 = list(np.polyfit(x, y, 1))
    out = odr.ODR(odr.RealData(x, y, sx=ux, sy=uy), odr.unilinear, beta0=beta0).run()
    return float(out.beta[0]), float(out.beta[1]), out.stopreason[0]


def main():
    p = argparse.ArgumentParser()
    p.add_argument("input")
    p.add_argument("--repeats", type=int, default=3)
    p.add_argument("--no-odr", action="store_true")
    p.add_argument("--no-rlm", action="store_true")
    a = p.parse_args()
    data = np.fromfile(a.input, dtype="<f8")
    if data.size % 4:
        sys.exit("expected a float64 array of shape (4, n)")
    data = data.reshape(4, -1)
    x, y, ux, uy = (np.ascontiguousarray(r) for r in data)
    out = {"versions": {"Python": sys.version.split()[0], "NumPy": np.__version__},
           "n": int(x.size), "fits": {}}
    fits = out["fits"]

    t, (k, c), peak = measure(a.repeats, lambda: fit_lstsq(x, y))
    fits["lstsq"] = {"seconds": t, "peak_bytes": peak, "slope": k, "intercept": c}
    t, (k, c), peak = measure(a.repeats, lambda: fit_polyfit(x, y))
    fits["polyfit"] = {"seconds": t, "peak_bytes": peak, "slope": k, "intercept": c}
    t, (k, c), peak = measure(a.repeats, lambda: fit_wls_lstsq(x, y, uy))
    fits["wls_lstsq"] = {"seconds": t, "peak_bytes": peak, "slope": k, "intercept": c}
    # The York setup (centring, squares, buffers) is part of the fit's time.
    t, (k, c, it), peak = measure(a.repeats, lambda: York(x, y, ux, uy)())
    fits["york"] = {"seconds": t, "peak_bytes": peak, "slope": k, "intercept": c, "iterations": it}
    if not a.no_odr:
        try:
            import scipy
            out["versions"]["SciPy"] = scipy.__version__
            t, (k, c, why), peak = measure(a.repeats, lambda: fit_odr(x, y, ux, uy))
            fits["odr"] = {"seconds": t, "peak_bytes": peak, "slope": k, "intercept": c,
                           "stopreason": why}
        except ImportError:
            pass
    if not a.no_rlm:
        try:
            import statsmodels
            out["versions"]["statsmodels"] = statsmodels.__version__
            t, (k, c), peak = measure(a.repeats, lambda: fit_rlm(x, y, uy))
            fits["rlm"] = {"seconds": t, "peak_bytes": peak, "slope": k, "intercept": c}
            t, (k, c), peak = measure(a.repeats, lambda: fit_rlm_mad(x, y))
            fits["rlm_mad"] = {"seconds": t, "peak_bytes": peak, "slope": k, "intercept": c}
        except ImportError:
            pass
    json.dump(out, sys.stdout)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
