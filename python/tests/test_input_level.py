"""The input's level from Python: ``simulate(level=…)`` drives the system by ``u − u₀`` (the
same samples as the deviation given as the input), ``fit(level=…, estimate_level=True)``
recovers it within its reported standard error as the parameter ``level``, an experiment file's
``[input] level`` is read as the command line reads it, and the confounded or malformed cases
raise ``ValueError`` naming the key."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import jitterid
from jitterid import System, inputs

REPO = Path(__file__).resolve().parents[2]

# The tank of examples/experiments/input-level.toml: 1/(s(s + 1)) with a structural integrator.
TANK = jitterid.system.from_name("tf", num=[1.0], den=[1.0, 1.0, 0.0], integrators=1)
STABLE = System.zpk(zeros=[-0.5], poles=[-0.25 + 0.3j, -0.25 - 0.3j], gain=0.2)
J = jitterid.jitter.from_name("uniform-sum", n=2, a=0.25)


def test_simulate_drives_the_system_by_the_deviation():
    u = inputs.random_binary(0.0, 201.0, seed=11, mean_dwell=3.0)
    moved = jitterid.simulate(TANK, J, u, samples=400, interval=0.5, noise_std=0.05, seed=3, level=0.4)
    deviation = inputs.piecewise(u.edges, u.levels - 0.4)
    by_hand = jitterid.simulate(TANK, J, deviation, samples=400, interval=0.5, noise_std=0.05, seed=3)
    # The same system driven by the same input, the same draws: the same samples.
    np.testing.assert_allclose(moved["y"], by_hand["y"], rtol=0, atol=1e-12)


def test_fit_recovers_the_level_beside_the_offset():
    u = inputs.random_binary(0.0, 201.0, seed=5, mean_dwell=3.0)
    record = jitterid.simulate(TANK, J, u, samples=400, interval=0.5, noise_std=0.05, seed=7, level=0.4,
                               offset=1.5)
    fit = jitterid.fit(dict(record, input=u), TANK, J, "bcls", noise_std=0.05, level=0.3, estimate_level=True,
                       offset=1.0, estimate_offset=True)
    assert fit.converged
    assert fit.names == ["b0", "a1", "level", "offset"]
    for name, truth in [("level", 0.4), ("offset", 1.5), ("b0", 1.0), ("a1", 1.0)]:
        i = fit.names.index(name)
        # Standard errors within 15 % of the Monte Carlo spread (docs/reproduction.md): 4 of
        # them leave a chance of about 6e-5.
        assert abs(fit.params[i] - truth) < 4 * fit.std_errors[i], (name, fit.params[i], fit.std_errors[i])
    assert fit.model["level"] == pytest.approx(fit.params[2])


def test_the_example_experiment_estimates_the_level():
    exp = jitterid.Experiment.from_toml(REPO / "examples" / "experiments" / "input-level.toml")
    fit = exp.fit(exp.simulate(run=1))
    assert fit.converged
    i = fit.names.index("level")
    assert abs(fit.params[i] - 0.5) < 4 * fit.std_errors[i]


@pytest.mark.parametrize(
    "kwargs, words",
    [
        ({"level": float("nan")}, ["level", "finite"]),
        ({"level": "0.4"}, ["level"]),
        ({"level": True}, ["level"]),
        ({"estimate_level": 1}, ["estimate_level"]),
        ({"level": 1e60}, ["level", "magnitude"]),
        # Through a system that settles, a level and an offset are both constants in y.
        ({"level": 0.1, "estimate_level": True, "offset": 0.0, "estimate_offset": True},
         ["[input] estimate_level", "confounded"]),
    ],
)
def test_bad_levels_raise_value_error_naming_the_key(kwargs, words):
    u = inputs.random_binary(0.0, 21.0, seed=1)
    record = jitterid.simulate(STABLE, J, u, samples=20, interval=1.0, noise_std=0.01, seed=1)
    with pytest.raises(ValueError) as e:
        jitterid.fit(dict(record, input=u), STABLE, J, "bcls", noise_std=0.01, **kwargs)
    for w in words:
        assert w in str(e.value), str(e.value)


def test_a_level_of_several_inputs_is_refused_here():
    g = System.several({"a": STABLE, "b": STABLE})
    u = {"a": inputs.random_binary(0.0, 21.0, seed=1), "b": inputs.random_binary(0.0, 21.0, seed=2)}
    with pytest.raises(ValueError, match=r"\[\[input\]\] level"):
        jitterid.simulate(g, J, inputs=u, samples=20, interval=1.0, level=0.2)
