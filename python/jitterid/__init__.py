"""jitterid: system identification when the sampling instants are noisy (sampling jitter).

The command line's experiments, from Python, with NumPy arrays in and out::

    import jitterid
    exp = jitterid.Experiment.from_toml("examples/experiments/table2.toml")
    record = exp.simulate(seed=1, run=0)          # dict: t, y, u, input_t, input_u
    fit = exp.fit(record, method="bcls")           # FitResult: names, params, std_errors, ...
    study = jitterid.montecarlo(exp, runs=128, seed=1)
    study.mean, study.std

Every number equals the command line's (``jitterid simulate / fit / montecarlo --json``) for
the same seed and run. Jitter models by name or class are in ``jitterid.jitter``. Studies split
into shards (``shard=(i, n)``) run anywhere, for example on Dask, and ``merge`` joins them.
"""

from __future__ import annotations

import json
import os
from typing import Any, Iterable, Mapping, Optional, Tuple, Union

from . import _jitterid, jitter
from .results import FitResult, MonteCarloResult

__version__: str = _jitterid.__version__
DEFAULT_SEED = 20_051_205

__all__ = [
    "Experiment",
    "FitResult",
    "MonteCarloResult",
    "DEFAULT_SEED",
    "jitter",
    "merge",
    "montecarlo",
    "read_record",
]


class Experiment(_jitterid.Experiment):
    """An experiment in the command line's TOML format (see ``docs/experiments.md``).

    ``Experiment.from_toml(path)`` reads a file; ``Experiment(text)`` takes the TOML text.
    Experiments pickle by their text.
    """

    def fit(self, record: Mapping[str, Any], method: Optional[str] = None) -> FitResult:
        """Fits ``record`` (a mapping with ``y``, and for a random-binary input the
        ``input_t``, ``input_u`` that ``simulate`` and ``read_record`` give) with ``method``
        (``"ls"``, ``"bcls"``, ``"bj"``, ``"ml"``, …; the file's by default). The same
        result as ``jitterid fit --json``. The GIL is released while fitting."""
        if not isinstance(record, Mapping) or "y" not in record:
            raise TypeError("record: expected a mapping with at least `y` (as simulate returns)")
        text = self.fit_json(record["y"], record.get("input_t"), record.get("input_u"), method)
        return FitResult(json.loads(text))


def montecarlo(
    experiment: Experiment,
    runs: int = 128,
    seed: int = DEFAULT_SEED,
    shard: Optional[Tuple[int, int]] = None,
    method: Optional[str] = None,
    threads: Optional[int] = None,
) -> MonteCarloResult:
    """``runs`` realisations of ``experiment`` fitted with ``method`` under master ``seed``
    (or shard ``(i, n)`` of them), on ``threads`` worker threads (all cores by default).
    ``to_dict()`` equals ``jitterid montecarlo --json`` (``--shard i/n``) apart from
    ``seconds``. The GIL is released while it runs."""
    if not isinstance(experiment, _jitterid.Experiment):
        raise TypeError(f"experiment: expected an Experiment, found {type(experiment).__name__}")
    text = _jitterid.montecarlo(experiment, runs, seed, shard, method, threads)
    return MonteCarloResult(json.loads(text))


def merge(shards: Iterable[Union[MonteCarloResult, Mapping[str, Any]]]) -> MonteCarloResult:
    """The result of the unsharded study from all its shards (results of ``montecarlo`` with
    ``shard=(i, n)``, or their ``to_dict()``, or the command line's shard files read as JSON),
    checked to belong together and to be whole, as ``jitterid merge --json``."""
    texts = [json.dumps(s.to_dict() if isinstance(s, MonteCarloResult) else dict(s)) for s in shards]
    return MonteCarloResult(json.loads(_jitterid.merge(texts)))


def read_record(path: Union[str, os.PathLike], input: Optional[Union[str, os.PathLike]] = None) -> dict:
    """The columns of a data file written by ``jitterid simulate`` (``k``, ``t``, ``y``, …) as
    arrays, with the input realisation ``input_t``, ``input_u`` from its side file
    ``<name>.input.csv`` (or ``input``) when there is one."""
    return _jitterid.read_record(os.fspath(path), None if input is None else os.fspath(input))
