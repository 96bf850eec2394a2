"""Records from pandas and xarray, classes with real signatures, and errors that name the
argument at fault (never an internal type or a command-line flag)."""

from __future__ import annotations

import inspect
import keyword
from typing import List

import numpy as np
import pytest

import jitterid
from jitterid import System, jitter

pd = pytest.importorskip("pandas")

G = System.zpk(zeros=[-0.5], poles=[-0.25 + 0.3j, -0.25 - 0.3j], gain=0.2)
J = jitter.UniformSum(n=2, a=0.28867513459481287)


@pytest.fixture(scope="module")
def record(table2):
    return table2.simulate(seed=3)


@pytest.fixture(scope="module")
def reference(table2, record):
    return table2.fit(record).to_dict(full=True)


def test_a_dict_of_pandas_series_fits_as_the_arrays_do(table2, record, reference):
    df = pd.DataFrame({"t": record["t"], "y": record["y"]})
    # Labels that are not positions: a Series' own indexing by label must not be used.
    df.index = df.index + 1000
    got = table2.fit({"y": df["y"], "t": df["t"], "input_t": pd.Series(record["input_t"]),
                      "input_u": pd.Series(record["input_u"])})
    assert got.to_dict(full=True) == reference


def test_module_fit_takes_series_in_a_dict(record):
    r = jitterid.simulate(G, J, jitterid.inputs.random_binary(0.0, 60.0, seed=2), samples=60, interval=1.0,
                          noise_std=0.01, seed=1)
    df = pd.DataFrame(r)
    df.index = df.index + 7
    u = jitterid.inputs.random_binary(0.0, 60.0, seed=2)
    a = jitterid.fit({"y": df["y"], "t": df["t"]}, G, J, input=u, noise_std=0.01)
    b = jitterid.fit(r, G, J, input=u, noise_std=0.01)
    np.testing.assert_array_equal(a.params, b.params)


@pytest.mark.parametrize("shape", ["frame-with-t", "frame-indexed-by-t", "series-indexed-by-t", "timedelta-index"])
def test_dataframes_and_series_are_records(table2, record, reference, shape):
    frame = pd.DataFrame({"y": record["y"]}, index=pd.Index(record["t"], name="t"))
    if shape == "frame-with-t":
        frame = pd.DataFrame({"t": record["t"], "y": record["y"]})
    elif shape == "timedelta-index":
        frame.index = pd.to_timedelta(record["t"], unit="s")
    source = frame["y"] if shape == "series-indexed-by-t" else frame
    r = jitterid._records.as_record(source)
    np.testing.assert_array_equal(r["t"], record["t"])
    np.testing.assert_array_equal(r["y"], record["y"])
    got = table2.fit({**r, "input_t": record["input_t"], "input_u": record["input_u"]})
    assert got.to_dict(full=True) == reference


def test_a_dataframe_is_a_record_for_a_known_input(record):
    u = jitterid.inputs.random_binary(0.0, 60.0, seed=2)
    r = jitterid.simulate(G, J, u, samples=60, interval=0.5, start=1.0, noise_std=0.01, seed=1)
    df = pd.DataFrame({"y": r["y"]}, index=r["t"])
    a = jitterid.fit(df, G, J, input=u, noise_std=0.01)
    b = jitterid.fit(r, G, J, input=u, noise_std=0.01)
    np.testing.assert_array_equal(a.params, b.params)


def test_xarray_records(table2, record, reference):
    xr = pytest.importorskip("xarray")
    da = xr.DataArray(record["y"], coords={"time": record["t"]}, dims="time")
    r = jitterid._records.as_record(da)
    np.testing.assert_array_equal(r["t"], record["t"])
    assert table2.fit({**r, "input_t": record["input_t"], "input_u": record["input_u"]}).to_dict(full=True) == reference
    ds = xr.Dataset({"y": ("time", record["y"])}, coords={"time": record["t"]})
    r = jitterid._records.as_record(ds)
    np.testing.assert_array_equal(r["t"], record["t"])
    np.testing.assert_array_equal(r["y"], record["y"])


@pytest.mark.parametrize(
    "bad, error, words",
    [
        (lambda r: pd.DataFrame({"x": r["y"]}), ValueError, ["record", "no column `y`", "x"]),
        (lambda r: {"x": r["y"]}, ValueError, ["record", "no `y`"]),
        (lambda r: [1.0, 2.0], TypeError, ["record", "DataFrame", "list"]),
        (lambda r: pd.Series(r["y"], index=pd.date_range("2026-01-01", periods=200, freq="s")), TypeError,
         ["record.index", "dates", "seconds"]),
    ],
)
def test_records_that_are_not_records_are_refused_by_name(table2, record, bad, error, words):
    with pytest.raises(error) as e:
        table2.fit(bad(record))
    for w in words:
        assert w in str(e.value), (w, str(e.value))


