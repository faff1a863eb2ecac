"""The campaign extra's packages (``pip install 'humanmpc[campaign]'``), imported when first used.

``evaluate``, ``report`` and the ORCA crowd model (``--crowd orca``) need them; ``generate``, ``build``,
``simulate`` and ``demo`` with the social force crowd do not, so every module of humanmpc imports without
them. A command that needs one and does not find it stops with an ``ImportError`` that names the extra and
the pip command that installs it into the Python running the command (:func:`install_line`).
"""

from __future__ import annotations

import importlib
import shlex
import sys
from pathlib import Path
from types import ModuleType

EXTRA = "campaign"


def install_line(extra: str = EXTRA) -> str:
    """The pip command that adds ``extra`` to this installation: from the checkout for an editable install
    (``make demo``'s .venv), else from the package index; with this interpreter's path, so that it installs
    where the command runs."""
    python = shlex.quote(sys.executable or "python3")
    checkout = Path(__file__).resolve().parents[2]
    if (checkout / "pyproject.toml").is_file() and (checkout / "python" / "eval" / "extras.py").is_file():
        return f"{python} -m pip install -e {shlex.quote(f'{checkout}[{extra}]')}"
    return f"{python} -m pip install 'humanmpc[{extra}]'"


def missing_extra(what: str, module: str) -> str:
    """The message of a missing package of the extra: what needs it, and the install line."""
    return f"{what} needs {module.split('.')[0]}, of humanmpc's '{EXTRA}' extra; install it with: {install_line()}"


def require(module: str, what: str) -> ModuleType:
    """``module`` imported, or an ``ImportError`` naming ``what`` needs it and how to install it."""
    try:
        return importlib.import_module(module)
    except ImportError:
        raise ImportError(missing_extra(what, module)) from None


def arrow() -> tuple[ModuleType, ModuleType]:
    """pyarrow and pyarrow.parquet, for the campaign's results."""
    return require("pyarrow", "the campaign's results (Parquet)"), require("pyarrow.parquet", "the campaign's results")
