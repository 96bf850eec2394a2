"""Experiment design from Python: ``jitterid.design`` gives the numbers of ``jitterid design
--json`` for the same file and options, writes the designed input and the experiment that reads
it (which simulates and fits), and refuses bad criteria and budgets with ``ValueError``."""

from __future__ import annotations

import json
import os
import subprocess
from pathlib import Path

import pytest

import jitterid

REPO = Path(__file__).resolve().parents[2]
# A cheap search: two input draws per design, three grid points.
CHEAP = "\n[design]\nmean_dwell = [1.0, 40.0]\ndraws = 2\ngrid = 3\n"


def table2_with_design(tmp_path: Path) -> Path:
    path = tmp_path / "t2.toml"
    path.write_text((REPO / "examples/experiments/table2.toml").read_text() + CHEAP)
    return path


def test_design_equals_the_command_line_s(tmp_path):
    path = table2_with_design(tmp_path)
    exp = jitterid.Experiment.from_toml(str(path))
    result = jitterid.design(exp, "param:gain", budget="samples=300", jitter_blind=True)
    assert result.criterion == "param:gain"
    assert result.design["samples"] == 300
    assert set(result.predicted) == {"gain", "zero0", "pole0.re", "pole0.im"}
    assert result.jitter_blind is not None
    binary = os.environ.get("JITTERID_BIN")
    if binary is None:
        pytest.skip("JITTERID_BIN is not set (the command line to compare with)")
    out = subprocess.run([binary, "design", str(path), "--criterion", "param:gain", "--budget", "samples=300",
                          "--jitter-blind", "--json"], capture_output=True, text=True, check=True)
    assert result.to_dict() == json.loads(out.stdout)


def test_derived_quantities_are_chosen_as_on_the_command_line(tmp_path):
    path = table2_with_design(tmp_path)
    exp = jitterid.Experiment.from_toml(str(path))
    result = jitterid.design(exp, derived=["pole_frequency", "gain@0.05"])
    assert list(result.derived) == ["pole1.frequency", "|G|@0.05Hz"]
    assert all(v > 0 for v in result.derived.values())
    with pytest.raises(TypeError, match="derived"):
        jitterid.design(exp, derived="static_gain")
    binary = os.environ.get("JITTERID_BIN")
    if binary is None:
        pytest.skip("JITTERID_BIN is not set (the command line to compare with)")
    out = subprocess.run([binary, "design", str(path), "--derived", "pole_frequency,gain@0.05", "--json"],
                         capture_output=True, text=True, check=True)
    assert result.to_dict() == json.loads(out.stdout)


def test_the_designed_input_is_written_and_runs(tmp_path):
    exp = jitterid.Experiment.from_toml(str(table2_with_design(tmp_path)))
    target = tmp_path / "designed.csv"
    result = jitterid.design(exp, write_input=target)
    designed = jitterid.Experiment.from_toml(str(tmp_path / "designed.toml"))
    assert designed.samples == result.design["samples"]
    fit = designed.fit(designed.simulate(seed=3))
    assert fit.converged
    assert target.read_text().startswith("t,u")


@pytest.mark.parametrize("kwargs, words", [
    ({"criterion": "e"}, "criterion"),
    ({"budget": "samples=0"}, "a budget that cannot be met"),
    ({"budget": "time=5"}, "expected duration="),
    ({"write_input": "designed.txt"}, "ending in .csv"),
    ({"derived": ["bogus"]}, "unknown derived quantity"),
    ({"derived": ["pole2.frequency"]}, r"\[design\] derived"),
])
def test_bad_design_arguments_raise_value_error(tmp_path, kwargs, words):
    exp = jitterid.Experiment.from_toml(str(table2_with_design(tmp_path)))
    with pytest.raises(ValueError, match=words):
        jitterid.design(exp, **kwargs)


def test_an_experiment_without_a_design_section_is_refused():
    exp = jitterid.Experiment.from_toml(str(REPO / "examples/experiments/table2.toml"))
    with pytest.raises(ValueError, match=r"no \[design\] section"):
        jitterid.design(exp)


