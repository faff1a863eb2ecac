"""cffi bindings of a generated solver: load the shared library and call it on numpy arrays.

ABI mode (dlopen) with the declarations the generator wrote next to the C code, so loading needs
no compiler beyond the one that built the library. Before dlopen the library must be a whole ELF file
and, when humanmpc built it, the one it recorded (size and SHA-256); its spec hash and sizes are checked
against the package's manifest before anything is called.
"""

from __future__ import annotations

from collections import namedtuple
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import cffi
import numpy as np
from numpy.typing import ArrayLike, NDArray

from .codegen.build import LibraryIntegrityError, build, check_library, is_stale
from .codegen.manifest import MANIFEST, Manifest, ManifestError, ManifestMissingError, ModelFunctionInfo
from .codegen.manifest import Dims as Dims
from .codegen.params import Param
from .solver import Solver
from .status import check_package_tables, status_enums

FloatArray = NDArray[np.float64]


class LoadError(RuntimeError):
    """A generated solver folder that cannot be loaded (missing, stale, or not matching its library)."""


def _as_input(fn: str, port: str, value: ArrayLike, shape: tuple[int, ...], dtype: Any = np.float64) -> Any:
    arr = np.asarray(value, dtype=np.float64)
    if arr.shape != shape and not (arr.size == 1 and shape == ()):
        want = "a scalar" if shape == () else f"shape {shape}"
        raise ValueError(f"{fn}(): input '{port}' must be {want}, got shape {arr.shape}")
    # Column-major buffer for matrices, as the C code reads them.
    return np.ascontiguousarray(arr.reshape(shape).T if arr.ndim == 2 else arr.reshape(-1), dtype=dtype)


class ModelFunction:
    """One generated model function, callable on numpy arrays; returns a named tuple of outputs."""

    def __init__(self, ffi: cffi.FFI, cfunc: Callable[..., int], meta: ModelFunctionInfo, real: str = "double") -> None:
        self._ffi = ffi
        self._cfunc = cfunc
        self._ctype = f"{real}[]"  # buffers of the solver's real type; results are returned as float64
        self._dtype = np.dtype(np.float32 if real == "float" else np.float64)
        self.name: str = meta.name
        self.__doc__ = meta.doc
        self.inputs: list[tuple[str, tuple[int, ...]]] = [
            (p.name, () if (p.rows, p.cols) == (1, 1) else (p.rows,) if p.cols == 1 else (p.rows, p.cols))
            for p in meta.inputs
        ]
        self.outputs: list[tuple[str, tuple[int, int]]] = [(p.name, (p.rows, p.cols)) for p in meta.outputs]
        self._result: Any = namedtuple(f"{self.name}_result", [n for n, _ in self.outputs])  # type: ignore[misc]

    def __call__(self, *args: ArrayLike) -> Any:
        if len(args) != len(self.inputs):
            names = ", ".join(n for n, _ in self.inputs)
            raise TypeError(f"{self.name}() takes {len(self.inputs)} inputs ({names}), got {len(args)}")
        ins = [_as_input(self.name, n, a, shape, self._dtype) for (n, shape), a in zip(self.inputs, args, strict=True)]
        outs = [np.empty(r * c, dtype=self._dtype) for _, (r, c) in self.outputs]
        fb = self._ffi.from_buffer
        ret = self._cfunc(*[fb(self._ctype, a) for a in ins], *[fb(self._ctype, o) for o in outs])
        if ret != 0:
            raise RuntimeError(f"{self.name}() returned {ret}")
        shaped: list[float | FloatArray] = []
        for (_, (r, c)), out in zip(self.outputs, outs, strict=True):
            o = out.astype(np.float64, copy=False)
            if r == 1 and c == 1:
                shaped.append(float(o[0]))
            elif c == 1:
                shaped.append(o)
            else:
                shaped.append(o.reshape(c, r).T)  # column-major buffer -> (rows, cols) view
        return self._result(*shaped)


