"""No import circles between the modules of joulepath (issue 38).

The graph has one node per module (a package is its ``__init__``) and an arrow for
every import of another joulepath module anywhere in the file: at the top, inside a
function, under ``TYPE_CHECKING``. ``from joulepath.a import b`` points at the
module ``joulepath.a.b`` when there is one, otherwise at the package ``joulepath.a``.
A circle is a strongly connected component of more than one module, or a module that
imports itself.
"""

import ast
from pathlib import Path

import joulepath

SRC = Path(joulepath.__file__).parent


def _modules(root: Path) -> dict[str, Path]:
    """Dotted module name -> file, for every ``.py`` file under the package ``root``."""
    out = {}
    for path in sorted(root.rglob("*.py")):
        parts = list(path.relative_to(root.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts.pop()
        out[".".join(parts)] = path
    return out


def import_graph(root: Path) -> dict[str, dict[str, int]]:
    """Module -> {imported module of the same package: first line importing it}."""
    modules = _modules(root)
    graph: dict[str, dict[str, int]] = {}
    for name, path in modules.items():
        package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
        edges: dict[str, int] = {}
        for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
            targets = []
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:  # relative: from . import x, from ..a import b
                    anchor = package[: len(package) - node.level + 1]
                    base = ".".join([*anchor, base] if base else anchor)
                for alias in node.names:
                    sub = f"{base}.{alias.name}"
                    targets.append(sub if sub in modules else base)
            for target in targets:
                if target in modules:
                    edges.setdefault(target, node.lineno)
        graph[name] = edges
    return graph


def import_cycles(graph: dict[str, dict[str, int]]) -> list[list[str]]:
    """Strongly connected components with a circle in them (Tarjan, iterative), each sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for root in sorted(graph):
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1 or node in graph[node]:
                    found.append(sorted(component))
    return found


def _describe(graph: dict[str, dict[str, int]], component: list[str]) -> str:
    arrows = [
        f"{a} -> {b} (line {graph[a][b]})" for a in component for b in sorted(graph[a]) if b in component
    ]
    return " <-> ".join(component) + ": " + "; ".join(arrows)


def test_joulepath_has_no_import_cycles():
    graph = import_graph(SRC)
    assert len(graph) > 100  # every module was read
    cycles = [_describe(graph, c) for c in import_cycles(graph)]
    assert cycles == [], "import circles (move the shared piece to the module it belongs to):\n" + "\n".join(
        cycles
    )


def _write(root: Path, files: dict[str, str]) -> Path:
    for rel, text in files.items():
        path = root / rel
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)
    return root / "pkg"


def test_import_cycles_finds_function_local_relative_and_type_checking_circles(tmp_path):
    pkg = _write(
        tmp_path,
        {
            "pkg/__init__.py": "from pkg.a import x\n",
            "pkg/a.py": "def x():\n    from pkg.b import y\n    return y\n",
            "pkg/b.py": "from typing import TYPE_CHECKING\nif TYPE_CHECKING:\n    from pkg import a\ny = 1\n",
            "pkg/sub/__init__.py": "",
            "pkg/sub/c.py": "from . import d\n",
            "pkg/sub/d.py": "from ..sub.c import z\nimport pkg.e\n",
            "pkg/e.py": "import os\nfrom pkg import sub\n",
        },
    )
    graph = import_graph(pkg)
    assert graph["pkg"] == {"pkg.a": 1}
    assert graph["pkg.a"] == {"pkg.b": 2}
    assert graph["pkg.sub.d"] == {"pkg.sub.c": 1, "pkg.e": 2}
    assert graph["pkg.e"] == {"pkg.sub": 2}
    assert import_cycles(graph) == [["pkg.a", "pkg.b"], ["pkg.sub.c", "pkg.sub.d"]]
    message = _describe(graph, ["pkg.a", "pkg.b"])
    assert message == "pkg.a <-> pkg.b: pkg.a -> pkg.b (line 2); pkg.b -> pkg.a (line 3)"


def test_import_cycles_accepts_a_layered_package_and_finds_a_self_import(tmp_path):
    pkg = _write(
        tmp_path,
        {
            "pkg/__init__.py": "from pkg.b import y\n",
            "pkg/a.py": "x = 1\n",
            "pkg/b.py": "from pkg.a import x\ny = x\n",
        },
    )
    assert import_cycles(import_graph(pkg)) == []
    (pkg / "a.py").write_text("def f():\n    import pkg.a\n")
    assert import_cycles(import_graph(pkg)) == [["pkg.a"]]


def private_imports(root: Path) -> list[str]:
    """``file:line: module`` for every import of another package's private module (issue 46):
    ``joulepath.a._b`` (or ``from joulepath.a import _b``) in a module outside ``joulepath.a``. A
    package is used through its ``__init__``'s names; the root's own modules (``joulepath._io`` ...)
    are the foundation every package shares."""
    out = []
    for path in sorted(root.rglob("*.py")):
        parts = path.relative_to(root).parts
        own = parts[0] if len(parts) > 1 else ""
        for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
            names: list[str] = []
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
                names = [node.module]
                if node.module.count(".") == 1:  # from joulepath.a import _b
                    names += [f"{node.module}.{alias.name}" for alias in node.names]
            for name in names:
                bits = name.split(".")
                if len(bits) >= 3 and bits[0] == "joulepath" and bits[1] != own and bits[2].startswith("_"):
                    out.append(f"{path.relative_to(root.parent)}:{node.lineno}: {name}")
    return sorted(set(out))


def test_packages_use_each_other_through_their_public_names():
    found = private_imports(SRC)
    assert not found, "imports of another package's private module:\n" + "\n".join(found)
