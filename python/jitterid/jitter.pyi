"""Type stubs of ``jitterid.jitter``: the family classes are made from the library's registry at
import, so their signatures are spelled here for IDEs and type checkers
(``python/tests/test_records.py`` holds this file to the registry). The family ``none`` is the
class ``getattr(jitter, "None")``, a name a stub cannot spell."""

from typing import Any, Dict, List, overload


from . import _jitterid
from ._spec import SpecTable

__all__: List[str]

class Jitter(SpecTable, _jitterid.Jitter):
    """A jitter model built from the registry (see ``from_name``)."""

    family_name: str

def from_name(family: str, **keys: Any) -> Jitter:
    """The member of ``family`` with the family's keys, e.g. ``from_name("gaussian", sigma=0.1)``."""

def from_std(family: str, sigma: float, **keys: Any) -> Jitter:
    """The member of ``family`` with standard deviation ``sigma`` (s)."""

def families() -> List[Dict[str, Any]]:
    """The registry's families with their keys."""

class UniformSum(Jitter):
    @overload
    def __new__(cls, n: int, a: float) -> UniformSum: ...
    @overload
    def __new__(cls, *, a: float, n: int = 0) -> UniformSum: ...

class Gaussian(Jitter):
    def __new__(cls, sigma: float) -> Gaussian: ...

class Laplace(Jitter):
    def __new__(cls, scale: float) -> Laplace: ...

class TwoPoint(Jitter):
    def __new__(cls, d: float) -> TwoPoint: ...

class Exponential(Jitter):
    def __new__(cls, mean: float) -> Exponential: ...

class Periodic(Jitter):
    def __new__(cls, amplitude: float) -> Periodic: ...

class Sum(Jitter):
    def __new__(cls, terms: list[dict[str, Any]]) -> Sum: ...

class Mixture(Jitter):
    def __new__(cls, terms: list[dict[str, Any]], weights: list[float], fixed_weights: bool = False) -> Mixture: ...
