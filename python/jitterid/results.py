"""Results: a fit (``Experiment.fit``) and a Monte Carlo study (``montecarlo``, ``merge``).

Both keep the command line's JSON (``to_dict()``) and pickle through it, so Dask can ship them.
"""

from __future__ import annotations

import copy
import json
from typing import Any, Dict, List, Mapping, Optional

import numpy as np


def _table(data: Any, what: str) -> None:
    """Refuses ``data`` that is not a mapping (what ``to_dict()`` gives) with ``TypeError``; a
    mapping without the keys of ``what`` raises ``KeyError`` naming the key."""
    if not isinstance(data, Mapping):
        raise TypeError(f"data: expected the mapping of {what} (as to_dict() gives it), found {type(data).__name__}")

__all__ = ["FitResult", "MonteCarloResult"]


class FitResult:
    """One fit, equal to ``jitterid fit --json`` on the same record.

    Attributes: ``method``, ``names``, ``params``, ``std_errors`` (NaN where not defined),
    ``cost``, ``iterations``, ``termination``, ``converged``, ``noise_std``, the fitted
    ``model`` (spec tables of the signal and the jitter, the noise parameters and level) and
    ``jitter`` (the fitted jitter model). ``covariance`` is the estimator's asymptotic
    covariance (``None`` where not defined) of the parameters ``covariance_names``: the
    estimated ones, in the estimator's order; ``names`` may add derived values (a profiled
    uniform-sum ``n`` and its ``σ``, a noise level estimated from the residuals).
    """

    _EXTRA = ("fitted_model", "estimated", "estimator_covariance")

    def __init__(self, data: Dict[str, Any]) -> None:
        _table(data, "a fit")
        self._data: Optional[Dict[str, Any]] = data
        self._fit: Any = None
        self.method: str = data["method"]
        self.converged: bool = data["converged"]
        self.cost: float = data["cost"]
        self.iterations: int = data["iterations"]
        self.termination: str = data["termination"]
        self.noise_std: float = data["noise_std"]
        params = data["parameters"]
        self.names: List[str] = [p["name"] for p in params]
        self.params: np.ndarray = np.array([p["estimate"] for p in params], dtype=float)
        self.std_errors: np.ndarray = np.array(
            [np.nan if p["stderr"] is None else p["stderr"] for p in params], dtype=float
        )
        cov = data.get("estimator_covariance")
        self.covariance_names: List[str] = list(data.get("estimated", []))
        self.covariance: Optional[np.ndarray] = None if cov is None else np.array(cov, dtype=float)

    @classmethod
    def _of(cls, fit: Any) -> "FitResult":
        """The result of the library's fit ``fit`` (``_jitterid.Fit``): its numbers now, the
        command line's JSON when first wanted."""
        self = cls.__new__(cls)
        self._data = None
        self._fit = fit
        (self.method, self.converged, self.cost, self.iterations, self.termination, self.noise_std,
         self.names, self.params, self.std_errors, self.covariance_names, self.covariance) = fit.fields()
        return self

    def _json(self) -> Dict[str, Any]:
        if self._data is None:
            self._data = json.loads(self._fit.json())
        return self._data

    @property
    def model(self) -> Dict[str, Any]:
        """The fitted model: spec tables of the ``signal`` and the ``jitter``, the ``noise``
        parameters and ``noise_std``."""
        return self._json()["fitted_model"]

    @property
    def jitter(self):
        """The fitted jitter model."""
        from .jitter import from_name

        spec = dict(self.model["jitter"])
        return from_name(spec.pop("family"), **spec)

    def __getitem__(self, name: str) -> float:
        """The estimate of parameter ``name``."""
        try:
            return float(self.params[self.names.index(name)])
        except ValueError:
            raise KeyError(f"no parameter {name!r}; parameters: {', '.join(self.names)}") from None

    def to_dict(self, model: bool = False) -> Dict[str, Any]:
        """The command line's ``fit --json`` output (with the fitted model and the covariance
        if ``model``)."""
        d = copy.deepcopy(self._json())
        if not model:
            for key in self._EXTRA:
                d.pop(key, None)
        return d

    def __reduce__(self) -> Any:
        return (FitResult, (self._json(),))

    def __repr__(self) -> str:
        rows = ", ".join(f"{n}={v:.6g}" for n, v in zip(self.names, self.params))
        state = "converged" if self.converged else "not converged"
        return f"FitResult({self.method}, {state}, {rows})"


class MonteCarloResult:
    """A Monte Carlo study (or one shard of it), equal to ``jitterid montecarlo --json``.

    ``names``, ``truth``, ``mean``, ``std``, ``se``, ``rmse`` are per parameter (NaN where
    undefined); ``runs``, ``converged``, ``terminations``, ``seconds``, ``seed``, ``method``;
    a shard also holds ``shard`` and the per-run ``estimates`` (runs × parameters).
    """

    def __init__(self, data: Dict[str, Any]) -> None:
        _table(data, "a Monte Carlo study")
        self._data = data
        params = data["parameters"]

        def column(key: str) -> np.ndarray:
            return np.array([np.nan if p[key] is None else p[key] for p in params], dtype=float)

        self.method: str = data["method"]
        self.runs: int = data["runs"]
        self.converged: int = data["converged"]
        self.terminations: Dict[str, int] = dict(data["terminations"])
        self.seconds: float = data["seconds"]
        self.seed: int = data["seed"]
        self.names: List[str] = [p["name"] for p in params]
        self.truth = column("true")
        self.mean = column("mean")
        self.std = column("std")
        self.se = column("se")
        self.rmse = column("rmse")
        self.shard: Optional[Dict[str, int]] = data.get("shard")
        runs = data.get("realizations")
        self.estimates: Optional[np.ndarray] = (
            None
            if runs is None
            else np.array([[np.nan if v is None else v for v in r["values"]] for r in runs], dtype=float).reshape(
                len(runs), len(self.names)
            )
        )

    def to_dict(self) -> Dict[str, Any]:
        """The command line's ``montecarlo --json`` (or ``merge --json``) output."""
        return copy.deepcopy(self._data)

    def __reduce__(self) -> Any:
        return (MonteCarloResult, (self._data,))

    def __repr__(self) -> str:
        rows = ", ".join(f"{n}={m:.6g}±{s:.2g}" for n, m, s in zip(self.names, self.mean, self.std))
        return f"MonteCarloResult({self.method}, {self.converged}/{self.runs} converged, {rows})"
