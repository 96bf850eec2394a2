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

import numpy as np

from . import _jitterid, inputs, jitter, system
from .inputs import Input
from .system import System
from .results import FitResult, MonteCarloResult

__version__: str = _jitterid.__version__
DEFAULT_SEED = 20_051_205

__all__ = [
    "Experiment",
    "FitResult",
    "MonteCarloResult",
    "DEFAULT_SEED",
    "Input",
    "System",
    "first_moment",
    "fit",
    "inputs",
    "second_moment",
    "simulate",
    "system",
    "jitter",
    "merge",
    "montecarlo",
    "read_record",
]


class Experiment(_jitterid.Experiment):
    """An experiment in the command line's TOML format (see ``docs/experiments.md``).

    ``Experiment.from_toml(path)`` reads a file; ``Experiment(text)`` takes the TOML text.
    Experiments pickle by their text.

    A file the experiment names (``[input] path``) is resolved against the experiment file's
    directory (for ``Experiment(text)``: ``dir``, the current directory by default) and must be
    inside it: an absolute path, a ``..`` component or a symbolic link leading out raises
    ``ValueError`` before the file is read, unless ``allow_paths_outside=True`` (keyword only,
    in both constructors; kept when pickled).
    """

    def fit(self, record: Mapping[str, Any], method: Optional[str] = None) -> FitResult:
        """Fits ``record`` (a mapping with ``y``, and for a random-binary input the
        ``input_t``, ``input_u`` that ``simulate`` and ``read_record`` give) with ``method``
        (``"ls"``, ``"bcls"``, ``"bj"``, ``"ml"``, …; the file's by default). The same
        result as ``jitterid fit --json``. The GIL is released while fitting."""
        if not isinstance(record, Mapping) or "y" not in record:
            raise TypeError("record: expected a mapping with at least `y` (as simulate returns)")
        return FitResult._of(self.fit_record(record["y"], record.get("input_t"), record.get("input_u"), method))


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
    ``seconds``. The GIL is released while it runs; Ctrl-C stops the study before its next
    realisations and raises ``KeyboardInterrupt``."""
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


def _grid(samples: int, interval: float, start: float) -> tuple:
    return int(samples), float(interval), float(start)


def simulate(system: System, jitter: jitter.Jitter, input: Optional[Input] = None, *, samples: int,
             interval: float, start: float = 0.0, noise_std: float = 0.0, seed: int = DEFAULT_SEED,
             truth: bool = False) -> dict:
    """``samples`` jittered samples ``y_k = s(t_k + τ_k) + v_k`` of ``system`` driven by
    ``input`` at ``t_k = start + k·interval``, white noise of std ``noise_std``, seeded by
    ``seed``: a dict of arrays ``t``, ``y``, ``u`` (with an input), and with ``truth`` the drawn
    ``tau`` and ``v``. The GIL is released while it runs."""
    return _jitterid.simulate(system, jitter, input, *_grid(samples, interval, start), float(noise_std),
                              int(seed), bool(truth))


def first_moment(system: System, jitter: jitter.Jitter, input: Optional[Input] = None, *, samples: int,
                 interval: float, start: float = 0.0) -> np.ndarray:
    """``m_k = E[s(t_k + τ)]`` at ``t_k = start + k·interval``, exact."""
    return _jitterid.first_moment(system, jitter, input, *_grid(samples, interval, start))


def second_moment(system: System, jitter: jitter.Jitter, input: Optional[Input] = None, *, samples: int,
                  interval: float, start: float = 0.0, noise_std: float = 0.0) -> np.ndarray:
    """``λ_k = Var y_k = noise_std² + E[s(t_k + τ)²] − m_k²`` at ``t_k = start + k·interval``, exact."""
    return _jitterid.second_moment(system, jitter, input, *_grid(samples, interval, start), float(noise_std))


def fit(record: Mapping[str, Any], system: System, jitter: jitter.Jitter, method: str = "bcls", *,
        estimate: Iterable[str] = ("system",), interval: Optional[float] = None,
        start: Optional[float] = None, input: Optional[Input] = None, noise_std: float = 0.0,
        options: Optional[Mapping[str, Any]] = None) -> FitResult:
    """Fits a record's samples with ``method``, starting from ``system`` and ``jitter``.

    Arguments:

    * ``record``: a mapping with the samples ``y`` and optionally ``T`` and ``t0`` (or ``t``)
      and the input (``input``, or ``input_t`` and ``input_u`` as ``simulate`` gives them).
    * ``system``, ``jitter``: the model, and the start of the estimated parts.
    * ``method``: ``"ls"``, ``"bcls"``, ``"bj"``, ``"ml"``, … (the command line's methods).
    * ``estimate``: the estimated parts among ``"system"``, ``"jitter"`` and ``"noise"``.
    * ``interval``, ``start``: the grid (default: the record's ``T``/``t0``, else its ``t``).
    * ``input``: the known input (default: the record's).
    * ``noise_std``: the measurement-noise level (known, or the start when estimated).
    * ``options``: further keys of the experiment file's ``[estimate]`` section
      (``solver``, ``frequencies``, ``max_iterations``, …).

    Returns a ``FitResult`` (``names``, ``params``, ``std_errors``, ``covariance``, …), equal
    to ``Experiment.fit`` on an experiment with the same sections. Raises ``ValueError``
    naming the argument or key at fault, ``TypeError`` for a record that is not a mapping.
    Each call reads the experiment its arguments spell: for many fits of one set-up, make an
    ``Experiment`` once and call its ``fit``.

    Example::

        record = jitterid.simulate(G, J, u, samples=200, interval=1.0, noise_std=0.01)
        fit = jitterid.fit(dict(record, input=u), G, J, "bcls", noise_std=0.01)
        fit.params, fit.std_errors
    """
    if not isinstance(record, Mapping) or "y" not in record:
        raise TypeError("record: expected a mapping with at least `y`")
    parts = set(estimate)
    unknown = parts - {"system", "jitter", "noise"}
    if unknown:
        raise ValueError(f"estimate: unknown part(s) {sorted(unknown)}; expected 'system', 'jitter' or 'noise'")
    y = np.asarray(record["y"], dtype=float)
    t = record.get("t")
    if interval is None:
        interval = record.get("T")
        if interval is None and t is not None and len(t) > 1:
            interval = (float(t[-1]) - float(t[0])) / (len(t) - 1)
        if interval is None:
            raise ValueError("interval: not given and the record has no `T` or `t` to take it from")
    if start is None:
        start = record.get("t0", float(t[0]) if t is not None and len(t) else 0.0)
    sections: dict = {"sampling": {"interval": float(interval), "samples": int(y.size), "start": float(start)}}
    if input is None:
        input = record.get("input")
    if input is None and record.get("input_t") is not None:
        u = np.asarray(record["input_u"], dtype=float)
        t_in = np.asarray(record["input_t"], dtype=float)
        sections["input"] = {"kind": "piecewise", "times": t_in.tolist(),
                             "values": (u[:-1] if len(u) >= 2 and u[-1] == 0.0 else u).tolist()}
    elif input is not None:
        sections["input"] = json.loads(input.section_json())
    sections["system"] = dict(system.spec, estimate="system" in parts)
    sections["jitter"] = dict(jitter.spec, estimate="jitter" in parts)
    sections["noise"] = {"std": float(noise_std), "estimate": "noise" in parts}
    sections["estimate"] = {"method": method, **dict(options or {})}
    from ._spec import spec_json

    exp = Experiment.from_sections(spec_json(sections), "fit arguments")
    return exp.fit({"y": y})
