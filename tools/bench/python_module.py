#!/usr/bin/python3
"""Python side of `uphill bench python`: the module `uphill` and NumPy, timed in one process.

Run by `uphill bench python` as a subprocess, with PYTHONPATH at the built module (also usable by
hand):

  python_module.py CONVERT.f64 CONVERT_OUT.f64 YORK.f64 --a A --b B [--repeats K]
      CONVERT.f64: raw float64 (3, n): L, H, D (m). Times uphill.convert_apparatus(L, H, D, a, b)
      writing into preallocated arrays (out=), the same call allocating its results, and the
      NumPy formula of numpy_convert.py (out= arrays too); saves the module's theta, alpha, x_eq
      (3, n) to CONVERT_OUT.f64 so that the caller compares them with its C++ kernel's, bit for bit.
      YORK.f64: raw float64 (4, n): X, Y, u(X), u(Y). Times uphill.fit_york and the NumPy York
      iteration of fit_peers.py.

Prints one JSON object: versions, and per row seconds (thread CPU time, best of K, as the C++
side measures), peak_bytes (peak_memory.py) and results (York: slope, intercept as repr floats).
"""
import argparse
import json
import sys

import numpy as np

from fit_peers import York
from numpy_convert import Work, convert
from peak_memory import measure


def main():
    p = argparse.ArgumentParser()
    p.add_argument("convert_in")
    p.add_argument("convert_out")
    p.add_argument("york_in")
    p.add_argument("--a", type=float, required=True)
    p.add_argument("--b", type=float, required=True)
    p.add_argument("--repeats", type=int, default=3)
    a = p.parse_args()
    import uphill

    L, H, D = (np.ascontiguousarray(r) for r in np.fromfile(a.convert_in, dtype="<f8").reshape(3, -1))
    n = L.size
    out = {"versions": {"Python": sys.version.split()[0], "NumPy": np.__version__, "uphill module": uphill.__version__},
           "module": uphill.__file__, "kernel": uphill.kernel(), "rows": {}}
    rows = out["rows"]

    theta, alpha, x_eq = np.empty(n), np.empty(n), np.empty(n)
    call = lambda: uphill.convert_apparatus(L, H, D, a.a, a.b, theta=theta, alpha=alpha, x_eq=x_eq)
    call()  # first touch of the output pages, outside the timing (as the C++ side does)
    t, _, peak = measure(a.repeats, call)
    rows["convert_out"] = {"seconds": t, "peak_bytes": peak}
    np.stack([theta, alpha, x_eq]).astype("<f8").tofile(a.convert_out)
    t, _, peak = measure(a.repeats, lambda: uphill.convert_apparatus(L, H, D, a.a, a.b))
    rows["convert_new"] = {"seconds": t, "peak_bytes": peak}
    w = Work(n)
    convert(L, H, D, a.a, a.b, w)
    t, (nt, na, nx), peak = measure(a.repeats, lambda: convert(L, H, D, a.a, a.b, w))
    rel = max(float(np.max(np.abs(mine / theirs - 1))) for mine, theirs in ((theta, nt), (alpha, na), (x_eq, nx)))
    rows["numpy_convert"] = {"seconds": t, "peak_bytes": peak, "max_rel_diff_vs_module": rel}

    x, y, ux, uy = (np.ascontiguousarray(r) for r in np.fromfile(a.york_in, dtype="<f8").reshape(4, -1))
    t, fit, peak = measure(a.repeats, lambda: uphill.fit_york(x, y, ux, uy))
    rows["york"] = {"seconds": t, "peak_bytes": peak, "slope": fit.slope, "intercept": fit.intercept}
    t, (k, c, it), peak = measure(a.repeats, lambda: York(x, y, ux, uy)())
    rows["numpy_york"] = {"seconds": t, "peak_bytes": peak, "slope": k, "intercept": c, "iterations": it}
    json.dump(out, sys.stdout)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
