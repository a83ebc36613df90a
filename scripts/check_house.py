#!/usr/bin/env python3
"""Checks the house rules that the compiler does not: inside each crate no file imports a file
that imports it back (through any chain), no `std::arch` outside a crate's `simd/` folder, and
no source file over 1,000 lines outside tests. Prints every breach and exits 1 if there is one.

Usage: python3 scripts/check_house.py [workspace root]
       python3 scripts/check_house.py --self-test   (the checks against small trees made to break them)
"""
import os
import re
import sys

MAX_LINES = 1000
USE = re.compile(r"^(?:pub(?:\([a-z]+\))?\s+)?use\s+([^;]+);", re.S)


def modules(src):
    """Maps each module path (tuple of names, () for the crate root) to its file."""
    found = {}
    for folder, _, files in os.walk(src):
        for name in files:
            if not name.endswith(".rs"):
                continue
            path = os.path.join(folder, name)
            parts = os.path.relpath(path, src)[:-3].split(os.sep)
            if parts[-1] in ("lib", "main", "mod"):
                parts = parts[:-1]
            found[tuple(parts)] = path
    return found


def top_level_code(path):
    """The file's text before its first `#[cfg(test)]` at column 0, without comments."""
    text = open(path, encoding="utf-8").read()
    cut = re.search(r"^#\[cfg\(test\)\]", text, re.M)
    if cut:
        text = text[: cut.start()]
    return re.sub(r"//[^\n]*", "", text)


def use_paths(tree):
    """Expands a use tree such as `crate::a::{b, c::{d, e}}` into its leaf paths."""
    tree = re.sub(r"\s+", "", tree)
    tree = re.sub(r"\bas\w+", "", tree.replace(" as ", "as"))
    out = []

    def walk(prefix, rest):
        if rest.startswith("{"):
            depth, start = 0, 1
            for i, ch in enumerate(rest):
                if ch == "{":
                    depth += 1
                elif ch == "}":
                    depth -= 1
                if (ch == "," and depth == 1) or (ch == "}" and depth == 0):
                    part = rest[start:i]
                    if part:
                        walk(prefix, part)
                    start = i + 1
            return
        head, sep, tail = rest.partition("::")
        if sep and tail:
            walk(prefix + [head], tail)
        else:
            out.append(prefix + [head])

    walk([], tree)
    return out


def imports(module, path, mods):
    """The modules of this crate that one file imports (`crate::`, `super::`, `self::` and
    child-module paths), each resolved to the module that holds the name."""
    code = top_level_code(path)
    found = set()
    for match in re.finditer(r"^([ \t]*)(?:pub(?:\([a-z]+\))?\s+)?use\s+([^;]+);", code, re.M):
        inline = bool(match.group(1))
        for parts in use_paths(match.group(2)):
            if inline and parts[0] != "crate":
                continue  # relative to an inline module of this file
            if parts[0] == "crate":
                base, rest = (), parts[1:]
            elif parts[0] == "super":
                base, rest = module, parts
                while rest and rest[0] == "super":
                    base, rest = base[:-1], rest[1:]
            elif parts[0] == "self":
                base, rest = module, parts[1:]
            elif module + (parts[0],) in mods:
                base, rest = module, parts
            else:
                continue
            target = resolve(tuple(base), list(rest), mods, 0)
            if target is not None and target != module:
                found.add(target)
    return found


def resolve(base, rest, mods, depth):
    """The module that defines `base::rest`, following `pub use` re-exports."""
    module = base
    while rest and module + (rest[0],) in mods:
        module, rest = module + (rest[0],), rest[1:]
    if not rest or rest == ["*"] or rest == ["self"] or depth > 8:
        return module
    name = rest[0]
    code = top_level_code(mods[module])
    for match in re.finditer(r"^pub(?:\([a-z]+\))?\s+use\s+([^;]+);", code, re.M):
        for parts in use_paths(match.group(1)):
            if parts[-1] != name:
                continue
            if parts[0] == "crate":
                return resolve((), parts[1:], mods, depth + 1)
            if parts[0] == "self":
                return resolve(module, parts[1:], mods, depth + 1)
            if parts[0] == "super":
                return resolve(module[:-1], parts[1:], mods, depth + 1)
            if module + (parts[0],) in mods:
                return resolve(module, parts, mods, depth + 1)
    return module


