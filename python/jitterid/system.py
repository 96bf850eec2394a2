"""Systems: transfer functions in zero-pole-gain and coefficient form, by the library's
signal registry, with ``frequency_response(f)``, ``step(t)`` and conversions::

    from jitterid import System
    g = System.zpk(zeros=[-0.5], poles=[-0.25 + 0.3j, -0.25 - 0.3j], gain=0.2)
    h = System.tf(num=[0.2, 0.1], den=[1.0, 0.5, 0.1525])
    g.frequency_response([0.0, 0.1]), g.step([0.0, 1.0]), g.to_tf(), g.to_ss()
    g.to_control(), g.to_scipy()       # python-control and SciPy objects (optional packages)

A system with several inputs (``y = Σ G_i u_i``) is ``System.several({"torque": g, "brake":
h})``, or one grey-box model whose ``b`` (and ``d``) have a column per input; ``simulate``,
``fit``, ``first_moment`` and ``second_moment`` drive it with ``inputs=[…]`` (or a dict by
input name). Its parameters are named by input (``torque.b0``); a shared grey-box model's are
the model's own.
"""

from __future__ import annotations

import json
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np

from . import _jitterid
from ._spec import SpecTable, integer, real_array, real_number, spec_json

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

    @staticmethod
    def grey_box(
        params: Dict[str, float],
        a: Any = None,
        b: Any = None,
        c: Any = None,
        d: Any = None,
        fixed: Optional[Dict[str, float]] = None,
        bounds: Optional[Dict[str, Any]] = None,
        inputs: Optional[Sequence[str]] = None,
        matrices: Optional[Callable[..., Any]] = None,
    ) -> "System":
        """``ẋ = A(θ)x + B(θ)u, y = C(θ)x + D(θ)u`` with named physical parameters ``params``
        (``{"m": 1.0, "damp": 0.4, "k": 2.0}``): ``a`` (n×n), ``b`` (n×m), ``c`` (1×n) and ``d``
        (1×m, default 0) are rows of expressions (``"-k/m"``) or numbers; ``fixed`` names known
        constants the expressions may use, ``bounds`` gives ``[lo, hi]`` per parameter. A bad
        expression, shape or value is a ``ValueError`` naming the key and the expression.

        ``matrices``, instead of ``a``, ``b``, ``c``, ``d``: a callable that returns NumPy
        matrices ``(A, B, C)`` or ``(A, B, C, D)`` from the parameters and the fixed constants
        as keyword arguments (``lambda m, damp, k: (np.array([[0, 1], [-k/m, -damp/m]]),
        [0, 1/m], [1, 0])``; a vector ``B`` is the column, ``C`` the row). It is called once,
        with symbols for the parameters, and what it computes (arithmetic and NumPy's ``sqrt``,
        ``exp``, ``log``, ``sin``, ``cos``, ``tan``, ``abs``) becomes the expressions above,
        differentiated exactly; a branch on a parameter's value or a function outside that list
        raises ``ValueError`` saying so.

        With ``m > 1`` columns of ``b`` the model has ``m`` inputs, named ``inputs`` (default
        ``u1``, ``u2``, …), that share its parameters: the experiment file's one grey-box
        ``[system]`` with ``[[input]]`` tables."""
        if matrices is not None:
            given = [k for k, v in (("a", a), ("b", b), ("c", c), ("d", d)) if v is not None]
            if given:
                raise ValueError(f"matrices: give the matrices as a callable or as {', '.join(given)}, not both")
            from ._trace import matrices_of

            names = [str(n) for n in dict(params)] + [str(n) for n in dict(fixed or {})]
            traced = matrices_of(matrices, names)
            a, b, c, d = traced["a"], traced["b"], traced["c"], traced.get("d")
        for key, value in (("a", a), ("b", b), ("c", c)):
            if value is None:
                raise ValueError(f"{key}: a grey-box model needs a, b and c (or matrices, a callable returning them)")
        keys: Dict[str, Any] = {"params": params, "a": a, "c": c}
        for key, value in (("fixed", fixed), ("bounds", bounds)):
            if value is not None:
                keys[key] = value
        columns = _columns(b, "b")
        if columns is None or columns == 1:
            if inputs is not None and len(list(inputs)) != 1:
                raise ValueError(f"inputs: b has one column (one input), found {len(list(inputs))} input names")
            return from_name("grey-box", b=b, **keys, **({} if d is None else {"d": d}))
        names = _input_names(inputs, columns, "b")
        if d is not None and _columns(d, "d") != columns:
            raise ValueError(f"d: expected one row of {columns} entries (one per column of b)")
        parts = [from_name("grey-box", b=[[row[j]] for row in b], **keys,
                           **({} if d is None else {"d": [[d[0][j]]]}))
                 for j in range(columns)]
        return System(_jitterid.System.several(names, parts, True).spec_json)

    @staticmethod
    def several(systems: Union[Sequence["System"], Mapping[str, "System"]]) -> "System":
        """The system with one input per entry of ``systems``, ``y = Σ G_i u_i``: a mapping
        from input names to systems (``{"torque": g, "brake": h}``), or a list of systems (inputs
        named ``u1``, ``u2``, …). Each is a system of one input (``zpk``, ``tf``, ``grey-box``,
        with its own delay); their parameters are named by input (``torque.b0``)."""
        if isinstance(systems, Mapping):
            names, parts = [str(k) for k in systems], list(systems.values())
        elif isinstance(systems, (list, tuple)):
            parts = list(systems)
            names = [f"u{i + 1}" for i in range(len(parts))]
        else:
            raise TypeError(f"systems: expected a list of systems or a dict of them by input name, found "
                            f"{type(systems).__name__}")
        for i, part in enumerate(parts):
            if not isinstance(part, _jitterid.System):
                raise TypeError(f"systems[{names[i]!r}]: expected a System, found {type(part).__name__}")
        return System(_jitterid.System.several(names, parts, False).spec_json)

    @property
    def channels(self) -> Optional[List["System"]]:  # type: ignore[override]
        """A system with several inputs: each input's system, in input order (``None`` for a
        system with one input)."""
        parts = _jitterid.System.channels.__get__(self)
        return None if parts is None else [System(p.spec_json) for p in parts]

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
        """A realisation ``(A, B, C, D)``: a grey-box system's own matrices at its parameters,
        the controllable canonical form of the others."""
        return self.state_space()

    def to_control(self, pade_order: Optional[int] = None) -> Any:
        """The system as a python-control ``TransferFunction`` (``control.tf(num, den)``, in
        ``s``, rad/s). python-control's transfer functions have no input delay: a delayed system
        needs ``pade_order``, the order of the Padé approximation of ``e^{−sD}`` multiplied in.
        Needs the optional package ``control`` (``pip install control``)."""
        # The arguments first: a wrong call is the caller's error whether or not the optional
        # package is there.
        if self.delay is not None and pade_order is None:
            raise ValueError(f"pade_order: the system has an input delay of {self.delay} s, which a python-control "
                             "TransferFunction cannot hold; give pade_order (say 5) to multiply in its Padé "
                             "approximation")
        order = None if self.delay is None else integer(pade_order, "pade_order")
        try:
            import control
        except ImportError:
            raise ImportError("System.to_control() needs python-control, which is not installed: "
                              "pip install control") from None
        num, den = self.tf_coefficients()
        g = control.tf(num, den)
        if self.delay is None:
            return g
        return g * control.tf(*control.pade(self.delay, order))

    def to_scipy(self) -> Any:
        """The system as a ``scipy.signal.lti`` (transfer-function form, in ``s``, rad/s).
        SciPy's linear systems have no input delay, so a delayed system raises ``ValueError``.
        Needs the optional package ``scipy`` (``pip install scipy``)."""
        if self.delay is not None:
            raise ValueError(f"the system has an input delay of {self.delay} s, which scipy.signal.lti cannot hold "
                             "(System.to_control(pade_order=…) approximates it)")
        try:
            from scipy import signal
        except ImportError:
            raise ImportError("System.to_scipy() needs SciPy, which is not installed: pip install scipy") from None
        num, den = self.tf_coefficients()
        return signal.lti(num, den)

    def __reduce__(self) -> Any:
        return (System, (self.spec_json,))


