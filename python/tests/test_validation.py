"""Arguments checked as the command line checks its files: sample times on the experiment's grid,
real and finite samples, times and frequencies, and values of the wrong type refused before any
conversion, each error naming the argument (and the element) at fault."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import jitterid
from jitterid import System, inputs, jitter
from jitterid.jitter import UniformSum

G = System.zpk(zeros=[-0.5], poles=[-0.25 + 0.3j, -0.25 - 0.3j], gain=0.2)
J = UniformSum(n=2, a=0.28867513459481287)
U = inputs.random_binary(0.0, 31.0, seed=5)


@pytest.fixture(scope="module")
def record():
    """A record with its input and its sample times ``t = 2 + 0.5·k``."""
    r = jitterid.simulate(G, J, U, samples=30, interval=0.5, start=2.0, noise_std=0.01, seed=3)
    return dict(r, input=U)


def raises(error, call, *words):
    """``call()`` raises ``error`` whose message holds every one of ``words``."""
    with warnings.catch_warnings():
        # A cast with a warning (NumPy's ComplexWarning) is what these checks replace.
        warnings.simplefilter("error")
        with pytest.raises(error) as e:
            call()
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_a_record_on_its_grid_fits_with_the_grid_taken_from_t(record):
    fit = jitterid.fit(record, G, J, "bcls", noise_std=0.01)
    again = jitterid.fit(dict(record, t=None), G, J, "bcls", noise_std=0.01, interval=0.5, start=2.0)
    assert fit.converged
    np.testing.assert_array_equal(fit.params, again.params)


@pytest.mark.parametrize(
    "change, error, words",
    [
        (lambda t: np.where(np.arange(t.size) == 4, np.nan, t), ValueError, ["t", "element 4", "nan"]),
        (lambda t: np.where(np.arange(t.size) == 0, np.inf, t), ValueError, ["t", "element 0", "inf"]),
        (lambda t: t[:-1], ValueError, ["t", "(29,)", "(30,)"]),
        (lambda t: np.stack([t, t]), ValueError, ["t", "(2, 30)"]),
        # Off the grid in the middle: the end points still give interval 0.5 and start 2.
        (lambda t: t + np.where(np.arange(t.size) == 7, 0.01, 0.0), ValueError, ["t", "element 7", "5.51", "5.5"]),
        # A non-uniform grid with the right ends.
        (lambda t: 2.0 + 14.5 * (np.arange(t.size) / (t.size - 1)) ** 2, ValueError, ["t", "element 1", "grid"]),
        (lambda t: t + 0j, TypeError, ["t", "complex"]),
        (lambda t: [str(v) for v in t], TypeError, ["t", "dtype <U"]),
    ],
)
def test_fit_refuses_sample_times_off_the_grid(record, change, error, words):
    bad = dict(record, t=change(np.asarray(record["t"])))
    raises(error, lambda: jitterid.fit(bad, G, J, "bcls", noise_std=0.01), *words)


def test_fit_refuses_t_off_the_grid_it_is_given(record):
    # The grid given by `interval`/`start` (or the record's T/t0) is checked against `t` too.
    raises(ValueError, lambda: jitterid.fit(record, G, J, "bcls", noise_std=0.01, interval=0.25), "t", "element 1")
    raises(ValueError, lambda: jitterid.fit(dict(record, t0=0.0), G, J, "bcls", noise_std=0.01), "t", "element 0")


def test_experiment_fit_checks_a_records_t_like_a_data_files(table2):
    record = table2.simulate(seed=2)
    t = record["t"].copy()
    t[11] += 0.5
    raises(ValueError, lambda: table2.fit(dict(record, t=t)), "t", "element 11", "11.5", "start + k·interval")
    raises(ValueError, lambda: table2.fit(dict(record, t=record["t"][:10])), "t", "10 times", "200")
    # Within the command line's tolerance (1e-6·T) is on the grid.
    assert table2.fit(dict(record, t=record["t"] + 1e-9)).converged


@pytest.mark.parametrize(
    "y, error, words",
    [
        (lambda y: y + 1j, TypeError, ["y", "complex"]),
        (lambda y: np.where(np.arange(y.size) == 3, np.nan, y), ValueError, ["y", "element 3", "NaN"]),
        (lambda y: np.where(np.arange(y.size) == 5, -np.inf, y), ValueError, ["y", "element 5", "inf"]),
        (lambda y: None, TypeError, ["y", "None"]),
        (lambda y: y.reshape(5, 6), ValueError, ["y", "one-dimensional"]),
        (lambda y: [[1.0], [1.0, 2.0]], ValueError, ["y", "not an array of real numbers"]),
    ],
)
def test_fit_refuses_samples_that_are_not_real_and_finite(record, y, error, words):
    bad = dict(record, y=y(np.asarray(record["y"])))
    raises(error, lambda: jitterid.fit(bad, G, J, "bcls", noise_std=0.01), *words)


def test_experiment_fit_refuses_complex_samples(table2):
    record = table2.simulate(seed=2)
    raises(TypeError, lambda: table2.fit(dict(record, y=record["y"] * (1 + 0j))), "y", "complex")
    raises(TypeError, lambda: table2.fit(dict(record, input_t=list(record["input_t"][:-1]) + [1j])),
           "input_t", "complex")


@pytest.mark.parametrize(
    "call, error, words",
    [
        (lambda: J.cf(None), TypeError, ["f", "None"]),
        (lambda: J.pdf(None), TypeError, ["t", "None"]),
        (lambda: J.cf("0.5"), TypeError, ["f", "str"]),
        (lambda: J.cf({"f": 1.0}), TypeError, ["f", "dict"]),
        (lambda: J.cf([0.1, None]), TypeError, ["f", "object"]),
        (lambda: J.cf([[0.1], [0.1, 0.2]]), ValueError, ["f", "not an array of real numbers"]),
        (lambda: J.cf(1 + 2j), TypeError, ["f", "complex"]),
        (lambda: J.pdf(np.array([0.0, 1j])), TypeError, ["t", "complex"]),
        (lambda: J.cf([0.1, np.nan]), ValueError, ["f", "element 1", "NaN"]),
        (lambda: J.pdf(np.where(np.arange(6).reshape(2, 3) == 5, np.inf, 0.1)), ValueError,
         ["t", "element (1, 2)", "inf"]),
        (lambda: J.cf(float("nan")), ValueError, ["f", "the value", "NaN"]),
        (lambda: J.mgf(None), TypeError, ["z", "None"]),
        (lambda: J.mgf([complex(np.nan, 1.0)]), ValueError, ["z", "element 0"]),
        (lambda: G.step([np.nan]), ValueError, ["t", "element 0", "NaN"]),
        (lambda: G.step([0.0, 1.0, np.inf]), ValueError, ["t", "element 2", "inf"]),
        (lambda: G.step([1j]), TypeError, ["t", "complex"]),
        (lambda: G.step(None), TypeError, ["t", "None"]),
        (lambda: G.frequency_response([0.1, np.nan]), ValueError, ["f", "element 1", "NaN"]),
        (lambda: G.frequency_response(0.1j), TypeError, ["f", "complex"]),
        (lambda: U.value([np.nan]), ValueError, ["t", "element 0", "NaN"]),
        (lambda: U.value([[0.0, -np.inf]]), ValueError, ["t", "element (0, 1)", "inf"]),
        (lambda: U.value("1.0"), TypeError, ["t", "str"]),
    ],
)
def test_times_and_frequencies_are_real_and_finite(call, error, words):
    raises(error, call, *words)


@pytest.mark.parametrize(
    "call, error, words",
    [
        (lambda: System.zpk(None, [-1.0], 1.0), TypeError, ["zeros", "None"]),
        (lambda: System.zpk([], [np.nan], 1.0), ValueError, ["poles", "element 0"]),
        (lambda: System.zpk([], [-1.0], None), TypeError, ["gain", "NoneType"]),
        (lambda: System.zpk([], [-1.0], 1j), TypeError, ["gain", "complex"]),
        (lambda: System.tf([1.0, np.nan], [1.0, 2.0]), ValueError, ["num", "[1]", "finite"]),
        (lambda: System.tf([1.0j], [1.0, 2.0]), TypeError, ["num", "complex"]),
        (lambda: inputs.piecewise([0.0, 1.0], [1j]), TypeError, ["levels", "complex"]),
        (lambda: inputs.piecewise([0.0, 1.0], 1.0), ValueError, ["levels", "one-dimensional"]),
        (lambda: inputs.multisine([0.1], phases=[None]), TypeError, ["phases", "object"]),
        (lambda: inputs.zero_order_hold([1.0], interval="1"), TypeError, ["interval", "str"]),
        (lambda: inputs.random_binary(0.0, 10.0, seed=1.5), TypeError, ["seed", "float"]),
        (lambda: jitterid.simulate(G, J, U, samples=2.5, interval=1.0), TypeError, ["samples", "float"]),
        (lambda: jitterid.simulate(G, J, U, samples=5, interval=None), TypeError, ["interval", "NoneType"]),
        (lambda: jitterid.simulate("G", J, U, samples=5, interval=1.0), TypeError, ["system", "str"]),
        (lambda: jitterid.first_moment(G, None, U, samples=5, interval=1.0), TypeError, ["jitter", "NoneType"]),
        (lambda: jitterid.second_moment(G, J, [0.0], samples=5, interval=1.0), TypeError, ["input", "list"]),
        (lambda: jitterid.fit({"y": [1.0, 2.0], "T": 1.0}, G, "J"), TypeError, ["jitter", "str"]),
        (lambda: jitterid.fit({"y": [1.0, 2.0], "T": 1.0}, G, J, estimate=3), TypeError, ["estimate", "int"]),
        (lambda: jitter.from_std("gaussian", "0.1"), TypeError, ["sigma", "str"]),
        (lambda: jitter.from_name("sum", terms=[{"family": "gaussian", "sigma": np.inf}]), ValueError,
         ["terms", "[0]", "sigma", "finite"]),
    ],
)
def test_arguments_of_the_wrong_type_are_refused_by_name(call, error, words):
    raises(error, call, *words)
