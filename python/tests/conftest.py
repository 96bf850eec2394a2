"""Shared fixtures: the repository's example experiments and the `jitterid` command line.

The cross-checks run the command line built from the same workspace (``JITTERID_BIN``, or
``target/debug/jitterid`` under ``CARGO_TARGET_DIR`` or the repository), so the Python numbers
are compared with an independent process on the same seeds.
"""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
EXPERIMENTS = REPO / "examples" / "experiments"


def _binary() -> Path:
    if os.environ.get("JITTERID_BIN"):
        return Path(os.environ["JITTERID_BIN"])
    target = Path(os.environ.get("CARGO_TARGET_DIR", REPO / "target"))
    return target / "debug" / "jitterid"


@pytest.fixture(scope="session")
def cli():
    """Runs the command line; returns its standard output (JSON parsed when asked)."""
    binary = _binary()
    if not binary.exists():
        pytest.fail(f"{binary}: the command line is not built (cargo build -p jitterid-cli, or set JITTERID_BIN)")

    def run(*args: str, parse_json: bool = False):
        done = subprocess.run([str(binary), *map(str, args)], capture_output=True, text=True, cwd=REPO)
        assert done.returncode == 0, f"jitterid {' '.join(map(str, args))}: {done.stderr}"
        return json.loads(done.stdout) if parse_json else done.stdout

    return run


@pytest.fixture(scope="session")
def table2_path() -> Path:
    return EXPERIMENTS / "table2.toml"


@pytest.fixture(scope="session")
def table2(table2_path):
    import jitterid

    return jitterid.Experiment.from_toml(table2_path)
