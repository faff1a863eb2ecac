"""The runtime parameters of a loaded solver or controller: read them, change them checked.

One object per C params struct. Every value is checked against its row of the parameter table (the
manifest's, the same rules as the spec's and the C check's) before any is written, and the C check
has the last word on the combination; nothing is changed unless everything passes.
"""

from __future__ import annotations

import threading
from typing import Any

from .codegen.params import Param


class RuntimeParams:
    """The ``<name>_params`` struct at ``pointer`` (owned by a solver or a controller)."""

    def __init__(self, ffi: Any, lib: Any, name: str, pointer: Any, table: tuple[Param, ...],
                 lock: threading.Lock) -> None:
        self._ffi = ffi
        self._pointer = pointer
        self._lock = lock
        self._fields = {f: t.type for f, t in ffi.typeof(f"{name}_params").fields}
        self.rows = {p.name: p for p in table}
        if list(self.rows) != list(self._fields):
            raise ValueError(f"the manifest's parameter table {list(self.rows)} does not match the library's "
                             f"params struct {list(self._fields)}")
        self._check = getattr(lib, f"{name}_params_check")
        self._rule = getattr(lib, f"{name}_params_rule")
        self._staged = ffi.new(f"{name}_params *")
        self._size = ffi.sizeof(f"{name}_params")

    @property
    def values(self) -> dict[str, Any]:
        """The parameters now in force."""
        out: dict[str, Any] = {}
        for field, ftype in self._fields.items():
            value = getattr(self._pointer, field)
            out[field] = tuple(value) if ftype.kind == "array" else value
        return out

    def set(self, **values: Any) -> None:
        """Change parameters; a ValueError lists every value that breaks its rule (a KeyError names
        unknown parameters), and then nothing is changed."""
        unknown = [key for key in values if key not in self.rows]
        if unknown:
            raise KeyError(f"unknown parameter {', '.join(repr(k) for k in unknown)}; parameters are "
                           f"{', '.join(self.rows)}")
        problems: list[str] = []
        staged: list[tuple[str, Any]] = []
        for key, value in values.items():
            row = self.rows[key]
            checked, why = row.check(value)
            if why is not None:
                problems.append(f"{key}: {why}: {row.name} must be {row.rule}")
            else:
                staged.append((key, list(checked) if row.size > 1 else checked))
        if problems:
            raise ValueError("invalid runtime parameter(s), none changed:\n  - " + "\n  - ".join(problems))
        ffi = self._ffi
        with self._lock:
            ffi.memmove(self._staged, self._pointer, self._size)
            for key, v in staged:
                setattr(self._staged, key, v)
            broken = int(self._check(self._staged))
            if broken:
                rule = ffi.string(self._rule(broken)).decode()
                raise ValueError(f"invalid runtime parameter(s), none changed: {rule}")
            ffi.memmove(self._pointer, self._staged, self._size)