def test_jitter_classes_have_real_signatures():
    u = jitter.UniformSum(2, 0.3)
    assert u == jitter.UniformSum(n=2, a=0.3) == jitter.from_name("uniform-sum", n=2, a=0.3)
    sig = inspect.signature(jitter.UniformSum)
    assert list(sig.parameters) == ["n", "a"]
    assert sig.parameters["n"].annotation is int and sig.parameters["a"].annotation is float
    assert "a : float [s]" in jitter.UniformSum.__doc__
    assert jitter.Gaussian(0.1) == jitter.from_name("gaussian", sigma=0.1)
    with pytest.raises(TypeError, match="UniformSum: .*'b'"):
        jitter.UniformSum(2, 0.3, b=1)
    with pytest.raises(TypeError, match=r"Gaussian: takes at most 1 positional arguments \(sigma\), 2 were given"):
        jitter.Gaussian(0.1, 0.2)
    with pytest.raises(TypeError, match="UniformSum: missing required argument"):
        jitter.UniformSum(2)
    assert jitter.UniformSum(a=0.3) == jitter.from_name("uniform-sum", a=0.3)


def _stub_of(cls) -> str:
    """The stub of a family class, as ``jitter.pyi`` must hold it: one ``__new__`` with the
    keys in order, or where a key without a default follows one with a default (which a
    ``def`` cannot spell), two overloads: every key positional, and every key by keyword."""
    names = {int: "int", float: "float", bool: "bool", List[float]: "list[float]"}

    def spell(p, default=True):
        text = f"{p.name}: {names.get(p.annotation, 'list[dict[str, Any]]')}"
        return text + ("" if p.default is p.empty or not default else f" = {p.default!r}")

    params = list(inspect.signature(cls).parameters.values())
    last_required = max((i for i, p in enumerate(params) if p.default is p.empty), default=-1)
    head = f"class {cls.__name__}(Jitter):\n"
    if all(p.default is p.empty for p in params[:last_required]):
        return head + f"    def __new__(cls{''.join(', ' + spell(p) for p in params)}) -> {cls.__name__}: ...\n"
    positional = ", ".join(spell(p, default=i > last_required) for i, p in enumerate(params))
    by_keyword = ", ".join(spell(p) for p in sorted(params, key=lambda p: p.default is not p.empty))
    return (head + f"    @overload\n    def __new__(cls, {positional}) -> {cls.__name__}: ...\n"
            f"    @overload\n    def __new__(cls, *, {by_keyword}) -> {cls.__name__}: ...\n")


def test_every_family_class_is_in_the_stub():
    # The stub gives IDEs and type checkers the signatures that are made at import: it must
    # hold every family with the registry's keys, in order, with their defaults.
    from pathlib import Path

    stub = Path(jitter.__file__).with_suffix(".pyi").read_text()
    for entry in jitter.families():
        name = jitter._class_name(entry["name"])
        if keyword.iskeyword(name):
            continue  # `None`: a name the stub cannot spell (its docstring says so)
        block = _stub_of(getattr(jitter, name))
        assert block in stub, f"jitter.pyi: expected\n{block}"


@pytest.mark.parametrize(
    "call, error, message",
    [
        (lambda t2, r: t2.fit(dict(r, y=np.stack([r["y"], r["y"]]))), ValueError, "y: expected a one-dimensional"),
        (lambda t2, r: jitterid.fit({"y": r["y"], "T": 1.0}, G, J, input=np.zeros(3)), TypeError,
         "input: expected an Input or None, found ndarray"),
        (lambda t2, r: jitterid.fit({"y": r["y"], "T": 1.0}, G, J, estimate=["sys"]), ValueError,
         "estimate: unknown part(s) ['sys']"),
        (lambda t2, r: jitterid.montecarlo(t2, runs=0), ValueError, "runs: expected at least 1"),
        (lambda t2, r: jitterid.fit({"y": r["y"], "T": 1.0}, G, J, estimate=3), TypeError, "estimate: expected"),
        (lambda t2, r: t2.fit(r, method=3), TypeError, "method: expected the name of a method"),
        # The study layer's own messages, which name the command line's flags there.
        (lambda t2, r: jitterid.montecarlo(t2, runs=10**8), ValueError, "runs: expected a number of realisations"),
        (lambda t2, r: jitterid.montecarlo(t2, runs=2, threads=5000), ValueError, "threads: expected 1 to 1024"),
        (lambda t2, r: jitterid.Experiment(t2.text.replace("1/(2√3) s\nestimate = false", "1/(2√3) s\nestimate = true"))
         .fit(r, method="ls"), ValueError, "method ls: naive least squares ignores the jitter"),
    ],
)
def test_errors_name_the_argument(table2, record, call, error, message):
    with pytest.raises(error) as e:
        call(table2, record)
    assert str(e.value).startswith(message), str(e.value)
    for leak in ("--", "not an instance of", "section_json", "_jitterid"):
        assert leak not in str(e.value), str(e.value)


def test_estimate_names_one_part(record):
    u = jitterid.inputs.random_binary(0.0, 60.0, seed=2)
    r = jitterid.simulate(G, J, u, samples=60, interval=1.0, noise_std=0.01, seed=1)
    a = jitterid.fit(r, G, J, input=u, noise_std=0.01, estimate="system")
    b = jitterid.fit(r, G, J, input=u, noise_std=0.01, estimate=("system",))
    np.testing.assert_array_equal(a.params, b.params)
