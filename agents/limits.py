"""Reading files and text from anyone with their sizes checked before their content.

Every reader here checks what it can without parsing first (a file's size,
an archive member's declared size, its compression ratio, an ``.npy``
header's shape) and ends in one :class:`UsageError` naming the file, what it
holds and what is allowed:

* YAML (:func:`load_yaml`): at most :data:`MAX_YAML_BYTES`; aliases
  (``*name``, and with them merge keys) are refused, so an alias bomb
  ("billion laughs") cannot expand; nesting at most :data:`MAX_DEPTH` and at
  most :data:`MAX_YAML_NODES` values; a mapping key given twice is refused.
* JSON (:func:`load_json`): at most the caller's byte cap; nesting at most
  :data:`MAX_DEPTH`.
* Zip archives (:func:`check_zip`): every member's declared size, their
  total, and (for members past :data:`RATIO_FLOOR` bytes) the ratio of
  declared to compressed size, all before a member is read.
* ``.npz`` files (:func:`load_npz`): the zip checks, then each ``.npy``
  header's shape and type against the member's declared size, before NumPy
  allocates the array.
* Hashes (:func:`sha256`): the file's size capped, then read in chunks.
"""

from __future__ import annotations

import hashlib
import json
import zipfile
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from motiongym.agents.errors import UsageError

MAX_YAML_BYTES = 256 * 1024  # a configuration file (the shipped ones are under 3 KB)
MAX_YAML_NODES = 20_000  # values in one YAML document
MAX_DEPTH = 64  # nesting of lists and mappings in YAML and JSON
MAX_HASHED_BYTES = 1 << 30  # a file of a model folder, hashed against its manifest
RATIO_FLOOR = 1 << 20  # members at most this large may compress any amount
MAX_RATIO = 10.0  # declared / compressed size of a larger member (SB3 stores: 1.0)


def _shown(value: Any, limit: int = 80) -> str:
    text = repr(value)
    return text if len(text) <= limit else f"{text[:limit]}... ({len(text)} characters)"


class _GuardedLoader(yaml.SafeLoader):
    """PyYAML's safe loader that refuses aliases and caps nesting and node count."""

    def __init__(self, stream: str, where: str) -> None:
        super().__init__(stream)
        self.where = where
        self.depth = 0
        self.nodes = 0

    def compose_node(self, parent: Any, index: Any) -> Any:
        if self.check_event(yaml.AliasEvent):
            event = self.peek_event()
            raise UsageError(
                f"{self.where}: YAML aliases are not allowed (found *{event.anchor} at line "
                f"{event.start_mark.line + 1}); write the value out"
            )
        self.nodes += 1
        if self.nodes > MAX_YAML_NODES:
            raise UsageError(f"{self.where}: more than {MAX_YAML_NODES} YAML values; refused")
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise UsageError(f"{self.where}: YAML nested deeper than {MAX_DEPTH} levels; refused")
        try:
            return super().compose_node(parent, index)
        finally:
            self.depth -= 1

    def construct_mapping(self, node: Any, deep: bool = False) -> Any:
        """PyYAML's mapping, but a key given twice is refused (PyYAML keeps the last)."""
        if isinstance(node, yaml.MappingNode):
            seen = set()
            for key_node, _ in node.value:
                key = self.construct_object(key_node, deep=True)
                try:
                    duplicate = key in seen
                    seen.add(key)
                except TypeError:  # unhashable: PyYAML's own error follows
                    continue
                if duplicate:
                    raise UsageError(
                        f"{self.where}: key {_shown(key)} given twice (line "
                        f"{key_node.start_mark.line + 1}); give each key once"
                    )
        return super().construct_mapping(node, deep)


def load_yaml(
    text: str | bytes, where: str, max_bytes: int = MAX_YAML_BYTES, malformed: str = ""
) -> Any:
    """The YAML document ``text`` (from ``where``, named in errors), checked as above;
    ``malformed``: the message of a syntax error, if not ``malformed YAML in <where>``."""
    size = len(text.encode() if isinstance(text, str) else text)
    if size > max_bytes:
        raise UsageError(f"{where} is {size} bytes of YAML; at most {max_bytes} allowed")
    if isinstance(text, bytes):
        try:
            text = text.decode()
        except UnicodeDecodeError as error:
            raise UsageError(f"{where} is not UTF-8 text ({error.reason})") from None
    loader = _GuardedLoader(text, where)
    try:
        return loader.get_single_data()
    except yaml.YAMLError as error:
        problem = " ".join(str(error).split())[:300]
        if malformed:
            problem = getattr(error, "problem", None) or type(error).__name__
            raise UsageError(f"{malformed} ({problem})") from None
        raise UsageError(f"malformed YAML in {where}: {problem}") from None
    except RecursionError:
        raise UsageError(f"{where}: YAML nested too deeply; refused") from None
    finally:
        loader.dispose()


def read_yaml_file(path: Path, max_bytes: int = MAX_YAML_BYTES) -> Any:
    """The YAML file at ``path``, its size checked before it is read."""
    return load_yaml(read_capped(path, max_bytes, "YAML"), str(path), max_bytes)


def read_capped(path: Path, max_bytes: int, kind: str) -> bytes:
    """The bytes of ``path``, refused unread when it is larger than ``max_bytes``."""
    try:
        size = path.stat().st_size
        if size > max_bytes:
            raise UsageError(f"{path} is {size} bytes of {kind}; at most {max_bytes} allowed")
        with path.open("rb") as handle:
            data = handle.read(max_bytes + 1)
    except OSError as error:
        raise UsageError(f"cannot read {path} ({error.strerror or error})") from None
    if len(data) > max_bytes:  # grew since, or a special file
        raise UsageError(f"{path} is more than {max_bytes} bytes of {kind}; refused")
    return data


