#!/usr/bin/env python3
"""Lists the function bodies longer than N lines (default 80) in the .cc files of calib/, stitch/,
triangulation/ and tools/ (or the folders given): issue 30 item 6, "a function longer than about
80 lines needs a reason" (docs/architecture.md section 9 gives the reason for each one listed).
A heuristic, not a parser: comments and strings are blanked, a `{` after a parameter list at the
file or namespace level opens a function, lambdas and blocks inside it count as its lines.
Usage: .ci/long_functions.py [N] [FOLDER...], from the repository root."""
import re, sys, pathlib
N = int(sys.argv[1]) if len(sys.argv) > 1 else 80
roots = sys.argv[2:] or ["calib", "stitch", "triangulation", "tools"]
def strip(s):
    s = re.sub(r'//[^\n]*', '', s)
    s = re.sub(r'/\*.*?\*/', lambda m: '\n' * m.group(0).count('\n'), s, flags=re.S)
    s = re.sub(r'R"([^(]*)\((.*?)\)\1"', lambda m: '""' + '\n' * m.group(0).count('\n'), s, flags=re.S)
    s = re.sub(r'"(\\.|[^"\\\n])*"', '""', s)
    s = re.sub(r"'(\\.|[^'\\\n])*'", "''", s)
    return s
out = []
for root in roots:
    for p in sorted(pathlib.Path(root).rglob("*.cc")):
        src = strip(p.read_text(errors="replace"))
        stack = []  # (kind, line, name)
        line = 1; i = 0
        while i < len(src):
            c = src[i]
            if c == '\n': line += 1
            elif c == '{':
                head = src[max(0, i-600):i]
                fn = re.search(r'([~\w:]+)\s*\(([^(){};]|\([^()]*\))*\)\s*(const)?\s*(noexcept)?\s*(override)?\s*(->\s*[\w:<>, ]+)?\s*(:[^{;]*)?$', head, re.S)
                is_ns = re.search(r'(namespace\s*[\w:]*|extern\s*""|struct\s+\w+[^;{}]*|class\s+\w+[^;{}]*)\s*$', head)
                outer_fn = any(k == 'fn' for k, _, _ in stack)
                if fn and not is_ns and not outer_fn and fn.group(1) not in ('if','for','while','switch','catch','return'):
                    stack.append(('fn', line, fn.group(1)))
                else:
                    stack.append(('blk', line, None))
            elif c == '}':
                if stack:
                    k, l0, name = stack.pop()
                    if k == 'fn' and line - l0 - 1 > N:
                        out.append((line - l0 - 1, str(p), l0, name))
            i += 1
for n, f, l, name in sorted(out, reverse=True):
    print(f"{n:4d}  {f}:{l}  {name}")