def cycles(graph):
    """Strongly connected components of more than one module (Tarjan, without recursion)."""
    index, low, on_stack, stack, out, counter = {}, {}, set(), [], [], [0]
    for root in graph:
        if root in index:
            continue
        work = [(root, iter(sorted(graph[root])))]
        index[root] = low[root] = counter[0]
        counter[0] += 1
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            advanced = False
            for child in children:
                if child not in index:
                    index[child] = low[child] = counter[0]
                    counter[0] += 1
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph.get(child, ())))))
                    advanced = True
                    break
                if child in on_stack:
                    low[node] = min(low[node], index[child])
            if advanced:
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    top = stack.pop()
                    on_stack.discard(top)
                    component.append(top)
                    if top == node:
                        break
                if len(component) > 1:
                    out.append(sorted(component))
    return out


def problems_in(root):
    """Every breach of the rules in the workspace at `root`."""
    crates = os.path.join(root, "crates")
    problems = []
    for crate in sorted(os.listdir(crates)):
        src = os.path.join(crates, crate, "src")
        if not os.path.isdir(src):
            continue
        mods = modules(src)
        graph = {m: imports(m, p, mods) for m, p in mods.items()}
        for component in cycles(graph):
            names = ", ".join(os.path.relpath(mods[m], src) for m in component)
            problems.append(f"{crate}: files import each other in a circle: {names}")
        for module, path in sorted(mods.items()):
            rel = os.path.relpath(path, src)
            text = open(path, encoding="utf-8").read()
            if "std::arch" in top_level_code(path) and "simd" not in module:
                problems.append(f"{crate}/src/{rel}: uses std::arch outside simd/")
            lines = text.count("\n")
            if lines > MAX_LINES and module[-1:] != ("tests",):
                problems.append(f"{crate}/src/{rel}: {lines} lines (at most {MAX_LINES})")
    return problems


def self_test():
    """Each rule against a tree that breaks it and one that keeps it."""
    import tempfile

    def tree(files):
        root = tempfile.mkdtemp()
        for rel, text in files.items():
            path = os.path.join(root, "crates", "c", "src", rel)
            os.makedirs(os.path.dirname(path), exist_ok=True)
            with open(path, "w", encoding="utf-8") as f:
                f.write(text)
        return root

    clean = {
        "lib.rs": "mod a;\nmod b;\nmod simd;\n",
        "a.rs": "use crate::b::B;\n// std::arch in a comment\n",
        "b.rs": "pub struct B;\n#[cfg(test)]\nmod tests {\n    use crate::a;\n    fn f() { std::arch::x86_64::_mm_pause() }\n}\n",
        "simd/mod.rs": "use std::arch::x86_64::*;\n",
    }
    assert problems_in(tree(clean)) == [], problems_in(tree(clean))
    circle = dict(clean, **{"b.rs": "use crate::a::{self, X};\npub struct B;\n"})
    assert any("circle: a.rs, b.rs" in p for p in problems_in(tree(circle)))
    through_reexport = dict(clean, **{
        "lib.rs": "mod a;\nmod b;\npub use b::B;\n",
        "a.rs": "use crate::B;\npub struct A;\n",
        "b.rs": "use super::a::A;\npub struct B;\n",
    })
    assert any("circle" in p for p in problems_in(tree(through_reexport)))
    arch = dict(clean, **{"a.rs": "fn f() { unsafe { std::arch::x86_64::_mm_pause() } }\n"})
    assert problems_in(tree(arch)) == ["c/src/a.rs: uses std::arch outside simd/"]
    long = dict(clean, **{"a.rs": "fn f() {}\n" * (MAX_LINES + 1)})
    assert problems_in(tree(long)) == [f"c/src/a.rs: {MAX_LINES + 1} lines (at most {MAX_LINES})"]
    print("self-test passed")


def main():
    if sys.argv[1:] == ["--self-test"]:
        self_test()
        return
    root = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..")
    crates = os.path.join(root, "crates")
    problems = problems_in(root)
    for problem in problems:
        print(problem)
    if problems:
        sys.exit(1)
    print(f"house rules hold in {len(os.listdir(crates))} crates")


if __name__ == "__main__":
    main()
