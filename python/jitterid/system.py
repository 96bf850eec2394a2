"""Systems: transfer functions in zero-pole-gain and coefficient form, by the library's
signal registry, with ``frequency_response(f)``, ``step(t)`` and conversions::

    from jitterid import System
    g = System.zpk(zeros=[-0.5], poles=[-0.25 + 0.3j, -0.25 - 0.3j], gain=0.2)
    h = System.tf(num=[0.2, 0.1], den=[1.0, 0.5, 0.1525])
    g.frequency_response([0.0, 0.1]), g.step([0.0, 1.0]), g.to_tf(), g.to_ss()
"""

from __future__ import annotations

import json
from typing import Any, Dict, List, Tuple

import numpy as np

from . import _jitterid
from ._spec import SpecTable, real_array, real_number, spec_json

__all__ = ["System", "from_name", "kinds"]


class System(SpecTable, _jitterid.System):
    """A system of the library's registry (``from_name``), driven by a known input."""

    @staticmethod
    def zpk(zeros: Any, poles: Any, gain: float) -> "System":
        """``gain · Π(s − z) / Π(s − p)``; complex roots come in conjugate pairs, listed in full."""
        return System(System.from_zpk(zeros, poles, real_number(gain, "gain")).spec_json)

    @staticmethod
    def tf(num: Any, den: Any) -> "System":
        """``N(s)/A(s)`` from coefficients, highest power first."""
        return from_name("tf", num=real_array(num, "num"), den=real_array(den, "den"))

    @property
    def names(self) -> List[str]:
        """Names of the parameters, in the estimator's order."""
        return list(self.param_names)

    def to_tf(self) -> "System":
        """The same system in coefficient form."""
        num, den = self.tf_coefficients()
        return System.tf(num, den)

    def to_zpk(self) -> "System":
        """The same system in zero-pole-gain form."""
        z, p, k = self.zpk_form()
        return System.zpk(z, p, k)

    def to_ss(self) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """The controllable canonical realisation ``(A, B, C, D)``."""
        return self.state_space()

    def __reduce__(self) -> Any:
        return (System, (self.spec_json,))


def from_name(kind: str, **keys: Any) -> System:
    """The system of registry kind ``kind`` with its keys (``from_name("zpk", gain=0.2,
    zeros=[-0.5], poles=[[-0.25, 0.3]])``: a pair as ``[re, im]``). Unknown kinds and keys
    raise ``ValueError`` naming them."""
    return System(spec_json({"kind": kind, **keys}))


def kinds() -> List[Dict[str, Any]]:
    """The registry's kinds: name, summary, keys, whether they need an input."""
    return json.loads(_jitterid.system_kinds())
