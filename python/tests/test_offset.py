"""The output offset from Python: ``simulate(offset=…)`` adds it, ``fit(estimate_offset=True)``
recovers it within its reported standard error as the parameter ``offset``, an experiment file's
``[output]`` table is read as the command line reads it, and bad values raise ``ValueError``."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import jitterid
from jitterid import System, inputs

REPO = Path(__file__).resolve().parents[2]

G = System.zpk(zeros=[-0.5], poles=[-0.25 + 0.3j, -0.25 - 0.3j], gain=0.2)
J = jitterid.jitter.from_name("uniform-sum", n=2, a=0.5 / np.sqrt(3.0))


def test_simulate_adds_the_offset_and_fit_recovers_it():
    u = inputs.random_binary(0.0, 201.0, seed=11)
    plain = jitterid.simulate(G, J, u, samples=200, interval=1.0, noise_std=0.01, seed=3)
    moved = jitterid.simulate(G, J, u, samples=200, interval=1.0, noise_std=0.01, seed=3, offset=1.5)
    # The same draws: the offset is added to every sample and changes nothing else.
    np.testing.assert_allclose(moved["y"] - plain["y"], 1.5, rtol=0, atol=1e-12)
    fit = jitterid.fit(dict(moved, input=u), G, J, "bcls", noise_std=0.01, offset=1.0, estimate_offset=True)
    assert fit.converged
    assert fit.names[-1] == "offset"
    est, se = fit.params[-1], fit.std_errors[-1]
    # The reported standard error matches the Monte Carlo spread within 15 %
    # (docs/reproduction.md): 4 standard errors leave a chance of about 6e-5.
    assert 0 < se < 0.01
    assert abs(est - 1.5) < 4 * se, (est, se)
    assert fit.model["offset"] == pytest.approx(est)
    # Without the offset in the model, no parameter is added.
    plain_fit = jitterid.fit(dict(plain, input=u), G, J, "bcls", noise_std=0.01)
    assert "offset" not in plain_fit.names


def test_the_example_experiment_estimates_the_offset():
    exp = jitterid.Experiment.from_toml(REPO / "examples" / "experiments" / "offset.toml")
    record = exp.simulate(seed=1, run=0)
    fit = exp.fit(record)
    assert fit.converged
    i = fit.names.index("offset")
    assert abs(fit.params[i] - 1.5) < 4 * fit.std_errors[i]


@pytest.mark.parametrize(
    "kwargs, words",
    [
        ({"offset": float("nan")}, ["offset", "finite"]),
        ({"offset": "1.5"}, ["offset"]),
        ({"offset": True}, ["offset"]),
        ({"estimate_offset": 1}, ["estimate_offset"]),
        ({"estimate_offset": "yes"}, ["estimate_offset"]),
        ({"offset": 1e60}, ["offset", "magnitude"]),
    ],
)
def test_bad_offsets_raise_value_error_naming_the_argument(kwargs, words):
    u = inputs.random_binary(0.0, 21.0, seed=1)
    record = jitterid.simulate(G, J, u, samples=20, interval=1.0, noise_std=0.01, seed=1)
    with pytest.raises(ValueError) as e:
        jitterid.fit(dict(record, input=u), G, J, "bcls", noise_std=0.01, **kwargs)
    for w in words:
        assert w in str(e.value), str(e.value)


def test_an_estimated_offset_needs_the_system_estimated():
    u = inputs.random_binary(0.0, 21.0, seed=1)
    record = jitterid.simulate(G, J, u, samples=20, interval=1.0, noise_std=0.01, seed=1)
    with pytest.raises(ValueError, match=r"\[output\] estimate_offset"):
        jitterid.fit(dict(record, input=u), G, J, "bcls", estimate="jitter", noise_std=0.01, estimate_offset=True)


def test_unknown_output_keys_are_refused():
    text = (REPO / "examples" / "experiments" / "offset.toml").read_text().replace(
        "estimate_offset = true", "estimate_ofset = true")
    with pytest.raises(ValueError, match="estimate_ofset"):
        jitterid.Experiment(text, "e.toml", str(REPO / "examples" / "experiments"))


def test_select_carries_the_output_offset():
    # An experiment with [output] is selected with the offset estimated in every candidate.
    text = (REPO / "examples/experiments/offset.toml").read_text() + (
        '\n[select]\npoles = [1, 2]\nzeros = [0, 1]\nfamilies = ["uniform-sum"]\n')
    exp = jitterid.Experiment(text, "offset-select.toml", str(REPO / "examples/experiments"))
    sel = jitterid.select(exp, exp.simulate(run=2))
    best = sel.best
    assert (best["poles"], best["zeros"]) == (2, 1)
    assert abs(best["estimates"]["offset"] - 1.5) < 0.05
