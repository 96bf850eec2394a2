"""Jitter models: the pdf of the sampling-time error ``τ``.

Every family of the library's registry is reachable by name and by class::

    from jitterid import jitter
    u = jitter.UniformSum(n=2, a=0.29)          # a class per registry family
    g = jitter.from_name("gaussian", sigma=0.1)  # the same by name
    s = jitter.from_std("uniform-sum", 0.1, n=2) # the member with a given standard deviation
    u.cf([0.0, 0.5]), u.pdf(0.1), u.sample(1000, seed=1), u.std, u.params

The classes are made from the registry when this module is imported (``families()`` lists
them with their keys), so a family added to the library appears here with no Python change.
"""

from __future__ import annotations

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


def _family_class(entry: Dict[str, Any]) -> type:
    family = entry["name"]
    keys = ", ".join(p["key"] for p in entry["params"]) or ("terms" if entry["takes_terms"] else "")

    def __new__(cls, **keys: Any) -> Jitter:  # noqa: N807
        return Jitter.__new__(cls, spec_json({"family": family, **keys}))

    doc = f"{entry['summary']}.\n\nKeys: {keys or 'none'}."
    for p in entry["params"]:
        unit = f" [{p['unit']}]" if p["unit"] else ""
        default = "" if p["default"] is None else f", default {p['default']:g}"
        doc += f"\n  {p['key']}{unit}: {p['meaning']} ({p['constraint']}{default})"
    return type(_class_name(family), (Jitter,), {"__new__": __new__, "__doc__": doc, "family_name": family})


for _entry in families():
    _cls = _family_class(_entry)
    globals()[_cls.__name__] = _cls
    __all__.append(_cls.__name__)
del _entry, _cls
