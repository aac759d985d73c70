#!/usr/bin/env python3
"""Peers for `uphill bench motion` (src/bench/motion_benchmark.cpp): the same trajectory problems
with SciPy and NumPy. Usage: motion_peers.py PROBLEM.txt, where PROBLEM.txt holds
"a b tan_theta tan_half_alpha g x0 v0 mu" and then one line "x t_reference" per position (the
50-digit reference of the C++ side: the first time the centre is at x). Prints a first line
"versions|{JSON}", then one row per method and setting:
"method|setting|microseconds|max_rel_err|peak_bytes" (peak resident memory, peak_memory.py).

Problem: a solid spheroid on line rails, thrown at x0 with velocity v0 (0: released at rest),
rolling resistance mu (docs/physics.md "Energy", "Rolling resistance").
  solve_ivp (equation of motion), every problem: m(u) u'' + m'(u) u'^2 / 2 = -g z'(u) - g mu |x'(u)| sgn u'
              in the ellipse parameter u = psi - psi0 (the coordinate src/motion integrates in),
              one solve_ivp per leg (RK45, DOP853, LSODA; rtol = tol, atol = 1e-3 tol), dense_output,
              terminal events at u' = 0 (turning point, or rest where |dz/dx| <= mu) and at the end
              of the rails; the time at each position from the dense output by vectorised Newton
              steps (start: linear interpolation between the steps).
  Released at rest with mu = 0 (the release trajectory) also, as in src/motion's quadrature:
  psi - psi0 = u0 cosh(w) removes the release singularity and
  dt/dw = sqrt(K M / (g z_eq sinc(u0 ch^2) sinc(u0 sh^2))) is smooth:
  quad        scipy.integrate.quad on each interval [w_{i-1}, w_i] (cumulative), epsrel = tol
  solve_ivp   dt/dw = f(w) integrated with t_eval = w_i (RK45, DOP853, LSODA), rtol = tol
  numpy GL    12-node Gauss-Legendre per interval in s, x = x0 + s^2 (removes the release
              singularity; the x form of the integrand), vectorised over all intervals
"""
import json
import math
import sys
import time

import numpy as np
from scipy import integrate
from scipy.integrate import solve_ivp

import peak_memory


def load(path):
    with open(path) as f:
        a, b, B, T, g, x0, v0, mu = (float(v) for v in f.readline().split())
        rows = np.array([[float(v) for v in line.split()] for line in f if line.strip()])
    return a, b, B, T, g, x0, v0, mu, rows[:, 0], rows[:, 1]


class Ellipse:
    def __init__(self, a, b, B, T):
        A = a * T / b
        P = 1 + A * A + B * B
        sp = np.sqrt(P)
        self.x_max = np.hypot(a, b / T)
        self.z_eq = a * np.hypot(A, B) / A
        h = np.hypot(A * sp, B)
        self.c0, self.s0 = A * sp / h, B / h
        hg = np.hypot(A * B, sp)
        self.cg, self.sg = sp / hg, A * B / hg
        self.q = A * A / P
        self.inertia = 0.4

    def u_of_x(self, x):
        sp = x / self.x_max
        cp = np.sqrt(np.maximum((self.x_max - x) / self.x_max, 0) * (1 + sp))
        return np.arctan2(sp * self.c0 - cp * self.s0, cp * self.c0 + sp * self.s0)

    def geometry(self, u):
        su, cu = np.sin(u), np.cos(u)
        sp = su * self.c0 + cu * self.s0
        cp = cu * self.c0 - su * self.s0
        cw = cp * self.cg - sp * self.sg
        sw = sp * self.cg + cp * self.sg
        dx, dz = self.x_max * cp, -self.z_eq * su
        d = cw * cw + self.q * sw * sw
        K = 1 + self.inertia / d
        return dx, dz, K

    def motion(self, u):
        """dx/du, dz/du, m = K M and dm/du at a scalar u (math, not NumPy: one point per call)."""
        su, cu = math.sin(u), math.cos(u)
        sp = su * self.c0 + cu * self.s0
        cp = cu * self.c0 - su * self.s0
        cw = cp * self.cg - sp * self.sg
        sw = sp * self.cg + cp * self.sg
        dx, dz = self.x_max * cp, -self.z_eq * su
        M = dx * dx + dz * dz
        d = cw * cw + self.q * sw * sw
        K = 1 + self.inertia / d
        dK = -self.inertia * 2 * (self.q - 1) * sw * cw / (d * d)
        dM = 2 * (-self.x_max * self.x_max * cp * sp + self.z_eq * self.z_eq * su * cu)
        return dx, dz, K * M, dK * M + K * dM

    def u_max(self):
        return math.atan2(self.c0, self.s0)

    def u_low(self):
        return -math.atan2(self.sg * self.c0 + self.cg * self.s0, self.cg * self.c0 - self.sg * self.s0)


