"""Grey-box state-space systems from Python: matrices as expressions of named physical
parameters or a callable returning NumPy matrices, their transfer function and realisation,
bad expressions and untraceable callables as ``ValueError``, and a fit in physical
parameters."""

from __future__ import annotations

import numpy as np
import pytest

import jitterid
from jitterid import System

MSD = dict(
    params={"m": 1.0, "damp": 0.4, "k": 2.0},
    a=[["0", "1"], ["-k/m", "-damp/m"]],
    b=[[0], ["1/m"]],
    c=[[1, 0]],
    bounds={"m": [0.0, 1e3]},
)


def test_names_transfer_function_and_realisation():
    g = System.grey_box(**MSD)
    assert g.names == ["damp", "k", "m"]
    num, den = g.tf_coefficients()
    # 1/(m s² + damp s + k) with m = 1, damp = 0.4, k = 2.
    np.testing.assert_allclose(den, [1.0, 0.4, 2.0], rtol=1e-14)
    np.testing.assert_allclose(num[-1], 1.0, rtol=1e-14)
    a, b, c, d = g.to_ss()
    np.testing.assert_array_equal(a, [[0.0, 1.0], [-2.0, -0.4]])
    np.testing.assert_array_equal(b, [[0.0], [1.0]])
    np.testing.assert_array_equal(c, [[1.0, 0.0]])
    np.testing.assert_array_equal(d, [[0.0]])
    np.testing.assert_allclose(
        g.frequency_response([0.1]), System.tf([1.0], [1.0, 0.4, 2.0]).frequency_response([0.1]),
        rtol=1e-12)


@pytest.mark.parametrize("change, words", [
    ({"a": [["0", "1"], ["-k/mass", "-damp/m"]]}, ["`a`", "unknown name \"mass\""]),
    ({"a": [["0", "1"], ["-k/(m", "-damp/m"]]}, ["`a`", "cannot parse \"-k/(m\""]),
    ({"b": [["1/m"]]}, ["`b`", "expected 2 row(s)"]),
    ({"params": {"m": -1.0, "damp": 0.4, "k": 2.0}}, ["`params`", "outside its bounds"]),
])
def test_bad_models_raise_value_error(change, words):
    with pytest.raises(ValueError) as e:
        System.grey_box(**dict(MSD, **change))
    for w in words:
        assert w in str(e.value)


def test_fit_in_physical_parameters():
    g = System.grey_box(**MSD)
    jit = jitterid.jitter.from_name("uniform-sum", n=2, a=0.25)
    u = jitterid.inputs.random_binary(0.0, 201.0, seed=5, mean_dwell=4.0)
    record = jitterid.simulate(g, jit, u, samples=400, interval=0.5, noise_std=0.01, seed=3)
    start = System.grey_box(**dict(MSD, params={"m": 1.2, "damp": 0.35, "k": 2.3}))
    fit = jitterid.fit(dict(record, input=u), start, jit, "bcls", noise_std=0.01)
    assert fit.names == ["damp", "k", "m"]
    for name, truth, est, se in zip(fit.names, [0.4, 2.0, 1.0], fit.params, fit.std_errors):
        assert abs(est - truth) < 4 * se, (name, est, se)


def msd_matrices(m, damp, k):
    """The mass–spring–damper's matrices as a Python function of its parameters."""
    return np.array([[0, 1], [-k / m, -damp / m]]), np.array([0, 1 / m]), np.array([1, 0])


