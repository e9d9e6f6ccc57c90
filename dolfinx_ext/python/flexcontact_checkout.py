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

SUBPACKAGES = {"flexcontact.forms": "forms", "flexcontact.meshes": "meshes"}


def checkout_of(package_dir: Path):
    """The checkout whose ``dolfinx_ext/python/flexcontact`` is ``package_dir``, or None
    (an installed wheel, which brings its own subpackages)."""
    if package_dir.name == "flexcontact" and package_dir.parent.name == "python" \
            and package_dir.parent.parent.name == "dolfinx_ext":
        return package_dir.parents[2]
    return None


class CheckoutFinder(importlib.abc.MetaPathFinder):
    """Finds ``flexcontact.forms`` and ``flexcontact.meshes`` in the folders of the checkout
    that the imported ``flexcontact`` comes from, whichever clone registered this finder
    (several clones may be on one machine, one of them registered by its .pth)."""

    def find_spec(self, name, path=None, target=None):
        sub = SUBPACKAGES.get(name)
        parent = sys.modules.get("flexcontact")
        if sub is None or parent is None:
            return None
        root = checkout_of(Path(getattr(parent, "__file__", "") or "").resolve().parent)
        folder = None if root is None else root / sub
        if folder is None or not (folder / "__init__.py").is_file():
            return None
        return importlib.util.spec_from_file_location(
            name, folder / "__init__.py", submodule_search_locations=[str(folder)])


def install() -> None:
    """Add the finder once (idempotent)."""
    if not any(isinstance(f, CheckoutFinder) for f in sys.meta_path):
        sys.meta_path.insert(0, CheckoutFinder())


install()
