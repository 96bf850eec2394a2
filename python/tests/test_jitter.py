"""Jitter families by name and class: values against independent routes, array handling,
bad input and pickling."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

from jitterid import jitter

A = 0.5 / np.sqrt(3.0)


def test_every_registry_family_has_a_class():
    names = [f["name"] for f in jitter.families()]
    assert "uniform-sum" in names and "gaussian" in names
    for name in names:
        cls_name = "".join(p.capitalize() for p in name.split("-"))
        assert issubclass(getattr(jitter, cls_name), jitter.Jitter)


def test_class_and_name_build_the_same_model():
    assert jitter.UniformSum(n=2, a=A) == jitter.from_name("uniform-sum", n=2, a=A)
    assert jitter.from_std("uniform-sum", A / 3.0, n=2).params["a"] == pytest.approx(A, rel=1e-15)


def test_uniform_sum_cf_is_the_corrected_eq15():
    u = jitter.UniformSum(n=2, a=A)
    f = np.linspace(0.05, 2.0, 17)
    x = 2 * np.pi * f * A / 3
    np.testing.assert_allclose(u.cf(f).real, (np.sin(x) / x) ** 3, rtol=1e-13, atol=1e-15)
    assert u.std == pytest.approx(A / 3.0, rel=1e-15)  # a²/(3(n+1)) with n = 2


@pytest.mark.parametrize("spec", [dict(family="gaussian", sigma=0.1), dict(family="uniform-sum", n=1, a=0.3),
                                  dict(family="laplace", scale=0.05)])
def test_cf_against_monte_carlo_of_samples(spec):
    # Independent route: the sample mean of exp(-i2πfτ). Each part's Monte Carlo standard
    # error is at most 1/sqrt(2M); 5 standard errors bound a false failure near 1e-6.
    model = jitter.from_name(**spec)
    m = 40_000
    tau = model.sample(m, seed=7)
    f = np.array([0.5, 1.5, 3.0])
    empirical = np.exp(-2j * np.pi * np.outer(f, tau)).mean(axis=1)
    tol = 5 / np.sqrt(2 * m)
    np.testing.assert_allclose(empirical.real, model.cf(f).real, atol=tol)
    np.testing.assert_allclose(empirical.imag, model.cf(f).imag, atol=tol)
    # The sample standard deviation's relative standard error is sqrt((κ - 1)/(4M)), with the
    # kurtosis κ at most 6 (Laplace) here.
    assert np.std(tau) == pytest.approx(model.std, rel=5 * np.sqrt(5 / (4 * m)))


def test_pdf_integrates_to_one_and_mgf_matches_cf():
    g = jitter.Gaussian(sigma=0.1)
    t = np.linspace(-1, 1, 4001)
    # The rectangle rule is spectrally accurate for a smooth density that vanishes at the ends.
    area = np.sum(g.pdf(t)) * (t[1] - t[0])
    assert area == pytest.approx(1.0, abs=1e-9)
    f = np.array([0.3, 1.1])
    # γ(f) = E[exp(-i2πfτ)] = M(-i2πf).
    np.testing.assert_allclose(g.mgf(-2j * np.pi * f), g.cf(f), rtol=1e-12)


def test_array_inputs_lists_float32_non_contiguous_and_shape():
    u = jitter.UniformSum(n=2, a=A)
    f64 = np.linspace(0.0, 2.0, 10)
    reference = u.cf(f64)
    np.testing.assert_array_equal(u.cf(list(f64)), reference)
    np.testing.assert_array_equal(u.cf(f64.astype(np.float32)), u.cf(f64.astype(np.float32).astype(np.float64)))
    wide = np.linspace(0.0, 2.0, 20)
    np.testing.assert_array_equal(u.cf(wide[::2]), u.cf(np.ascontiguousarray(wide[::2])))
    assert u.pdf(np.zeros((3, 4))).shape == (3, 4)
    assert u.cf(np.arange(6.0).reshape(2, 3)).dtype == np.complex128
    assert u.sample(0, seed=1).shape == (0,)


def test_samples_are_reproducible_by_seed():
    u = jitter.UniformSum(n=2, a=A)
    np.testing.assert_array_equal(u.sample(100, seed=3), u.sample(100, seed=3))
    assert not np.array_equal(u.sample(100, seed=3), u.sample(100, seed=4))
    assert np.all(np.abs(u.sample(1000, seed=5)) <= A)


@pytest.mark.parametrize(
    "make, words",
    [
        (lambda: jitter.from_name("no-such-family"), ["no-such-family", "uniform-sum"]),
        (lambda: jitter.UniformSum(n=2, a=-1.0), ["`a`", "> 0"]),
        (lambda: jitter.Gaussian(sigma=float("nan")), ["sigma", "finite"]),
        (lambda: jitter.from_std("gaussian", -0.1), ["sigma"]),
        (lambda: jitter.from_name("gaussian", sigma=0.1, width=2), ["width"]),
        (lambda: jitter.from_name("gaussian"), ["sigma"]),
    ],
)
def test_bad_input_raises_value_error_naming_the_key(make, words):
    with pytest.raises(ValueError) as e:
        make()
    for w in words:
        assert w in str(e.value)


@pytest.mark.parametrize(
    "make, words",
    [
        # A class's keys are its parameters: a wrong call is refused as Python refuses one.
        (lambda: jitter.Gaussian(sigma=0.1, width=2), ["Gaussian", "width", "sigma"]),
        (lambda: jitter.Gaussian(), ["Gaussian", "missing", "sigma"]),
    ],
)
def test_a_class_called_with_wrong_keys_raises_type_error_naming_them(make, words):
    with pytest.raises(TypeError) as e:
        make()
    for w in words:
        assert w in str(e.value)


def test_unserialisable_key_is_a_type_error():
    with pytest.raises(TypeError):
        jitter.Gaussian(sigma=object())


def test_pickle_round_trip():
    for model in [jitter.UniformSum(n=2, a=A), jitter.from_name("sum", terms=[dict(family="gaussian", sigma=0.1),
                                                                            dict(family="uniform-sum", a=0.2)])]:
        again = pickle.loads(pickle.dumps(model))
        assert again == model and isinstance(again, jitter.Jitter)
        np.testing.assert_array_equal(again.cf([0.7]), model.cf([0.7]))
