#!/usr/bin/env python3
"""Functions of solver/ longer than a limit (default 80 lines, docs/contributing.md): prints each as
`file:line: name (N lines)` and exits 1 if there is any. A function is a top-level (namespace-level) brace
block that is not a class, struct, enum or initialiser; its length counts its lines from the signature's
last line to the closing brace. Comments and string literals are stripped first. Standard library only:
`python3 tools/check_function_length.py [--limit N] [files...]`."""
from __future__ import annotations

import argparse
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
NOT_FUNCTION = re.compile(r"^\s*(template\s*<.*>\s*)?(struct|class|enum|union|namespace|extern)\b|=\s*$|=\s*\{")


def strip(text: str) -> str:
    text = re.sub(r"/\*.*?\*/", lambda m: "\n" * m[0].count("\n"), text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r'"(\\.|[^"\\\n])*"', '""', text)
    return re.sub(r"'(\\.|[^'\\\n])'", "''", text)


def long_functions(path: pathlib.Path, limit: int) -> list[tuple[int, str, int]]:
    lines = strip(path.read_text(errors="replace")).splitlines()
    out, depth, start, head, ns_depth = [], 0, None, "", []
    for n, line in enumerate(lines, 1):
        for ch in line:
            if ch == "{":
                if depth == len(ns_depth) and re.match(r"^\s*(inline\s+)?namespace\b", line):
                    ns_depth.append(depth)
                elif depth == len(ns_depth) and start is None:
                    start = (n, head + line)
                depth += 1
            elif ch == "}":
                depth -= 1
                if ns_depth and depth == ns_depth[-1] and start is None:
                    ns_depth.pop()
                elif start is not None and depth == len(ns_depth):
                    sig = start[1]
                    if not NOT_FUNCTION.search(sig.split("(")[0] if "(" in sig else sig) and "(" in sig:
                        length = n - start[0] + 1
                        if length > limit:
                            name = re.findall(r"([\w:~]+)\s*\(", sig)
                            out.append((start[0], name[0] if name else "?", length))
                    start = None
        if start is None and depth == len(ns_depth):  # a signature's earlier lines, until ';', '{' or '}'
            stripped = line.strip()
            head = "" if not stripped or stripped.endswith((";", "{", "}")) else head + " " + stripped
    return out


def main(argv: list[str]) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--limit", type=int, default=80)
    p.add_argument("files", nargs="*", type=pathlib.Path)
    a = p.parse_args(argv)
    files = a.files or sorted([*ROOT.glob("solver/**/*.cpp"), *ROOT.glob("solver/**/*.hpp")])
    found = 0
    for f in files:
        for line, name, length in long_functions(f, a.limit):
            shown = f.relative_to(ROOT) if f.is_relative_to(ROOT) else f
            print(f"{shown}:{line}: {name} ({length} lines)")
            found += 1
    if not found:
        print(f"check_function_length: no function over {a.limit} lines in {len(files)} files")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
