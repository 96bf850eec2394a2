"""The random binary input's levels as design variables from Python: ``jitterid.design``'s
dict carries the designed and the file's levels (as ``jitterid design --json`` does), the
written input takes the designed levels, and a bad ``[design] low``/``high`` range raises
``ValueError`` naming the key."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest

import jitterid

REPO = Path(__file__).resolve().parents[2]
# A cheap search over both levels: two input draws per design, three grid points each.
LEVELS = "\n[design]\nlow = [-1.0, 0.0]\nhigh = [0.5, 1.5]\ndraws = 2\ngrid = 3\n"


def table2_with(tmp_path: Path, design: str) -> Path:
    path = tmp_path / "t2.toml"
    text = (REPO / "examples/experiments/table2.toml").read_text().replace("samples = 200", "samples = 100")
    path.write_text(text + design)
    return path


def test_the_designed_levels_are_in_the_dict_and_the_written_input(tmp_path):
    path = table2_with(tmp_path, LEVELS)
    exp = jitterid.Experiment.from_toml(str(path))
    target = tmp_path / "designed.csv"
    result = jitterid.design(exp, write_input=target)
    low, high = result.design["low"], result.design["high"]
    assert -1.0 <= low <= 0.0 and 0.5 <= high <= 1.5
    assert (result.baseline["low"], result.baseline["high"]) == (0.0, 1.0)
    assert "low=" in repr(result) and "high=" in repr(result)
    # The written input's levels are the designed ones (and the 0 of the last row that ends it).
    rows = target.read_text().splitlines()
    assert rows[0] == "t,u"
    values = {float(r.split(",")[1]) for r in rows[1:-1]}
    assert values == {low, high}, values
    assert "between the designed levels" in (tmp_path / "designed.toml").read_text()
    binary = os.environ.get("JITTERID_BIN")
    if binary is None:
        pytest.skip("JITTERID_BIN is not set (the command line to compare with)")
    out = subprocess.run([binary, "design", str(path), "--json"], capture_output=True, text=True, check=True)
    assert result.to_dict() == json.loads(out.stdout)


def test_a_design_without_free_levels_has_none_in_its_dict(tmp_path):
    exp = jitterid.Experiment.from_toml(str(table2_with(tmp_path, "\n[design]\nmean_dwell = [4.0, 16.0]\n"
                                                                   "draws = 1\ngrid = 3\n")))
    result = jitterid.design(exp)
    assert "low" not in result.design and "high" not in result.design
    assert "low" not in result.baseline


@pytest.mark.parametrize("design, words", [
    ("\n[design]\nlow = [1.0, -1.0]\n", r"\[design\] low: expected \[min, max\]"),
    ("\n[design]\nhigh = [nan, 1.0]\n", r"\[design\] high: expected \[min, max\]"),
    ("\n[design]\nlow = [0.5, 0.5]\nhigh = [0.5, 0.5]\ndraws = 1\ngrid = 3\n", r"\[design\] low, high: no feasible"),
])
def test_bad_level_ranges_raise_value_error(tmp_path, design, words):
    with pytest.raises(ValueError, match=words):
        jitterid.design(jitterid.Experiment.from_toml(str(table2_with(tmp_path, design))))
