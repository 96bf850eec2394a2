"""Experiments: records, fits and Monte Carlo equal to the command line's on the same seeds;
array handling, bad input and pickling."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import jitterid


def test_simulate_equals_the_command_line(cli, table2, table2_path, tmp_path):
    out = tmp_path / "d.csv"
    cli("simulate", table2_path, "--seed", 5, "--run", 3, "--out", out, "--truth")
    written = jitterid.read_record(out)
    record = table2.simulate(seed=5, run=3, truth=True)
    for key in ["t", "y", "u", "tau", "v", "input_t", "input_u"]:
        np.testing.assert_array_equal(record[key], written[key], err_msg=key)
    assert len(record["y"]) == table2.samples == 200


def test_fit_equals_the_command_line(cli, table2, table2_path, tmp_path):
    out = tmp_path / "d.csv"
    cli("simulate", table2_path, "--seed", 11, "--out", out)
    expected = cli("fit", table2_path, "--data", out, "--json", parse_json=True)
    fit = table2.fit(jitterid.read_record(out))
    assert fit.to_dict() == expected
    assert fit.converged and fit.names == ["gain", "zero0", "pole0.re", "pole0.im"]
    assert fit["gain"] == pytest.approx(0.2, abs=5 * fit.std_errors[0])
    assert fit.jitter == jitterid.jitter.UniformSum(n=2, a=0.28867513459481287)


def test_fit_methods_equal_the_command_line(cli, table2, table2_path, tmp_path):
    out = tmp_path / "d.csv"
    cli("simulate", table2_path, "--seed", 2, "--out", out)
    record = jitterid.read_record(out)
    expected = cli("fit", table2_path, "--data", out, "--json", "--method", "ls", parse_json=True)
    assert table2.fit(record, method="ls").to_dict() == expected


def test_table2_montecarlo_equals_the_command_line(cli, table2, table2_path):
    # The paper's Table 2: 128 records, BCLS, the default seed.
    expected = cli("montecarlo", table2_path, "--runs", 128, "--json", parse_json=True)
    study = jitterid.montecarlo(table2, runs=128)
    got = study.to_dict()
    for d in (got, expected):
        d.pop("seconds")
    assert got == expected
    for p, q in zip(study.to_dict()["parameters"], expected["parameters"]):
        for key in ["mean", "std", "se", "rmse"]:
            assert abs(p[key] - q[key]) <= 1e-12
    # The paper's means [0.2000, 0.5012, -0.2504, 0.3001], within 4 standard errors.
    np.testing.assert_array_less(np.abs(study.mean - study.truth), 4 * study.se)


def test_fit_takes_lists_float32_and_non_contiguous_samples(table2):
    record = table2.simulate(seed=4)
    reference = table2.fit(record).to_dict(full=True)
    as_list = dict(record, y=list(record["y"]))
    assert table2.fit(as_list).to_dict(full=True) == reference
    wide = np.repeat(record["y"], 2)
    assert table2.fit(dict(record, y=wide[::2])).to_dict(full=True) == reference
    float32 = dict(record, y=record["y"].astype(np.float32))
    assert table2.fit(float32).converged


@pytest.mark.parametrize(
    "change, words",
    [
        (lambda r: dict(r, y=np.full(200, np.nan)), ["y", "element 0", "NaN"]),
        (lambda r: dict(r, y=np.array([])), ["y", "empty"]),
        (lambda r: dict(r, y=r["y"][:150]), ["150", "200"]),
        (lambda r: {"y": r["y"]}, ["random-binary", "input_t"]),
        (lambda r: dict(r, input_u=r["input_u"][:-2]), ["input_t", "input_u"]),
    ],
)
def test_bad_records_raise_value_error(table2, change, words):
    record = table2.simulate(seed=1)
    with pytest.raises(ValueError) as e:
        table2.fit(change(record))
    for w in words:
        assert w in str(e.value)


def test_bad_arguments(table2, tmp_path):
    with pytest.raises(ValueError, match="method"):
        table2.fit(table2.simulate(seed=1), method="no-such-method")
    with pytest.raises(TypeError):
        table2.fit([1.0, 2.0])
    with pytest.raises(OSError, match="does-not-exist.toml"):
        jitterid.Experiment.from_toml(tmp_path / "does-not-exist.toml")
    with pytest.raises(ValueError, match="sampling"):
        jitterid.Experiment("title = 'no sections'\n")
    with pytest.raises(ValueError, match="shard"):
        jitterid.montecarlo(table2, runs=4, shard=(3, 3))
    with pytest.raises(ValueError, match="runs"):
        jitterid.montecarlo(table2, runs=0)
    with pytest.raises(OverflowError):
        table2.simulate(seed=-1)
    with pytest.raises(TypeError, match="Experiment"):
        jitterid.montecarlo("table2.toml", runs=4)


def test_fit_fields_equal_their_json(table2):
    # A fit's numbers are read from the library's result; its JSON (to_dict, pickling) is formed
    # on demand. Both routes give the same values, bit for bit (NaN where a value is undefined).
    record = table2.simulate(seed=6)
    for method in ["bcls", "ls"]:
        fit = table2.fit(record, method=method)
        assert isinstance(fit.params, np.ndarray) and fit.params.dtype == np.float64
        via_json = jitterid.FitResult(fit.to_dict(full=True))
        for key in ["method", "converged", "cost", "iterations", "termination", "noise_std", "names",
                    "covariance_names", "model", "fitted_model"]:
            assert getattr(fit, key) == getattr(via_json, key), (method, key)
        for key in ["params", "std_errors", "covariance"]:
            a, b = getattr(fit, key), getattr(via_json, key)
            assert (a is None) == (b is None), (method, key)
            if a is not None:
                np.testing.assert_array_equal(a, b, err_msg=f"{method} {key}")
        assert repr(fit) == repr(via_json)


def test_pickling_experiments_and_results(table2):
    again = pickle.loads(pickle.dumps(table2))
    assert isinstance(again, jitterid.Experiment)
    assert again.fingerprint == table2.fingerprint and again.file == table2.file
    record = table2.simulate(seed=9)
    np.testing.assert_array_equal(again.simulate(seed=9)["y"], record["y"])
    fit = table2.fit(record)
    fit_again = pickle.loads(pickle.dumps(fit))
    assert fit_again.to_dict(full=True) == fit.to_dict(full=True)
    np.testing.assert_array_equal(fit_again.params, fit.params)
    study = jitterid.montecarlo(table2, runs=4, seed=1, shard=(0, 2))
    assert pickle.loads(pickle.dumps(study)).to_dict() == study.to_dict()


def test_shards_merge_to_the_single_run(table2):
    whole = jitterid.montecarlo(table2, runs=12, seed=3)
    shards = [jitterid.montecarlo(table2, runs=12, seed=3, shard=(i, 3)) for i in range(3)]
    assert shards[1].estimates.shape == (4, 4)
    merged = jitterid.merge(reversed(shards))
    a, b = merged.to_dict(), whole.to_dict()
    a.pop("seconds"), b.pop("seconds")
    assert a == b
    with pytest.raises(ValueError, match="missing"):
        jitterid.merge(shards[:2])
    with pytest.raises(ValueError, match="twice"):
        jitterid.merge([shards[0], shards[0], shards[1]])


def test_covariance_matches_the_standard_errors(table2):
    fit = table2.fit(table2.simulate(seed=6))
    assert fit.covariance_names == fit.names
    np.testing.assert_allclose(np.sqrt(np.diag(fit.covariance)), fit.std_errors, rtol=1e-12)
    np.testing.assert_allclose(fit.covariance, fit.covariance.T, rtol=1e-12, atol=0)
    assert np.all(np.linalg.eigvalsh(fit.covariance) > 0)


def test_ctrl_c_stops_a_long_study(table2):
    """Ctrl-C during a study stops it before its next realisations and raises KeyboardInterrupt
    from inside the call, its cause the study's report of how far it got (a study that ran to
    its end and was interrupted afterwards would have no such cause)."""
    import os
    import re
    import signal
    import threading

    runs = 100_000
    # Python's own SIGINT handler, which a process started with SIGINT ignored (a background
    # job of a shell) does not install.
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt) as interrupted:
            jitterid.montecarlo(table2, runs=runs, threads=1)
    finally:
        timer.cancel()
        signal.signal(signal.SIGINT, previous)
    report = str(interrupted.value.__cause__)
    done = re.fullmatch(r"interrupted: the study was stopped after (\d+) of (\d+) realisations", report)
    assert done is not None, report
    assert int(done.group(2)) == runs
    assert int(done.group(1)) < runs
