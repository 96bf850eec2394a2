"""Type stubs of the compiled core (the public API is in ``jitterid`` and ``jitterid.jitter``)."""

from os import PathLike
from typing import Any, Callable, List, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

class Jitter:
    """A jitter model: the pdf of the sampling-time error ``τ``."""

    def __new__(cls, spec: str) -> Jitter: ...
    @staticmethod
    def from_std_dev(name: str, sigma: float, spec: str) -> Jitter: ...
    @property
    def family(self) -> str: ...
    @property
    def spec_json(self) -> str: ...
    @property
    def param_names(self) -> list[str]: ...
    @property
    def param_values(self) -> list[float]: ...
    @property
    def std(self) -> float:
        """Standard deviation of ``τ`` (s)."""
    @property
    def mean(self) -> float:
        """Mean of ``τ`` (s)."""
    @property
    def variance(self) -> float:
        """Variance of ``τ`` (s²)."""
    def cf(self, f: npt.ArrayLike) -> npt.NDArray[np.complex128]:
        """Characteristic function ``γ(f) = E[exp(-i2πfτ)]`` at frequencies ``f`` (Hz)."""
    def mgf(self, z: npt.ArrayLike) -> npt.NDArray[np.complex128]:
        """Moment generating function ``E[exp(zτ)]``; NaN where it does not exist."""
    def pdf(self, t: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """Density of ``τ`` at ``t`` (1/s)."""
    def sample(self, size: int, seed: int) -> npt.NDArray[np.float64]:
        """``size`` independent draws of ``τ`` from a generator seeded with ``seed``."""

class Experiment:
    """An experiment in the command line's TOML format."""

    def __new__(
        cls, text: str, file: str = "<string>", dir: str = ".", *, allow_paths_outside: bool = False
    ) -> Experiment: ...
    @classmethod
    def from_toml(cls, path: Union[str, PathLike[str]], *, allow_paths_outside: bool = False) -> Experiment: ...
    @property
    def file(self) -> str: ...
    @property
    def title(self) -> Optional[str]: ...
    @property
    def text(self) -> str: ...
    @property
    def method(self) -> str: ...
    @property
    def samples(self) -> int: ...
    @property
    def interval(self) -> float: ...
    @property
    def start(self) -> float: ...
    @property
    def fingerprint(self) -> str: ...
    @property
    def random_input(self) -> bool: ...
    def simulate(self, seed: int = ..., run: int = 0, truth: bool = False) -> dict[str, npt.NDArray[np.float64]]:
        """Record ``run`` under master ``seed``, as ``jitterid simulate`` writes it."""
    @classmethod
    def from_sections(cls, sections: str, file: str) -> Experiment:
        """The experiment whose sections are the tables of ``sections`` (JSON text)."""
    def fit_record(
        self,
        y: npt.ArrayLike,
        input_t: Optional[npt.ArrayLike] = None,
        input_u: Optional[npt.ArrayLike] = None,
        method: Optional[str] = None,
        t: Optional[npt.ArrayLike] = None,
        progress: Optional[Callable[[int, float], Any]] = None,
        init: Optional[str] = None,
    ) -> Fit:
        """Fits the samples ``y`` (with the random input's realisation; ``t``, if given, on the
        experiment's grid) as ``jitterid fit [--init]``; ``progress(iteration, cost)`` follows
        the solver, and Ctrl-C or an exception it raises stops it."""

class Fit:
    """One fit as the library returns it (``jitterid.FitResult`` reads it)."""

    def fields(
        self,
    ) -> Tuple[
        str, bool, float, int, str, float, list[str], npt.NDArray[np.float64], npt.NDArray[np.float64], list[str],
        Optional[npt.NDArray[np.float64]],
    ]:
        """``(method, converged, cost, iterations, termination, noise_std, names, params, std_errors,
        covariance_names, covariance)``."""
    def json(self) -> str:
        """``jitterid fit --json`` with ``fitted_model``, ``estimated``, ``estimator_covariance``."""
    def bode(self) -> Optional[dict[str, npt.NDArray[np.float64]]]:
        """The fitted system's Bode diagram with ±2σ bands (``validate --bode``)."""
    def step_response(self) -> Optional[dict[str, npt.NDArray[np.float64]]]:
        """The fitted system's step response with its ±2σ band."""
    @property
    def system_spec_json(self) -> str:
        """The fitted system's spec table, as JSON text."""

class Validated:
    """A validated model (``jitterid.ValidationResult`` reads it)."""

    def json(self) -> str:
        """``jitterid validate --json``."""
    def bode(self) -> Optional[dict[str, npt.NDArray[np.float64]]]: ...
    def step(self) -> Optional[dict[str, npt.NDArray[np.float64]]]: ...
    def records(self) -> dict[str, dict[str, npt.NDArray[np.float64]]]: ...
    @property
    def system_spec_json(self) -> str: ...
    @property
    def noise_std(self) -> float: ...

def design(
    experiment: Experiment, criterion: Optional[str], jitter_blind_design: bool, budget: Optional[str],
    input_name: Optional[str], derived: Optional[List[str]] = None, dac_rate: Optional[float] = None,
) -> Tuple[str, Optional[Tuple[str, str]]]:
    """``design --json``'s text, and with ``input_name`` the designed input's CSV and experiment texts
    (a designed multisine's CSV: its sample sequence at ``dac_rate`` Hz)."""
def validate(
    experiment: Experiment,
    y: npt.ArrayLike,
    input_t: Optional[npt.ArrayLike] = None,
    input_u: Optional[npt.ArrayLike] = None,
    t: Optional[npt.ArrayLike] = None,
    validation_y: Optional[npt.ArrayLike] = None,
    validation_t: Optional[npt.ArrayLike] = None,
    validation_input_t: Optional[npt.ArrayLike] = None,
    validation_input_u: Optional[npt.ArrayLike] = None,
    fit_json: Optional[str] = None,
    level: float = 0.01,
    method: Optional[str] = None,
) -> Validated:
    """``jitterid validate [--validation] [--model] [--level]`` on records in memory."""
def select(experiment: Experiment, data: str, validation: Optional[str] = None, time_limit: Optional[float] = None) -> str:
    """``jitterid select --json`` on the data files ``data`` (and ``validation``)."""

def jitter_families() -> str: ...
def montecarlo(
    experiment: Experiment,
    runs: int = 128,
    seed: int = ...,
    shard: Optional[Tuple[int, int]] = None,
    method: Optional[str] = None,
    threads: Optional[int] = None,
    progress: Optional[Callable[[int, int], Any]] = None,
) -> str: ...
def merge(shards: list[str]) -> str: ...
def read_record(path: str, input: Optional[str] = None) -> dict[str, npt.NDArray[np.float64]]: ...


class System:
    """A system of the signal registry (rational kinds also in tf/zpk/state-space form)."""

    def __new__(cls, spec: str) -> System: ...
    @staticmethod
    def from_zpk(zeros: npt.ArrayLike, poles: npt.ArrayLike, gain: float) -> System: ...
    @staticmethod
    def several(names: list[str], systems: list[System], shared: bool) -> System:
        """One system per input, added; ``shared``: the columns of one grey-box model."""
    @property
    def inputs(self) -> Optional[list[str]]:
        """The input names of a system with several inputs, ``None`` for one."""
    @property
    def channels(self) -> Optional[list[System]]:
        """Each input's system, in input order, ``None`` for a system with one input."""
    @property
    def kind(self) -> str: ...
    @property
    def spec_json(self) -> str: ...
    @property
    def param_names(self) -> list[str]: ...
    @property
    def param_values(self) -> list[float]: ...
    def tf_coefficients(self) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """``(num, den)``, highest power first, ``den`` monic."""
    def zpk_form(self) -> Tuple[npt.NDArray[np.complex128], npt.NDArray[np.complex128], float]:
        """Zeros, poles (pairs in full) and gain."""
    def state_space(
        self,
    ) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]:
        """The controllable canonical realisation ``(A, B, C, D)``."""
    @property
    def delay(self) -> Optional[float]:
        """The input delay ``D`` (s), ``None`` without one."""
    def frequency_response(self, f: npt.ArrayLike) -> npt.NDArray[np.complex128]:
        """``G(i2πf) e^{−i2πfD}`` at ``f`` (Hz), ``D`` the input delay (0 without one)."""
    def step(self, t: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """The unit-step response at ``t`` (s), exact."""

class Input:
    """A known input ``u(t)``."""

    def __new__(cls, json: str) -> Input: ...
    @staticmethod
    def piecewise(edges: npt.ArrayLike, levels: npt.ArrayLike) -> Input: ...
    @staticmethod
    def zero_order_hold(values: npt.ArrayLike, interval: float, start: float) -> Input: ...
    @staticmethod
    def random_binary(start: float, end: float, seed: int, mean_dwell: float, low: float, high: float) -> Input: ...
    @staticmethod
    def multisine(
        frequencies: npt.ArrayLike, amplitudes: Optional[npt.ArrayLike] = None, phases: Optional[npt.ArrayLike] = None
    ) -> Input: ...
    @property
    def kind(self) -> str: ...
    @property
    def edges(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def levels(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def tones(self) -> list[Tuple[float, float, float]]: ...
    def value(self, t: npt.ArrayLike) -> npt.NDArray[np.float64]:
        """``u(t)`` at ``t`` (s)."""
    def to_json(self) -> str: ...
    def section_json(self) -> str: ...

def system_kinds() -> str: ...
def simulate(
    system: System, jitter: Jitter, inputs: list[Input], samples: int, interval: float, start: float,
    noise_std: float, seed: int, truth: bool,
) -> dict[str, Any]: ...
def first_moment(
    system: System, jitter: Jitter, inputs: list[Input], samples: int, interval: float, start: float
) -> npt.NDArray[np.float64]: ...
def second_moment(
    system: System, jitter: Jitter, inputs: list[Input], samples: int, interval: float, start: float,
    noise_std: float,
) -> npt.NDArray[np.float64]: ...
