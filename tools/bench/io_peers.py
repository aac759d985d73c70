#!/usr/bin/python3
"""NumPy peer of `uphill bench io`: the same CSV file read and fitted or converted end to end, as a
user's script would do it. Run by the benchmark as its own process (interpreter start and `import
numpy` included, as the uphill process's start is); the benchmark measures the process's CPU time
and peak resident memory.

  io_peers.py fit FILE --method ols|york
      np.loadtxt of the X,Y,uX,uY file, then numpy.linalg.lstsq of [X, 1] against Y (ols) or the
      vectorised York iteration of fit_peers.py (york).
  io_peers.py convert FILE --a A --b B [--out OUT.csv]
      np.loadtxt of the L_mm,H_mm,D_mm file, then theta, alpha, phi, X, x_max of the spheroid a, b (m)
      on line rails (the formulas of numpy_convert.py); with --out also np.savetxt of the same
      columns and formats as `uphill convert --csv` (angles %.6f deg, lengths %.6g mm).

Prints one JSON object: versions, rows, the results (fit: slope, intercept; convert: the largest
X), and the thread CPU time of the load and of the rest.
"""
import argparse
import json
import sys
import time

import numpy as np

from fit_peers import York


def main():
    p = argparse.ArgumentParser()
    sub = p.add_subparsers(dest="mode", required=True)
    f = sub.add_parser("fit")
    f.add_argument("file")
    f.add_argument("--method", choices=("ols", "york"), default="ols")
    c = sub.add_parser("convert")
    c.add_argument("file")
    c.add_argument("--a", type=float, required=True)
    c.add_argument("--b", type=float, required=True)
    c.add_argument("--out")
    a = p.parse_args()
    out = {"versions": {"Python": sys.version.split()[0], "NumPy": np.__version__}}
    t0 = time.thread_time()
    data = np.loadtxt(a.file, delimiter=",", skiprows=1, ndmin=2)
    t1 = time.thread_time()
    out["rows"] = int(data.shape[0])
    if a.mode == "fit":
        x, y = data[:, 0], data[:, 1]
        if a.method == "ols":
            design = np.empty((x.size, 2))
            design[:, 0] = x
            design[:, 1] = 1.0
            (k, c0), *_ = np.linalg.lstsq(design, y, rcond=None)
        else:
            k, c0, _ = York(x, y, np.ascontiguousarray(data[:, 2]), np.ascontiguousarray(data[:, 3]))()
        out.update(slope=float(k), intercept=float(c0))
    else:
        L, H, D = (data[:, j] * 1e-3 for j in range(3))  # mm -> m
        B = H / L
        T = D / (2.0 * L)
        theta = np.arctan(B)
        alpha = 2.0 * np.arctan(T)
        phi = np.arctan(T / np.hypot(1.0, B))
        A = a.a * T / a.b
        X = a.a * B / (A * np.hypot(A, B))
        x_max = np.hypot(a.a, a.b / T)
        out["largest_X"] = float(X.max())
        if a.out:
            deg = 180.0 / np.pi
            np.savetxt(a.out, np.column_stack((theta * deg, alpha * deg, phi * deg, X * 1e3, x_max * 1e3)),
                       fmt=("%.6f", "%.6f", "%.6f", "%.6g", "%.6g"), delimiter=",",
                       header="theta_deg,alpha_deg,phi_deg,X_mm,x_max_mm", comments="")
    t2 = time.thread_time()
    out.update(load_seconds=t1 - t0, work_seconds=t2 - t1)
    json.dump(out, sys.stdout)
    sys.stdout.write("\n")


if __name__ == "__main__":
    main()