def multisine_with(tmp_path: Path, extra: str = "") -> Path:
    """``design-multisine.toml`` with four tones (a cheap search), then ``extra`` keys."""
    path = tmp_path / "ms.toml"
    text = (REPO / "examples/experiments/design-multisine.toml").read_text()
    path.write_text(text.replace("tones = 8 ", "tones = 4 ") + extra)
    return path


def test_a_multisine_design_reports_its_tones_and_writes_its_samples(tmp_path):
    exp = jitterid.Experiment.from_toml(str(multisine_with(tmp_path)))
    target = tmp_path / "designed.csv"
    result = jitterid.design(exp, write_input=target, dac_rate=2.0)
    m = result.multisine
    assert m is not None and result.design["multisine"] == m
    assert set(m) == {"frequencies", "amplitudes", "phases", "crest_factor", "power"}
    # At most the four candidates: tones the design gives no power are left out.
    n = len(m["frequencies"])
    assert 1 <= n <= 4 and all(a > 0 for a in m["amplitudes"])
    # The power constraint: the file's own, exactly.
    assert result.baseline_multisine is not None
    assert abs(sum(a * a / 2 for a in m["amplitudes"]) - result.baseline_multisine["power"]) < 1e-12
    assert f"multisine of {n} tones" in repr(result)
    # The written experiment is the designed multisine; the CSV its samples at 2 Hz over 200 s.
    designed = jitterid.Experiment.from_toml(str(tmp_path / "designed.toml"))
    assert designed.samples == 200
    rows = target.read_text().splitlines()
    assert rows[0] == "t,u" and len(rows) == 1 + 400
    fit = designed.fit(designed.simulate(seed=3))
    assert fit.converged
    binary = os.environ.get("JITTERID_BIN")
    if binary is None:
        pytest.skip("JITTERID_BIN is not set (the command line to compare with)")
    out = subprocess.run([binary, "design", str(tmp_path / "ms.toml"), "--json"], capture_output=True, text=True,
                         check=True)
    assert result.to_dict() == json.loads(out.stdout)


@pytest.mark.parametrize("extra, kwargs, words", [
    ("power = -1.0\n", {}, r"\[design\] power"),
    ("power = 1.0\npeak = 0.5\n", {}, "cannot hold the power"),
    ("", {"write_input": "x.csv", "dac_rate": 0.5}, "dac_rate"),
    ('phases = "random"\n', {}, r"\[design\] phases"),
])
def test_bad_multisine_keys_raise_value_error(tmp_path, extra, kwargs, words):
    path = multisine_with(tmp_path, extra)
    exp_text = path.read_text().replace("dac_rate = 20.0 ", "")
    path.write_text(exp_text)
    if "write_input" in kwargs:
        kwargs = dict(kwargs, write_input=tmp_path / kwargs["write_input"])
    with pytest.raises(ValueError, match=words):
        jitterid.design(jitterid.Experiment.from_toml(str(path)), **kwargs)


def test_a_jitter_that_follows_the_interval_is_reported_at_each_design(tmp_path):
    """``[design] jitter_exponent = 1``: the jitter's σ at the designed interval is the file's
    times ``T / T0`` (``T0 = 1 s``), as the command line's JSON says; a bad exponent raises
    ``ValueError`` naming the key."""
    text = (REPO / "examples/experiments/table2.toml").read_text()
    section = '\n[design]\ninterval = [0.25, 4.0]\nhold = "samples"\ndraws = 4\ngrid = 5\n'
    path = tmp_path / "t.toml"
    path.write_text(text + section + "jitter_exponent = 1.0\n")
    result = jitterid.design(jitterid.Experiment.from_toml(str(path)))
    d = result.to_dict()
    assert result.jitter_std == d["jitter_std"] and result.baseline_jitter_std == d["baseline"]["jitter_std"]
    assert abs(result.jitter_std / result.baseline_jitter_std - result.design["interval"]) < 1e-12
    path.write_text(text + section)
    assert jitterid.design(jitterid.Experiment.from_toml(str(path))).jitter_std is None
    path.write_text(text + section + "jitter_exponent = 3.0\n")
    with pytest.raises(ValueError, match=r"\[design\] jitter_exponent"):
        jitterid.design(jitterid.Experiment.from_toml(str(path)))
