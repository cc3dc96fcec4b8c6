#!/usr/bin/env python3
"""The module import graph of a Rust crate, and its cycles.

    python3 scripts/import-graph.py SRC_DIR [--print]

Nodes are the crate's modules (`a.rs` or `a/mod.rs` is `a`; `a/b.rs` is `a::b`); an edge
`a -> b` means a file of module `a` names `crate::b...` (in a `use` or a path) or, inside a
folder module, `super::b`. Tests (`#[cfg(test)]` modules and `tests.rs` files) are left out: they
may reach anywhere. Sub-module edges are folded onto the top-level modules of the crate root,
except that a folder's own sub-modules keep their edges to each other (`align::auto ->
align::icp`). Exits 1 and prints every cycle when the graph has one; with `--print`, prints the
edges.
"""
import re
import sys
from pathlib import Path

USE = re.compile(r"\bcrate::([a-z_][a-z0-9_]*)(?:::([a-z_][a-z0-9_]*))?")
SUPER = re.compile(r"\bsuper::([a-z_][a-z0-9_]*)")


def module_of(src: Path, f: Path) -> str:
    parts = list(f.relative_to(src).with_suffix("").parts)
    if parts[-1] in ("mod", "lib", "main"):
        parts = parts[:-1]
    return "::".join(parts) or "crate"


def strip_tests(text: str) -> str:
    """Drops `#[cfg(test)] mod x { ... }` blocks (brace matching) and `#[cfg(test)] mod x;`."""
    out, i = [], 0
    for m in re.finditer(r"#\[cfg\(test\)\]\s*(?:#\[[^\]]*\]\s*)*(?:pub(?:\([^)]*\))?\s+)?mod\s+\w+\s*([{;])", text):
        if m.start() < i:
            continue
        out.append(text[i:m.start()])
        if m.group(1) == ";":
            i = m.end()
            continue
        depth, j = 1, m.end()
        while j < len(text) and depth:
            depth += {"{": 1, "}": -1}.get(text[j], 0)
            j += 1
        i = j
    out.append(text[i:])
    return "".join(out)


TEST_MOD = re.compile(r"#\[cfg\(test\)\]\s*(?:#\[[^\]]*\]\s*)*(?:pub(?:\([^)]*\))?\s+)?mod\s+(\w+)\s*;")


def graph(src: Path):
    files = list(src.rglob("*.rs"))
    test_files = set()
    for f in files:
        folder = f.parent if f.name in ("mod.rs", "lib.rs", "main.rs") else f.with_suffix("")
        for name in TEST_MOD.findall(f.read_text()):
            test_files.update({folder / f"{name}.rs", folder / name / "mod.rs"})
    modules = {module_of(src, f): f for f in files if f.name != "tests.rs" and f not in test_files}
    top = {m.split("::")[0] for m in modules if m != "crate"}
    edges = set()
    for m, f in modules.items():
        if m == "crate":
            continue
        text = strip_tests(re.sub(r"//[^\n]*", "", f.read_text()))
        here = m.split("::")
        for a, b in USE.findall(text):
            if a not in top:
                continue
            target = a
            # Inside the same folder module, keep the sub-module edge.
            if len(here) > 1 and a == here[0] and b and f"{a}::{b}" in modules:
                target = f"{a}::{b}"
            src_node = m if (len(here) > 1 and target.startswith(here[0] + "::")) else here[0]
            if target != src_node:
                edges.add((src_node, target))
        if len(here) > 1 or f.name == "mod.rs":
            parent = here[0] if f.name != "mod.rs" else m
            for b in SUPER.findall(text):
                target = f"{parent}::{b}" if f.name != "mod.rs" else b
                if target in modules and target != m:
                    edges.add((m, target))
    return edges


def cycles(edges):
    adj = {}
    for a, b in edges:
        adj.setdefault(a, set()).add(b)
    found, state, stack = [], {}, []

    def visit(n):
        state[n] = 1
        stack.append(n)
        for m in sorted(adj.get(n, ())):
            if state.get(m) == 1:
                found.append(stack[stack.index(m):] + [m])
            elif m not in state:
                visit(m)
        stack.pop()
        state[n] = 2

    for n in sorted(adj):
        if n not in state:
            visit(n)
    return found


def main():
    src = Path(sys.argv[1])
    edges = graph(src)
    if "--print" in sys.argv:
        for a, b in sorted(edges):
            print(f"{a} -> {b}")
    found = cycles(edges)
    for c in found:
        print("cycle: " + " -> ".join(c))
    print(f"{src}: {len(edges)} edges, {len(found)} cycle(s)")
    sys.exit(1 if found else 0)


if __name__ == "__main__":
    main()
