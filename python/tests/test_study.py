"""The study layer from Python: validate, select, fit with init="auto", the fitted system's
Bode and step responses with bands, each compared number for number with the command line on
the same files."""

from __future__ import annotations

import csv
import json
from pathlib import Path

import numpy as np
import pytest

import jitterid

REPO = Path(__file__).resolve().parents[2]

WALK = REPO / "examples" / "walkthrough"

# A small selection (4 candidates on 200 samples), so that the debug build runs it in seconds.
SELECT_TOML = """
title = "Python parity: a small selection"

[sampling]
interval = 1.0
samples = 200

[input]
kind = "random-binary"
mean_dwell = 3.0

[system]
kind = "zpk"
gain = 1.0
poles = [-0.4]
estimate = true

[jitter]
family = "gaussian"
sigma = 0.2

[noise]
std = 0.02

[estimate]
method = "bcls"

[select]
poles = [1, 2]
zeros = [0, 0]
families = ["none", "gaussian"]
"""


@pytest.fixture(scope="module")
def model_exp():
    return jitterid.Experiment.from_toml(WALK / "model.toml")


@pytest.fixture(scope="module")
def estimation():
    return jitterid.read_record(WALK / "estimation.csv")


@pytest.fixture(scope="module")
def validation_record():
    return jitterid.read_record(WALK / "validation.csv")


@pytest.fixture(scope="module")
def small(tmp_path_factory, cli):
    """The small selection's experiment file and a record of it written by the command line."""
    d = tmp_path_factory.mktemp("small")
    path = d / "select.toml"
    path.write_text(SELECT_TOML)
    cli("simulate", path, "--seed", 4, "--out", d / "data.csv")
    cli("simulate", path, "--seed", 4, "--run", 1, "--out", d / "check.csv")
    return path, d / "data.csv", d / "check.csv"


def test_validate_equals_the_command_line(cli, small):
    path, data, check = small
    exp = jitterid.Experiment.from_toml(path)
    expected = cli("validate", path, "--data", data, "--validation", check, "--level", 0.01, "--json", parse_json=True)
    got = jitterid.validate(exp, jitterid.read_record(data), validation=jitterid.read_record(check), level=0.01)
    d = got.to_dict()
    # The records are named by their files on the command line and by their arguments here.
    for role, name in [("estimation", "record"), ("validation", "validation")]:
        assert d[role].pop("record") == name
        expected[role].pop("record")
    assert d == expected
    assert got.level == 0.01 and got.fit_percent["validation"] == expected["fit_percent"]["validation"]
    assert 0.0 <= got.whiteness["p_value"] <= 1.0 and got.whiteness["passed"] == (got.whiteness["p_value"] >= 0.01)


def test_validate_of_a_given_fit_equals_validate_model(cli, small, tmp_path):
    path, data, _ = small
    exp = jitterid.Experiment.from_toml(path)
    fit_file = tmp_path / "fit.json"
    fit_file.write_text(cli("fit", path, "--data", data, "--json"))
    expected = cli("validate", path, "--data", data, "--model", fit_file, "--json", parse_json=True)
    record = jitterid.read_record(data)
    got = jitterid.validate(exp, record, fit=exp.fit(record)).to_dict()
    got["estimation"].pop("record"), expected["estimation"].pop("record")
    assert got == expected


def test_bode_equals_validate_bode(cli, small, tmp_path):
    path, data, _ = small
    exp = jitterid.Experiment.from_toml(path)
    out = tmp_path / "bode.csv"
    cli("validate", path, "--data", data, "--bode", out)
    with open(out) as f:
        rows = list(csv.DictReader(f))
    columns = {"f": "f_hz", "omega": "omega_rad_s", "magnitude_db": "magnitude_db", "phase_deg": "phase_deg",
               "magnitude_db_lo": "magnitude_db_lo", "magnitude_db_hi": "magnitude_db_hi",
               "phase_deg_lo": "phase_deg_lo", "phase_deg_hi": "phase_deg_hi"}
    record = jitterid.read_record(data)
    fit = exp.fit(record)
    for bode in (jitterid.validate(exp, record).bode(), fit.bode()):
        assert len(rows) == 200
        for ours, theirs in columns.items():
            np.testing.assert_array_equal(bode[ours], [float(r[theirs]) for r in rows], err_msg=ours)
    # The bands are the delta method's ±2σ: they hold the estimate and are not empty.
    bode = fit.bode()
    assert np.all(bode["magnitude_db_lo"] < bode["magnitude_db"]) and np.all(bode["magnitude_db"] < bode["magnitude_db_hi"])
    # The same response as the fitted System's, in dB and degrees.
    g = fit.system.frequency_response(bode["f"])
    np.testing.assert_allclose(bode["magnitude_db"], 20 * np.log10(np.abs(g)), rtol=1e-12, atol=1e-12)


def test_step_is_the_fitted_systems_with_a_band(small):
    path, data, _ = small
    exp = jitterid.Experiment.from_toml(path)
    fit = exp.fit(jitterid.read_record(data))
    step = fit.step()
    assert step["t"].shape == (200,) and step["t"][0] == 0.0
    # The study layer's step response against the signal library's exact one, by another route.
    np.testing.assert_allclose(step["value"], fit.system.step(step["t"]), rtol=1e-9, atol=1e-12)
    inside = step["t"] > 0
    assert np.all(step["lo"][inside] < step["value"][inside]) and np.all(step["value"][inside] < step["hi"][inside])


def test_select_equals_the_command_line(cli, small):
    path, data, check = small
    exp = jitterid.Experiment.from_toml(path)
    expected = cli("select", path, "--data", data, "--validation", check, "--json", parse_json=True)
    got = jitterid.select(exp, jitterid.read_record(data), validation=jitterid.read_record(check))
    assert got.to_dict() == expected
    assert got.best == expected["best"] and len(got.candidates) == 4


