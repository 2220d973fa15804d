"""Frames between the host, the supervisor and the per-run child: a JSON header and raw blobs.

A frame is ``MAGIC`` + u32 header length + the UTF-8 JSON header + the blobs, back to back, whose
names and sizes the header lists under ``"blobs"``. Arrays travel as ``.npy`` blobs and are read
with ``allow_pickle=False``; nothing is ever unpickled. Stdlib and numpy only: the supervisor
imports this module too.
"""

from __future__ import annotations

import io
import json
import struct
from collections.abc import Mapping
from typing import Any

import numpy as np
from numpy.typing import NDArray

__all__ = [
    "MAGIC",
    "ProtocolError",
    "decode_arrays",
    "decode_frame",
    "encode_arrays",
    "encode_frame",
    "frame_length",
]

MAGIC = b"SBX1"
_HEAD = struct.Struct("<4sI")
_MAX_HEADER = 8 << 20
_NUMERIC_KINDS = "biuf"


class ProtocolError(ValueError):
    """A frame that does not follow the protocol (bad magic, sizes, JSON or array)."""


def encode_frame(header: Mapping[str, Any], blobs: Mapping[str, bytes] | None = None) -> bytes:
    """Encode a header and named blobs into one frame."""
    blobs = dict(blobs or {})
    full = dict(header)
    full["blobs"] = [[name, len(data)] for name, data in blobs.items()]
    text = json.dumps(full, allow_nan=False).encode()
    return b"".join([_HEAD.pack(MAGIC, len(text)), text, *blobs.values()])


def frame_length(prefix: bytes, *, max_bytes: int) -> int | None:
    """Total length of the frame starting with ``prefix``, or ``None`` until the header is complete.

    Raises
    ------
    ProtocolError
        On a bad magic, an oversized header, or a frame longer than ``max_bytes``.
    """
    if len(prefix) < _HEAD.size:
        return None
    magic, header_len = _HEAD.unpack_from(prefix)
    if magic != MAGIC:
        raise ProtocolError(f"bad magic {magic!r} (expected {MAGIC!r})")
    if header_len > _MAX_HEADER:
        raise ProtocolError(f"header of {header_len} bytes is too large (at most {_MAX_HEADER})")
    end = _HEAD.size + int(header_len)
    if len(prefix) < end:
        return None
    header = _parse_header(prefix[_HEAD.size : end])
    total = end + sum(size for _, size in _blob_list(header))
    if total > max_bytes:
        raise ProtocolError(f"frame of {total} bytes is too large (at most {max_bytes})")
    return total


def decode_frame(data: bytes, *, max_bytes: int) -> tuple[dict[str, Any], dict[str, bytes]]:
    """Decode one complete frame into its header (without ``"blobs"``) and named blobs.

    Raises
    ------
    ProtocolError
        When ``data`` is not exactly one well-formed frame.
    """
    total = frame_length(data, max_bytes=max_bytes)
    if total is None:
        raise ProtocolError(f"truncated frame ({len(data)} bytes)")
    if total != len(data):
        raise ProtocolError(f"frame is {len(data)} bytes but its header says {total}")
    (header_len,) = struct.unpack_from("<I", data, 4)
    offset = _HEAD.size + header_len
    header = _parse_header(data[_HEAD.size : offset])
    blobs: dict[str, bytes] = {}
    for name, size in _blob_list(header):
        blobs[name] = data[offset : offset + size]
        offset += size
    header.pop("blobs", None)
    return header, blobs


def encode_arrays(arrays: Mapping[str, NDArray[Any]]) -> dict[str, bytes]:
    """Encode arrays as ``.npy`` blobs (no pickling)."""
    out: dict[str, bytes] = {}
    for name, array in arrays.items():
        buffer = io.BytesIO()
        np.save(buffer, np.asarray(array), allow_pickle=False)
        out[name] = buffer.getvalue()
    return out


def decode_arrays(blobs: Mapping[str, bytes]) -> dict[str, NDArray[np.float64]]:
    """Decode ``.npy`` blobs as float64 arrays, accepting only numeric dtypes (never unpickling).

    Raises
    ------
    ProtocolError
        When a blob is not a valid ``.npy`` array of a boolean, integer or floating dtype.
    """
    out: dict[str, NDArray[np.float64]] = {}
    for name, blob in blobs.items():
        try:
            array = np.load(io.BytesIO(blob), allow_pickle=False)
        except (ValueError, OSError, EOFError) as error:
            raise ProtocolError(f"result {name!r} is not a valid numeric array: {error}") from None
        if not isinstance(array, np.ndarray) or array.dtype.kind not in _NUMERIC_KINDS:
            kind = getattr(array, "dtype", type(array))
            raise ProtocolError(f"result {name!r} has dtype {kind}; expected booleans, integers or floats")
        out[name] = array.astype(np.float64)
    return out


def _parse_header(raw: bytes) -> dict[str, Any]:
    try:
        header = json.loads(raw.decode())
    except (UnicodeDecodeError, json.JSONDecodeError) as error:
        raise ProtocolError(f"header is not JSON: {error}") from None
    if not isinstance(header, dict):
        raise ProtocolError(f"header is a {type(header).__name__}, not a JSON object")
    return header


def _blob_list(header: Mapping[str, Any]) -> list[tuple[str, int]]:
    raw = header.get("blobs", [])
    if not isinstance(raw, list):
        raise ProtocolError("header field 'blobs' is not a list")
    out: list[tuple[str, int]] = []
    for item in raw:
        if (
            not isinstance(item, list)
            or len(item) != 2
            or not isinstance(item[0], str)
            or not isinstance(item[1], int)
            or item[1] < 0
        ):
            raise ProtocolError(f"malformed blob entry {item!r}")
        out.append((item[0], item[1]))
    return out
