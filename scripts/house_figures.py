"""The house's figures of issue 46, measured on the source: RAPID readers, imports of another package's
private module, the largest class and function (in lines), and the CLI's ``cycle`` (signature, body).

Run: ``python scripts/house_figures.py`` (prints a small table; nothing is written).
"""

from __future__ import annotations

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src" / "joulepath"


def _trees() -> dict[Path, ast.Module]:
    return {p: ast.parse(p.read_text(encoding="utf-8"), filename=str(p)) for p in sorted(SRC.rglob("*.py"))}


def rapid_readers(trees: dict[Path, ast.Module]) -> list[str]:
    """Modules that define a ``parse_module`` (a reader of RAPID text into a tree of their own)."""
    return [
        str(p.relative_to(SRC.parent))
        for p, tree in trees.items()
        if any(isinstance(n, ast.FunctionDef) and n.name == "parse_module" for n in tree.body)
    ]


def private_imports(trees: dict[Path, ast.Module]) -> list[str]:
    out = []
    for p, tree in trees.items():
        parts = p.relative_to(SRC).parts
        own = parts[0] if len(parts) > 1 else ""
        for node in ast.walk(tree):
            names = []
            if isinstance(node, ast.ImportFrom) and node.module and not node.level:
                names = [node.module]
                if node.module.count(".") == 1:
                    names += [f"{node.module}.{a.name}" for a in node.names]
            elif isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            for name in names:
                bits = name.split(".")
                if len(bits) >= 3 and bits[0] == "joulepath" and bits[1] != own and bits[2].startswith("_"):
                    out.append(f"{p.relative_to(SRC.parent)}:{node.lineno}: {name}")
    return sorted(set(out))


def largest(trees: dict[Path, ast.Module], kind: type, under: tuple[str, ...] = ()) -> tuple[int, str]:
    best = (0, "")
    for p, tree in trees.items():
        rel = str(p.relative_to(SRC))
        if under and not rel.startswith(under):
            continue
        for node in ast.walk(tree):
            if isinstance(node, kind):
                n = node.end_lineno - node.lineno + 1  # type: ignore[attr-defined]
                if n > best[0]:
                    best = (n, f"{rel}:{node.lineno} {node.name}")  # type: ignore[attr-defined]
    return best


def cli_cycle(trees: dict[Path, ast.Module]) -> tuple[int, int, int]:
    """Lines of ``joulepath.cli._cycle.cycle``: all, its signature (options), its body below the docstring."""
    tree = trees[SRC / "cli" / "_cycle.py"]
    fn = next(n for n in tree.body if isinstance(n, ast.FunctionDef) and n.name == "cycle")
    first = fn.body[1] if isinstance(fn.body[0], ast.Expr) else fn.body[0]
    total = fn.end_lineno - fn.lineno + 1
    body = fn.end_lineno - first.lineno + 1
    signature = fn.body[0].lineno - fn.lineno
    return total, signature, body


def main() -> None:
    trees = _trees()
    readers = rapid_readers(trees)
    private = private_imports(trees)
    cls = largest(trees, ast.ClassDef)
    fn_all = largest(trees, ast.FunctionDef)
    fn_prog = largest(trees, ast.FunctionDef, ("program/", "rapid/", "plant/"))
    total, sig, body = cli_cycle(trees)
    print(f"RAPID readers (modules defining parse_module): {len(readers)}: {', '.join(readers)}")
    print(f"imports of another package's private module: {len(private)}")
    print(f"largest class: {cls[0]} lines ({cls[1]})")
    print(f"largest function: {fn_all[0]} lines ({fn_all[1]})")
    print(f"largest function in program/, rapid/, plant/: {fn_prog[0]} lines ({fn_prog[1]})")
    print(f"the CLI's cycle: {total} lines: signature (options) {sig}, body below the docstring {body}")


if __name__ == "__main__":
    main()
