#!/usr/bin/env python3
"""Draws the module graph of a Rust crate from its imports and reports its cycles.

A module is a file under src/ (`a/b.rs` and `a/b/mod.rs` are `a::b`); an edge A -> B is any
path `crate::B...` or `super::...` resolving into B written in A's code (comments, including
doc links, are ignored; test modules count: a test is code too). Modules nested in one another
(`a` and `a::b`) do not count as a cycle between parent and child only when the child is the
one using the parent's items. Exit status 1 when a cycle exists.

Usage: scripts/checks/import_cycles.py CRATE_SRC_DIR [--depth N]   (N: module depth kept, default 2)
"""

from __future__ import annotations

import re
import sys
from pathlib import Path


def module_of(path: Path, src: Path) -> str:
    rel = path.relative_to(src).with_suffix("")
    parts = list(rel.parts)
    if parts[-1] in ("mod", "lib", "main"):
        parts = parts[:-1]
    return "::".join(parts)


def strip_comments(text: str) -> str:
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    return "\n".join(line.split("//")[0] for line in text.splitlines())


def cut(module: str, depth: int) -> str:
    return "::".join(module.split("::")[:depth])


def edges(src: Path, depth: int) -> dict[str, set[str]]:
    modules = {module_of(p, src) for p in src.rglob("*.rs")}
    graph: dict[str, set[str]] = {}
    for path in src.rglob("*.rs"):
        if "bin" in path.relative_to(src).parts:
            continue
        me = module_of(path, src)
        code = strip_comments(path.read_text())
        targets: set[str] = set()
        for m in re.finditer(r"\bcrate((?:::[a-z_][a-z0-9_]*)+)", code):
            targets.add(m.group(1).lstrip(":"))
        for m in re.finditer(r"\b((?:super::)+)((?:[a-z_][a-z0-9_]*::?)*)", code):
            ups = m.group(1).count("super")
            base = me.split("::")[: max(0, len(me.split("::")) - ups)]
            rest = [p for p in m.group(2).split("::") if p]
            targets.add("::".join(base + rest))
        for t in targets:
            # The longest known module that prefixes the path.
            parts = t.split("::")
            while parts and "::".join(parts) not in modules:
                parts.pop()
            if not parts:
                continue
            a, b = cut(me, depth), cut("::".join(parts), depth)
            if a != b and not a.startswith(b + "::") and not b.startswith(a + "::"):
                graph.setdefault(a, set()).add(b)
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """Strongly connected components with more than one module (Tarjan)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []
    counter = [0]

    def visit(v: str) -> None:
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in list(graph):
        if v not in index:
            visit(v)
    return out


def main() -> int:
    src = Path(sys.argv[1])
    depth = int(sys.argv[sys.argv.index("--depth") + 1]) if "--depth" in sys.argv else 2
    graph = edges(src, depth)
    found = cycles(graph)
    for comp in found:
        print(f"{src}: import cycle among {', '.join(comp)}")
        for a in comp:
            print(f"  {a} -> {', '.join(sorted(b for b in graph.get(a, ()) if b in comp))}")
    if not found:
        print(f"{src}: no import cycle ({len(graph)} modules with imports, depth {depth})")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