def _columns(matrix: Any, key: str) -> Optional[int]:
    """The number of columns of ``matrix`` (rows of entries), ``None`` when it is not a list of
    equally long rows (the library's reader then names what is wrong)."""
    if not isinstance(matrix, (list, tuple)) or not matrix:
        return None
    widths = {len(row) if isinstance(row, (list, tuple)) else -1 for row in matrix}
    if len(widths) != 1 or -1 in widths:
        return None
    return widths.pop()


def _input_names(names: Optional[Sequence[str]], count: int, key: str) -> List[str]:
    """``names`` checked as ``count`` input names (default ``u1``, ``u2``, …)."""
    if names is None:
        return [f"u{i + 1}" for i in range(count)]
    out = [str(n) for n in names]
    if len(out) != count:
        raise ValueError(f"inputs: {key} has {count} columns (one per input), found {len(out)} input names")
    return out


def from_name(kind: str, **keys: Any) -> System:
    """The system of registry kind ``kind`` with its keys (``from_name("zpk", gain=0.2,
    zeros=[-0.5], poles=[[-0.25, 0.3]])``: a pair as ``[re, im]``). Unknown kinds and keys
    raise ``ValueError`` naming them."""
    return System(spec_json({"kind": kind, **keys}))


def kinds() -> List[Dict[str, Any]]:
    """The registry's kinds: name, summary, keys, whether they need an input."""
    return json.loads(_jitterid.system_kinds())
