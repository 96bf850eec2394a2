"""Long calls stay under the caller's control: ``progress`` callbacks of fits and studies, an
exception raised by one stops the work, and Ctrl-C stops a running fit at its solver's next
iteration."""

from __future__ import annotations

import re
import signal
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import jitterid


class Stop(Exception):
    """Raised by a test's progress callback."""


def test_fit_progress_reports_every_iteration_and_changes_nothing(table2):
    record = table2.simulate(seed=4)
    seen = []
    fit = table2.fit(record, progress=lambda iteration, cost: seen.append((iteration, cost)))
    iterations = [i for i, _ in seen]
    costs = np.array([c for _, c in seen])
    # The start's evaluation, then each iteration of the Levenberg–Marquardt solver, whose cost
    # never increases (a rejected step keeps the point).
    assert iterations == list(range(len(seen))) and iterations[-1] == fit.iterations > 1
    assert np.all(np.isfinite(costs)) and np.all(np.diff(costs) <= 0) and costs[-1] < costs[0]
    # The hook only watches: the fit is the one without it.
    assert fit.to_dict(full=True) == table2.fit(record).to_dict(full=True)


def test_fit_on_arrays_takes_a_progress_callback(table2):
    seen = []
    jitterid.fit(table2.simulate(seed=4), jitterid.System.zpk([-0.5], [-0.25 + 0.3j, -0.25 - 0.3j], 0.2),
                 jitterid.jitter.UniformSum(n=2, a=0.28867513459481287), "bcls", noise_std=0.01,
                 progress=lambda i, c: seen.append(i))
    assert seen[0] == 0 and seen == sorted(set(seen)) and len(seen) > 2


def test_an_exception_in_the_fit_progress_callback_stops_the_fit(table2):
    record = table2.simulate(seed=4)
    whole = table2.fit(record)
    seen = []

    def progress(iteration, cost):
        seen.append(iteration)
        if iteration == 1:
            raise Stop("enough")

    with pytest.raises(Stop, match="enough") as stopped:
        table2.fit(record, progress=progress)
    # Not called again once it raised; the fit stopped where it was, well before its end.
    assert seen == [0, 1]
    report = str(stopped.value.__cause__)
    done = re.fullmatch(r"interrupted: the fit was stopped after (\d+) iterations \(stopped by the caller\)", report)
    assert done is not None, report
    # The fit waits for each callback, so it stops at the iteration whose callback raised.
    assert int(done.group(1)) == 1 < whole.iterations


@pytest.mark.parametrize("threads", [1, 2])
def test_montecarlo_progress_counts_the_realisations(table2, threads):
    seen = []
    study = jitterid.montecarlo(table2, runs=6, seed=2, threads=threads, progress=lambda d, t: seen.append((d, t)))
    # Increasing counts ending at the total (with several threads a count that arrives after a
    # larger one is not reported again).
    assert [t for _, t in seen] == [6] * len(seen)
    assert [d for d, _ in seen] == sorted(set(d for d, _ in seen)) and seen[-1] == (6, 6)
    if threads == 1:
        assert [d for d, _ in seen] == [1, 2, 3, 4, 5, 6]
    assert study.to_dict()["parameters"] == jitterid.montecarlo(table2, runs=6, seed=2).to_dict()["parameters"]


def test_an_exception_in_the_montecarlo_progress_callback_stops_the_study(table2):
    runs = 100_000

    def progress(done, total):
        if done == 3:
            raise Stop("enough")

    with pytest.raises(Stop) as stopped:
        jitterid.montecarlo(table2, runs=runs, threads=1, progress=progress)
    report = str(stopped.value.__cause__)
    done = re.fullmatch(r"interrupted: the study was stopped after (\d+) of (\d+) realisations", report)
    assert done is not None, report
    assert int(done.group(2)) == runs and 3 <= int(done.group(1)) < runs


@pytest.mark.parametrize("bad", ["not a function", 3])
def test_progress_must_be_callable(table2, bad):
    with pytest.raises(TypeError, match="progress"):
        table2.fit(table2.simulate(seed=1), progress=bad)
    with pytest.raises(TypeError, match="progress"):
        jitterid.montecarlo(table2, runs=2, progress=bad)


#: A child that fits a long record (N = 5 000, BFGS on the likelihood, no iteration limit to
#: speak of) and prints each iteration as its progress callback sees it, then what the
#: KeyboardInterrupt said.
LONG_FIT = textwrap.dedent(
    """
    import signal, sys
    import jitterid
    # Python's own SIGINT handler, which a process started with SIGINT ignored (a background
    # job of a shell) does not install.
    signal.signal(signal.SIGINT, signal.default_int_handler)
    G = jitterid.System.zpk([-0.5], [-0.25 + 0.3j, -0.25 - 0.3j], 0.2)
    J = jitterid.jitter.Gaussian(sigma=0.2)
    U = jitterid.inputs.random_binary(0.0, 5001.0, seed=5)
    record = jitterid.simulate(G, J, U, samples=5000, interval=1.0, noise_std=0.01, seed=1)
    start = jitterid.jitter.Gaussian(sigma=0.05)
    def progress(iteration, cost):
        print("iteration", iteration, flush=True)
    try:
        fit = jitterid.fit(dict(record, input=U), G, start, "ml", estimate=("system", "jitter"), noise_std=0.01,
                           options={"max_iterations": 100000}, progress=progress)
        print("finished", fit.iterations, fit.termination, flush=True)
    except KeyboardInterrupt as e:
        print("cause:", e.__cause__, flush=True)
    """
)


def test_ctrl_c_stops_a_running_fit_at_its_next_iteration():
    """SIGINT sent to a Python process while its fit runs raises KeyboardInterrupt from inside
    the call, its cause the stopped fit's report: stopped by the caller after fewer iterations
    than the fit takes to its end (a fit that had run to its end would say so instead)."""
    child = subprocess.Popen([sys.executable, "-c", LONG_FIT], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True)
    lines = []
    try:
        for line in child.stdout:
            lines.append(line.strip())
            if line.startswith("iteration 1"):
                child.send_signal(signal.SIGINT)
                break
        rest, err = child.communicate(timeout=600)
    finally:
        child.kill()
    lines += rest.splitlines()
    last = lines[-1] if lines else ""
    assert child.returncode == 0, err
    stopped = re.fullmatch(r"cause: interrupted: the fit was stopped after (\d+) iterations "
                           r"\(stopped by the caller\)", last)
    assert stopped is not None, "\n".join(lines[-5:]) + err
    seen = [int(line.split()[1]) for line in lines if line.startswith("iteration")]
    assert int(stopped.group(1)) <= max(seen) + 1
