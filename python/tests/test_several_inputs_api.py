"""Several inputs through the keyword-argument functions: ``simulate``, ``fit``,
``first_moment`` and ``second_moment`` with ``inputs=[…]`` (or a dict by input name) and a
``System`` per input (``System.several``) or one grey-box model with a column of ``b`` per
input.

Each result is checked against an independent route to the same number: the fit against the
experiment file's own fit of the same record, the first moment against the sum of the
inputs' first moments (the expectation is linear), a shared grey-box model against the
separate systems of its columns, and the second moment of a jitter-free record against the
noise alone."""

from __future__ import annotations

import pickle
from pathlib import Path

import numpy as np
import pytest

import jitterid
from jitterid import System, inputs, jitter

REPO = Path(__file__).resolve().parents[2]

# examples/experiments/two-input.toml's systems and jitter, written as keyword arguments.
TORQUE = System.tf([0.5], [1.0, 0.5])
BRAKE = System.zpk(zeros=[-0.5], poles=[-0.25 + 0.3j, -0.25 - 0.3j], gain=0.2)
JITTER = jitter.from_name("uniform-sum", n=2, a=0.28867513459481287)


def mass_spring(b, d=None, names=None) -> System:
    return System.grey_box(params={"m": 1.0, "damp": 0.4, "k": 2.0}, a=[["0", "1"], ["-k/m", "-damp/m"]], b=b,
                           c=[[1, 0]], d=d, inputs=names)


def two_inputs(end: float):
    return (inputs.random_binary(0.0, end, seed=11, mean_dwell=6.0),
            inputs.random_binary(0.0, end, seed=12, mean_dwell=10.0, low=-1.0, high=1.0))


