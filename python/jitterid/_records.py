"""Records in: a mapping of arrays (what ``simulate`` and ``read_record`` give), a pandas
DataFrame or Series, or an xarray Dataset or DataArray, made into one plain dict of NumPy
arrays at the door, so that every function after it sees one kind of record.

The sample times come from a column ``t`` or, failing that, from the index (pandas) or the
one dimension's coordinate (xarray), unless that index is the default ``0, 1, 2, …`` of row
numbers, which says nothing about time. A ``TimedeltaIndex`` is read in seconds.
"""

from __future__ import annotations

from typing import Any, Dict, Mapping

import numpy as np

# Keys of a record whose values are not arrays of samples: the grid's numbers and the input.
_SCALARS = ("T", "t0", "input")


def _module_of(value: Any) -> str:
    return type(value).__module__.split(".")[0]


def _is_row_numbers(index: Any) -> bool:
    """Whether a pandas index is the default ``RangeIndex`` ``0, 1, …, n−1``."""
    import pandas as pd

    return isinstance(index, pd.RangeIndex) and index.start == 0 and index.step == 1


def _seconds(index: Any, name: str) -> np.ndarray:
    """A pandas index or an xarray coordinate as times in seconds."""
    values = np.asarray(index)
    if values.dtype.kind == "m":
        return values.astype("timedelta64[ns]").astype(np.int64) / 1e9
    if values.dtype.kind == "M":
        raise TypeError(f"{name}: the times are dates ({values.dtype}); give the sample times in seconds, for "
                        "example (index - index[0]).total_seconds(), as a column `t` or as the index")
    return values


def _column(value: Any) -> Any:
    """A record's value as a NumPy array when it is a pandas or xarray column (their own
    indexing, by label, is what ``series[-1]`` would use); other values unchanged."""
    if _module_of(value) in ("pandas", "xarray") and hasattr(value, "to_numpy"):
        return value.to_numpy()
    return value


def as_record(record: Any, name: str = "record") -> Dict[str, Any]:
    """``record`` as a dict of NumPy arrays (and the scalars ``T``, ``t0`` and the ``input``
    as given); ``name`` names the argument in messages.

    Accepted: a mapping with at least ``y``; a pandas DataFrame with a column ``y``; a pandas
    Series (the samples ``y``, their times the index); an xarray Dataset with a variable ``y``,
    or a DataArray (the samples). Anything else raises ``TypeError`` naming ``name``.
    """
    module = _module_of(record)
    if module == "pandas":
        import pandas as pd

        if isinstance(record, pd.DataFrame):
            columns = {str(c): record[c].to_numpy() for c in record.columns}
            if "y" not in columns:
                raise ValueError(f"{name}: the DataFrame has no column `y` (columns: {', '.join(columns)})")
            if "t" not in columns and not _is_row_numbers(record.index):
                columns["t"] = _seconds(record.index, f"{name}.index")
            return columns
        if isinstance(record, pd.Series):
            out: Dict[str, Any] = {"y": record.to_numpy()}
            if not _is_row_numbers(record.index):
                out["t"] = _seconds(record.index, f"{name}.index")
            return out
    if module == "xarray":
        import xarray as xr

        if isinstance(record, xr.DataArray):
            if record.ndim != 1:
                raise ValueError(f"{name}: expected a one-dimensional DataArray, found dimensions {record.dims}")
            out = {"y": record.to_numpy()}
            dim = record.dims[0]
            if dim in record.coords:
                out["t"] = _seconds(record.coords[dim].to_numpy(), f"{name}.{dim}")
            return out
        if isinstance(record, xr.Dataset):
            columns = {str(k): v.to_numpy() for k, v in record.data_vars.items()}
            if "y" not in columns:
                raise ValueError(f"{name}: the Dataset has no variable `y` (variables: {', '.join(columns)})")
            dims = list(record["y"].dims)
            if "t" not in columns and len(dims) == 1 and dims[0] in record.coords:
                columns["t"] = _seconds(record.coords[dims[0]].to_numpy(), f"{name}.{dims[0]}")
            return columns
    if isinstance(record, Mapping):
        if "y" not in record:
            raise ValueError(f"{name}: the record has no `y` (keys: {', '.join(map(str, record))})")
        return {str(k): (v if k in _SCALARS else _column(v)) for k, v in record.items()}
    raise TypeError(f"{name}: expected a record: a mapping with `y` (as simulate returns), a pandas DataFrame "
                    f"or Series, or an xarray Dataset or DataArray; found {type(record).__name__}")
