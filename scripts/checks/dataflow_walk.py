#!/usr/bin/env python3
"""Follows one parameter through the code, from its function's imports and calls (issue 44).

    python3 scripts/checks/dataflow_walk.py crates/rod-ig-core/src planar/entry.rs evaluate a [--trace] [--typed]

The walk starts in the named function with the named parameter tracked. In a function's body a
tracked value is any tracked parameter, `self` when the function was reached as a method of a
tracked receiver, or a local bound (`let`, `if let`, closure parameter) from an expression that
mentions one. Every call whose arguments or receiver mention a tracked value is entered (once
per function: the walk is a depth-first traversal of first visits), and the callee's parameter
at that position becomes tracked. A call resolves by name: a path's module names the file
(`closed::f` → `closed.rs` or `closed/mod.rs`), else the caller's own file, else the files the
caller's file imports from, else any file of the crate (all definitions of that name). With `--typed`, a method call on a value whose type the code
names (an argument `&ClosedForm { … }` or `dispatch::Evaluate`, a local `let x = Foo::new(…)`,
`self` in an impl) resolves to that type's method or its trait's default only, and a generic
function is walked once per binding of its parameters' types (a reader following one
instantiation).

Printed: the walk's sequence of files (runs of the same file collapsed), the number of *stays*
(runs) and of *returns* (runs in a file the walk had already left). Test modules
(`#[cfg(test)]`, `tests.rs`) are not followed. A reader's view, not a compiler's: trait calls
resolve by method name, and macros are not expanded.
"""
import os
import re
import sys

FN_RE = re.compile(r"\bfn\s+([A-Za-z_][A-Za-z0-9_]*)\s*(<[^{;]*?>)?\s*\(")
CALL_RE = re.compile(r"(?:(\b[A-Za-z_][A-Za-z0-9_]*)\s*::\s*)?(\.)?\b([a-z_][A-Za-z0-9_]*)\s*(?:::<[^>]*>)?\s*\(")
KEYWORDS = {"if", "while", "for", "match", "return", "loop", "fn", "let", "in", "as", "move",
            "Some", "Ok", "Err", "None", "unsafe", "impl", "where", "mut", "ref"}


def strip_comments(text):
    """Comments and string contents blanked (lengths kept, so offsets stay valid)."""
    out, i, n = [], 0, len(text)
    while i < n:
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        elif text[i] == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append('"' + " " * (j - i - 1) + '"')
            i = j + 1
        elif text[i] == "'" and i + 2 < n and (text[i + 2] == "'" or text[i + 1] == "\\"):
            j = text.find("'", i + 2 if text[i + 1] == "\\" else i + 1)
            out.append(" " * (j - i + 1))
            i = j + 1
        else:
            out.append(text[i])
            i += 1
    return "".join(out)


def matching(text, i, open_c, close_c):
    depth = 0
    for j in range(i, len(text)):
        if text[j] == open_c:
            depth += 1
        elif text[j] == close_c:
            depth -= 1
            if depth == 0:
                return j
    return len(text) - 1


def split_args(s):
    args, depth, cur = [], 0, ""
    for ch in s:
        if ch in "([{<" and not (ch == "<" and cur.rstrip().endswith(("=", "-"))):
            depth += 1
        elif ch in ")]}>" and not (ch == ">" and cur.rstrip().endswith(("-", "="))):
            depth -= 1
        if ch == "," and depth == 0:
            args.append(cur)
            cur = ""
        else:
            cur += ch
    if cur.strip():
        args.append(cur)
    return args


def test_spans(text):
    """Spans of `#[cfg(test)] mod … { … }` bodies."""
    spans = []
    for m in re.finditer(r"#\[cfg\(test\)\]\s*mod\s+\w+\s*\{", text):
        spans.append((m.start(), matching(text, m.end() - 1, "{", "}")))
    return spans


class Fn:
    def __init__(self, file, name, params, body, is_method, owner=(None, None)):
        self.file, self.name, self.params, self.body, self.is_method = file, name, params, body, is_method
        # (self type, trait) of the enclosing `impl Trait for Type` / `impl Type` / `trait Trait`.
        self.owner = owner


IMPL_RE = re.compile(r"\b(?:impl(?:<[^{]*?>)?\s+(?:([\w:]+)(?:<[^{]*?>)?\s+for\s+)?&?([\w:]+)[^{;]*?"
                     r"|(?:pub(?:\([\w]+\))?\s+)?trait\s+(\w+)[^{;]*?)\{")


def owners(text):
    """Spans of impl and trait blocks with their (type, trait)."""
    spans = []
    for m in IMPL_RE.finditer(text):
        trait, ty, own_trait = m.group(1), m.group(2), m.group(3)
        end = matching(text, m.end() - 1, "{", "}")
        if own_trait:
            spans.append((m.end(), end, (None, own_trait)))
        else:
            spans.append((m.end(), end, (ty.split("::")[-1], trait.split("::")[-1] if trait else None)))
    return spans


