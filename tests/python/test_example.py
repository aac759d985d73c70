"""docs/python-example.py runs as documented and draws its figure; the batch kernel's X of every
setting agrees with the analysis's (the scalar model) within a few ulp, as the script prints."""
import os
import re
import subprocess
import sys

from conftest import SOURCE


def test_example_runs_and_draws(tmp_path):
    png = tmp_path / "example.png"
    done = subprocess.run([sys.executable, str(SOURCE / "docs" / "python-example.py"), str(png)],
                          capture_output=True, text=True, env=dict(os.environ, MPLBACKEND="Agg"), cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    assert png.stat().st_size > 10000 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    agreement = float(re.search(r"agrees with the analysis to (\S+)", done.stdout).group(1))
    assert agreement <= 2.7e-15
    for method in ("ols", "wls", "york", "robust", "friction"):
        assert re.search(rf"^{method}\s", done.stdout, re.M), method