def test_a_callable_model_is_the_written_model():
    written = System.grey_box(**MSD)
    traced = System.grey_box(params=MSD["params"], matrices=msd_matrices, bounds=MSD["bounds"])
    assert traced.names == written.names
    assert traced.spec["a"][1] == ["-k / m", "-damp / m"]
    jit = jitterid.jitter.from_name("uniform-sum", n=2, a=0.25)
    u = jitterid.inputs.random_binary(0.0, 201.0, seed=5, mean_dwell=4.0)
    grid = dict(samples=400, interval=0.5)
    np.testing.assert_allclose(jitterid.second_moment(traced, jit, u, noise_std=0.01, **grid),
                               jitterid.second_moment(written, jit, u, noise_std=0.01, **grid), rtol=1e-12)
    record = jitterid.simulate(written, jit, u, noise_std=0.01, seed=3, **grid)
    start = dict(params={"m": 1.2, "damp": 0.35, "k": 2.3}, bounds=MSD["bounds"])
    by_text = jitterid.fit(dict(record, input=u), System.grey_box(**dict(MSD, **start)), jit, "bcls", noise_std=0.01)
    by_call = jitterid.fit(dict(record, input=u), System.grey_box(matrices=msd_matrices, **start), jit, "bcls",
                           noise_std=0.01)
    np.testing.assert_allclose(by_call.params, by_text.params, rtol=1e-10)
    np.testing.assert_allclose(by_call.std_errors, by_text.std_errors, rtol=1e-8)


def test_a_callable_with_fixed_constants_functions_and_a_feed_through():
    # A DC motor, voltage in, speed out: R and L known; D = 0 written as a NumPy scalar times a
    # parameter-free function value.
    def motor(J, b, K, R, L):
        a = np.array([[-b / J, K / J], [-K / L, -R / L]])
        return a, [0, 1 / L], [1, 0], np.array([[0.0 * np.exp(0.0)]])

    g = System.grey_box(params={"J": 0.01, "b": 0.1, "K": 0.01}, fixed={"R": 1.0, "L": 0.5}, matrices=motor)
    written = System.grey_box(params={"J": 0.01, "b": 0.1, "K": 0.01}, fixed={"R": 1.0, "L": 0.5},
                              a=[["-b/J", "K/J"], ["-K/L", "-R/L"]], b=[[0], ["1/L"]], c=[[1, 0]])
    np.testing.assert_allclose(g.frequency_response([0.0, 0.3, 2.0]), written.frequency_response([0.0, 0.3, 2.0]),
                               rtol=1e-13)
    # np.sqrt and friends become the language's functions; the value is the same.
    s = System.grey_box(params={"w": 2.0}, matrices=lambda w: ([[-np.sqrt(w) * np.abs(np.cos(0.0))]], [1], [1]))
    assert s.spec["a"] == [["-sqrt(w) * 1.0"]]
    np.testing.assert_allclose(s.to_ss()[0], [[-np.sqrt(2.0)]], rtol=1e-15)


@pytest.mark.parametrize("matrices, words", [
    (lambda m, damp, k: ([[0, 1], [-k / m if k > 0 else 0, -damp / m]], [0, 1], [1, 0]), "a branch on the value"),
    (lambda m, damp, k: ([[0, 1], [-__import__("math").sqrt(k), -damp / m]], [0, 1], [1, 0]), "use numpy's"),
    (lambda m, damp, k: ([[0, 1], [np.arctan(k), -damp / m]], [0, 1], [1, 0]), "arctan"),
    (lambda m, damp, k: ([[0, 1], [-k / m, -damp / m]], [0, 1]), "(A, B, C)"),
    (lambda m, damp, k: ([[0, 1], [-k / mass, -damp / m]], [0, 1], [1, 0]), "NameError"),  # noqa: F821
    (lambda m, damp, k: ([[0, 1], [-k / m, np.inf]], [0, 1], [1, 0]), "A[1][1]"),
    (lambda m, damp: ([[0, 1], [-1 / m, -damp / m]], [0, 1], [1, 0]), "keyword arguments"),
])
def test_a_callable_that_cannot_be_traced_raises_value_error_naming_why(matrices, words):
    with pytest.raises((ValueError, NameError)) as e:
        System.grey_box(params=MSD["params"], matrices=matrices)
    assert words in str(e.value) or words in type(e.value).__name__


def test_matrices_and_written_matrices_together_are_refused():
    with pytest.raises(ValueError, match="not both"):
        System.grey_box(params=MSD["params"], a=MSD["a"], matrices=msd_matrices)
    with pytest.raises(TypeError, match="callable"):
        System.grey_box(params=MSD["params"], matrices="-k/m")