def parse(root):
    fns, imports, types = {}, {}, {}
    for dirpath, _, files in os.walk(root):
        for f in files:
            if not f.endswith(".rs") or f == "tests.rs":
                continue
            path = os.path.relpath(os.path.join(dirpath, f), root)
            text = strip_comments(open(os.path.join(root, path), encoding="utf-8").read())
            spans = test_spans(text)
            blocks = owners(text)
            imports[path] = set(re.findall(r"\buse\s+(?:crate::|super::|self::)?([\w:]+)", text))
            for t in re.findall(r"\bimpl(?:<[^>]*>)?\s+(?:[\w:<>, ]+\s+for\s+)?(\w+)", text):
                types.setdefault(t, set()).add(path)
            for m in FN_RE.finditer(text):
                if any(a <= m.start() <= b for a, b in spans):
                    continue
                close = matching(text, m.end() - 1, "(", ")")
                brace = text.find("{", close)
                semi = text.find(";", close)
                if brace < 0 or (0 <= semi < brace):
                    continue  # a declaration without a body (trait item)
                end = matching(text, brace, "{", "}")
                raw = split_args(text[m.end():close])
                is_method = bool(raw) and "self" in raw[0].split(":")[0]
                params = []
                for p in raw[1:] if is_method else raw:
                    name = p.split(":")[0].strip()
                    name = re.sub(r"^(mut|ref)\s+", "", name)
                    params.append(name if re.fullmatch(r"\w+", name) else None)
                owner = next((o for a, b, o in reversed(blocks) if a <= m.start() <= b), (None, None))
                fns.setdefault(m.group(1), []).append(
                    Fn(path, m.group(1), params, text[brace:end + 1], is_method, owner))
    return fns, imports, types


# Number types: their methods are arithmetic (`x.sqrt()`, `d.recip()`), followed no more than
# an operator is.
ARITHMETIC = {"scalar.rs", "dd.rs", "eft.rs", "simd.rs"}
# Methods of std's traits and of the number trait, wherever a type implements them.
STD_METHODS = {"abs", "sqrt", "sin_cos", "sin", "cos", "exp", "ln", "powi", "powf", "recip",
               "min", "max", "mul_add", "hypot", "is_finite", "is_nan", "partial_cmp", "cmp",
               "clone", "eq", "fmt", "from", "into", "default", "next", "neg", "add", "sub",
               "mul", "div", "constant", "to_f64", "as_slice", "iter", "len", "deref"}


def module_candidates(cands, caller, module):
    """Definitions in module `module` as the caller's file names it: a child or sibling first."""
    here = os.path.dirname(caller.file)
    for base in (os.path.join(here, os.path.basename(caller.file)[:-3]) if not caller.file.endswith("mod.rs") else here,
                 here, os.path.dirname(here), ""):
        files = {os.path.normpath(os.path.join(base, module + ".rs")),
                 os.path.normpath(os.path.join(base, module, "mod.rs"))}
        found = [f for f in cands if f.file in files]
        # Re-exported from the module's own files (`pub use series::f` in `stability/mod.rs`).
        found = found or [f for f in cands
                          if os.path.dirname(f.file) == os.path.normpath(os.path.join(base, module))]
        if found:
            return found
    return []


def resolve(fns, imports, types, caller, qual, name, method):
    if method and name in STD_METHODS:
        return []
    cands = [f for f in fns.get(name, []) if f.file not in ARITHMETIC]
    if not cands:
        return []
    if qual and qual[0].isupper() and qual != "Self":
        return [f for f in cands if f.file in types.get(qual, ())]
    if qual and qual not in ("Self", "self", "super", "crate"):
        return module_candidates(cands, caller, qual)
    if qual == "Self":
        return [f for f in cands if f.file == caller.file]
    same = [f for f in cands if f.file == caller.file and f.is_method == method]
    if same:
        return same
    used = {u.split("::")[-1] for u in imports.get(caller.file, ())} | {
        u.split("::")[-2] for u in imports.get(caller.file, ()) if "::" in u}
    imported = [f for f in cands if f.is_method == method and any(
        module_candidates([f], caller, m) for m in used)]
    if imported:
        return imported
    # A name defined once in the crate needs no type to resolve.
    return cands if len(cands) == 1 and cands[0].is_method == method else []


def tainted(body, seeds):
    """The tracked names in a body: the seeds and the locals bound from them (to a fixed point)."""
    names = set(seeds)
    binds = re.compile(r"(?:let|if let|while let)\s+(?:mut\s+)?([^=]+?)(?::[^=]+)?=([^;{]+)")
    closures = re.compile(r"\|([^|]*)\|")
    changed = True
    while changed:
        changed = False
        for m in binds.finditer(body):
            if mentions(m.group(2), names):
                for v in re.findall(r"\b[a-z_]\w*\b", m.group(1)):
                    if v not in KEYWORDS and v not in names:
                        names.add(v)
                        changed = True
        for m in closures.finditer(body):
            if mentions(body[m.end():m.end() + 200], names):
                for v in re.findall(r"\b[a-z_]\w*\b", m.group(1)):
                    if v not in KEYWORDS and v not in names and v != "_":
                        names.add(v)
                        changed = True
    return names


