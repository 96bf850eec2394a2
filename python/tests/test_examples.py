"""The Python examples run to their end, as a user runs them: the walkthrough notebook (a
jupytext script) in its small form, with a non-interactive matplotlib backend, writing its
figures."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]

pytest.importorskip("matplotlib")


def test_the_walkthrough_notebook_runs_and_draws(tmp_path):
    out = tmp_path / "figs"
    env = dict(os.environ, MPLBACKEND="Agg", JITTERID_EXAMPLE_SMALL="1")
    done = subprocess.run([sys.executable, str(REPO / "examples" / "python" / "walkthrough.py"), "--out", str(out)],
                          capture_output=True, text=True, cwd=tmp_path, env=env, timeout=900)
    assert done.returncode == 0, done.stderr
    for name in ["records.png", "bode.png", "step.png", "whiteness.png"]:
        # A PNG with something drawn in it: more than a blank canvas compresses to.
        assert (out / name).stat().st_size > 10_000, name
    assert "ValidationResult(" in done.stdout and "two-point" in done.stdout
