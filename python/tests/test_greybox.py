"""Grey-box state-space systems from Python: matrices as expressions of named physical
parameters, their transfer function and realisation, bad expressions as ``ValueError``, and a
fit in physical parameters."""

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
