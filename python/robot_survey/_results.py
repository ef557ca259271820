"""Turning the library's JSON (the CLI's ``--format json``) into DataFrames and objects."""

from __future__ import annotations

import copy
import json
import os
from typing import Any, Dict, Iterable, List, Mapping, Optional, Union

import polars as pl


def flatten(record: Mapping[str, Any], prefix: str = "") -> Dict[str, Any]:
    """One flat row from a nested JSON object.

    Nested objects become ``outer_inner`` columns; an interval ``[lo, hi]`` (a list of two
    numbers) becomes ``name_lo`` and ``name_hi``; other lists stay lists.
    """
    out: Dict[str, Any] = {}
    for key, value in record.items():
        name = f"{prefix}{key}"
        if isinstance(value, Mapping):
            out.update(flatten(value, name + "_"))
        elif (
            isinstance(value, list)
            and len(value) == 2
            and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
        ):
            out[name + "_lo"] = value[0]
            out[name + "_hi"] = value[1]
        else:
            out[name] = value
    return out


def frame(records: Iterable[Mapping[str, Any]], **fixed: Any) -> pl.DataFrame:
    """A DataFrame of flattened records (``fixed`` columns first, e.g. the design).

    Columns keep the order in which they first appear; a number column that is an integer in
    some rows and a float in others is a float column (values exactly as in the JSON).
    """
    rows = [{**fixed, **flatten(r)} for r in records]
    if not rows:
        return pl.DataFrame()
    columns: List[str] = []
    for r in rows:
        for k in r:
            if k not in columns:
                columns.append(k)
    data: Dict[str, List[Any]] = {c: [r.get(c) for r in rows] for c in columns}
    # An optional interval or object that is null in some rows and flattened in others:
    # keep the flattened columns (null in those rows), drop the all-null stub.
    for c in list(data):
        if all(v is None for v in data[c]) and any(
            o.startswith(c + "_") for o in data if o != c
        ):
            del data[c]
    for c, values in data.items():
        kinds = {type(v) for v in values if v is not None}
        if kinds == {int, float}:
            data[c] = [float(v) if v is not None else None for v in values]
        elif kinds and all(k in (list, tuple) for k in kinds):
            # Lists of pairs (e.g. knob values) are kept as text: polars wants one type.
            data[c] = [json.dumps(v) if v is not None else None for v in values]
    return pl.DataFrame(data, strict=False)


class Result:
    """A result of the library: the CLI's JSON as a dict, with attribute access.

    ``result.to_dict()`` is exactly what ``survey … --format json`` prints (as Python
    objects); ``result["key"]`` and ``result.key`` read its top-level keys.
    """

    def __init__(self, data: Dict[str, Any]) -> None:
        self._data = data

    def to_dict(self) -> Dict[str, Any]:
        """The result as the CLI's JSON (a deep copy)."""
        return copy.deepcopy(self._data)

    def to_json(self) -> str:
        """The result as JSON text."""
        return json.dumps(self._data, ensure_ascii=False, indent=2)

    def keys(self) -> List[str]:
        """The top-level keys."""
        return list(self._data)

    def __getitem__(self, key: str) -> Any:
        return self._data[key]

    def __getattr__(self, key: str) -> Any:
        if key.startswith("_"):
            raise AttributeError(key)
        try:
            return self._data[key]
        except KeyError:
            raise AttributeError(
                f"{type(self).__name__} has no attribute {key!r} "
                f"(keys: {', '.join(self._data)})"
            ) from None

    def __dir__(self) -> List[str]:
        return sorted(set(super().__dir__()) | set(self._data))

    def __repr__(self) -> str:
        return f"{type(self).__name__}({', '.join(self._data)})"


PathLike = Union[str, "os.PathLike[str]"]


def fspath(p: Optional[PathLike]) -> Optional[str]:
    return None if p is None else os.fspath(p)
