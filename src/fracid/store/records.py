"""Records of runs as JSON bytes: a JSON-like dict that may hold numpy arrays, stored losslessly
(:func:`encode_record`, :func:`decode_record`); the form in which :class:`fracid.store.runs.RunStore` keeps them
and in which a batch's workers send them to the parent (:func:`fracid.runtime.batch.run_batch`).
"""

from __future__ import annotations

import base64
import json
from collections.abc import Mapping

import numpy as np

__all__ = ["decode_record", "encode_record", "require_str_key"]

_ARRAY_TAG = "__ndarray__"


def encode_record(record: Mapping) -> bytes:
    """Serialise a record (a dict of JSON types and numpy arrays) to UTF-8 JSON bytes.

    Arrays are stored bit for bit as ``{"__ndarray__": base64 of the C-order bytes, "dtype": ...,
    "shape": [...]}``; any dtype but ``object`` is allowed. Numpy scalars become Python numbers,
    tuples become lists. NaN and infinities are kept.

    Raises
    ------
    TypeError
        If ``record`` is not a dict or holds a value that is not storable (the message names it).
    ValueError
        If a dict uses the reserved key ``"__ndarray__"``.
    """
    if not isinstance(record, Mapping):
        raise TypeError(f"a record must be a dict, got {type(record).__name__}")
    plain = _to_json(record, "record")
    return json.dumps(plain, separators=(",", ":"), allow_nan=True).encode("utf-8")


def decode_record(blob: bytes | bytearray | memoryview | str) -> dict:
    """Inverse of :func:`encode_record`: arrays come back with their dtype, shape and bytes."""
    if isinstance(blob, (bytearray, memoryview)):
        blob = bytes(blob)
    return json.loads(blob, object_hook=_from_json)


def _to_json(value, where: str):
    """``value`` as JSON types, arrays as tagged dicts; errors name the offending entry."""
    if value is None or isinstance(value, (bool, str)):
        return value
    if isinstance(value, np.generic) and not isinstance(value, np.void):
        value = value.item()
        if isinstance(value, (bool, int, float, str)):
            return value
    if isinstance(value, (int, float)):
        return value
    if isinstance(value, np.ndarray):
        return _encode_array(value, where)
    if isinstance(value, Mapping):
        return _encode_mapping(value, where)
    if isinstance(value, (list, tuple)):
        return [_to_json(v, f"{where}[{i}]") for i, v in enumerate(value)]
    raise TypeError(
        f"{where} = {value!r} (type {type(value).__name__}) cannot be stored; "
        "records hold None, bool, int, float, str, lists, dicts with str keys and numpy arrays"
    )


def _encode_mapping(value: Mapping, where: str) -> dict:
    if _ARRAY_TAG in value:
        raise ValueError(f"{where}: the key {_ARRAY_TAG!r} is reserved for arrays")
    return {require_str_key(k, where): _to_json(v, f"{where}[{k!r}]") for k, v in value.items()}


def _encode_array(array: np.ndarray, where: str) -> dict:
    if array.dtype.hasobject:
        raise TypeError(f"{where}: arrays of dtype {array.dtype} cannot be stored (convert to lists)")
    data = np.ascontiguousarray(array).tobytes()
    return {
        _ARRAY_TAG: base64.b64encode(data).decode("ascii"),
        "dtype": np.lib.format.dtype_to_descr(array.dtype),
        "shape": list(array.shape),
    }


def _from_json(obj: dict):
    if _ARRAY_TAG not in obj:
        return obj
    descr = obj["dtype"]
    dtype = np.lib.format.descr_to_dtype(_as_descr(descr))
    raw = base64.b64decode(obj[_ARRAY_TAG])
    return np.frombuffer(raw, dtype=dtype).reshape(obj["shape"]).copy()


def _as_descr(descr):
    """JSON turned the tuples of a structured dtype's descr into lists; turn them back."""
    if not isinstance(descr, list):
        return descr
    fields = []
    for name, kind, *shape in descr:
        name = tuple(name) if isinstance(name, list) else name  # (title, name)
        fields.append((name, _as_descr(kind), *(tuple(s) for s in shape)))
    return fields


def require_str_key(key, where: str) -> str:
    """``key`` if it is a str; TypeError naming ``where`` (the dict it keys) otherwise."""
    if not isinstance(key, str):
        raise TypeError(f"{where}: dict keys must be str, got {key!r} ({type(key).__name__})")
    return key