def main():
    import scipy
    print("versions|" + json.dumps({"Python": sys.version.split()[0], "NumPy": np.__version__,
                                    "SciPy": scipy.__version__}), flush=True)
    a, b, B, T, g, x0, v0, mu, xs, ref = load(sys.argv[1])
    e = Ellipse(a, b, B, T)
    u0 = float(e.u_of_x(x0))
    gz = g * e.z_eq

    def f(w):
        ch, sh = np.cosh(0.5 * w), np.sinh(0.5 * w)
        a1, a2 = u0 * ch * ch, u0 * sh * sh
        dx, dz, K = e.geometry(a1 + a2)
        return np.sqrt(K * (dx * dx + dz * dz) / (gz * np.sinc(a1 / np.pi) * np.sinc(a2 / np.pi)))

    def f_scalar(w):
        return float(f(np.float64(w)))

    def w_of(x):
        u = e.u_of_x(x)
        return 2 * np.arcsinh(np.sqrt(np.maximum((u - u0) / (2 * u0), 0)))

    ws = w_of(xs) if v0 == 0 and mu == 0 else None

    def timed(work):
        peak_memory.reset_peak()
        best = 1e300
        for _ in range(3):
            n, start = 0, time.perf_counter()
            while True:
                out = work()
                n += 1
                el = time.perf_counter() - start
                if el > 0.2:
                    break
            best = min(best, el / n)
        return best * 1e6, out, peak_memory.peak_bytes()

    def report(method, setting, work):
        try:
            micros, got, peak = timed(work)
        except Exception as exc:  # e.g. a tolerance the solver refuses
            print(f"# {method} {setting}: failed ({exc})", file=sys.stderr)
            return
        err = float(np.max(np.abs(got / ref - 1)))
        print(f"{method}|{setting}|{micros:.3f}|{err:.3e}|{peak}", flush=True)

    eom_peers(e, g, x0, v0, mu, xs, report)
    if v0 != 0 or mu != 0:
        return
    tols = [10.0 ** -k for k in (3, 5, 7, 9, 11, 13)]
    for tol in tols:
        def quad_work():
            edges = np.concatenate(([0.0], ws))
            pieces = [integrate.quad(f_scalar, edges[i], edges[i + 1], epsabs=0, epsrel=tol, limit=200)[0]
                      for i in range(len(ws))]
            return np.cumsum(pieces)
        report("scipy quad (w substitution)", f"epsrel {tol:.0e}", quad_work)
    for method in ("RK45", "DOP853", "LSODA"):
        for tol in tols:
            def ivp_work():
                sol = integrate.solve_ivp(lambda w, t: [f_scalar(w)], (0.0, ws[-1]), [0.0], method=method,
                                          t_eval=ws, rtol=tol, atol=1e-20)
                if not sol.success or len(sol.y[0]) != len(ws):
                    raise RuntimeError(sol.message)
                return sol.y[0]
            report(f"scipy solve_ivp {method} (dt/dw)", f"rtol {tol:.0e}", ivp_work)

    # NumPy Gauss-Legendre, 12 nodes per interval in s (x = x0 + s^2), vectorised.
    nodes, weights = np.polynomial.legendre.leggauss(12)
    z0 = e.z_eq * np.cos(u0)
    del z0

    def gl_work():
        s_edges = np.concatenate(([0.0], np.sqrt(xs - x0)))
        lo, hi = s_edges[:-1, None], s_edges[1:, None]
        s = 0.5 * (hi - lo) * nodes[None, :] + 0.5 * (hi + lo)
        x = x0 + s * s
        u = e.u_of_x(x)
        dx, dz, K = e.geometry(u)
        slope = dz / dx
        drop = 2 * e.z_eq * np.sin(0.5 * (u + u0)) * np.sin(0.5 * (u - u0))
        # dt/ds = 2 s / xdot, xdot = sqrt(2 g drop / (K (1 + z'^2)))
        integrand = 2 * s * np.sqrt(K * (1 + slope * slope) / (2 * g * drop))
        pieces = 0.5 * (hi[:, 0] - lo[:, 0]) * (integrand @ weights)
        return np.cumsum(pieces)
    report("numpy Gauss-Legendre 12/interval (x = x0 + s^2)", "12 nodes", gl_work)


