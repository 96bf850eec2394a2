"""A grey-box model's matrices from a Python callable, traced into the expression language of
``docs/experiments.md`` (``"-k/m"``).

The callable is called once with symbols in place of its parameters; arithmetic on them and
NumPy's elementwise functions (``np.sqrt``, ``np.exp``, ``np.log``, ``np.sin``, ``np.cos``,
``np.tan``, ``np.abs``) build expression texts, which the library parses and differentiates
exactly (forward mode), as it does the texts an experiment file gives. So a callable model is
fitted, simulated, pickled and written to an experiment file like a written one, and its
gradient is analytic. What a text cannot say is refused with ``ValueError`` naming it: a
branch on a parameter's value (``if k > 0``), ``math.sqrt`` (use ``np.sqrt``), a function the
language does not have.
"""

from __future__ import annotations

import numbers
from typing import Any, Callable, Dict, List, Sequence

import numpy as np

# Precedence of what a text is, as the grammar reads it: a sum, a product, a signed term, a
# power, an atom (a number, a name, a call, a parenthesised text).
_SUM, _PRODUCT, _UNARY, _POWER, _ATOM = range(1, 6)

class _Refused(Exception):
    """What the expression language cannot say."""


class Symbol:
    """A parameter, or an expression of parameters, while the callable is traced."""

    __slots__ = ("text", "level")

    def __init__(self, text: str, level: int = _ATOM) -> None:
        self.text = text
        self.level = level

    def _at(self, level: int) -> str:
        return self.text if self.level >= level else f"({self.text})"

    @staticmethod
    def _of(x: Any) -> "Symbol":
        if isinstance(x, Symbol):
            return x
        if isinstance(x, (bool, np.bool_)) or not isinstance(x, numbers.Real):
            raise _Refused(f"a value of type {type(x).__name__} in an expression of the parameters")
        v = float(x)
        if not np.isfinite(v):
            raise _Refused(f"the number {v} in an expression of the parameters")
        text = repr(v)
        return Symbol(text, _UNARY if v < 0 or text.startswith("-") else _ATOM)

    def _binary(self, other: Any, op: str, level: int, right: bool) -> Any:
        if isinstance(other, np.ndarray) and other.ndim:
            # NumPy maps the operation over the array's elements.
            return NotImplemented
        a, b = (Symbol._of(other), self) if right else (self, Symbol._of(other))
        if op == "^":
            return Symbol(f"{a._at(_ATOM)}^{b._at(_UNARY)}", _POWER)
        return Symbol(f"{a._at(level)} {op} {b._at(level + 1)}", level)

    def __neg__(self) -> "Symbol":
        return Symbol(f"-{self._at(_UNARY)}", _UNARY)

    def __pos__(self) -> "Symbol":
        return self

    def __abs__(self) -> "Symbol":
        return self._call("abs")

    def _call(self, name: str) -> "Symbol":
        return Symbol(f"{name}({self.text})", _ATOM)

    def _refuse(self, *_: Any) -> Any:
        raise _Refused(f"a comparison or a branch on the value of {self.text}: the matrices must be the same "
                       "expressions of the parameters for every value")

    __lt__ = __le__ = __gt__ = __ge__ = __bool__ = _refuse  # type: ignore[assignment]

    def __float__(self) -> float:
        raise _Refused(f"{self.text} taken as a number (math.sqrt and the like); use numpy's functions "
                       "(np.sqrt, np.exp, …), which keep it an expression")

    __int__ = __index__ = __complex__ = __float__  # type: ignore[assignment]

    def __repr__(self) -> str:
        return f"Symbol({self.text!r})"


def _operator(op: str, level: int, right: bool) -> Callable[[Symbol, Any], Any]:
    return lambda self, other: self._binary(other, op, level, right)


def _function(name: str) -> Callable[[Symbol], Symbol]:
    return lambda self: self._call(name)


# The operators, each also with the number on its left (`2 * k`).
for _name, _op, _level in (("add", "+", _SUM), ("sub", "-", _SUM), ("mul", "*", _PRODUCT),
                           ("truediv", "/", _PRODUCT), ("pow", "^", _POWER)):
    setattr(Symbol, f"__{_name}__", _operator(_op, _level, False))
    setattr(Symbol, f"__r{_name}__", _operator(_op, _level, True))
# NumPy's elementwise functions call these methods on the elements of an object array.
for _name, _text in (("sqrt", "sqrt"), ("exp", "exp"), ("log", "ln"), ("sin", "sin"), ("cos", "cos"),
                     ("tan", "tan")):
    setattr(Symbol, _name, _function(_text))


def _entries(value: Any, name: str, shape: str) -> List[List[Any]]:
    """A returned matrix as rows of texts and numbers (a vector as the column or row the matrix
    must be: ``b`` a column, ``c`` a row; a scalar ``d`` as ``[[d]]``)."""
    a = np.asarray(value, dtype=object)
    if a.ndim == 0:
        a = a.reshape(1, 1)
    elif a.ndim == 1:
        a = a.reshape(-1, 1) if shape == "column" else a.reshape(1, -1)
    if a.ndim != 2:
        raise ValueError(f"matrices: {name} has {a.ndim} dimensions; expected a matrix")
    rows = []
    for i, row in enumerate(a.tolist()):
        out = []
        for j, x in enumerate(row):
            try:
                s = Symbol._of(x)
            except _Refused as e:
                raise ValueError(f"matrices: {name}[{i}][{j}]: {e}") from None
            out.append(s.text if isinstance(x, Symbol) else float(x))
        rows.append(out)
    return rows


def matrices_of(callable_: Callable[..., Any], names: Sequence[str]) -> Dict[str, Any]:
    """The keys ``a``, ``b``, ``c`` and ``d`` of the matrices ``callable_`` returns, called with
    a symbol for each of ``names`` (keyword arguments): ``(A, B, C)`` or ``(A, B, C, D)``."""
    if not callable(callable_):
        raise TypeError(f"matrices: expected a callable returning (A, B, C[, D]), found {type(callable_).__name__}")
    try:
        returned = callable_(**{n: Symbol(n) for n in names})
    except _Refused as e:
        raise ValueError(f"matrices: the callable cannot be written as expressions of its parameters: {e}") from None
    except (TypeError, AttributeError) as e:
        # NumPy's message for a function a symbol has no method for, or a wrong signature.
        raise ValueError(f"matrices: the callable, called with the parameters {list(names)} as keyword arguments "
                         f"(symbols: arithmetic and numpy's sqrt, exp, log, sin, cos, tan, abs), raised "
                         f"{type(e).__name__}: {e}") from None
    if not isinstance(returned, (tuple, list)) or len(returned) not in (3, 4):
        raise ValueError("matrices: expected the callable to return (A, B, C) or (A, B, C, D)")
    keys = {"a": _entries(returned[0], "A", "matrix"), "b": _entries(returned[1], "B", "column"),
            "c": _entries(returned[2], "C", "row")}
    if len(returned) == 4:
        keys["d"] = _entries(returned[3], "D", "row")
    return keys
