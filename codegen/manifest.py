"""The manifest of a generated solver package (``manifest.json``): one typed record, one writer, one reader.

The generator writes it (:func:`Manifest.write`); the build, the binding, the tools' solver cache, the
benches and the firmware read it (:func:`Manifest.read`), which checks every key and type and names
the first that is wrong (:class:`ManifestError`), so that no reader indexes raw JSON.
"""

from __future__ import annotations

import json
import re
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

MANIFEST = "manifest.json"

_IDENT = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")
REGENERATE = "generate the package again (humanmpc-gen generate SPEC -o DIR --force)"


class ManifestError(ValueError):
    """A manifest that is missing or does not hold what a package's manifest holds; the message names
    the file, the key and what to do."""


class ManifestMissingError(ManifestError):
    """The folder, or its manifest.json, does not exist."""


@dataclass(frozen=True)
class Dims:
    """The package's fixed sizes and timing."""

    nx: int
    nu: int
    N: int        # shooting intervals
    nh: int       # people the OCP takes
    ng: int       # distance rows per node (people + the obstacle)
    qp_rows: int = field(repr=False)  # distance rows one QP holds
    dt: float     # interval [s]
    T: float      # horizon [s]


@dataclass(frozen=True)
class Port:
    """One input or output of a model function: its name and shape (column-major)."""

    name: str
    rows: int
    cols: int


@dataclass(frozen=True)
class ModelFunctionInfo:
    name: str
    doc: str
    inputs: tuple[Port, ...]
    outputs: tuple[Port, ...]


@dataclass(frozen=True)
class StatusRow:
    """One row of a status table of runtime/hm_status.h: value, (lower-case) name, message."""

    value: int
    name: str
    message: str


@dataclass(frozen=True)
class Manifest:
    generator: str
    generator_version: str
    casadi_version: str
    name: str                 # the solver's C prefix
    spec_hash: str            # sha256 of the resolved spec
    real: str                 # "double" or "float"
    dims: Dims
    functions: tuple[ModelFunctionInfo, ...]
    library: str              # the shared library, relative to the package
    # the runtime parameters' table (humanmpc.codegen.params) with this solver's defaults: what a
    # binding checks set_params against (rows as Param.manifest_row writes them)
    params: tuple[Mapping[str, Any], ...]
    # status codes and stop reasons (runtime/hm_status.h) by table: qp_status, status, stop_reason, outcome
    statuses: Mapping[str, tuple[StatusRow, ...]]

    def to_json(self) -> dict[str, Any]:
        return {
            "generator": self.generator,
            "generator_version": self.generator_version,
            "casadi_version": self.casadi_version,
            "name": self.name,
            "spec_hash": self.spec_hash,
            "real": self.real,
            "dims": {"nx": self.dims.nx, "nu": self.dims.nu, "N": self.dims.N, "nh": self.dims.nh,
                     "ng": self.dims.ng, "qp_rows": self.dims.qp_rows, "dt": self.dims.dt, "T": self.dims.T},
            "functions": [
                {"name": f.name, "doc": f.doc, "inputs": [[p.name, p.rows, p.cols] for p in f.inputs],
                 "outputs": [[p.name, p.rows, p.cols] for p in f.outputs]}
                for f in self.functions
            ],
            "library": self.library,
            "params": [dict(row) for row in self.params],
            "statuses": {key: [[r.value, r.name, r.message] for r in rows] for key, rows in self.statuses.items()},
        }

    @classmethod
    def from_json(cls, data: object, where: str = MANIFEST) -> Manifest:
        """The manifest in ``data`` (parsed JSON), checked; ``where`` names it in messages."""
        r = _Reader(where)
        top = r.obj(data, "")
        name = r.string(top, "name")
        if not _IDENT.fullmatch(name):
            raise ManifestError(f"{where}: the name {name!r} is not a C identifier: {REGENERATE}")
        real = r.string(top, "real")
        if real not in ("double", "float"):
            raise ManifestError(f"{where}: 'real' is {real!r}, not 'double' or 'float': {REGENERATE}")
        d = r.obj(top.get("dims"), "dims")
        dims = Dims(nx=r.integer(d, "nx", "dims."), nu=r.integer(d, "nu", "dims."), N=r.integer(d, "N", "dims."),
                    nh=r.integer(d, "nh", "dims."), ng=r.integer(d, "ng", "dims."),
                    qp_rows=r.integer(d, "qp_rows", "dims."), dt=r.number(d, "dt", "dims."),
                    T=r.number(d, "T", "dims."))
        functions = tuple(
            ModelFunctionInfo(name=r.string(f, "name", f"functions[{i}]."), doc=r.string(f, "doc", f"functions[{i}]."),
                              inputs=r.ports(f, "inputs", i), outputs=r.ports(f, "outputs", i))
            for i, f in enumerate(r.obj(x, f"functions[{i}]") for i, x in enumerate(r.array(top, "functions")))
        )
        if "params" not in top:
            raise ManifestError(f"{where} was written by humanmpc {top.get('generator_version', '?')}, whose "
                                f"manifest has no parameter table: {REGENERATE}")
        params = tuple(r.obj(x, f"params[{i}]") for i, x in enumerate(r.array(top, "params")))
        tables = r.obj(top.get("statuses"), "statuses")
        statuses = {key: tuple(r.status_row(row, f"statuses.{key}[{i}]")
                               for i, row in enumerate(r.array(tables, key, "statuses.")))
                    for key in tables}
        return cls(generator=r.string(top, "generator"), generator_version=r.string(top, "generator_version"),
                   casadi_version=r.string(top, "casadi_version"), name=name, spec_hash=r.string(top, "spec_hash"),
                   real=real, dims=dims, functions=functions, library=r.string(top, "library"), params=params,
                   statuses=statuses)

    def write(self, solver_dir: Path) -> None:
        (Path(solver_dir) / MANIFEST).write_text(json.dumps(self.to_json(), indent=2) + "\n")

    @classmethod
    def read(cls, solver_dir: str | Path) -> Manifest:
        """The manifest of the package in ``solver_dir``; ManifestMissingError when the folder or its
        manifest does not exist, ManifestError when it cannot be read as one."""
        d = Path(solver_dir)
        path = d / MANIFEST
        if not d.exists():
            raise ManifestMissingError(f"{d} does not exist: give the folder `humanmpc-gen generate` wrote "
                                       "(by default generated/<name>)")
        if not d.is_dir():
            raise ManifestMissingError(f"{d} is a file, not a folder: give the folder `humanmpc-gen generate` wrote")
        if not path.is_file():
            raise ManifestMissingError(f"{d} is not a generated humanmpc solver: {MANIFEST} is missing")
        try:
            data = json.loads(path.read_text())
        except (OSError, ValueError) as err:
            raise ManifestError(f"{path} is not a humanmpc manifest ({err}): {REGENERATE}") from None
        return cls.from_json(data, str(path))


