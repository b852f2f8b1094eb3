"""Running from a checkout, not installed: the laws and the catalogue then sit beside the
package, in controllers/ and models/, where an installed mbcontrol has them as
`mbcontrol.controllers` and `mbcontrol.models` (pyproject's package-dir). `install()` lets
those two names import from the checkout's folders, and nothing else; it does nothing when
either is found by the ordinary machinery (an install, editable or not)."""
from __future__ import annotations

import importlib.abc
import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FOLDERS = {"mbcontrol.controllers": ROOT / "controllers", "mbcontrol.models": ROOT / "models"}


class _Beside(importlib.abc.MetaPathFinder):
    """Finds exactly `FOLDERS`' packages in the checkout (their submodules then follow their
    __path__ as usual)."""

    def find_spec(self, name, path=None, target=None):
        folder = FOLDERS.get(name)
        if folder is None or not (folder / "__init__.py").is_file():
            return None
        return importlib.util.spec_from_file_location(
            name, folder / "__init__.py", submodule_search_locations=[str(folder)])


def install() -> None:
    """Add the finder at the end of sys.meta_path, once: an installed package wins."""
    if not any(isinstance(f, _Beside) for f in sys.meta_path):
        sys.meta_path.append(_Beside())
