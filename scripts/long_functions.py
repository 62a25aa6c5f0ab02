#!/usr/bin/env python3
"""Functions and files in `src/` longer than a limit.

    python3 scripts/long_functions.py [--functions N] [--files N] [src]

Counts each `fn` from its signature to its closing brace (comments, strings and char
literals blanked first), and each file's lines. Prints the longest first; exit 1 when
any function is over N lines (default 150) or any file over the file limit (default 1000).
"""
import re, sys, pathlib

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
            j = t.find(close, i + len(m.group(0))); e = n if j < 0 else j + len(close); out.append('""' + "\n" * t[i:e].count("\n")); i = e
        elif c == '"':
            s0 = i; i += 1
            while i < n and t[i] != '"':
                i += 2 if t[i] == "\\" else 1
            i += 1; out.append('""' + "\n" * t[s0:i].count("\n"))
        elif c == "'":
            m = re.match(r"'(\\.[^']*|[^'\\])'", t[i:])
            if m: i += len(m.group(0)); out.append("' '")
            else: out.append(c); i += 1
        else:
            out.append(c); i += 1
    return "".join(out)


args = sys.argv[1:]
fn_limit, file_limit, root = 150, 1000, "src"
while args:
    a = args.pop(0)
    if a == "--functions": fn_limit = int(args.pop(0))
    elif a == "--files": file_limit = int(args.pop(0))
    else: root = a
fn_re = re.compile(r'\bfn\s+(\w+)')
long_fns, long_files = [], []
for p in sorted(pathlib.Path(root).rglob("*.rs")):
    raw = p.read_text()
    if raw.count("\n") > file_limit:
        long_files.append((raw.count("\n"), str(p)))
    t = strip(raw)
    for m in fn_re.finditer(t):
        # the body: the first '{' outside brackets before any ';'
        i, d = m.end(), 0
        while i < len(t):
            c = t[i]
            if c in "([": d += 1
            elif c in ")]": d -= 1
            elif c == ";" and d <= 0: i = -1; break
            elif c == "{" and d <= 0: break
            i += 1
        if i < 0 or i >= len(t): continue
        j, b = i, 0
        while j < len(t):
            if t[j] == "{": b += 1
            elif t[j] == "}":
                b -= 1
                if b == 0: break
            j += 1
        start = t.count("\n", 0, m.start()) + 1
        n = t.count("\n", m.start(), j) + 1
        if n > fn_limit:
            long_fns.append((n, f"{p}:{start}", m.group(1)))
for n, loc, name in sorted(long_fns, reverse=True):
    print(f"function {n:5d} lines  {loc}  {name}")
for n, p in sorted(long_files, reverse=True):
    print(f"file     {n:5d} lines  {p}")
print(f"{len(long_fns)} functions over {fn_limit} lines, {len(long_files)} files over {file_limit} lines")
sys.exit(1 if long_fns or long_files else 0)
