"""Files only where the user meant: a path in an experiment (``[input] path``) must stay inside
the experiment's directory unless ``allow_paths_outside=True``; experiment files are read as the
command line reads them (regular files of bounded size only)."""

from __future__ import annotations

import os
import pickle
import sys

import pytest

import jitterid

INPUT = "t,u\n0.0,0.0\n3.0,1.0\n17.5,0.0\n30.0,1.0\n50.0,0.0\n"
SECRET = "root:$6$saltsalt$hashhashhashhashhashhash:19000:0:99999:7:::\ndaemon:*:19000:0:99999:7:::\n"


def text(path: str) -> str:
    return f"""[sampling]
interval = 1.0
samples = 60
[input]
kind = "csv"
path = {path!r}
[system]
kind = "zpk"
gain = 0.5
poles = [-0.5]
estimate = true
[jitter]
family = "gaussian"
sigma = 0.05
""".replace("'", '"')


@pytest.fixture
def dirs(tmp_path):
    here, outside = tmp_path / "exp", tmp_path / "outside"
    here.mkdir()
    outside.mkdir()
    (here / "u.csv").write_text(INPUT)
    (outside / "u.csv").write_text(INPUT)
    (outside / "secret.csv").write_text(SECRET)
    return here, outside


def refused(excinfo) -> str:
    message = str(excinfo.value)
    assert "[input] path" in message and "allow_paths_outside" in message, message
    assert "root:" not in message and "daemon" not in message, message
    return message


def test_from_toml_refuses_paths_outside_its_directory(dirs):
    here, outside = dirs
    for path, why in [
        ("/etc/passwd", "absolute path"),
        (str(outside / "u.csv"), "absolute path"),
        ("../outside/secret.csv", "`..`"),
    ]:
        (here / "e.toml").write_text(text(path))
        with pytest.raises(ValueError) as e:
            jitterid.Experiment.from_toml(here / "e.toml")
        assert why in refused(e)
    (here / "e.toml").write_text(text("../outside/u.csv"))
    exp = jitterid.Experiment.from_toml(here / "e.toml", allow_paths_outside=True)
    assert exp.samples == 60
    (here / "e.toml").write_text(text("u.csv"))
    assert jitterid.Experiment.from_toml(here / "e.toml").samples == 60


@pytest.mark.skipif(not hasattr(os, "symlink") or sys.platform == "win32", reason="symbolic links")
def test_a_symbolic_link_leading_out_is_refused(dirs):
    here, outside = dirs
    os.symlink(outside / "secret.csv", here / "link.csv")
    (here / "e.toml").write_text(text("link.csv"))
    with pytest.raises(ValueError) as e:
        jitterid.Experiment.from_toml(here / "e.toml")
    assert "symbolic link" in refused(e)


def test_text_resolves_against_dir_or_the_current_directory(dirs, monkeypatch):
    here, outside = dirs
    # With a dir: relative to it, and kept inside it.
    assert jitterid.Experiment(text("u.csv"), dir=str(here)).samples == 60
    with pytest.raises(ValueError) as e:
        jitterid.Experiment(text("../outside/u.csv"), dir=str(here))
    refused(e)
    # Without one: the current directory, with the same rule.
    monkeypatch.chdir(here)
    assert jitterid.Experiment(text("u.csv")).samples == 60
    with pytest.raises(ValueError) as e:
        jitterid.Experiment(text("/etc/passwd"))
    refused(e)
    with pytest.raises(ValueError) as e:
        jitterid.Experiment(text("../outside/secret.csv"))
    refused(e)
    # Allowed explicitly; the permission travels with the pickle (to Dask workers).
    exp = jitterid.Experiment(text("../outside/u.csv"), allow_paths_outside=True)
    again = pickle.loads(pickle.dumps(exp))
    assert again.fingerprint == exp.fingerprint
    assert isinstance(again, jitterid.Experiment)
    # Positional arguments are as before.
    assert jitterid.Experiment(text("u.csv"), "mine.toml", str(here)).file == "mine.toml"


def test_an_allowed_file_that_is_not_a_csv_is_quoted_by_a_short_excerpt_only(dirs):
    here, _ = dirs
    with pytest.raises(ValueError) as e:
        jitterid.Experiment(text("../outside/secret.csv"), dir=str(here), allow_paths_outside=True)
    message = str(e.value)
    assert "secret.csv:2:1" in message, message
    assert "hashhash" not in message and "99999:7" not in message, message


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="needs /dev/zero")
def test_from_toml_refuses_a_device_instead_of_reading_forever():
    with pytest.raises(OSError, match="not a regular file"):
        jitterid.Experiment.from_toml("/dev/zero")


def test_from_toml_refuses_a_directory(tmp_path):
    with pytest.raises(OSError, match="not a regular file"):
        jitterid.Experiment.from_toml(tmp_path)


def test_read_record_refuses_a_device():
    if not os.path.exists("/dev/zero"):
        pytest.skip("needs /dev/zero")
    with pytest.raises((OSError, ValueError), match="not a regular file"):
        jitterid.read_record("/dev/zero")


def test_read_record_quotes_a_short_excerpt_only(dirs):
    _, outside = dirs
    with pytest.raises(ValueError) as e:
        jitterid.read_record(outside / "secret.csv")
    message = str(e.value)
    assert "secret.csv:" in message, message
    assert "hashhash" not in message and "99999:7" not in message, message
