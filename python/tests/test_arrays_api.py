"""Systems, inputs, simulation, exact moments and fits on arrays: cross-checked against direct
polynomial evaluation, Monte Carlo means, and ``Experiment.fit`` on the same record."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import jitterid
from jitterid import System, inputs
from jitterid.jitter import UniformSum

G = System.zpk(zeros=[-0.5], poles=[-0.25 + 0.3j, -0.25 - 0.3j], gain=0.2)
J = UniformSum(n=2, a=0.28867513459481287)


def test_frequency_response_equals_polynomial_evaluation():
    f = np.linspace(0.0, 0.5, 11)
    s = 2j * np.pi * f
    direct = 0.2 * (s + 0.5) / ((s + 0.25) ** 2 + 0.09)
    np.testing.assert_allclose(G.frequency_response(f), direct, rtol=1e-13)
    h = System.tf([0.2, 0.1], [1.0, 0.5, 0.1525])
    np.testing.assert_allclose(h.frequency_response(f), direct, rtol=1e-13)


def test_a_delayed_system_has_the_delay_in_its_phase_and_its_step():
    d = 1.3
    gd = jitterid.system.from_name("zpk", gain=0.2, zeros=[-0.5], poles=[[-0.25, 0.3]], delay=d)
    assert gd.delay == d and G.delay is None
    f = np.linspace(0.0, 0.5, 11)
    np.testing.assert_allclose(
        gd.frequency_response(f), G.frequency_response(f) * np.exp(-2j * np.pi * f * d), rtol=1e-13
    )
    t = np.array([0.5, 1.3, 2.0, 7.7, 40.0])
    np.testing.assert_allclose(gd.step(t), G.step(t - d), rtol=1e-12, atol=1e-15)


def test_conversions_round_trip():
    num, den = G.tf_coefficients()
    np.testing.assert_allclose(num, [0.2, 0.1], rtol=1e-14)
    np.testing.assert_allclose(den, [1.0, 0.5, 0.1525], rtol=1e-14)
    back = G.to_tf().to_zpk()
    np.testing.assert_allclose(back.param_values, G.param_values, rtol=1e-12)
    a, b, c, d = G.to_ss()
    assert a.shape == (2, 2) and b.shape == (2, 1) and c.shape == (1, 2) and d.shape == (1, 1)
    s = 0.3j
    ss = (c @ np.linalg.solve(s * np.eye(2) - a, b) + d)[0, 0]
    np.testing.assert_allclose(ss, G.frequency_response(0.3 / (2 * np.pi)), rtol=1e-12)
    assert G.names == ["gain", "zero0", "pole0.re", "pole0.im"]
    assert pickle.loads(pickle.dumps(G)) == G


def test_step_tends_to_the_dc_gain():
    y = G.step([-1.0, 0.0, 200.0])
    assert y[0] == 0.0
    np.testing.assert_allclose(y[2], G.frequency_response(0.0).real, rtol=1e-9)


def test_first_moment_matches_the_mean_of_simulations():
    u = inputs.random_binary(0.0, 31.0, seed=5)
    runs, n = 400, 30
    ys = np.array([jitterid.simulate(G, J, u, samples=n, interval=1.0, seed=s)["y"] for s in range(runs)])
    m = jitterid.first_moment(G, J, u, samples=n, interval=1.0)
    lam = jitterid.second_moment(G, J, u, samples=n, interval=1.0)
    # The sample mean's standard error is sqrt(λ_k / runs); allow 5 standard errors (fixed seeds).
    se = np.sqrt(lam / runs)
    assert np.all(np.abs(ys.mean(axis=0) - m) <= 5 * se + 1e-15)


def test_simulate_truth_and_input():
    u = inputs.zero_order_hold([0.0, 1.0, 1.0, 0.0], interval=5.0)
    r = jitterid.simulate(G, J, u, samples=20, interval=1.0, noise_std=0.01, seed=2, truth=True)
    np.testing.assert_array_equal(r["u"], u.value(r["t"]))
    assert r["tau"].shape == r["v"].shape == (20,)
    sine = inputs.sine(0.05, 2.0)
    np.testing.assert_allclose(sine.value([5.0]), [2.0], rtol=1e-14)


def test_fit_on_arrays_equals_experiment_fit(table2):
    record = table2.simulate(seed=11)
    expected = table2.fit(record)
    got = jitterid.fit(record, G, J, "bcls", noise_std=0.01, options={"frequencies": "dft", "solver": "lm"})
    np.testing.assert_allclose(got.params, expected.params, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got.std_errors, expected.std_errors, rtol=0, atol=1e-12)
    assert got.names == expected.names and got.converged


@pytest.mark.parametrize(
    "call, error, words",
    [
        (lambda: System.tf([1.0], [0.0, 0.0]), ValueError, ["den"]),
        (lambda: jitterid.system.from_name("no-such-kind"), ValueError, ["no-such-kind"]),
        (lambda: System.zpk([], [-1 + 1j], 1.0), ValueError, ["pole"]),
        (lambda: inputs.piecewise([0.0, 1.0], [np.nan]), ValueError, ["levels", "NaN"]),
        (lambda: inputs.piecewise([], []), ValueError, ["empty"]),
        (lambda: inputs.multisine([0.1, 0.2], [1.0]), ValueError, ["amplitudes", "2"]),
        (lambda: jitterid.simulate(G, J, None, samples=5, interval=1.0), ValueError, ["input"]),
        (lambda: jitterid.fit({"y": [1.0, 2.0]}, G, J), ValueError, ["interval"]),
        (lambda: jitterid.fit([1.0], G, J), TypeError, ["record"]),
    ],
)
def test_bad_input(call, error, words):
    with pytest.raises(error) as e:
        call()
    for w in words:
        assert w in str(e.value)


def test_lists_float32_and_views():
    levels = np.array([1.0, 0.0, 1.0, 1.0], dtype=np.float32)[::2]
    u = inputs.piecewise([0.0, 3.0, 9.0], levels)
    assert u == inputs.piecewise(np.array([0.0, 3.0, 9.0]), [1.0, 1.0])
    f = np.repeat(np.linspace(0, 0.5, 4), 2)[::2]
    np.testing.assert_array_equal(G.frequency_response(f), G.frequency_response(list(f)))
