"""Run flexcontact from a source checkout, as an editable install would.

The repository keeps the UFL forms and the gmsh meshes in the top-level folders ``forms/``
and ``meshes/``; they are the subpackages ``flexcontact.forms`` and ``flexcontact.meshes``.
The wheel maps them in (pyproject.toml's package-dir). In a checkout this module does the
same at import time: ``install()`` puts a finder on ``sys.meta_path`` that answers for those
two names with the folders. ``scripts/setup.sh`` registers the checkout with a ``.pth`` file
that imports this module, and the tests' conftest calls ``install()`` too.
"""
from __future__ import annotations

import importlib.abc
import importlib.machinery
import importlib.util
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
SUBPACKAGES = {"flexcontact.forms": ROOT / "forms", "flexcontact.meshes": ROOT / "meshes"}


class CheckoutFinder(importlib.abc.MetaPathFinder):
    """Finds ``flexcontact.forms`` and ``flexcontact.meshes`` in the checkout's folders."""

    def find_spec(self, name, path=None, target=None):
        folder = SUBPACKAGES.get(name)
        if folder is None or not (folder / "__init__.py").is_file():
            return None
        # Only for this checkout's package: an installed wheel brings its own subpackages.
        parent = sys.modules.get("flexcontact")
        home = Path(getattr(parent, "__file__", "") or "").resolve().parent
        if home != ROOT / "dolfinx_ext" / "python" / "flexcontact":
            return None
        return importlib.util.spec_from_file_location(
            name, folder / "__init__.py", submodule_search_locations=[str(folder)])


def install() -> None:
    """Add the finder once (idempotent)."""
    if not any(isinstance(f, CheckoutFinder) for f in sys.meta_path):
        sys.meta_path.insert(0, CheckoutFinder())


install()
