#!/usr/bin/python3
"""The sample experiment data/series2-fixed-L analysed from Python with `import uphill`.

A notebook in script form: run it cell by cell in Jupyter (each `# %%` starts a cell) or at once:

    PYTHONPATH=build/release/python python3 docs/python-example.py [OUT.png]

(no PYTHONPATH once the module is installed: `cmake --install` or the python3-uphill package).
It reads the experiment folder, converts its settings with uncertainties, fits Y against X with the
five methods, compares the friction model with the straight line, and draws Y − X against X with
the fits and the friction model (matplotlib, Debian's python3-matplotlib). Numbers are SI: metres
and radians; the figure shows millimetres.
"""
# %% The experiment folder, read once
import pathlib
import sys

import numpy as np

import uphill

root = pathlib.Path(__file__).resolve().parents[1]
folder = root / "data" / "series2-fixed-L"
experiment = uphill.read_experiment(str(folder))
print(experiment.title, "-", len(experiment.rows), "rows,", len(experiment.errors), "left out")

# %% Each setting's X with its uncertainty, the measured Y, and the five fits (as `uphill fit`)
analysis = uphill.analyse_experiment(experiment, mc_trials=20000)
x, u_x, y, u_y = analysis.x_eq, analysis.u_x_eq, analysis.y, analysis.u_y
for method, fit in analysis.fits.items():
    names = ", ".join(f"{p.name} = {p.value:.6g} ± {p.se_unscaled:.2g}" for p in fit.parameters)
    print(f"{method:9s} {names}  chi2/dof = {fit.reduced_chi2:.3g}")
print(analysis.friction_vs_line["verdict"])

# %% The same conversion with the batch kernel: all settings in one call, first-order u(X)
scenes = experiment.scenes
rows = [r for r in experiment.rows if r["configuration"]]
L = np.array([r["configuration"]["L"]["value"] for r in rows])
H = np.array([r["configuration"]["H"]["value"] for r in rows])
D = np.array([r["configuration"]["D"]["value"] for r in rows])
u_D = np.array([r["configuration"]["D"]["u"] for r in rows])
body = scenes[0].body
batch = uphill.convert("spheroid", L=L, H=H, D=D, a=body.across, b=body.along, u_D=u_D)
print("batch X agrees with the analysis to", np.max(np.abs(batch["x_eq"] / x - 1)))

# %% York's line through Y − X (errors in both variables) and the friction model's rest positions
york = analysis.fits["york"]
mu = analysis.fits["friction"].parameter("mu").value
band_high = np.array([s.rest(mu)[1] for s in scenes])

# %% The figure: Y − X against X, with error bars, York's line and the friction model
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt

mm = 1e3
order = np.argsort(x)
fig, ax = plt.subplots(figsize=(7, 4.5))
ax.errorbar(x * mm, (y - x) * mm, xerr=u_x * mm, yerr=u_y * mm, fmt="o", ms=4, capsize=2, label="measured Y − X")
ax.plot(x[order] * mm, (york.slope * x[order] + york.intercept - x[order]) * mm, label="York: Y = kX + c, minus X")
ax.plot(x[order] * mm, (band_high[order] - x[order]) * mm, "--", label=f"friction model, mu = {mu:.4f}")
ax.axhline(0, color="grey", lw=0.8)
ax.set_xlabel("X = x_eq (mm)")
ax.set_ylabel("Y − X (mm)")
ax.set_title(experiment.title)
ax.legend()
fig.tight_layout()
out = sys.argv[1] if len(sys.argv) > 1 else "python-example.png"
fig.savefig(out, dpi=120)
print("wrote", out)
