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

def _system_of(signal_spec: str) -> Any:
    """The system of a fitted signal's spec table: the signal without its free response (the
    keys ``initial`` and ``origin``, the state at the record's first instant)."""
    from .system import System

    spec = json.loads(signal_spec)
    for key in ("initial", "origin"):
        spec.pop(key, None)
    return System(json.dumps(spec))


__all__ = ["DesignResult", "FitResult", "MonteCarloResult", "SelectionResult", "ValidationResult"]


class FitResult:
    """One fit, equal to ``jitterid fit --json`` on the same record.

    Attributes: ``method``, ``names``, ``params``, ``std_errors`` (NaN where not defined),
    ``cost``, ``iterations``, ``termination``, ``converged``, ``noise_std``; ``system`` (the
    fitted system, a ``System``), ``jitter`` (the fitted jitter model), ``model`` (the fitted
    system's export forms ``zpk``, ``tf``, ``ss`` and ``delay``, as ``to_dict()["model"]``)
    and ``fitted_model`` (the spec tables of the fitted signal and jitter, the noise
    parameters and level). ``covariance`` is the estimator's asymptotic covariance (``None``
    where not defined) of the parameters ``covariance_names``: the estimated ones, in the
    estimator's order; ``names`` may add derived values (a profiled uniform-sum ``n`` and its
    ``σ``, a noise level estimated from the residuals).

    ``bode()`` and ``step()`` give the fitted system's Bode diagram (dB, degrees) and step
    response with ±2σ bands from the covariance, as ``jitterid validate --bode`` and
    ``--plot`` compute them.
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
    def fitted_model(self) -> Dict[str, Any]:
        """The fitted model's parts as spec tables: the ``signal`` (system), the ``jitter``, the
        ``noise`` parameters and ``noise_std``."""
        return self._json()["fitted_model"]

    @property
    def model(self) -> Optional[Dict[str, Any]]:
        """The fitted system's export forms, as ``jitterid fit --json`` gives them under
        ``model``: ``zpk`` (zeros, poles, gain), ``tf`` (num, den), ``ss`` (a, b, c, d) and, for a
        delayed system, ``delay``; ``None`` for a system that is not rational. ``system`` gives
        the same system as a ``System``."""
        return copy.deepcopy(self._json().get("model"))

    @property
    def system(self):
        """The fitted system ``G(s) e^{−sD}``, a ``System`` (with ``frequency_response``,
        ``step``, ``to_control()``, ``to_scipy()``); a free response estimated from the record's
        initial state is the record's, not the system's, and is left out."""
        spec = self._fit.system_spec_json if self._fit is not None else json.dumps(self.fitted_model["signal"])
        return _system_of(spec)

    @property
    def jitter(self):
        """The fitted jitter model."""
        from .jitter import from_name

        spec = dict(self.fitted_model["jitter"])
        return from_name(spec.pop("family"), **spec)

    def _library_fit(self, what: str) -> Any:
        if self._fit is None:
            raise ValueError(f"{what}: this result was rebuilt from its JSON (unpickled or made from a dict), which "
                             "has no covariance of the system's parameters; call it on the result of the fit itself")
        return self._fit

    def bode(self) -> Optional[Dict[str, np.ndarray]]:
        """The fitted system's Bode diagram on 200 frequencies log-spaced from ``1/(NT)`` to the
        Nyquist frequency ``1/(2T)``: a dict of arrays ``f`` (Hz), ``omega`` (rad/s),
        ``magnitude_db``, ``phase_deg`` (unwrapped) and the ±2σ bands ``magnitude_db_lo``,
        ``magnitude_db_hi``, ``phase_deg_lo``, ``phase_deg_hi`` (NaN without a covariance);
        the numbers of ``jitterid validate --bode``. ``None`` for a system that is not rational."""
        return self._library_fit("bode()").bode()

    def step(self) -> Optional[Dict[str, np.ndarray]]:
        """The fitted system's unit-step response on 200 times from the step to 8 time constants
        of its slowest pole (at most the record's duration, plus an input delay): a dict of
        arrays ``t`` (s), ``value`` and the ±2σ band ``lo``, ``hi`` (NaN without a covariance).
        ``None`` for a system that is not rational."""
        return self._library_fit("step()").step_response()

    def __getitem__(self, name: str) -> float:
        """The estimate of parameter ``name``."""
        try:
            return float(self.params[self.names.index(name)])
        except ValueError:
            raise KeyError(f"no parameter {name!r}; parameters: {', '.join(self.names)}") from None

    def to_dict(self, full: bool = False) -> Dict[str, Any]:
        """The command line's ``fit --json`` output; with ``full``, also the ``fitted_model``
        (spec tables), the ``estimated`` parameters' names and the ``estimator_covariance``."""
        d = copy.deepcopy(self._json())
        if not full:
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


class ValidationResult:
    """A validated model, equal to ``jitterid validate --json`` on the same records.

    Attributes: ``level`` (of the tests' verdicts), ``fit_percent`` (``{"estimation": …,
    "validation": …}``, the normalised fit of the expected samples in percent), ``whiteness``
    and ``cross_correlation`` (the estimation record's residual tests: ``test``, ``statistic``,
    ``dof``, ``p_value``, ``passed``, and the per-lag ``lags``, ``values``, ``bound``,
    ``outside``, ``allowed``, ``lags_passed``; ``cross_correlation`` is ``None`` without an
    input), ``flatness`` (of the residual spectrum), ``estimation`` and ``validation`` (each
    record's report; ``validation`` is ``None`` without a validation record), ``passed``
    (every test passed at ``level``), ``system`` (the validated system) and ``noise_std``.

    ``bode()`` and ``step()`` give the system's responses with ±2σ bands (as ``validate
    --bode`` and ``--plot``), ``records()`` each record's samples and the model's expected
    samples.
    """

    def __init__(self, validated: Any) -> None:
        from . import _jitterid

        if not isinstance(validated, _jitterid.Validated):
            raise TypeError(f"validated: expected the library's validation (jitterid.validate makes results), found "
                            f"{type(validated).__name__}")
        self._validated = validated
        self._data: Dict[str, Any] = json.loads(validated.json())
        d = self._data
        self.level: float = d["level"]
        self.fit_percent: Dict[str, Optional[float]] = dict(d["fit_percent"])
        self.whiteness: Dict[str, Any] = d["whiteness"]
        self.cross_correlation: Optional[Dict[str, Any]] = d["cross_correlation"]
        self.flatness: Optional[float] = d["flatness"]
        self.estimation: Dict[str, Any] = d["estimation"]
        self.validation: Optional[Dict[str, Any]] = d["validation"]
        self.noise_std: float = validated.noise_std

    @property
    def passed(self) -> bool:
        """Whether every residual test of every record passed at ``level``."""
        tests = []
        for report in (self.estimation, self.validation):
            if report is not None:
                tests += [report["whiteness"], report["cross_correlation"]]
        return all(t["passed"] for t in tests if t is not None)

    @property
    def system(self):
        """The validated (fitted) system, a ``System`` (see ``FitResult.system``)."""
        return _system_of(self._validated.system_spec_json)

    def bode(self) -> Optional[Dict[str, np.ndarray]]:
        """The system's Bode diagram with ±2σ bands (see ``FitResult.bode``); the numbers of
        ``jitterid validate --bode``."""
        return self._validated.bode()

    def step(self) -> Optional[Dict[str, np.ndarray]]:
        """The system's unit-step response with its ±2σ band (see ``FitResult.step``)."""
        return self._validated.step()

    def records(self) -> Dict[str, Dict[str, np.ndarray]]:
        """``{"estimation": {"t", "y", "expected"}, "validation": {…}}``: each record's times,
        samples and the model's expected samples ``m_k`` on it."""
        return self._validated.records()

    def to_dict(self) -> Dict[str, Any]:
        """The command line's ``validate --json`` output."""
        return copy.deepcopy(self._data)

    def __repr__(self) -> str:
        fits = ", ".join(f"{k} {v:.2f} %" for k, v in self.fit_percent.items() if v is not None)
        return (f"ValidationResult(fit {fits}; whiteness p = {self.whiteness['p_value']:.3g}; "
                f"{'passed' if self.passed else 'failed'} at level {self.level:g})")


class _CommandJson:
    """A result that is the command line's JSON (``_data``): ``to_dict()`` gives it, and it
    pickles through it."""

    _data: Dict[str, Any]

    def to_dict(self) -> Dict[str, Any]:
        """The command line's ``--json`` output."""
        return copy.deepcopy(self._data)

    def __reduce__(self) -> Any:
        return (type(self), (self._data,))


class SelectionResult(_CommandJson):
    """A selection among model orders and jitter families, equal to ``jitterid select --json``.

    ``candidates`` are ranked best first (each a dict: ``poles``, ``zeros``, ``family``,
    ``criterion`` and ``ranked_by``, ``bcls_criterion``, ``likelihood_criterion``,
    ``converged``, ``estimates``, ``validation_fit_percent``, ``failure``); ``best`` is the
    first, ``best_validation`` the one that fits the validation record best (``None`` without
    one).
    """

    def __init__(self, data: Dict[str, Any]) -> None:
        _table(data, "a selection")
        self._data = data
        self.candidates: List[Dict[str, Any]] = data["candidates"]
        self.best: Optional[Dict[str, Any]] = data["best"]
        self.best_validation: Optional[Dict[str, Any]] = data.get("best_validation")


    def __repr__(self) -> str:
        b = self.best
        best = "none" if b is None else f"{b['poles']} poles, {b['zeros']} zeros, {b['family']}"
        return f"SelectionResult({len(self.candidates)} candidates, best: {best})"


class DesignResult(_CommandJson):
    """An experiment design, equal to ``jitterid design --json``: the designed experiment
    (``design``: the free variables' values, ``interval``, ``samples``; ``low`` and ``high``, the
    random binary input's levels, when ``[design] low`` or ``high`` frees them), its predicted standard
    deviations (``predicted``, a dict by parameter name; ``derived`` for derived quantities such
    as the static gain), the same for the experiment file's own design (``baseline``,
    ``baseline_predicted``), and with ``jitter_blind=True`` the design that ignores the jitter
    (``jitter_blind``: its design and its standard deviations under the true, jittered prior).
    A designed multisine (``[design] band``) is ``multisine`` (``frequencies``, ``amplitudes``,
    ``phases``, ``crest_factor``, ``power``; also ``design["multisine"]``) beside the file's own,
    ``baseline_multisine``; both are ``None`` for other designs. Under ``[design]
    jitter_exponent`` (a jitter that follows the sampling interval) ``jitter_std`` and
    ``baseline_jitter_std`` are the jitter's σ at the designed and the file's interval (s);
    ``None`` otherwise.
    """

    def __init__(self, data: Dict[str, Any]) -> None:
        _table(data, "a design")
        self._data = data
        self.criterion: str = data["criterion"]
        self.design: Dict[str, Any] = data["design"]
        self.predicted: Dict[str, float] = {p["name"]: p["std"] for p in data["predicted"]}
        self.derived: Dict[str, float] = {p["name"]: p["std"] for p in data.get("derived", [])}
        base = data.get("baseline") or {}
        self.baseline: Optional[Dict[str, Any]] = base.get("design")
        self.baseline_predicted: Dict[str, float] = {p["name"]: p["std"] for p in base.get("predicted", [])}
        self.jitter_blind: Optional[Dict[str, Any]] = data.get("jitter_blind")
        self.multisine: Optional[Dict[str, Any]] = self.design.get("multisine")
        self.baseline_multisine: Optional[Dict[str, Any]] = (self.baseline or {}).get("multisine")
        self.jitter_std: Optional[float] = data.get("jitter_std")
        self.baseline_jitter_std: Optional[float] = base.get("jitter_std")


    def __repr__(self) -> str:
        design = ", ".join(f"{k}={v:.6g}" for k, v in self.design.items() if isinstance(v, (int, float)))
        if self.multisine is not None:
            design += f", multisine of {len(self.multisine['frequencies'])} tones"
        return f"DesignResult(criterion {self.criterion}: {design})"
