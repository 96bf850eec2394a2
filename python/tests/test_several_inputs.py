"""Several inputs from Python: an experiment file with ``[[input]]`` and ``[[system]]`` tables is
simulated with one array per input (dicts by input name), fitted with every parameter named by
its input and within 4 reported standard errors of the truth, and validated; a record without
one input's levels raises ``ValueError`` naming it."""

from __future__ import annotations

from pathlib import Path

import pytest

import jitterid

REPO = Path(__file__).resolve().parents[2]
TRUTH = {"torque.b0": 0.5, "torque.a0": 0.5, "brake.gain": 0.2, "brake.zero0": -0.5,
         "brake.pole0.re": -0.25, "brake.pole0.im": 0.3}


def experiment() -> jitterid.Experiment:
    return jitterid.Experiment.from_toml(str(REPO / "examples/experiments/two-input.toml"))


def test_a_two_input_record_round_trips_through_python():
    exp = experiment()
    assert exp.random_input
    rec = exp.simulate(run=3)
    assert sorted(rec["u"]) == ["brake", "torque"]
    assert sorted(rec["input_u"]) == ["brake", "torque"]
    assert len(rec["input_t"]) == len(rec["input_u"]["torque"]) == len(rec["input_u"]["brake"])
    fit = exp.fit(rec)
    assert fit.converged
    assert list(fit.names) == list(TRUTH)
    for name, est, se in zip(fit.names, fit.params, fit.std_errors):
        # Reported standard errors match the Monte Carlo spread within 15 % (docs/reproduction.md).
        assert 0 < se and abs(est - TRUTH[name]) < 4 * se, (name, est, se)
    assert [i["name"] for i in fit.model["inputs"]] == ["torque", "brake"]
    validated = jitterid.validate(exp, rec, fit=fit)
    assert validated is not None


def test_a_record_without_one_input_s_levels_is_refused():
    exp = experiment()
    rec = exp.simulate(run=3)
    rec["input_u"] = {"torque": rec["input_u"]["torque"]}
    with pytest.raises(ValueError, match='no levels for the input "brake"'):
        exp.fit(rec)


def test_select_ranks_each_input_s_order_from_python():
    # The command line's multi-input selection through jitterid.select, whose temporary side
    # file holds one column per input.
    text = (REPO / "examples/experiments/two-input.toml").read_text() + (
        '\n[select]\nfamilies = ["gaussian"]\norders = { torque = [[1, 0], [2, 0]], brake = [[1, 0], [2, 1]] }\n')
    exp = jitterid.Experiment(text, "two-input-select.toml", str(REPO / "examples/experiments"))
    sel = jitterid.select(exp, exp.simulate(run=3))
    assert len(sel.candidates) == 4
    assert sel.best["orders"] == {"torque": [1, 0], "brake": [2, 1]}


def test_init_auto_reaches_the_fit_from_the_truth():
    exp = experiment()
    rec = exp.simulate(run=5)
    truth = exp.fit(rec)
    auto = exp.fit(rec, init="auto")
    assert auto.converged
    for a, t, se in zip(auto.params, truth.params, truth.std_errors):
        assert abs(a - t) < 0.01 * se
