"""The library's documented limits and representable ranges, from Python: the same inputs the
command line refuses are refused here with the same words, before anything is allocated."""

from __future__ import annotations

import pytest

import jitterid
from jitterid import System, inputs, jitter
from jitterid.jitter import UniformSum

G = System.zpk(zeros=[-0.5], poles=[-0.25 + 0.3j, -0.25 - 0.3j], gain=0.2)
J = UniformSum(n=2, a=0.28867513459481287)
U = inputs.random_binary(0.0, 31.0, seed=5)


def refused(call, *words):
    with pytest.raises(ValueError) as e:
        call()
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_draws_beyond_the_sample_limit_are_refused():
    refused(lambda: J.sample(10**12, 1), "1000000000000 samples exceed the limit of 10000000 samples")
    refused(lambda: J.sample(2**62, 1), "exceed the limit of 10000000 samples")


def test_a_grid_beyond_the_sample_limit_is_refused_in_every_call():
    for call in (jitterid.simulate, jitterid.first_moment, jitterid.second_moment):
        refused(lambda: call(G, J, U, samples=10**12, interval=1.0), "[sampling] samples", "10000000")


def test_more_poles_than_the_limit_are_refused():
    refused(lambda: System.zpk([], [-1.0] * 31, 1.0), "31 poles exceed the limit of 30 poles")
    refused(lambda: System.zpk([], [-1.0] * 10_000, 1.0), "10000 poles exceed the limit")
    refused(lambda: System.tf([1.0], [1.0] * 32), "31 poles exceed the limit")


def test_more_tones_than_the_limit_are_refused():
    refused(lambda: inputs.multisine([0.001 * (k + 1) for k in range(1001)]), "1001 tones exceed the limit of 1000")


def test_a_phase_beyond_its_digits_is_refused():
    refused(lambda: inputs.multisine([0.1], phases=[1e308]), "phase")


def test_sums_beyond_their_limits_are_refused():
    dens = [{"family": "gaussian", "sigma": 0.1}, {"family": "uniform-sum", "n": 0, "a": 0.2},
            {"family": "laplace", "scale": 0.1}]
    refused(lambda: jitter.from_name("sum", terms=dens), "3 terms with a density exceed the limit of 2")
    atoms = [{"family": "two-point", "d": 0.01}] * 9
    refused(lambda: jitter.from_name("sum", terms=atoms), "9 terms exceed the limit of 8 terms")


def test_a_spread_beyond_double_precision_is_refused():
    refused(lambda: jitter.from_name("gaussian", sigma=1e308), "beyond double precision")


def test_values_the_command_line_refuses_against_the_grid_are_refused_in_simulate():
    zero_gain = System.zpk(zeros=[-0.5], poles=[-0.25 + 0.3j, -0.25 - 0.3j], gain=0.0)
    refused(lambda: jitterid.simulate(zero_gain, J, U, samples=30, interval=1.0), "[system] gain", "nonzero")
    far_pole = System.zpk(zeros=[], poles=[-1e300], gain=1.0)
    refused(lambda: jitterid.simulate(far_pole, J, U, samples=30, interval=1.0), "[system] poles")
    wide = UniformSum(n=0, a=1e6)
    refused(lambda: jitterid.first_moment(G, wide, U, samples=30, interval=1.0), "[jitter] a", "time scale")