def test_the_function_fit_equals_the_experiment_file_s_fit_of_the_same_record():
    exp = jitterid.Experiment.from_toml(str(REPO / "examples/experiments/two-input.toml"))
    rec = exp.simulate(run=5)
    by_file = exp.fit(rec)
    # The record's realisations (input_t, input_u by name) are the inputs, as for one input.
    by_args = jitterid.fit(rec, {"torque": TORQUE, "brake": BRAKE}, JITTER, "bcls", noise_std=0.01,
                           options={"frequencies": "dft", "solver": "lm"})
    assert by_args.names == by_file.names
    np.testing.assert_allclose(by_args.params, by_file.params, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(by_args.std_errors, by_file.std_errors, rtol=1e-9)


def test_a_record_simulated_from_the_functions_is_fitted_within_four_standard_errors():
    u1, u2 = two_inputs(420.0)
    systems = {"torque": TORQUE, "brake": BRAKE}
    rec = jitterid.simulate(systems, JITTER, inputs={"brake": u2, "torque": u1}, samples=400, interval=1.0,
                            noise_std=0.01, seed=3)
    assert sorted(rec["u"]) == ["brake", "torque"]
    np.testing.assert_array_equal(rec["u"]["brake"], [u2.value(t) for t in rec["t"]])
    fit = jitterid.fit(rec, systems, JITTER, "bcls", inputs=[u1, u2], noise_std=0.01)
    assert fit.converged
    truth = dict(zip(System.several(systems).names, System.several(systems).param_values))
    assert list(fit.names) == list(truth)
    for name, est, se in zip(fit.names, fit.params, fit.std_errors):
        assert 0 < se and abs(est - truth[name]) < 4 * se, (name, est, se)
    assert fit.system.inputs == ["torque", "brake"]
    assert [c.kind for c in fit.system.channels] == ["tf", "zpk"]


def test_the_first_moment_of_a_sum_is_the_sum_of_the_first_moments():
    u1, u2 = two_inputs(60.0)
    grid = dict(samples=50, interval=1.0, start=0.5)
    both = jitterid.first_moment([TORQUE, BRAKE], JITTER, inputs=[u1, u2], **grid)
    one = jitterid.first_moment(TORQUE, JITTER, u1, **grid)
    other = jitterid.first_moment(BRAKE, JITTER, u2, **grid)
    np.testing.assert_allclose(both, one + other, rtol=1e-12, atol=1e-14)


def test_a_shared_grey_box_model_equals_the_separate_systems_of_its_columns():
    u1, u2 = two_inputs(40.0)
    shared = mass_spring([[0, 0], ["1/m", "0.5/m"]], names=["force", "wind"])
    assert shared.inputs == ["force", "wind"]
    assert shared.names == ["damp", "k", "m"]
    separate = System.several({"force": mass_spring([[0], ["1/m"]]), "wind": mass_spring([[0], ["0.5/m"]])})
    grid = dict(samples=60, interval=0.5, noise_std=0.01)
    a = jitterid.second_moment(shared, JITTER, inputs=[u1, u2], **grid)
    b = jitterid.second_moment(separate, JITTER, inputs=[u1, u2], **grid)
    np.testing.assert_allclose(a, b, rtol=1e-10)
    # The jitter adds variance after the switches, and the cross terms are part of it.
    assert a.max() > 2 * 0.01**2


def test_without_jitter_the_second_moment_of_several_inputs_is_the_noise():
    u1, u2 = two_inputs(40.0)
    none = jitter.from_name("none")
    lam = jitterid.second_moment([TORQUE, BRAKE], none, inputs=[u1, u2], samples=30, interval=1.0,
                                 noise_std=0.02)
    np.testing.assert_allclose(lam, 0.02**2, rtol=1e-12)


def test_a_shared_grey_box_model_is_fitted_in_its_physical_parameters():
    u1, u2 = two_inputs(160.0)
    model = mass_spring([[0, 0], ["1/m", "0.5/m"]], names=["force", "wind"])
    rec = jitterid.simulate(model, JITTER, inputs=[u1, u2], samples=300, interval=0.5, noise_std=0.01, seed=4)
    fit = jitterid.fit(rec, model, JITTER, "bcls", inputs={"wind": u2, "force": u1}, noise_std=0.01)
    assert fit.converged and list(fit.names) == ["damp", "k", "m"]
    for est, truth, se in zip(fit.params, [0.4, 2.0, 1.0], fit.std_errors):
        assert abs(est - truth) < 4 * se, (est, truth, se)
    assert np.shape(fit.model["ss"]["b"]) == (2, 2)


def test_a_system_with_several_inputs_pickles_and_has_no_single_transfer_function():
    several = System.several([TORQUE, BRAKE])
    assert several.inputs == ["u1", "u2"]
    assert pickle.loads(pickle.dumps(several)) == several
    with pytest.raises(ValueError, match="one transfer function per input"):
        several.frequency_response([0.1])
    assert TORQUE.inputs is None and TORQUE.channels is None


@pytest.mark.parametrize("call, message", [
    (lambda u: jitterid.simulate([TORQUE, BRAKE], JITTER, inputs=[u], samples=10, interval=1.0),
     "the system has 2 inputs"),
    (lambda u: jitterid.simulate({"torque": TORQUE, "brake": BRAKE}, JITTER, inputs={"torque": u, "gas": u},
                                 samples=10, interval=1.0), "found inputs named"),
    (lambda u: jitterid.simulate([TORQUE, BRAKE], JITTER, u, samples=10, interval=1.0), "several inputs"),
    (lambda u: jitterid.simulate(TORQUE, JITTER, u, inputs=[u], samples=10, interval=1.0), "not both"),
    (lambda u: jitterid.simulate(TORQUE, JITTER, inputs=[u, u], samples=10, interval=1.0), "has one input"),
    (lambda u: mass_spring([[0, 0], ["1/m", "1"]], names=["a"]), "2 columns"),
    (lambda u: mass_spring([[0, 0], ["1/m", "1"]], d=[[0]]), "one row of 2 entries"),
    (lambda u: mass_spring([[0, 0], ["1/m", "1/q"]]), "q"),
    (lambda u: System.several([TORQUE]), "at least two inputs"),
    (lambda u: System.several([TORQUE, System.several([TORQUE, BRAKE])]), "already a system with several"),
])
def test_bad_several_input_arguments_raise_value_error_naming_them(call, message):
    u = inputs.piecewise([0.0, 5.0, 10.0], [1.0, 0.0])
    with pytest.raises(ValueError, match=message):
        call(u)


def test_an_input_of_the_wrong_type_raises_type_error_naming_it():
    with pytest.raises(TypeError, match=r"inputs\['u2'\]: expected an Input"):
        jitterid.simulate([TORQUE, BRAKE], JITTER, inputs=[inputs.sine(0.1), 3.0], samples=10, interval=1.0)
    with pytest.raises(TypeError, match="systems"):
        System.several([TORQUE, "brake"])
