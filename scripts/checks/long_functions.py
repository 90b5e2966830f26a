#!/usr/bin/env python3
"""Lists Rust functions longer than a limit (default 80 lines, signature to closing brace),
outside tests and coefficient tables (a `const`/`static` array is not a function; a function
that is one, such as a Runge–Kutta method's stages, says so on the line above its `fn`).

Usage: scripts/checks/long_functions.py [--limit N] DIR...   Exit status 1 when one is found.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

FN = re.compile(r"^(\s*)(pub(\([^)]*\))?\s+)?(const\s+)?(async\s+)?(unsafe\s+)?fn\s+(\w+)")


def functions(path: Path):
    lines = path.read_text().splitlines()
    in_tests = None
    i = 0
    while i < len(lines):
        line = lines[i]
        if re.match(r"^\s*#\[cfg\(test\)\]", line):
            in_tests = len(line) - len(line.lstrip())
        m = FN.match(line)
        exempt = any("coefficient table" in lines[k] for k in range(max(0, i - 3), i))
        if m and in_tests is None and not exempt:
            depth, start, j, opened = 0, i, i, False
            while j < len(lines):
                code = lines[j].split("//")[0]
                depth += code.count("{") - code.count("}")
                opened = opened or "{" in code
                if opened and depth <= 0:
                    break
                if not opened and code.rstrip().endswith(";"):
                    break  # a declaration without a body
                j += 1
            if opened:
                yield m.group(7), start + 1, j - start + 1
            i = j + 1
            continue
        i += 1


def main() -> int:
    args = sys.argv[1:]
    limit = 80
    if "--limit" in args:
        k = args.index("--limit")
        limit = int(args[k + 1])
        del args[k : k + 2]
    found = []
    for d in args:
        for path in sorted(Path(d).rglob("*.rs")):
            if "/tests/" in str(path) or "/benches/" in str(path):
                continue
            for name, line, length in functions(path):
                if length > limit:
                    found.append((length, f"{path}:{line} {name} ({length} lines)"))
    for _, text in sorted(found, reverse=True):
        print(text)
    print(f"{len(found)} function(s) over {limit} lines")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
