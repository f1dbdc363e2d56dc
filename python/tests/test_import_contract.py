"""The package's import layering: the import-linter contract of python/pyproject.toml holds, and
no module of python/src/phsplit takes part in an import cycle."""
import ast
import os
import subprocess
import sys

import grimp

PYTHON_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SRC = os.path.join(PYTHON_DIR, "src", "phsplit")
#: The modules that may import the package itself (``import phsplit``): the front door and the CLI.
MAY_IMPORT_ROOT = {"__init__", "__main__", "cli"}


def test_the_layers_contract_is_kept():
    exe = os.path.join(os.path.dirname(sys.executable), "lint-imports")
    r = subprocess.run([exe, "--no-cache"], cwd=PYTHON_DIR, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "0 broken" in r.stdout


def _imports_of_root(path: str) -> list[str]:
    """The imports of the package root in a module, other than of its compiled core."""
    tree = ast.parse(open(path, encoding="utf-8").read())
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [a.name for a in node.names if a.name == "phsplit"]
        elif isinstance(node, ast.ImportFrom):
            root = (node.level == 1 and not node.module) or (node.level == 0 and node.module == "phsplit")
            if root:
                found += [a.name for a in node.names if a.name != "_core"]
    return found


def test_only_the_front_ends_import_the_package_itself():
    # The contract ignores `from . import _core` (read as an import of the package, since the
    # compiled core is invisible to import-linter); this makes sure nothing else hides there.
    offenders = {}
    for f in sorted(os.listdir(SRC)):
        if f.endswith(".py") and f[:-3] not in MAY_IMPORT_ROOT:
            names = _imports_of_root(os.path.join(SRC, f))
            if any(n == "phsplit" or not os.path.exists(os.path.join(SRC, n + ".py")) for n in names):
                offenders[f] = names
    assert offenders == {}


def test_no_import_cycle():
    graph = grimp.build_graph("phsplit", cache_dir=None)
    modules = sorted(m for m in graph.modules if m.startswith("phsplit."))
    for m in modules:  # `from . import _core`, checked above
        if graph.direct_import_exists(importer=m, imported="phsplit"):
            graph.remove_import(importer=m, imported="phsplit")
    cycles = []
    for a in modules:
        for b in graph.find_modules_directly_imported_by(a):
            if b != "phsplit" and graph.find_shortest_chain(importer=b, imported=a):
                cycles.append((a, b))
    assert cycles == []
