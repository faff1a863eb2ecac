"""The runtime parameters of a loaded solver or controller: read them, change them checked.

One object per face: a solver's ``<name>_params``; a controller's own ``<name>_controller_params``
together with its solver's ``<name>_params``, read and changed by name as one set. Every value is
checked against its row of the parameter table (the manifest's, the same rules as the spec's and the C
check's) before any is written, and each struct's C check has the last word on the combination;
nothing is changed in any struct unless everything passes.
"""

from __future__ import annotations

import threading
from collections.abc import Sequence
from typing import Any

from .codegen.params import Param


class _Struct:
    """One C params struct of type ``ctype`` at ``pointer``, whose fields are ``rows``, in order."""

    def __init__(self, ffi: Any, lib: Any, ctype: str, pointer: Any, rows: Sequence[Param]) -> None:
        self.pointer = pointer
        self.fields = {f: t.type for f, t in ffi.typeof(ctype).fields}
        names = [p.name for p in rows]
        if names != list(self.fields):
            raise ValueError(f"the manifest's parameter table {names} does not match the library's {ctype} struct "
                             f"{list(self.fields)}: regenerate and rebuild the package")
        self.check = getattr(lib, f"{ctype}_check")
        self.rule = getattr(lib, f"{ctype}_rule")
        self.staged = ffi.new(f"{ctype} *")
        self.size = ffi.sizeof(ctype)


class RuntimeParams:
    """The parameters in ``structs``: (C type, pointer to it, the table's rows that are its fields)."""

    def __init__(self, ffi: Any, lib: Any, structs: Sequence[tuple[str, Any, Sequence[Param]]],
                 lock: threading.Lock) -> None:
        self._ffi = ffi
        self._lock = lock
        self._structs = [_Struct(ffi, lib, ctype, pointer, rows) for ctype, pointer, rows in structs]
        self.rows = {p.name: p for _, _, rows in structs for p in rows}
        self._home = {p.name: s for s, (_, _, rows) in zip(self._structs, structs, strict=True) for p in rows}

    @property
    def values(self) -> dict[str, Any]:
        """The parameters now in force, by name."""
        out: dict[str, Any] = {}
        for name in self.rows:
            s = self._home[name]
            value = getattr(s.pointer, name)
            out[name] = tuple(value) if s.fields[name].kind == "array" else value
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
            for s in self._structs:
                ffi.memmove(s.staged, s.pointer, s.size)
            for key, v in staged:
                setattr(self._home[key].staged, key, v)
            for s in self._structs:
                broken = int(s.check(s.staged))
                if broken:
                    rule = ffi.string(s.rule(broken)).decode()
                    raise ValueError(f"invalid runtime parameter(s), none changed: {rule}")
            for s in self._structs:
                ffi.memmove(s.pointer, s.staged, s.size)