def mentions(expr, names):
    return any(re.search(r"(?<![\w.])" + re.escape(n) + r"\b", expr) for n in names)


TYPE_ARG_RE = re.compile(r"^\s*&?\s*(?:\w+::)*([A-Z]\w*)\s*(?:[({]|::\s*new\b|$)")


def type_of(expr, known, types):
    """The type (one with impls) an argument or a local's initialiser names (`&ClosedForm { … }`,
    `dispatch::Evaluate`, `Foo::new(…)`), or the type bound to the plain name it is."""
    m = TYPE_ARG_RE.match(expr)
    if m:
        return m.group(1) if m.group(1) in types else None
    name = re.fullmatch(r"\s*&?\s*(\w+)\s*", expr)
    return known.get(name.group(1)) if name else None


def typed_candidates(fns, name, ty, traits_of):
    """The method `name` of type `ty`: its impls' own, else its traits' default."""
    own = [f for f in fns.get(name, []) if f.owner[0] == ty]
    if own:
        return own
    return [f for f in fns.get(name, []) if f.owner[0] is None and f.owner[1] in traits_of.get(ty, ())]


def walk(fns, imports, types, start, seeds, trace, typed=False):
    seq, seen = [], set()
    traits_of = {}
    for defs in fns.values():
        for f in defs:
            if f.owner[0] and f.owner[1]:
                traits_of.setdefault(f.owner[0], set()).add(f.owner[1])

    def visit(fn, tracked, depth, bound=None):
        bound = bound or {}
        key = (fn.file, fn.name, fn.body[:40], tuple(sorted(bound.items())) if typed else ())
        if key in seen:
            return
        seen.add(key)
        seq.append(fn.file)
        if trace:
            print("  " * depth + f"{fn.file}::{fn.name} {sorted(tracked)}" + (f" {bound}" if bound else ""))
        names = tainted(fn.body, tracked)
        # Locals whose type their initialiser names (typed walk only).
        known = dict(bound)
        if typed:
            for m in re.finditer(r"let\s+(?:mut\s+)?(\w+)\s*(?::[^=]+)?=\s*([^;]+);", fn.body):
                t = type_of(m.group(2), known, types)
                if t:
                    known[m.group(1)] = t
        for m in CALL_RE.finditer(fn.body):
            qual, dot, name = m.group(1), m.group(2), m.group(3)
            if name in KEYWORDS:
                continue
            close = matching(fn.body, m.end() - 1, "(", ")")
            args = split_args(fn.body[m.end():close])
            receiver = ""
            if dot:
                k = m.start()
                receiver = re.findall(r"([\w.\[\]()]+)\s*$", fn.body[max(0, k - 60):k] or "")
                receiver = receiver[0] if receiver else ""
            hits = [i for i, x in enumerate(args) if mentions(x, names)]
            via_receiver = bool(dot) and mentions(receiver, names)
            if not hits and not via_receiver:
                continue
            callees = None
            if typed and dot:
                recv = re.fullmatch(r"&?(\w+)", receiver or "")
                ty = known.get(recv.group(1)) if recv else None
                if recv and recv.group(1) == "self" and fn.owner[0]:
                    ty = fn.owner[0]
                if ty:
                    callees = typed_candidates(fns, name, ty, traits_of)
            if callees is None:
                callees = resolve(fns, imports, types, fn, qual, name, bool(dot))
            for callee in callees:
                if callee is fn:
                    continue
                seeds2 = {callee.params[i] for i in hits
                          if i < len(callee.params) and callee.params[i]}
                if via_receiver and callee.is_method:
                    seeds2.add("self")
                if not seeds2:
                    continue
                bound2 = {}
                if typed:
                    for i, x in enumerate(args):
                        t = type_of(x, known, types)
                        if t and i < len(callee.params) and callee.params[i]:
                            bound2[callee.params[i]] = t
                    if via_receiver and callee.is_method and callee.owner[0]:
                        bound2["self"] = callee.owner[0]
                visit(callee, seeds2, depth + 1, bound2)
                seq.append(fn.file)

    visit(start, set(seeds), 0)
    runs = []
    for f in seq:
        if not runs or runs[-1] != f:
            runs.append(f)
    left, returns = set(), 0
    for i, f in enumerate(runs):
        if f in left:
            returns += 1
        if i > 0:
            left.add(runs[i - 1])
    return runs, returns


def main():
    args = [a for a in sys.argv[1:] if not a.startswith("--")]
    if len(args) != 4:
        sys.exit(__doc__)
    root, file, name, param = args
    fns, imports, types = parse(root)
    start = [f for f in fns.get(name, []) if f.file == file]
    if not start:
        sys.exit(f"no fn {name} in {file}")
    runs, returns = walk(fns, imports, types, start[0], [param], "--trace" in sys.argv,
                         "--typed" in sys.argv)
    print(" -> ".join(runs))
    print(f"{len(runs)} stays in {len(set(runs))} files, {returns} returns to a file it had left")


if __name__ == "__main__":
    main()
