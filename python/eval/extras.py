"""The campaign extra's packages (``pip install 'humanmpc[campaign]'``), imported when first used.

The tool's other commands need none of them, so every module of humanmpc imports without them; a
campaign that needs one and does not find it is an ``ImportError`` that says what to install.
"""

from __future__ import annotations

import importlib
from types import ModuleType


def require(module: str, what: str) -> ModuleType:
    """``module`` imported, or an ``ImportError`` naming ``what`` needs it and how to install it."""
    try:
        return importlib.import_module(module)
    except ImportError as err:
        raise ImportError(f"{what} needs {module.split('.')[0]} ({err}): pip install 'humanmpc[campaign]'") from None


def arrow() -> tuple[ModuleType, ModuleType]:
    """pyarrow and pyarrow.parquet, for the campaign's results."""
    return require("pyarrow", "the campaign's results (Parquet)"), require("pyarrow.parquet", "the campaign's results")
