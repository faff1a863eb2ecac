"""Where the generator finds what it renders and copies: its package data, the templates
(humanmpc.codegen.templates, the checkout's templates/) and the C runtime (humanmpc.codegen.c_runtime,
the checkout's c_runtime/), located with importlib.resources so that a wheel and an editable checkout
both work."""

from __future__ import annotations

import functools
import hashlib
from importlib import resources
from pathlib import Path

from . import __version__


def _data_dir(package: str) -> Path:
    try:
        root = resources.files(package)
    except ModuleNotFoundError:
        raise FileNotFoundError(
            f"humanmpc {__version__}: the package data {package} is not installed: reinstall humanmpc "
            "(pip install humanmpc, or pip install -e . from a checkout)"
        ) from None
    path = Path(str(root))
    if not path.is_dir():
        raise FileNotFoundError(
            f"humanmpc {__version__}: {package} is at {root}, which is not a folder: install humanmpc unzipped "
            "(pip does) so that the generator can read its templates and C runtime"
        )
    return path


def templates_dir() -> Path:
    """The Jinja2 templates of the generated package (and of the firmware and Ipopt builds)."""
    return _data_dir("humanmpc.codegen.templates")


def runtime_dir() -> Path:
    return _data_dir("humanmpc.codegen.c_runtime")


def check_resources() -> None:
    """Fail early, with the reason, when the generator's data are missing."""
    for d in (templates_dir(), runtime_dir()):
        if not any(d.iterdir()):
            raise FileNotFoundError(f"humanmpc {__version__}: {d} is empty: reinstall humanmpc")


def runtime_files() -> list[Path]:
    """The hand-written C runtime copied into every generated solver."""
    return sorted(p for p in runtime_dir().iterdir() if p.suffix in (".c", ".h"))


@functools.lru_cache(maxsize=1)
def generator_digest() -> str:
    """SHA-256 of everything that turns a spec into C besides the spec: the generator's modules, the
    templates and the C runtime (relative paths and contents). Two generators with the same digest
    write the same package for the same spec; caches of built solvers are keyed by it with the spec's
    digest, so a changed runtime is never served from a cache built by an older one."""
    h = hashlib.sha256()
    roots = (("codegen", Path(__file__).resolve().parent, "*.py"), ("templates", templates_dir(), "*.j2"),
             ("runtime", runtime_dir(), "*.[ch]"))
    for label, root, pattern in roots:
        for path in sorted(root.rglob(pattern)):
            h.update(f"{label}/{path.relative_to(root).as_posix()}\0".encode())
            h.update(path.read_bytes())
            h.update(b"\0")
    return h.hexdigest()