def held_spec_hash(solver_dir: str | Path) -> str | None:
    """The spec hash in ``solver_dir``'s manifest; None when there is no readable manifest."""
    try:
        return Manifest.read(solver_dir).spec_hash
    except ManifestError:
        return None


class _Reader:
    """Typed access to parsed JSON, naming the key that is missing or of the wrong type."""

    def __init__(self, where: str) -> None:
        self.where = where

    def _fail(self, key: str, want: str, got: object) -> ManifestError:
        what = f"'{key}'" if key else "the file"
        return ManifestError(f"{self.where} is not a humanmpc manifest: {what} must be {want}, "
                             f"got {type(got).__name__} {got!r:.60}: {REGENERATE}")

    def _get(self, obj: Mapping[str, Any], key: str, prefix: str) -> Any:
        if key not in obj:
            raise ManifestError(f"{self.where} is not a humanmpc manifest: '{prefix}{key}' is missing: {REGENERATE}")
        return obj[key]

    def obj(self, value: object, key: str) -> Mapping[str, Any]:
        if not isinstance(value, dict):
            raise self._fail(key, "a JSON object", value)
        return value

    def array(self, obj: Mapping[str, Any], key: str, prefix: str = "") -> list[Any]:
        value = self._get(obj, key, prefix)
        if not isinstance(value, list):
            raise self._fail(prefix + key, "a list", value)
        return value

    def string(self, obj: Mapping[str, Any], key: str, prefix: str = "") -> str:
        value = self._get(obj, key, prefix)
        if not isinstance(value, str):
            raise self._fail(prefix + key, "a string", value)
        return value

    def integer(self, obj: Mapping[str, Any], key: str, prefix: str = "") -> int:
        value = self._get(obj, key, prefix)
        if not isinstance(value, int) or isinstance(value, bool):
            raise self._fail(prefix + key, "an integer", value)
        return value

    def number(self, obj: Mapping[str, Any], key: str, prefix: str = "") -> float:
        value = self._get(obj, key, prefix)
        if not isinstance(value, int | float) or isinstance(value, bool):
            raise self._fail(prefix + key, "a number", value)
        return float(value)

    def ports(self, f: Mapping[str, Any], key: str, i: int) -> tuple[Port, ...]:
        out = []
        for k, p in enumerate(self.array(f, key, f"functions[{i}].")):
            where = f"functions[{i}].{key}[{k}]"
            if not (isinstance(p, list) and len(p) == 3 and isinstance(p[0], str)
                    and all(isinstance(n, int) and not isinstance(n, bool) and n >= 0 for n in p[1:])):
                raise self._fail(where, "[name, rows, cols]", p)
            out.append(Port(p[0], p[1], p[2]))
        return tuple(out)

    def status_row(self, row: object, where: str) -> StatusRow:
        if not (isinstance(row, list) and len(row) == 3 and isinstance(row[0], int) and not isinstance(row[0], bool)
                and isinstance(row[1], str) and _IDENT.fullmatch(row[1]) and isinstance(row[2], str)):
            raise self._fail(where, "[value, name, message]", row)
        return StatusRow(row[0], row[1], row[2])
