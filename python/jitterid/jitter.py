"""Jitter models: the pdf of the sampling-time error ``τ``.

Every family of the library's registry is reachable by name and by class::

    from jitterid import jitter
    u = jitter.UniformSum(n=2, a=0.29)          # a class per registry family (or UniformSum(2, 0.29))
    g = jitter.from_name("gaussian", sigma=0.1)  # the same by name
    s = jitter.from_std("uniform-sum", 0.1, n=2) # the member with a given standard deviation
    u.cf([0.0, 0.5]), u.pdf(0.1), u.sample(1000, seed=1), u.std, u.params

The classes are made from the registry when this module is imported (``families()`` lists
them with their keys), so a family added to the library appears here with no Python change.
"""

from __future__ import annotations

import inspect
import json
from typing import Any, Dict, List

from . import _jitterid
from ._spec import SpecTable, real_number, spec_json

__all__ = ["Jitter", "from_name", "from_std", "families"]


class Jitter(SpecTable, _jitterid.Jitter):
    """A jitter model built from the registry (see ``from_name``)."""

    def __reduce__(self) -> Any:
        # By spec table, so that Dask and multiprocessing can ship models.
        return (_from_spec_json, (self.spec_json,))


def _from_spec_json(text: str) -> Jitter:
    return Jitter(text)


def from_name(family: str, **keys: Any) -> Jitter:
    """The member of ``family`` with the family's keys, e.g. ``from_name("gaussian", sigma=0.1)``.

    Sums and mixtures take ``terms=[{"family": ..., ...}, ...]``. Unknown families and keys,
    and values out of range, raise ``ValueError`` naming the key.
    """
    return Jitter(spec_json({"family": family, **keys}))


def from_std(family: str, sigma: float, **keys: Any) -> Jitter:
    """The member of ``family`` with standard deviation ``sigma`` (s); ``keys`` holds the
    family's structural keys, such as the uniform sum's ``n``."""
    # Built by the registry's standard-deviation form, then rewrapped through its spec table
    # (an exact round trip) so that it is this module's class.
    return Jitter(Jitter.from_std_dev(family, real_number(sigma, "sigma"), spec_json(keys)).spec_json)


def families() -> List[Dict[str, Any]]:
    """The registry's families: name, summary, keys (``params``: key, meaning, unit,
    constraint, integer, default), whether they take ``terms`` and a standard-deviation form."""
    return json.loads(_jitterid.jitter_families())


def _class_name(family: str) -> str:
    return "".join(part.capitalize() for part in family.replace("_", "-").split("-"))


def _parameters(entry: Dict[str, Any]) -> List[inspect.Parameter]:
    """The family's keys as Python parameters: ``terms`` first for a family that takes them,
    then the keys in the registry's order, each positional or by keyword, with the registry's
    default where it has one."""
    params: List[inspect.Parameter] = []
    if entry["takes_terms"]:
        params.append(inspect.Parameter("terms", inspect.Parameter.POSITIONAL_OR_KEYWORD,
                                        annotation=List[Dict[str, Any]]))
    for p in entry["params"]:
        kind = _kind(p)
        default = inspect.Parameter.empty if p["default"] is None else kind(p["default"])
        params.append(inspect.Parameter(p["key"], inspect.Parameter.POSITIONAL_OR_KEYWORD, default=default,
                                        annotation=kind))
    return params


def _kind(p: Dict[str, Any]) -> Any:
    """The Python type of a registry key: the registry marks integers and booleans, and says
    "an array" of a key that holds one value per term."""
    if p["integer"]:
        return int
    if p.get("boolean"):
        return bool
    if "an array" in p["meaning"]:
        return List[float]
    return float


def _signature(params: List[inspect.Parameter]) -> inspect.Signature:
    # The registry's order is kept even where a key without a default follows one with a default
    # (the uniform sum's `n = 0` before `a`), which a `def` cannot spell but the call below
    # binds: `UniformSum(2, 0.3)`, `UniformSum(a=0.3)`.
    return inspect.Signature(params, __validate_parameters__=False)  # type: ignore[call-arg]


def _bind(name: str, params: List[inspect.Parameter], args: tuple, keys: Dict[str, Any]) -> Dict[str, Any]:
    """The keys a call gives: positional arguments in the parameters' order, then keywords;
    keys left out are left to the registry, which applies its defaults and names a missing key."""
    if len(args) > len(params):
        raise TypeError(f"{name}: takes at most {len(params)} positional arguments "
                        f"({', '.join(p.name for p in params)}), {len(args)} were given")
    bound = {p.name: v for p, v in zip(params, args)}
    names = {p.name for p in params}
    for key, value in keys.items():
        if key not in names:
            raise TypeError(f"{name}: unexpected keyword argument {key!r}; its keys are "
                            f"{', '.join(p.name for p in params) or 'none'}")
        if key in bound:
            raise TypeError(f"{name}: got multiple values for argument {key!r}")
        bound[key] = value
    missing = [p.name for p in params if p.default is p.empty and p.name not in bound]
    if missing:
        raise TypeError(f"{name}: missing required argument(s) {', '.join(map(repr, missing))}")
    return bound


def _family_doc(entry: Dict[str, Any]) -> str:
    doc = f"{entry['summary']}.\n\nParameters\n----------\n"
    if entry["takes_terms"]:
        doc += ("terms : list of dict\n    The terms, each a spec table such as "
                "``{\"family\": \"gaussian\", \"sigma\": 0.1}``.\n")
    for p in entry["params"]:
        kind = {int: "int", bool: "bool", float: "float"}.get(_kind(p), "list of float")
        unit = f" [{p['unit']}]" if p["unit"] else ""
        default = "" if p["default"] is None else f", default {_kind(p)(p['default'])}"
        doc += f"{p['key']} : {kind}{unit}\n    {p['meaning']} ({p['constraint']}{default}).\n"
    if not entry["params"] and not entry["takes_terms"]:
        doc += "(none)\n"
    return doc


def _family_class(entry: Dict[str, Any]) -> type:
    family = entry["name"]
    params = _parameters(entry)
    name = _class_name(family)

    def __new__(cls, *args: Any, **keys: Any) -> Jitter:  # noqa: N807
        return Jitter.__new__(cls, spec_json({"family": family, **_bind(cls.__name__, params, args, keys)}))

    __new__.__signature__ = _signature(  # type: ignore[attr-defined]
        [inspect.Parameter("cls", inspect.Parameter.POSITIONAL_OR_KEYWORD), *params])
    cls = type(name, (Jitter,), {"__new__": __new__, "__doc__": _family_doc(entry), "family_name": family,
                                 "__module__": __name__})
    cls.__signature__ = _signature(params)  # type: ignore[attr-defined]
    return cls


for _entry in families():
    _cls = _family_class(_entry)
    globals()[_cls.__name__] = _cls
    __all__.append(_cls.__name__)
del _entry, _cls
