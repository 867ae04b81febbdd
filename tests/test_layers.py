"""The package's layers import only downwards.

Every module under ``src/polind`` is parsed with :mod:`ast`; each
``import``/``from ... import`` statement, at module level or inside a function
(a lazy import is still a dependency), relative ones resolved, and each
``importlib.import_module("polind....")`` / ``__import__("polind....")`` with a
literal name, is mapped to the layer of the module it imports.  A module in a
subpackage belongs to the subpackage's layer.  Importing a module of a higher
layer fails the test, naming the importing file, the imported module and both
layers; importing within one layer is allowed.

``polind/__init__.py`` (the public façade) and ``polind/__main__.py`` may
import anything.  Importing the façade itself (``import polind``, ``from
polind import __version__``) counts as importing the highest layer the façade
names.  A module that is not in :data:`LAYERS` is an error of this test: place
it in the order below before anything else is checked.
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "polind"
PACKAGE = "polind"

#: Top to bottom.  A layer may import its own layer and any layer below it.
LAYERS = (
    ("cli",),
    ("demo", "report", "bench", "topography_figure"),
    ("phenomena", "sweeps"),
    ("identification",),
    ("structures", "control", "fmu", "batch", "stepper", "dynamics", "simulation"),
    ("models",),
    ("io", "datasets"),
    ("contact", "topography"),
    ("kernels",),
    ("validation", "errors", "resources"),
)
LAYER_OF = {name: index for index, names in enumerate(LAYERS) for name in names}

#: Modules that may import anything (the public façade and ``python -m``).
UNRESTRICTED = {PACKAGE, f"{PACKAGE}.__main__"}

#: Upward imports known today and not yet fixed, as (importer, imported
#: module) pairs.  Empty: every layer violation fails.  Add a pair here only
#: together with the reason it cannot be fixed yet; a new violation still fails.
KNOWN: frozenset[tuple[str, str]] = frozenset()


class UnplacedModule(Exception):
    """A polind module that :data:`LAYERS` does not place: the test itself must be updated."""


def layer_label(index: int) -> str:
    return "/".join(LAYERS[index])


def component(module: str) -> str | None:
    """The first name under ``polind`` (``None`` for the façade ``polind`` itself)."""
    parts = module.split(".")
    if parts[0] != PACKAGE:
        raise ValueError(f"{module} is not a {PACKAGE} module")
    return parts[1] if len(parts) > 1 else None


def layer_of(module: str) -> int:
    name = component(module)
    if name is None or name == "__main__":
        raise ValueError(f"{module} has no layer (façade)")
    if name not in LAYER_OF:
        raise UnplacedModule(
            f"{module}: '{name}' is not in LAYERS of tests/test_layers.py; "
            f"decide which layer it belongs to and add it there"
        )
    return LAYER_OF[name]


def module_name(path: Path) -> tuple[str, bool]:
    """Dotted name of a source file under SRC and whether it is a package ``__init__``."""
    parts = list(path.relative_to(SRC).with_suffix("").parts)
    is_package = parts[-1] == "__init__"
    if is_package:
        parts = parts[:-1]
    return ".".join([PACKAGE, *parts]), is_package


def package_modules() -> dict[str, tuple[Path, bool]]:
    modules = {}
    for path in sorted(SRC.rglob("*.py")):
        name, is_package = module_name(path)
        modules[name] = (path, is_package)
    return modules


def _literal_import(node: ast.Call) -> str | None:
    """The name in ``importlib.import_module("x")`` / ``import_module("x")`` / ``__import__("x")``."""
    func = node.func
    name = func.attr if isinstance(func, ast.Attribute) else func.id if isinstance(func, ast.Name) else None
    if name not in ("import_module", "__import__") or not node.args:
        return None
    first = node.args[0]
    if isinstance(first, ast.Constant) and isinstance(first.value, str) and not first.value.startswith("."):
        return first.value
    return None


def imports_of(source: str, module: str, is_package: bool = False, known: frozenset | set = frozenset()):
    """``(line, imported module)`` for every polind import in ``source``, at any depth.

    ``module`` is the importing module's dotted name (to resolve relative
    imports); ``known`` the names of existing polind modules, so that
    ``from polind import io`` is the module ``polind.io`` while ``from
    polind import __version__`` is the façade ``polind``.
    """
    tree = ast.parse(source)
    package = module if is_package else module.rpartition(".")[0]
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                found.append((node.lineno, alias.name))
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                parts = package.split(".")
                if node.level - 1 >= len(parts):
                    raise ValueError(f"{module}:{node.lineno}: relative import beyond the top package")
                base = ".".join(parts[: len(parts) - (node.level - 1)])
                if node.module:
                    base = f"{base}.{node.module}"
            else:
                base = node.module
            for alias in node.names:
                candidate = f"{base}.{alias.name}"
                # A submodule if it exists (or, for polind itself, if its name is a layer).
                is_module = candidate in known or (base == PACKAGE and alias.name in LAYER_OF)
                found.append((node.lineno, candidate if is_module else base))
        elif isinstance(node, ast.Call):
            name = _literal_import(node)
            if name is not None:
                found.append((node.lineno, name))
    return [(line, name) for line, name in found if name == PACKAGE or name.startswith(PACKAGE + ".")]


def facade_layer(source: str, known: frozenset | set) -> int:
    """Layer of ``import polind``: the highest layer the façade imports or names in a string."""
    names = [name for _, name in imports_of(source, PACKAGE, True, known) if name not in UNRESTRICTED]
    tree = ast.parse(source)
    names += [
        node.value
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and node.value in known
        and node.value not in UNRESTRICTED
    ]
    return min((layer_of(name) for name in names), default=len(LAYERS) - 1)


def check_source(source: str, module: str, *, path: str = "<snippet>", is_package: bool = False,
                 known: frozenset | set = frozenset(), facade: int = 0) -> list[tuple[str, str, str]]:
    """Upward imports in one module: ``(importer, imported, message)`` each.

    ``facade`` is the layer that importing the façade ``polind`` counts as.
    """
    if module in UNRESTRICTED:
        return []
    own = layer_of(module)
    violations = []
    for line, target in imports_of(source, module, is_package, known):
        if target == f"{PACKAGE}.__main__":
            other, label = -1, "__main__, above everything"
        else:
            other = facade if target == PACKAGE else layer_of(target)
            label = layer_label(other)
        if other < own:
            violations.append((
                module,
                target,
                f"{path}:{line}: {module} (layer '{layer_label(own)}') imports {target} "
                f"(layer '{label}', higher)",
            ))
    return violations


def package_violations():
    modules = package_modules()
    known = frozenset(modules)
    facade = facade_layer(modules[PACKAGE][0].read_text(encoding="utf-8"), known)
    found = []
    for name, (path, is_package) in modules.items():
        found += check_source(path.read_text(encoding="utf-8"), name, path=str(path.relative_to(ROOT)),
                              is_package=is_package, known=known, facade=facade)
    return found


def package_imports(prefix: str):
    """``(file, line, imported)`` for every polind import of the modules under ``prefix``."""
    modules = package_modules()
    known = frozenset(modules)
    for name, (path, is_package) in modules.items():
        if name == prefix or name.startswith(prefix + "."):
            for line, target in imports_of(path.read_text(encoding="utf-8"), name, is_package, known):
                yield str(path.relative_to(ROOT)), line, target


# ---------------------------------------------------------------------------
# The package
# ---------------------------------------------------------------------------


def test_every_module_is_placed_in_a_layer():
    unplaced = []
    for name in package_modules():
        if name in UNRESTRICTED:
            continue
        try:
            layer_of(name)
        except UnplacedModule as error:
            unplaced.append(str(error))
    assert not unplaced, "\n".join(unplaced)


def test_layers_import_only_downwards():
    found = package_violations()
    new = [message for importer, imported, message in found if (importer, imported) not in KNOWN]
    assert not new, "upward imports:\n" + "\n".join(new)


def test_known_violations_are_still_there():
    # A fixed violation must leave KNOWN, so the list never hides a new one.
    found = {(importer, imported) for importer, imported, _ in package_violations()}
    assert not (KNOWN - found), f"fixed, remove from KNOWN: {sorted(KNOWN - found)}"


def test_kernels_import_only_kernels():
    bad = [
        f"{path}:{line}: imports {target}"
        for path, line, target in package_imports(f"{PACKAGE}.kernels")
        if not (target == f"{PACKAGE}.kernels" or target.startswith(f"{PACKAGE}.kernels."))
    ]
    assert not bad, "the kernels may import only polind.kernels.*:\n" + "\n".join(bad)


def imports_between(importer: str, imported: str) -> list[str]:
    """``file:line: imports module`` for each import of ``polind.<imported>`` under ``polind.<importer>``."""
    return [
        f"{path}:{line}: imports {target}"
        for path, line, target in package_imports(f"{PACKAGE}.{importer}")
        if target == f"{PACKAGE}.{imported}" or target.startswith(f"{PACKAGE}.{imported}.")
    ]


def test_contact_never_imports_models():
    bad = imports_between("contact", "models")
    assert not bad, "contact must not import polind.models:\n" + "\n".join(bad)


def test_topography_never_imports_contact():
    # One layer, one way: contact builds surfaces from topography's results.
    bad = imports_between("topography", "contact")
    assert not bad, "topography must not import polind.contact:\n" + "\n".join(bad)


def private_imports(source: str, module: str, is_package: bool = False) -> list[str]:
    """``line: name from module`` for each private name (``_x``) imported from another module.

    A helper one module lends another is public where it lives (the package's
    boundaries are its files' boundaries); only dunders are exempt.
    """
    package = module if is_package else module.rpartition(".")[0]
    found = []
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, ast.ImportFrom):
            continue
        if node.level:
            parts = package.split(".")
            base = ".".join(parts[: len(parts) - (node.level - 1)])
            base = f"{base}.{node.module}" if node.module else base
        else:
            base = node.module or ""
        if not (base == PACKAGE or base.startswith(PACKAGE + ".")) or base == module:
            continue
        for alias in node.names:
            if alias.name.startswith("_") and not alias.name.startswith("__"):
                found.append(f"{node.lineno}: {alias.name} from {base}")
    return found


def test_no_private_name_is_imported_across_modules():
    bad = [f"{path.relative_to(ROOT)}:{entry}"
           for name, (path, is_package) in package_modules().items()
           for entry in private_imports(path.read_text(encoding="utf-8"), name, is_package)]
    assert not bad, "private names imported from another module:\n" + "\n".join(bad)


def component_graph() -> dict[str, set[str]]:
    """``{component: components it imports}`` between polind's top-level modules and packages."""
    graph: dict[str, set[str]] = {}
    for path, _, target in package_imports(PACKAGE):
        importer = component(module_name(ROOT / path)[0])
        imported = component(target)
        if importer not in (None, "__main__") and imported not in (None, importer):
            graph.setdefault(importer, set()).add(imported)
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Every elementary cycle's nodes found by a depth-first search (each cycle once)."""
    found, seen = [], set()

    def visit(node, trail):
        for nxt in sorted(graph.get(node, ())):
            if nxt in trail:
                cycle = trail[trail.index(nxt):]
                key = frozenset(cycle)
                if key not in seen:
                    seen.add(key)
                    found.append(cycle + [nxt])
            elif len(trail) < len(graph) + 1:
                visit(nxt, trail + [nxt])

    for start in sorted(graph):
        visit(start, [start])
    return found


def test_no_import_cycle_between_packages():
    found = cycles(component_graph())
    assert not found, "import cycles between polind's packages:\n" + "\n".join(
        " -> ".join(cycle) for cycle in found)


def test_no_module_over_about_600_lines():
    """One idea per module: a module that grows past ~600 lines holds more than one."""
    long = [f"{path.relative_to(ROOT)}: {count} lines"
            for path, _ in package_modules().values()
            if (count := len(path.read_text(encoding="utf-8").splitlines())) > 650]
    assert not long, "modules of more than one idea:\n" + "\n".join(long)


def test_no_module_shares_its_name_with_a_function_of_the_public_api():
    """``polind.sweep`` is a function, so no module ``polind.sweep`` (and so on)."""
    import polind

    clash = sorted(name for name in polind.__all__
                   if callable(getattr(polind, name)) and not isinstance(getattr(polind, name), type)
                   and f"{PACKAGE}.{name}" in package_modules())
    assert not clash, f"modules named like a public function: {clash}"


# ---------------------------------------------------------------------------
# The checker itself: it must report what it is meant to report
# ---------------------------------------------------------------------------


def test_checker_reports_an_upward_import():
    source = "from polind.models.params import check_number\n"
    found = check_source(source, "polind.contact._checks", path="src/polind/contact/_checks.py")
    assert [(importer, imported) for importer, imported, _ in found] == [
        ("polind.contact._checks", "polind.models.params")
    ]
    message = found[0][2]
    for part in ("src/polind/contact/_checks.py:1", "polind.models.params", "'contact/topography'", "'models'"):
        assert part in message


def test_checker_reports_a_lazy_import_inside_a_function():
    source = "import numpy as np\n\n\ndef run():\n    if True:\n        from polind import io\n    return io\n"
    found = check_source(source, "polind.kernels.single", known={"polind.io"})
    assert [(imported, message.split(":")[1]) for _, imported, message in found] == [("polind.io", "6")]


def test_checker_reports_plain_and_relative_and_dynamic_imports():
    source = (
        "import polind.simulation\n"
        "from ..models import base\n"
        "from . import surface\n"
        "import importlib\n"
        "importlib.import_module('polind.phenomena')\n"
    )
    known = {"polind.models.base", "polind.contact.surface"}
    found = check_source(source, "polind.contact.elements", known=known)
    assert [imported for _, imported, _ in found] == ["polind.simulation", "polind.models.base", "polind.phenomena"]


def test_checker_allows_same_layer_and_downward_imports():
    source = (
        "from polind.simulation import simulate\n"
        "from polind.kernels import dynamics as kernel\n"
        "from polind.errors import InputError\n"
        "from polind.validation import check_number\n"
        "import numpy\n"
    )
    assert check_source(source, "polind.dynamics", known={"polind.kernels.dynamics"}) == []


def test_checker_counts_the_facade_as_its_highest_import():
    facade = "from polind.simulation import simulate\n_LAZY = {'x': 'polind.identification'}\n"
    layer = facade_layer(facade, {"polind.simulation", "polind.identification"})
    assert layer == LAYER_OF["identification"]
    assert check_source("import polind\n", "polind.models.base", facade=layer)
    assert check_source("from polind import __version__\n", "polind.demo", facade=layer) == []


def test_checker_refuses_an_unplaced_module():
    with pytest.raises(UnplacedModule, match="polind.newthing"):
        check_source("", "polind.newthing.core")
    with pytest.raises(UnplacedModule, match="polind.elsewhere"):
        check_source("from polind.elsewhere import x\n", "polind.cli")


def test_checker_reports_a_private_import_and_a_cycle():
    source = "from polind.io import _atomic_open\nfrom .elements import _table, __all__\n"
    assert private_imports(source, "polind.contact.surface") == [
        "1: _atomic_open from polind.io", "2: _table from polind.contact.elements"]
    assert private_imports("from ..io import _x\n", "polind.contact", is_package=True) == [
        "1: _x from polind.io"]
    assert private_imports("from polind.contact.surface import _y\n", "polind.contact.surface") == []
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c", "a"]]
    assert cycles({"a": {"b"}, "b": set()}) == []