class ModelFunctions:
    """The model functions of a solver, as attributes: ``solver.model.dynamics(x, u)``."""

    def __init__(self, functions: dict[str, ModelFunction]) -> None:
        self._functions = functions
        for name, fn in functions.items():
            setattr(self, name, fn)

    def __iter__(self) -> Iterator[ModelFunction]:
        return iter(self._functions.values())

    def __repr__(self) -> str:
        return f"ModelFunctions({', '.join(self._functions)})"


def load(solver_dir: str | Path, *, build_if_needed: bool = True) -> Solver:
    """Load the generated solver in ``solver_dir`` (compiling it first when its library is stale)."""
    d = Path(solver_dir).resolve()
    try:
        manifest = Manifest.read(d)
    except ManifestMissingError:
        raise LoadError(f"{d} is not a generated humanmpc solver (no {MANIFEST}); "
                        "run `humanmpc-gen generate`") from None
    except ManifestError as err:
        raise LoadError(str(err)) from None
    name = manifest.name
    if is_stale(d):
        if not build_if_needed:
            raise LoadError(f"{d}: the library is missing or older than its sources; run `humanmpc-gen build {d}`")
        build(d)
    # the library is the package's own: a manifest may not point anywhere else
    lib_path = (d / manifest.library).resolve()
    if not lib_path.is_relative_to(d) or lib_path.suffix != ".so":
        raise LoadError(f"{d}: the manifest's library {manifest.library!r} is not a .so inside the package")
    ffi = cffi.FFI()
    try:
        ffi.cdef((d / f"{name}_cffi.h").read_text())
    except (OSError, cffi.CDefError) as err:
        raise LoadError(f"{d}: {name}_cffi.h cannot be read as the package's declarations ({err}); "
                        "regenerate the package") from None
    # a truncated or altered library would crash the process inside dlopen (SIGBUS): checked before
    try:
        check_library(lib_path)
    except (OSError, LibraryIntegrityError) as err:
        raise LoadError(f"{d}: {err}") from None
    lib = ffi.dlopen(str(lib_path))
    got_hash = ffi.string(getattr(lib, f"{name}_spec_hash")()).decode()
    if got_hash != manifest.spec_hash:
        raise LoadError(f"{d}: the library was built from spec {got_hash[:12]}, the folder holds "
                        f"{manifest.spec_hash[:12]}; rebuild it")
    sizes = ffi.new("int[5]")
    getattr(lib, f"{name}_dims")(sizes + 0, sizes + 1, sizes + 2, sizes + 3, sizes + 4)
    m = manifest.dims
    if list(sizes) != [m.nx, m.nu, m.N, m.nh, m.ng]:
        raise LoadError(f"{d}: library sizes {list(sizes)} do not match the manifest")
    # the declarations cffi writes through must be the compiled structs, byte for byte in size
    compiled = ffi.new("size_t[3]")
    getattr(lib, f"{name}_struct_sizes")(compiled + 0, compiled + 1, compiled + 2)
    declared = [ffi.sizeof(f"{name}_{s}") for s in ("params", "input", "output")]
    if list(compiled) != declared:
        raise LoadError(f"{d}: {name}_cffi.h declares params/input/output of {declared} bytes, the library "
                        f"was compiled with {list(compiled)}: regenerate and rebuild the package")
    model = ModelFunctions(
        {f.name: ModelFunction(ffi, getattr(lib, f"{name}_{f.name}"), f, manifest.real) for f in manifest.functions}
    )
    table = tuple(Param.from_manifest_row(row) for row in manifest.params)
    try:
        check_package_tables(manifest.statuses, str(d))
        statuses = status_enums(manifest.statuses, str(d))
    except ValueError as err:
        raise LoadError(str(err)) from None
    solver = Solver(name, manifest.dims, ffi, lib, model, d, manifest.spec_hash, table)
    solver.statuses = statuses  # the package's own enums (its manifest's tables)
    return solver
