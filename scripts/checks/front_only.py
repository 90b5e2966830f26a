#!/usr/bin/env python3
"""Checks that a module's mod.rs is a front only (issue 53, item 3): it declares modules,
re-exports by name and documents, and defines nothing; and that no file below it imports an
item through it (`super::ITEM`, `super::super::ITEM`, `crate::planar::ITEM` where ITEM is not
a module), so every name inside says where it lives. No glob re-export anywhere below it.

Usage: scripts/checks/front_only.py DIR [--crate-path crate::planar]   Exit status 1 on a finding.
Test modules (`tests.rs`, `mod tests { … }`) may import `super::*`: they test their parent.
"""
import argparse
import pathlib
import re
import sys

ITEM = re.compile(r"^\s*(?:pub(?:\([a-z]+\))?\s+)?(?:const|static|fn|struct|enum|trait|type|impl)\b", re.M)
MOD = re.compile(r"^\s*(?:pub(?:\([a-z]+\))?\s+)?mod\s+([a-z_0-9]+)\s*;", re.M)


def strip_comments(text):
    return re.sub(r"//[^\n]*", "", text)


def code_outside_tests(text):
    """The text without `#[cfg(test)] mod tests { … }` blocks (brace-matched)."""
    out, i = [], 0
    for m in re.finditer(r"#\[cfg\(test\)\]\s*(?:pub(?:\([a-z]+\))?\s+)?mod\s+\w+\s*\{", text):
        if m.start() < i:
            continue
        out.append(text[i:m.start()])
        depth, j = 1, m.end()
        while j < len(text) and depth:
            depth += {"{": 1, "}": -1}.get(text[j], 0)
            j += 1
        i = j
    out.append(text[i:])
    return "".join(out)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("dir")
    ap.add_argument("--crate-path", default="crate::planar")
    args = ap.parse_args()
    root = pathlib.Path(args.dir)
    front = strip_comments((root / "mod.rs").read_text())
    findings = []
    body = re.sub(r"#\[cfg\(test\)\]\s*mod\s+tests\s*;", "", front)
    if ITEM.search(body):
        findings.append(f"{root / 'mod.rs'}: defines an item (a front declares, re-exports and documents only)")
    modules = set(MOD.findall(front))
    for path in sorted(root.rglob("*.rs")):
        rel = path.relative_to(root)
        text = strip_comments(path.read_text())
        if re.search(r"\bpub(?:\([a-z]+\))?\s+use\s+[^;]*\*\s*;", text):
            findings.append(f"{path}: glob re-export")
        if path.name == "tests.rs" or path == root / "mod.rs":
            continue
        code = code_outside_tests(text)
        depth = len(rel.parts) - (1 if path.name == "mod.rs" else 0)
        if depth == 1 and re.search(r"^\s*use\s+super::\*\s*;", code, re.M):
            findings.append(f"{path}: `use super::*` (everything of the front) outside a test module")
        ups = [re.escape(args.crate_path) + "::"]
        ups.append("super::" if depth == 1 else "super::super::" if depth == 2 else "super::super::super::")
        for up in ups:
            for m in re.finditer(r"(?<![\w:])" + up + r"(\{[^}]*\}|[A-Za-z_0-9]+)", code):
                names = [n.strip().split("::")[0].split(" ")[0] for n in m.group(1).strip("{}").split(",")]
                for name in names:
                    if name and name not in modules and name != "self":
                        line = code[: m.start()].count("\n") + 1
                        findings.append(f"{path}:{line}: imports `{name}` through {args.crate_path} (import it from its module)")
    for f in findings:
        print(f)
    print(f"{root}: {len(findings)} finding(s); front declares {len(modules)} modules")
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
