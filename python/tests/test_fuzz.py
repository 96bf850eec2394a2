"""The fuzz driver (``fuzz_driver.py``) in a small seeded version: hostile arguments to every
public function and method, each finding confirmed in an interpreter of its own. A new finding
fails the test; the library's known ones are listed below with what is being done about them.

``JITTERID_FUZZ_CALLS`` sets the number of calls (300 by default, every public function and
method once and more, some ten seconds on two cores);
``JITTERID_FUZZ_SEED`` the seed."""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
import fuzz_driver  # noqa: E402

CALLS = int(os.environ.get("JITTERID_FUZZ_CALLS", "300"))
SEED = int(os.environ.get("JITTERID_FUZZ_SEED", "1"))

#: Findings that are known and accepted, as (what, predicate on a finding); a finding that
#: matches none of them fails the test. Empty: the sizes that once aborted the interpreter
#: (draws, grids of 10**12 or 2**62 samples) are refused by the library's limits, and their
#: one-call reproducers below are now ordinary regression tests.
KNOWN: list = []

#: One-call reproducers of what the driver once found: each must now end as a Python error.
FIXED_REPRODUCERS = [
    "R['JG'].sample(10**12, 1)",
    "R['JG'].sample(2**62, 1)",
    "jitterid.simulate(R['G'], R['J'], R['U'], samples=10**12, interval=1.0)",
    "jitterid.second_moment(R['G'], R['J'], R['U'], samples=2**62, interval=1.0)",
    "jitterid.System.zpk([], [-1.0]*1000, 1.0)",
]


def known(finding: fuzz_driver.Finding) -> bool:
    return any(predicate(finding) for _, predicate in KNOWN)


def test_the_driver_reaches_every_public_function_and_method():
    names = {t.name for t in fuzz_driver.targets()}
    for expected in ["jitterid.fit", "jitterid.montecarlo", "jitterid.simulate", "jitterid.Experiment.fit",
                     "jitterid.System.step", "jitterid.jitter.Jitter.cf", "jitterid.jitter.Gaussian",
                     "jitterid.Input.value", "jitterid.FitResult.__getitem__", "jitterid.read_record"]:
        assert expected in names, expected
    # A small run still calls every target once before any twice.
    drawn = {name for name, _ in fuzz_driver.draw_calls(SEED, len(names))}
    assert drawn == names


def test_the_driver_sees_a_panic_an_abort_and_a_hang():
    # The driver's own check: calls that fail in each way it classifies are reported as such.
    outcomes = fuzz_driver.run_batch(
        [(0, "1/0"), (1, "int('x')"), (2, "__import__('os').abort()")], timeout=20)
    assert outcomes[0].kind == "unexpected" and "ZeroDivisionError" in outcomes[0].detail
    assert outcomes[1].kind == "fine"
    assert outcomes[2].kind == "signal" and "SIGABRT" in outcomes[2].detail
    hung = fuzz_driver.run_batch([(0, "__import__('time').sleep(30)")], timeout=2)
    assert hung[0].kind == "timeout"


def test_hostile_calls_end_in_a_return_or_a_clean_exception():
    calls = fuzz_driver.draw_calls(SEED, CALLS)
    findings = fuzz_driver.run(calls)
    new = [f for f in findings if not known(f)]
    assert not new, f"{len(new)} new finding(s) in {len(calls)} calls:\n" + "\n".join(f.report() for f in new)


@pytest.mark.parametrize("code", FIXED_REPRODUCERS)
def test_what_the_driver_once_found_now_ends_as_a_python_error(code):
    outcome = fuzz_driver.run_batch([(0, code)])[0]
    assert not outcome.failed, f"{outcome.kind}: {outcome.detail}"
