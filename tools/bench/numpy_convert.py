#!/usr/bin/python3
"""NumPy peer of `uphill bench convert`: the same conversion and the same Monte Carlo, vectorised.

Run by `uphill bench convert` as a subprocess (it is also usable by hand):

  numpy_convert.py convert IN.f64 OUT.f64 [--repeats K]
      IN.f64: raw little-endian float64 array of shape (3, n), C order, holding L, H, D (metres, horizontal convention);
      computes θ, α (rad) and X = x_eq (m) of the spheroid --a/--b on line rails and saves them to
      OUT.f64, shape (3, n). The formulas are uphill's (src/model/batch_convert.hpp):
      B = H/L, T = D/(2L), θ = atan(B), α = 2 atan(T), A = a·T/b, X = a·B/(A·hypot(A, B)).
  numpy_convert.py mc --trials M --seed S [--case JSON] [--repeats K]
      GUM Supplement 1 Monte Carlo: Gaussian L, H, D, a, b (JSON {"L": [value, u], ...}, metres;
      default the lab case below); θ, α, φ, X, x_max; per output the mean, the standard deviation
      (ddof 1) and the probabilistically symmetric 95 % interval from order statistics
      (np.partition), as uphill's propagation reports them.

Prints one JSON object on stdout: versions, timings (seconds, best of K repeats, thread CPU time
like the C++ side: the throughput of one core, robust to other load on the machine), the peak
resident memory (peak_bytes, peak_memory.py) and, for mc, the statistics.
Written to be a fair, tuned NumPy baseline: float64 throughout, every ufunc writing with out= into
arrays allocated once (no temporaries, no page faults in the timed region), atan of the ratios
(cheaper than arctan2 here), one in-place partition per output for both ends of the interval.
"""
import argparse
import json
import sys

import numpy as np

from peak_memory import measure

LAB = {  # the lab spheroid and a plausible set of measurement uncertainties (metres)
    "L": (1.165, 0.002), "H": (0.300, 0.001), "D": (0.045, 0.0005),
    "a": (0.015875, 2e-5), "b": (0.0254, 2e-5),
}


class Work:
    """Preallocated float64 arrays, reused by every repeat: the timing measures arithmetic and
    memory traffic, not the kernel zeroing fresh pages for new temporaries (which, at 10^7
    values, costs as much as the arithmetic and varies with the machine's load)."""

    def __init__(self, n):
        self.n = n
        self.pool = {}

    def __call__(self, name):
        if name not in self.pool:
            self.pool[name] = np.empty(self.n)
        return self.pool[name]


def convert(L, H, D, a, b, w):
    B = np.divide(H, L, out=w("B"))
    T = np.multiply(L, 2.0, out=w("T"))
    np.divide(D, T, out=T)
    theta = np.arctan(B, out=w("theta"))
    alpha = np.arctan(T, out=w("alpha"))
    alpha *= 2.0
    A = np.multiply(T, a / b, out=w("A"))
    h = np.hypot(A, B, out=w("h"))
    h *= A
    X = np.multiply(B, a, out=w("X"))
    X /= h
    return theta, alpha, X


def monte_carlo(trials, seed, case, w, coverage=0.95):
    rng = np.random.default_rng(seed)
    draws = {}
    for name in ("L", "H", "D", "a", "b"):
        value, u = case[name]
        x = rng.standard_normal(out=w(name))
        x *= u
        x += value
        draws[name] = x
    L, H, D, a, b = (draws[k] for k in ("L", "H", "D", "a", "b"))
    # Screen unphysical draws as uphill does (none are expected for these uncertainties).
    ok = (L > 0) & (H >= 0) & (D > 0) & (a > 0) & (b > 0)
    if not ok.all():
        L, H, D, a, b = L[ok], H[ok], D[ok], a[ok], b[ok]
        w = Work(L.size)
    B = np.divide(H, L, out=w("B"))
    T = np.multiply(L, 2.0, out=w("T"))
    np.divide(D, T, out=T)
    theta = np.arctan(B, out=w("theta"))
    alpha = np.arctan(T, out=w("alpha"))
    alpha *= 2.0
    phi = np.hypot(1.0, B, out=w("phi"))
    np.divide(T, phi, out=phi)
    np.arctan(phi, out=phi)
    A = np.multiply(a, T, out=w("A"))
    A /= b
    h = np.hypot(A, B, out=w("h"))
    h *= A
    x_eq = np.multiply(a, B, out=w("x_eq"))
    x_eq /= h
    x_max = np.divide(b, T, out=w("x_max"))
    np.hypot(a, x_max, out=x_max)
    m = theta.size
    pm = coverage * m
    q = int(pm) if float(int(pm)) == pm else int(pm + 0.5)
    r = max((m - q + 1) // 2, 1)
    hi = min(r + q, m)
    stats = {}
    part = w("partition")[:m]
    for name, y in (("theta", theta), ("alpha", alpha), ("phi", phi), ("x_eq", x_eq),
                    ("x_max", x_max)):
        mean = y.mean()
        np.subtract(y, mean, out=part)  # the variance without np.std's temporaries
        np.square(part, out=part)
        u = np.sqrt(part.sum() / (m - 1))
        part[:] = y
        part.partition((r - 1, hi - 1))
        stats[name] = {"mean": float(mean), "u": float(u),
                       "low": float(part[r - 1]), "high": float(part[hi - 1])}
    return stats, int(trials - m)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = ap.add_subparsers(dest="mode", required=True)
    c = sub.add_parser("convert")
    c.add_argument("input")
    c.add_argument("output")
    c.add_argument("--a", type=float, default=LAB["a"][0])
    c.add_argument("--b", type=float, default=LAB["b"][0])
    c.add_argument("--repeats", type=int, default=3)
    m = sub.add_parser("mc")
    m.add_argument("--trials", type=int, default=1_000_000)
    m.add_argument("--seed", type=int, default=1)
    m.add_argument("--case", type=json.loads, default=LAB)
    m.add_argument("--repeats", type=int, default=3)
    args = ap.parse_args()
    info = {"versions": {"Python": sys.version.split()[0], "NumPy": np.__version__}}
    if args.mode == "convert":
        L, H, D = np.fromfile(args.input, dtype="<f8").reshape(3, -1)
        work = Work(L.size)
        convert(L, H, D, args.a, args.b, work)  # allocate and touch the work arrays once
        seconds, (theta, alpha, X), peak = measure(
            args.repeats, lambda: convert(L, H, D, args.a, args.b, work))
        np.stack((theta, alpha, X)).astype("<f8").tofile(args.output)
        info.update(mode="convert", n=int(L.size), seconds=seconds, peak_bytes=peak,
                    repeats=args.repeats)
    else:
        work = Work(args.trials)
        monte_carlo(args.trials, args.seed, args.case, work)  # allocate and touch once
        seconds, (stats, rejected), peak = measure(
            args.repeats, lambda: monte_carlo(args.trials, args.seed, args.case, work))
        info.update(mode="mc", trials=args.trials, seconds=seconds, peak_bytes=peak,
                    repeats=args.repeats,
                    rejected=rejected, stats=stats, inputs=args.case)
    json.dump(info, sys.stdout)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
