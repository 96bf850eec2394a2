"""Keyword arguments to the library's spec tables (JSON objects), and arrays in."""

from __future__ import annotations

import json
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


def spec_json(table: Mapping[str, Any]) -> str:
    """The spec table ``table`` as the JSON text the registries read.

    ``allow_nan=False`` refuses NaN and infinity here with the offending key in the message,
    since JSON has no spelling for them.
    """
    plain = _plain(dict(table))
    for key, value in plain.items():
        if isinstance(value, float) and not np.isfinite(value):
            raise ValueError(f"`{key}`: expected a finite number, found {value}")
    try:
        return json.dumps(plain, allow_nan=False)
    except (TypeError, ValueError) as e:
        raise TypeError(f"spec table: {e}") from None


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
