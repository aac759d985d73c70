"""Shared fixtures of the Python module's tests (run by ctest: tests/CMakeLists.txt sets
PYTHONPATH to the built module, UPHILL_SOURCE_DIR and UPHILL_PROGRAM)."""
import json
import os
import pathlib
import subprocess

import pytest

SOURCE = pathlib.Path(os.environ.get("UPHILL_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
PROGRAM = os.environ.get("UPHILL_PROGRAM", "uphill")


def reference_file():
    with open(SOURCE / "tests" / "data" / "physics_reference.json") as f:
        return json.load(f)


def ref(value):
    """A reference value (a 25-digit string or a number) as the nearest double."""
    return float(value)


def tolerance(reference, cond=1.0):
    """The reference file's rule: max(1e-12, 16·cond·1.1e-16) relative, 1e-15 absolute at 0."""
    if reference == 0.0:
        return 1e-15
    return abs(reference) * max(1e-12, 16.0 * float(cond) * 1.1e-16)


def assert_ref(actual, reference_value, cond=1.0, what=""):
    r = ref(reference_value)
    assert abs(actual - r) <= tolerance(r, cond), f"{what}: {actual!r} vs reference {r!r} (cond {cond})"


def run_cli(*args):
    """Runs the uphill program, returns (status, stdout, stderr)."""
    done = subprocess.run([PROGRAM, *map(str, args)], capture_output=True, text=True, check=False)
    return done.returncode, done.stdout, done.stderr


@pytest.fixture(scope="session")
def reference():
    return reference_file()


@pytest.fixture(scope="session")
def source():
    return SOURCE