def eom_peers(e, g, x0, v0, mu, xs, report):
    """solve_ivp on the equation of motion, one call per leg, times at the positions by Newton."""
    u_hi, u_lo = e.u_max(), e.u_low()
    us = e.u_of_x(xs)

    def rhs(d):
        def f(t, y):
            dx, dz, m, dm = e.motion(y[0])
            force = -g * dz - 0.5 * dm * y[1] * y[1] - g * mu * abs(dx) * d
            return [y[1], force / m]
        return f

    def solve(method, tol):
        u0 = float(e.u_of_x(x0))
        dx0, dz0, m0, _ = e.motion(u0)
        ud0 = v0 / math.hypot(dx0, dz0)
        if v0 != 0:
            d = 1 if v0 > 0 else -1
        else:
            d = 1 if dz0 < 0 else -1
        times = np.full(len(us), np.nan)
        todo = np.ones(len(us), dtype=bool)
        t0, y0 = 0.0, [u0, ud0]
        for _ in range(16):
            def turn(t, y):
                return y[1]
            turn.terminal, turn.direction = True, -d

            def end(t, y):
                return y[0] - (u_hi if d > 0 else u_lo)
            end.terminal, end.direction = True, d
            sol = solve_ivp(rhs(d), (t0, t0 + 100.0), y0, method=method, rtol=tol, atol=1e-3 * tol,
                            dense_output=True, events=[turn, end])
            if sol.status != 1:
                raise RuntimeError(sol.message)
            u_s, u_e = sol.y[0][0], sol.y[0][-1]
            mine = todo & ((us - u_s) * d > 0) & ((u_e - us) * d >= 0)
            if mine.any():
                target = us[mine]
                t = np.interp(d * target, d * sol.y[0], sol.t)
                for _ in range(4):
                    y = sol.sol(t)
                    t = np.clip(t - (y[0] - target) / y[1], sol.t[0], sol.t[-1])
                times[mine] = t
                todo &= ~mine
            if len(sol.t_events[0]) == 0:
                break  # fell off (or reached O)
            u_t = sol.y_events[0][0][0]
            dx, dz, _, _ = e.motion(u_t)
            if abs(dz) <= mu * abs(dx):
                break  # comes to rest
            d = 1 if dz < 0 else -1
            t0, y0 = sol.t_events[0][0], [u_t, 0.0]
        return times

    for method in ("RK45", "DOP853", "LSODA"):
        for k in range(3, 14):
            tol = 10.0 ** -k
            report(f"scipy solve_ivp {method} (equation of motion)", f"rtol {tol:.0e}", lambda: solve(method, tol))


if __name__ == "__main__":
    main()
