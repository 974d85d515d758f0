#!/usr/bin/env python3
"""Functions of solver/ longer than a limit (default 80 lines, docs/contributing.md): prints each as
`file:line: name (N lines)` and exits 1 if there is any. A function is a brace block with a parameter list
at namespace level or directly inside a class, struct or union body (methods, inline ones in headers
included; a method is named Class::method); classes, structs, unions and namespaces are looked into, enums
and initialisers are not, and a function's body is measured whole (a local struct or lambda counts as part of
it). Its length counts its lines from the line of its opening brace to that of its closing one. Comments,
string and character literals and preprocessor lines are stripped first. Standard library only:
`python3 tools/check_function_length.py [--limit N] [files...]`."""
from __future__ import annotations

import argparse
import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent
TEMPLATE_HEAD = re.compile(r"^template\s*<")
CLASS_HEAD = re.compile(r"^(typedef\s+)?(class|struct|union)\b\s*(?:alignas\s*\([^)]*\)\s*)?(\w*)")
NAMESPACE_HEAD = re.compile(r"^((inline\s+)?namespace\b|extern\s*\"\")")
ACCESS = re.compile(r"\b(public|private|protected)\s*:(?!:)")
ATTRIBUTE = re.compile(r"\[\[.*?\]\]")
OPERATOR = re.compile(r"\boperator\s*(\(\)|[^\s(]+)\s*\(")
INIT_LIST = re.compile(r"\)\s*(noexcept\s*)?:(?!:)")


def strip(text: str) -> str:
    """Comments, literals and preprocessor lines blanked; the line count kept."""
    text = re.sub(r"/\*.*?\*/", lambda m: "\n" * m[0].count("\n"), text, flags=re.S)
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r'"(\\.|[^"\\\n])*"', '""', text)
    text = re.sub(r"'(\\.|[^'\\\n])'", "''", text)
    return re.sub(r"^[ \t]*#([^\n]*\\\n)*[^\n]*", "", text, flags=re.M)


def drop_template_prefix(head: str) -> str:
    """`template <...>` prefixes removed (angle brackets balanced)."""
    while TEMPLATE_HEAD.match(head):
        depth, i = 0, head.index("<")
        for i in range(i, len(head)):
            depth += {"<": 1, ">": -1}.get(head[i], 0)
            if depth == 0:
                break
        head = head[i + 1:].lstrip()
    return head


def classify(head: str) -> tuple[str, str]:
    """What a '{' after `head` opens at namespace or class level: ('namespace' | 'class' | 'function' | 'other',
    name)."""
    head = drop_template_prefix(ATTRIBUTE.sub(" ", ACCESS.sub(" ", head)).strip())
    if NAMESPACE_HEAD.match(head):
        return "namespace", ""
    m = CLASS_HEAD.match(head)
    if m:
        return "class", m[3] or "?"
    if re.match(r"^enum\b", head) or "(" not in head:
        return "other", ""
    head = OPERATOR.sub("operator(", head)
    if "=" in head.split("(")[0]:  # an initialiser (a lambda or a braced value)
        return "other", ""
    name = re.findall(r"([\w:~]+)\s*\(", head)
    return "function", name[0] if name else "?"


def long_functions(path: pathlib.Path, limit: int) -> list[tuple[int, str, int]]:
    lines = strip(path.read_text(errors="replace")).splitlines()
    out: list[tuple[int, str, int]] = []
    # the open blocks: (kind, name, first line); kinds 'namespace' and 'class' are looked into, the others not
    stack: list[tuple[str, str, int]] = []
    head, inner = "", 0  # text since the last ';', '{' or '}' at a level looked into; braces nested in it
    for n, line in enumerate(lines, 1):
        for ch in line:
            looking = not stack or stack[-1][0] in ("namespace", "class")
            if not looking:
                if ch == "{":
                    stack.append(("inner", "", n))
                elif ch == "}":
                    kind, name, first = stack.pop()
                    if kind == "function" and first and n - first + 1 > limit:
                        out.append((first, name, n - first + 1))
                continue
            if ch == "{":
                if inner or (INIT_LIST.search(head) and re.search(r"[\w>]\s*$", head)):
                    inner += 1  # a member's braced initialiser in a constructor's list, `a_{1}`: part of the head
                    head += ch
                    continue
                kind, name = classify(head)
                if kind == "function":
                    owners = [nm for k, nm, _ in stack if k == "class"]
                    stack.append(("function", "::".join([*owners, name]), n))
                else:
                    stack.append((kind if kind != "other" else "inner", name, n))
                head = ""
            elif ch == "}":
                if inner:
                    inner -= 1
                    head += ch
                    continue
                if stack:
                    stack.pop()
                head = ""
            elif ch == ";":
                head = ""
            else:
                head += ch
        head += " "
    return out


def run_check(argv: list[str], doc: str, name: str, default_files, long_functions_of) -> int:
    """The command line both length checks share: --limit N and files (default_files() when none), one line
    `file:line: name (N lines)` per function over the limit from long_functions_of(path, limit); exit 1 if any."""
    p = argparse.ArgumentParser(description=doc, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--limit", type=int, default=80)
    p.add_argument("files", nargs="*", type=pathlib.Path)
    a = p.parse_args(argv)
    files = a.files or default_files()
    found = 0
    for f in files:
        for line, function, length in long_functions_of(f, a.limit):
            shown = f.resolve().relative_to(ROOT) if f.resolve().is_relative_to(ROOT) else f
            print(f"{shown}:{line}: {function} ({length} lines)")
            found += 1
    if not found:
        print(f"{name}: no function over {a.limit} lines in {len(files)} files")
    return 1 if found else 0


def main(argv: list[str]) -> int:
    return run_check(argv, __doc__, "check_function_length",
                     lambda: sorted([*ROOT.glob("solver/**/*.cpp"), *ROOT.glob("solver/**/*.hpp")]), long_functions)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