def test_select_names_the_arguments_not_its_files(small):
    path, data, _ = small
    exp = jitterid.Experiment.from_toml(path)
    record = jitterid.read_record(data)
    with pytest.raises(ValueError) as e:
        jitterid.select(exp, {"y": record["y"][:150], "input_t": record["input_t"], "input_u": record["input_u"]})
    assert str(e.value).startswith("record: has 150 data rows, expected 200"), str(e.value)
    assert "jitterid-select-" not in str(e.value)
    with pytest.raises(ValueError, match="^validation: the experiment's input is random-binary"):
        jitterid.select(exp, record, validation={"y": record["y"]})


def test_fit_init_auto_equals_the_command_line(cli, small):
    path, data, _ = small
    exp = jitterid.Experiment.from_toml(path)
    expected = cli("fit", path, "--data", data, "--init", "auto", "--json", parse_json=True)
    got = exp.fit(jitterid.read_record(data), init="auto")
    assert got.to_dict() == expected
    with pytest.raises(ValueError, match="init: expected experiment, auto or experiment-only"):
        exp.fit(jitterid.read_record(data), init="automatic")


def test_walkthrough_fit_equals_the_command_line(cli, model_exp, estimation):
    expected = cli("fit", WALK / "model.toml", "--data", WALK / "estimation.csv", "--method", "bcls", "--init",
                   "auto", "--json", parse_json=True)
    fit = model_exp.fit(estimation, method="bcls", init="auto")
    assert fit.to_dict() == expected
    # One meaning of `model`: the export forms, as the command line's JSON has them.
    assert fit.model == expected["model"]
    assert fit.system.delay == expected["model"]["delay"]
    assert set(fit.fitted_model) == {"signal", "jitter", "noise", "noise_std"}
    # The system is G(s) e^{-sD}: the record's free response (initial state) is not part of it,
    # so its exact step response is the study layer's, delay included.
    assert "initial" in fit.fitted_model["signal"] and "initial" not in fit.system.spec
    step = fit.step()
    np.testing.assert_allclose(fit.system.step(step["t"]), step["value"], rtol=1e-9, atol=1e-12)


def test_the_fitted_system_converts_to_python_control_and_scipy(small):
    path, data, _ = small
    fit = jitterid.Experiment.from_toml(path).fit(jitterid.read_record(data))
    f = np.array([0.01, 0.1, 0.4])
    g = fit.system.frequency_response(f)
    control = pytest.importorskip("control")
    np.testing.assert_allclose(control.evalfr(fit.system.to_control(), 2j * np.pi * f[1]), g[1], rtol=1e-12)
    signal = pytest.importorskip("scipy.signal")
    _, h = signal.freqresp(fit.system.to_scipy(), 2 * np.pi * f)
    np.testing.assert_allclose(h, g, rtol=1e-12)


def test_conversions_say_what_is_missing(monkeypatch, small):
    import builtins

    real_import = builtins.__import__

    def without(name, *args, **kwargs):
        if name.split(".")[0] in ("control", "scipy"):
            raise ImportError(f"No module named {name!r}")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", without)
    g = jitterid.System.zpk([], [-1.0], 1.0)
    with pytest.raises(ImportError, match="pip install control"):
        g.to_control()
    with pytest.raises(ImportError, match="pip install scipy"):
        g.to_scipy()


def test_a_delayed_system_is_not_converted_without_its_delay(model_exp, estimation):
    system = model_exp.fit(estimation, method="bcls").system
    assert system.delay is not None
    with pytest.raises(ValueError, match="pade_order"):
        system.to_control()
    control = pytest.importorskip("control")
    # With the delay's Padé approximation: the exact response where the approximation holds
    # (ω·D well below the order).
    f = np.array([0.001, 0.01, 0.05])
    approx = np.array([control.evalfr(system.to_control(pade_order=6), 2j * np.pi * x) for x in f])
    np.testing.assert_allclose(approx, system.frequency_response(f), rtol=1e-6)
    pytest.importorskip("scipy")
    with pytest.raises(ValueError, match="input delay"):
        system.to_scipy()


def test_validate_checks_its_arguments_by_name(small):
    path, data, _ = small
    exp = jitterid.Experiment.from_toml(path)
    record = jitterid.read_record(data)
    with pytest.raises(ValueError, match="^level: expected a test level strictly between 0 and 1, found 1.5"):
        jitterid.validate(exp, record, level=1.5)
    with pytest.raises(TypeError, match="^fit: expected a FitResult"):
        jitterid.validate(exp, record, fit=record)
    with pytest.raises(ValueError, match="^validation: validation: 5 samples, too short"):
        jitterid.validate(exp, record, validation={k: v[:5] for k, v in record.items() if k in ("y", "t")})
    with pytest.raises(ValueError, match="^validation input"):
        jitterid.validate(exp, record, validation={"y": record["y"]})
    with pytest.raises(TypeError, match="^experiment: expected an Experiment"):
        jitterid.validate(str(path), record)
    with pytest.raises(TypeError, match="^record: expected a record"):
        jitterid.select(exp, [1.0, 2.0])


def test_validation_json_round_trip(small):
    path, data, _ = small
    exp = jitterid.Experiment.from_toml(path)
    v = jitterid.validate(exp, jitterid.read_record(data))
    json.dumps(v.to_dict())
    records = v.records()
    assert set(records) == {"estimation"}
    np.testing.assert_array_equal(records["estimation"]["y"], jitterid.read_record(data)["y"])
    assert v.passed == all(t["passed"] for t in [v.whiteness, v.cross_correlation])
