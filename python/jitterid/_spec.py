"""Keyword arguments to the library's spec tables (JSON objects), and arguments in: numbers and
arrays checked as the extension checks them, naming the argument at fault."""

from __future__ import annotations

import json
import numbers
import operator
from typing import Any, Dict, Mapping

import numpy as np


def _plain(value: Any) -> Any:
    """A JSON-ready value: NumPy scalars and arrays become Python numbers and lists."""
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


def _check_plain(value: Any, where: str) -> None:
    """Refuses what JSON cannot spell in a plain value, naming where it is (``where``)."""
    if isinstance(value, float) and not np.isfinite(value):
        raise ValueError(f"{where}: expected a finite number, found {value}")
    if isinstance(value, dict):
        for k, v in value.items():
            _check_plain(v, f"{where}.{k}")
    elif isinstance(value, list):
        for i, v in enumerate(value):
            _check_plain(v, f"{where}[{i}]")
    elif not (value is None or isinstance(value, (str, int, float))):
        raise TypeError(f"{where}: expected a number, text, list or table, found {type(value).__name__}")


def spec_json(table: Mapping[str, Any]) -> str:
    """The spec table ``table`` as the JSON text the registries read.

    NaN and infinity (which JSON cannot spell) raise ``ValueError``, values of other types
    (complex numbers, objects) ``TypeError``, naming the key, and the element within it
    (``terms[1].sigma``).
    """
    plain = _plain(dict(table))
    for key, value in plain.items():
        _check_plain(value, f"`{key}`")
    return json.dumps(plain, allow_nan=False)


def real_array(value: Any, name: str) -> np.ndarray:
    """``value`` (a number or an array-like of real numbers) as a float64 array.

    Refused as the extension refuses it, before any conversion (which would turn ``None`` into
    NaN and drop an imaginary part with only a warning): ``None``, text, objects and complex
    values raise ``TypeError``, a ragged nesting ``ValueError``, each naming ``name``.
    Finiteness is left to the caller (the extension names the element at fault).
    """
    if value is None:
        raise TypeError(f"{name}: expected real numbers (a number or an array of them), found None")
    try:
        a = np.asarray(value)
    except (TypeError, ValueError) as e:
        raise ValueError(f"{name}: not an array of real numbers: {e}") from None
    if a.dtype.kind == "c":
        raise TypeError(f"{name}: expected real numbers, found complex values (pass their .real or abs() if that "
                        "is what is meant)")
    if a.dtype.kind not in "biuf":
        found = f"a value of type {type(value).__name__}" if a.ndim == 0 else f"an array of dtype {a.dtype}"
        raise TypeError(f"{name}: expected real numbers, found {found}")
    return a.astype(np.float64)


def real_number(value: Any, name: str) -> float:
    """``value`` (an int, a float or a NumPy real scalar) as a float; anything else (``None``,
    text, a complex number, an array) raises ``TypeError`` naming ``name``. Whether the value is
    in range is the library's to say."""
    if isinstance(value, numbers.Real) or (isinstance(value, np.ndarray) and value.ndim == 0
                                            and value.dtype.kind in "biuf"):
        return float(value)
    raise TypeError(f"{name}: expected a real number, found {type(value).__name__}")


def integer(value: Any, name: str) -> int:
    """``value`` (an int or a NumPy integer) as an int; a float, text or ``None`` raises
    ``TypeError`` naming ``name`` (``int(2.7)`` would quietly give 2)."""
    try:
        return operator.index(value)
    except TypeError:
        raise TypeError(f"{name}: expected an integer, found {type(value).__name__}") from None


class SpecTable:
    """What a registry object (a jitter model, a system) shows of its spec table: mixed into
    the Python classes over the extension's, which provide ``param_names``, ``param_values``
    and ``spec_json``."""

    param_names: Any
    param_values: Any
    spec_json: str

    @property
    def params(self) -> Dict[str, float]:
        """The (continuous) parameters by name, in the estimator's order."""
        return dict(zip(self.param_names, self.param_values))

    @property
    def spec(self) -> Dict[str, Any]:
        """The spec table that rebuilds this object (``from_name(**spec)``)."""
        return json.loads(self.spec_json)
