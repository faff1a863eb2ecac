"""Where the generator finds what it copies and renders: templates/ and c_runtime/."""

from __future__ import annotations

from pathlib import Path

from . import __version__

PROJECT_ROOT = Path(__file__).resolve().parent.parent
TEMPLATES_DIR = PROJECT_ROOT / "templates"
RUNTIME_DIR = PROJECT_ROOT / "c_runtime"


def check_resources() -> None:
    """Fail early, with the reason, when the package is not run from a humanmpc source tree."""
    for d in (TEMPLATES_DIR, RUNTIME_DIR):
        if not d.is_dir():
            raise FileNotFoundError(
                f"humanmpc {__version__}: {d} is missing; the generator reads templates/ and c_runtime/ "
                "from the source tree, so install it with `pip install -e .` from a checkout"
            )


def runtime_files() -> list[Path]:
    """The hand-written C runtime copied into every generated solver."""
    return sorted(p for p in RUNTIME_DIR.iterdir() if p.suffix in (".c", ".h"))
