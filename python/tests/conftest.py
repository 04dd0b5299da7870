"""Shared helpers of the Python package's tests. Each test module skips, with one line naming
what is missing, when the package or its NetCDF backend is not installed: `cargo test` needs
neither, and `.ci/run` builds the wheel and runs these."""

import os
import pathlib
import shutil
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[2]

# Coarse enough for seconds per run, fine enough for every product to have pixels.
DECIMATION = 8


def cli():
    """The `shoal` binary of this checkout ($SHOAL_BIN, else target/release, else target/debug)."""
    candidates = [os.environ.get("SHOAL_BIN"), REPO / "target/release/shoal", REPO / "target/debug/shoal"]
    for c in candidates:
        if c and pathlib.Path(c).is_file():
            return str(c)
    pytest.skip("no shoal binary: build it (cargo build --release) or set SHOAL_BIN")


def run_cli(*args, cwd=None):
    """Run the binary; its standard error in the failure message."""
    done = subprocess.run([cli(), *args], capture_output=True, text=True, cwd=cwd)
    assert done.returncode == 0, done.stderr
    return done


def has_program_python():
    """The external-program path runs `python3` from PATH: it needs xarray and a NetCDF backend."""
    python = shutil.which("python3")
    if python is None:
        return False
    probe = subprocess.run([python, "-c", "import xarray, netCDF4"], capture_output=True)
    return probe.returncode == 0