def _depth(value: Any) -> int:
    """The nesting of lists and dicts in ``value`` (walked without recursion; stops
    counting past :data:`MAX_DEPTH`)."""
    deepest, stack = 0, [(value, 1)]
    while stack:
        item, depth = stack.pop()
        if isinstance(item, (list, dict)):
            deepest = max(deepest, depth)
            if deepest > MAX_DEPTH:
                break
            children = item.values() if isinstance(item, dict) else item
            stack.extend((v, depth + 1) for v in children)
    return deepest


def load_json(text: str | bytes, where: str, max_bytes: int) -> Any:
    """The JSON document ``text`` (from ``where``), at most ``max_bytes`` and :data:`MAX_DEPTH`
    levels deep."""
    size = len(text.encode() if isinstance(text, str) else text)
    if size > max_bytes:
        raise UsageError(f"{where} is {size} bytes of JSON; at most {max_bytes} allowed")
    try:
        value = json.loads(text)
    except RecursionError:
        value = None
        deep = True
    except (UnicodeDecodeError, ValueError) as error:
        problem = " ".join(str(error).split())[:200]
        raise UsageError(f"{where} is not JSON ({problem})") from None
    else:
        deep = _depth(value) > MAX_DEPTH
    if deep:
        raise UsageError(f"{where}: JSON nested deeper than {MAX_DEPTH} levels; refused")
    return value


def read_json_file(path: Path, max_bytes: int) -> Any:
    """The JSON file at ``path``, its size checked before it is read."""
    return load_json(read_capped(path, max_bytes, "JSON"), str(path), max_bytes)


def check_zip(
    path: Path, archive: zipfile.ZipFile, max_member: int, max_total: int
) -> list[zipfile.ZipInfo]:
    """The members of ``archive``, after checking their declared sizes (each at most
    ``max_member`` bytes, all together at most ``max_total``) and, for members past
    :data:`RATIO_FLOOR` bytes, a compression ratio of at most :data:`MAX_RATIO`."""
    members = archive.infolist()
    total = 0
    for info in members:
        if info.file_size > max_member:
            raise UsageError(
                f"{path}: member {info.filename!r} declares {info.file_size} bytes; "
                f"at most {max_member} allowed"
            )
        if info.file_size > RATIO_FLOOR and info.file_size > MAX_RATIO * max(info.compress_size, 1):
            raise UsageError(
                f"{path}: member {info.filename!r} unpacks {info.file_size} bytes from "
                f"{info.compress_size}; a ratio over {MAX_RATIO:g} is refused"
            )
        total += info.file_size
    if total > max_total:
        raise UsageError(
            f"{path}: members declare {total} bytes in all; at most {max_total} allowed"
        )
    return members


def load_npz(path: Path, max_member: int, max_total: int) -> dict[str, np.ndarray]:
    """The arrays of the ``.npz`` file at ``path`` (no pickles), every size checked first:
    the zip's (:func:`check_zip`) and each ``.npy`` header's shape against the member's
    declared size."""
    try:
        with zipfile.ZipFile(path) as archive:
            members = check_zip(path, archive, max_member, max_total)
            arrays = {}
            for info in members:
                name = info.filename.removesuffix(".npy")
                with archive.open(info) as member:
                    version = np.lib.format.read_magic(member)
                    if version not in ((1, 0), (2, 0), (3, 0)):
                        raise ValueError(f"unknown .npy version {version}")
                    read = getattr(np.lib.format, f"read_array_header_{version[0]}_0")
                    shape, fortran, dtype = read(member)
                    if dtype.hasobject:
                        raise UsageError(f"{path}: {name} holds Python objects; refused")
                    nbytes = int(np.prod(shape, dtype=object)) * dtype.itemsize
                    if nbytes > info.file_size:
                        raise UsageError(
                            f"{path}: {name} declares shape {shape} ({nbytes} bytes) in a "
                            f"member of {info.file_size} bytes; refused"
                        )
                    data = member.read(nbytes)
                if len(data) != nbytes:
                    raise ValueError(f"{name} is truncated")
                array = np.frombuffer(data, dtype=dtype)
                arrays[name] = array.reshape(shape, order="F" if fortran else "C").copy()
            return arrays
    except UsageError:
        raise
    except Exception as error:  # noqa: BLE001 - any failure to read a file from anyone
        problem = " ".join(str(error).split())[:200]
        raise UsageError(f"{path}: not a readable .npz file ({problem})") from None


def sha256(path: Path, max_bytes: int = MAX_HASHED_BYTES) -> str:
    """The SHA-256 of ``path``, read in 1 MiB chunks after its size is checked."""
    size = path.stat().st_size
    if size > max_bytes:
        raise UsageError(f"{path} is {size} bytes; at most {max_bytes} allowed")
    digest = hashlib.sha256()
    with path.open("rb") as handle:
        for chunk in iter(lambda: handle.read(1 << 20), b""):
            digest.update(chunk)
    return digest.hexdigest()


__all__ = [
    "MAX_DEPTH",
    "MAX_YAML_BYTES",
    "UsageError",
    "check_zip",
    "load_json",
    "load_npz",
    "load_yaml",
    "read_capped",
    "read_json_file",
    "read_yaml_file",
    "sha256",
]
