#!/usr/bin/env python3
"""Import circles between the crate's modules, at two levels.

Reads every `.rs` file under `src/` (binaries in `src/bin/` are leaves and skipped; test
modules, `#[cfg(test)] mod ... { }`, may import anything), takes each `use` path and each
inline `crate::`/`super::`/`self::` path, resolves it to the module that *defines* the
item (following `pub use` re-exports), and reports:

- file level: every strongly connected component of more than one file module, with
  one cycle through it. A parent module that imports from its child and a child that
  imports from its parent form a circle too.
- module level: for every module with children, each child taken with its whole
  subtree (a folder module and all its files) as one node, an edge from child A to
  child B when any file under A imports an item defined under B; every component of
  more than one child is a circle (`model` <-> `solver` when a file of the model calls
  into the solver and the solver reads the model), even when no two files import each
  other. Each edge of the cycle shows one import that makes it.

Exit 1 when a circle exists at either level.

    python3 scripts/import_cycles.py [src]
"""
import re, sys, pathlib
from collections import defaultdict

root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else "src")

def modpath(p):
    rel = p.relative_to(root).with_suffix("")
    parts = list(rel.parts)
    if parts == ["lib"]:
        return ("crate",)
    if parts[-1] == "mod":
        parts = parts[:-1]
    return ("crate", *parts)

files = {}
for p in sorted(root.rglob("*.rs")):
    if "bin" in p.relative_to(root).parts[:1]:
        continue
    files[modpath(p)] = p

def strip(t):
    """Blank out comments, string and char literals (a small lexer, not regexes)."""
    out, i, n = [], 0, len(t)
    while i < n:
        c = t[i]
        if t.startswith("//", i):
            j = t.find("\n", i); i = n if j < 0 else j
        elif t.startswith("/*", i):
            d, i = 1, i + 2
            while i < n and d:
                if t.startswith("/*", i): d += 1; i += 2
                elif t.startswith("*/", i): d -= 1; i += 2
                else: i += 1
        elif c == "r" and re.match(r'r#*"', t[i:i+10]) and (i == 0 or not (t[i-1].isalnum() or t[i-1] == "_")):
            m = re.match(r'r(#*)"', t[i:]); close = '"' + m.group(1)
            j = t.find(close, i + len(m.group(0))); i = n if j < 0 else j + len(close); out.append('""')
        elif c == '"':
            i += 1
            while i < n and t[i] != '"':
                i += 2 if t[i] == "\\" else 1
            i += 1; out.append('""')
        elif c == "'":
            m = re.match(r"'(\\.[^']*|[^'\\])'", t[i:])
            if m: i += len(m.group(0)); out.append("' '")
            else: out.append(c); i += 1
        else:
            out.append(c); i += 1
    return "".join(out)

src = {m: strip(p.read_text()) for m, p in files.items()}
# cut #[cfg(test)] mod tests { ... } blocks: tests may import anything
def cut_tests(t):
    out, i = [], 0
    for m in re.finditer(r'#\[cfg\(test\)\]\s*(pub(\([^)]*\))?\s+)?mod\s+\w+\s*\{', t):
        if m.start() < i:
            continue
        out.append(t[i:m.start()])
        d, j = 1, m.end()
        while j < len(t) and d:
            d += {'{': 1, '}': -1}.get(t[j], 0); j += 1
        i = j
    out.append(t[i:])
    return "".join(out)
src = {m: cut_tests(t) for m, t in src.items()}

defs = defaultdict(set)      # module -> names defined there
reexp = {}                   # (module, name) -> absolute path tuple of the source
def expand_use(tree):
    """`a::b::{c, d::e as f, g::*}` -> list of (path tuple, alias)."""
    tree = tree.replace(" ", "").replace("\n", "")
    res = []
    def rec(prefix, s):
        # split top-level commas
        parts, d, cur = [], 0, ""
        for ch in s:
            if ch == "{": d += 1
            if ch == "}": d -= 1
            if ch == "," and d == 0:
                parts.append(cur); cur = ""
            else:
                cur += ch
        if cur: parts.append(cur)
        for part in parts:
            if "{" in part:
                head, rest = part.split("{", 1)
                rest = rest[:rest.rfind("}")]
                rec(prefix + [x for x in head.split("::") if x], rest)
            else:
                alias = None
                if "as" in part and re.search(r'\bas\b', part.replace("::", " :: ")):
                    part, alias = re.split(r'as(?=[A-Za-z_])', part, 1) if False else part.rsplit("as", 1)
                segs = [x for x in part.split("::") if x]
                if segs:
                    res.append((prefix + segs, alias))
    rec([], tree)
    return res

def absolute(mod, segs):
    segs = list(segs)
    if not segs: return None
    if segs[0] == "crate":
        base = ["crate"]; segs = segs[1:]
    elif segs[0] == "self":
        base = list(mod); segs = segs[1:]
    elif segs[0] == "super":
        base = list(mod)
        while segs and segs[0] == "super":
            base = base[:-1]; segs = segs[1:]
    else:
        # a child module of this one, or an external crate
        if tuple(mod) + (segs[0],) in files or any(k[:len(mod)+1] == tuple(mod) + (segs[0],) for k in files):
            base = list(mod)
        else:
            return None
    return tuple(base + segs)

