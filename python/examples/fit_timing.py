"""The Table 2 fit timed from Python, against `fit_timing.rs` (the same fit from Rust), and a
Monte Carlo study timed from Python, against the command line (`docs/performance.md`).

    python python/examples/fit_timing.py [repeats]
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import jitterid

repeats = int(sys.argv[1]) if len(sys.argv) > 1 else 200
exp = jitterid.Experiment.from_toml(Path(__file__).resolve().parents[2] / "examples/experiments/table2.toml")
record = exp.simulate(seed=jitterid.DEFAULT_SEED, run=0)
times = []
for _ in range(repeats):
    t0 = time.perf_counter()
    fit = exp.fit(record)
    times.append(time.perf_counter() - t0)
    assert fit.converged
times.sort()
print(f"Table 2 fit from Python: median {1e3 * times[repeats // 2]:.3f} ms, min {1e3 * times[0]:.3f} ms over {repeats} fits")
t0 = time.perf_counter()
study = jitterid.montecarlo(exp, runs=128)
print(f"montecarlo 128 runs from Python: {time.perf_counter() - t0:.3f} s (study's own clock {study.seconds:.3f} s)")
