"""The README's example runs and prints its tables."""

import subprocess
import sys

import pytest

pytest.importorskip("xarray", reason="xarray is not installed")
pytest.importorskip("shoal", reason="the shoal package is not installed: pip install ./python")

from conftest import REPO  # noqa: E402


def test_the_example_runs():
    done = subprocess.run([sys.executable, str(REPO / "python" / "examples" / "sweep_and_oc4.py"), "16"],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    out = done.stdout
    assert "chl-a over the Lake Hume bloom" in out and "oc4" in out and "aLMI" in out
    assert out.count("\n") > 12, out