item_re = re.compile(r'\bpub(?:\([^)]*\))?\s+(?:const\s+fn|async\s+fn|unsafe\s+fn|fn|struct|enum|trait|type|const|static|mod|union)\s+(\w+)')
macro_re = re.compile(r'macro_rules!\s*(\w+)')
use_re = re.compile(r'\b(pub(?:\([^)]*\))?\s+)?use\s+([^;]+);')
for m, t in src.items():
    for x in item_re.finditer(t):
        defs[m].add(x.group(1))
    for x in macro_re.finditer(t):
        defs[m].add(x.group(1))
    for x in use_re.finditer(t):
        if not x.group(1):
            continue
        for segs, alias in expand_use(x.group(2)):
            if segs[-1] == "self": segs = segs[:-1]
            a = absolute(m, segs)
            if a and segs[-1] != "*":
                reexp[(m, alias or segs[-1])] = a

def resolve(a, depth=0):
    """Absolute path -> the module that defines its item (or the module itself)."""
    if depth > 20: return None
    a = tuple(a)
    # longest module prefix
    for k in range(len(a), 0, -1):
        if a[:k] in files:
            mod, rest = a[:k], a[k:]
            break
    else:
        if a and a[0] == "crate" and len(a) > 1 and a[1] in ("families",):  # exported macros
            pass
        return None
    if not rest:
        return mod
    name = rest[0]
    if name == "*":
        return mod
    if (mod, name) in reexp and name not in defs[mod]:
        return resolve(reexp[(mod, name)] + rest[1:], depth + 1)
    return mod

edges = defaultdict(set)
why = {}
path_re = re.compile(r'\b((?:crate|super|self)(?:::\w+)+)')
for m, t in src.items():
    for x in use_re.finditer(t):
        for segs, alias in expand_use(x.group(2)):
            if segs[-1] == "self": segs = segs[:-1]
            a = absolute(m, segs)
            if not a: continue
            r = resolve(a)
            if r and r != m and r != ("crate",):
                edges[m].add(r); why.setdefault((m, r), "use " + "::".join(segs))
    body = use_re.sub("", t)
    for x in path_re.finditer(body):
        segs = x.group(1).split("::")
        a = absolute(m, segs)
        if not a: continue
        r = resolve(a)
        if r and r != m and r != ("crate",):
            edges[m].add(r); why.setdefault((m, r), x.group(1))

name = lambda m: "::".join(m[1:]) or "crate"

def components(nodes, out):
    """Strongly connected components of the graph `out` (node -> set of nodes), Tarjan."""
    index, low, on, stack, comps, idx = {}, {}, set(), [], [], [0]
    def strong(v):
        index[v] = low[v] = idx[0]; idx[0] += 1; stack.append(v); on.add(v)
        for w in sorted(out[v]):
            if w not in index:
                strong(w); low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            c = []
            while True:
                w = stack.pop(); on.discard(w); c.append(w)
                if w == v: break
            comps.append(c)
    for v in nodes:
        if v not in index:
            strong(v)
    return [c for c in comps if len(c) > 1]

def one_cycle(c, out):
    """A cycle through the component `c`: a breadth-first path from its first node back."""
    cs = set(c); start = sorted(c)[0]
    prev = {start: None}; q = [start]; found = None
    while q and not found:
        v = q.pop(0)
        for w in sorted(out[v]):
            if w not in cs: continue
            if w == start: found = v; break
            if w not in prev: prev[w] = v; q.append(w)
    cyc = [start]; v = found
    while v is not None and v != start:
        cyc.insert(1, v); v = prev[v]
    return cyc + [start]

HINT = ("    hint: move what both sides need below both (a module of its own that neither "
        "imports back), or let the lower one define it")

# File level.
bad = components(list(files), edges)
for c in bad:
    print(f"circle of {len(c)} modules: " + ", ".join(sorted(name(x) for x in c)))
    cyc = one_cycle(c, edges)
    for a, b in zip(cyc, cyc[1:]):
        print(f"    {name(a)} -> {name(b)}   ({why.get((a, b), '?')})")
    print(HINT)

# Module level: the children of each module, each with its subtree.
children = defaultdict(set)
for m in files:
    for k in range(1, len(m)):
        children[m[:k]].add(m[:k + 1])
bad_modules = 0
for parent in sorted(children):
    kids = sorted(children[parent])
    if len(kids) < 2:
        continue
    def child_of(m):
        for c in kids:
            if m[:len(c)] == c:
                return c
        return None
    out, via = defaultdict(set), {}
    for a, targets in edges.items():
        ca = child_of(a)
        if ca is None: continue
        for b in targets:
            cb = child_of(b)
            if cb is None or cb == ca: continue
            out[ca].add(cb)
            via.setdefault((ca, cb), (a, b))
    for c in components(kids, out):
        bad_modules += 1
        print(f"module circle under `{name(parent)}`: " + ", ".join(sorted(name(x) for x in c)))
        cyc = one_cycle(c, out)
        for a, b in zip(cyc, cyc[1:]):
            fa, fb = via[(a, b)]
            print(f"    {name(a)} -> {name(b)}   ({files[fa]}: {why.get((fa, fb), name(fb))})")
        print(HINT)

print(f"{len(files)} modules, {sum(len(e) for e in edges.values())} import edges, "
      f"{len(bad)} circles between files, {bad_modules} between modules")
sys.exit(1 if bad or bad_modules else 0)
