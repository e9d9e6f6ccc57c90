"""Imports flow one way (docs/architecture.md §6, "Layers").

Every module of the package, forms/ and meshes/ is read as source (AST, nothing is
imported), and each of its imports, at module level or inside a function, is resolved to a
module of the package. A module may import from its own layer and the layers below it;
an import of a higher layer fails the test, naming the importing file, the line and both
layers.
"""
import ast
import importlib.util
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "dolfinx_ext" / "python" / "flexcontact"
SOURCES = {"flexcontact": PACKAGE, "flexcontact.forms": ROOT / "forms",
           "flexcontact.meshes": ROOT / "meshes"}

# The table alone, without importing the package (and its compiled module).
_spec = importlib.util.spec_from_file_location("_layers", PACKAGE / "layers.py")
_layers = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(_layers)
LAYERS, layer_of = _layers.LAYERS, _layers.layer_of


def _modules() -> dict[str, Path]:
    """Dotted module name → source file, for the package and the folders it maps in."""
    out = {}
    for prefix, folder in SOURCES.items():
        for path in sorted(folder.rglob("*.py")):
            rel = path.relative_to(folder).with_suffix("")
            parts = [p for p in rel.parts if p != "__init__"]
            out[".".join([prefix, *parts])] = path
    return out


MODULES = _modules()
COMPILED = {"flexcontact._cpp"}


def _is_package(name: str) -> bool:
    return MODULES.get(name, Path()).name == "__init__.py"


def _targets(name: str, node: ast.AST) -> list[str]:
    """The package modules an import statement refers to ([] for outside packages)."""
    if isinstance(node, ast.Import):
        return [a.name for a in node.names if a.name.split(".")[0] == "flexcontact"]
    base = node.module or ""
    if node.level:
        here = name.split(".") if _is_package(name) else name.split(".")[:-1]
        here = here[:len(here) - (node.level - 1)]
        base = ".".join(here + ([base] if base else []))
    if base.split(".")[0] != "flexcontact":
        return []
    # `from pkg import sub` names a submodule when there is one, else something in pkg.
    known = MODULES.keys() | COMPILED
    return [f"{base}.{a.name}" if f"{base}.{a.name}" in known else base for a in node.names]


def _violations() -> list[str]:
    found = []
    for name, path in MODULES.items():
        mine = layer_of(name)
        tree = ast.parse(path.read_text(), filename=str(path))
        for node in ast.walk(tree):
            if not isinstance(node, (ast.Import, ast.ImportFrom)):
                continue
            for target in _targets(name, node):
                theirs = layer_of(target)
                if LAYERS.index(theirs) > LAYERS.index(mine):
                    found.append(f"{path.relative_to(ROOT)}:{node.lineno}: {name} ({mine}) "
                                 f"imports {target} ({theirs}), a higher layer")
    return found


def test_every_module_has_a_layer():
    for name in MODULES:
        assert layer_of(name) in LAYERS, name


def test_no_module_imports_a_higher_layer():
    found = _violations()
    assert not found, "upward imports:\n" + "\n".join(found)


@pytest.mark.parametrize("source, target", [
    ("flexcontact.forms.elasticity", "flexcontact.problem"),
    ("flexcontact.problem", "flexcontact.meshes.hertz2d"),
    ("flexcontact.meshes.dam", "flexcontact.dam.scenario"),
    ("flexcontact.compat", "flexcontact.forms"),
])
def test_the_rule_sees_an_upward_import(source, target):
    """The rule itself: each of these imports would go up a layer."""
    assert LAYERS.index(layer_of(target)) > LAYERS.index(layer_of(source))


def test_relative_imports_resolve_inside_the_package():
    tree = ast.parse("from ..condensation import kernel_pairs\nfrom . import _cpp\n")
    a, b = tree.body
    assert _targets("flexcontact.dam.coupled_step", a) == ["flexcontact.condensation"]
    assert _targets("flexcontact.problem", b) == ["flexcontact._cpp"]
