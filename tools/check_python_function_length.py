#!/usr/bin/env python3
"""Functions of the product's Python longer than a limit (default 80 lines, docs/contributing.md), beside
tools/check_function_length.py for the solver's C++: prints each as `file:line: name (N lines)` and exits 1 if
there is any. The product's Python is every .py file under PRODUCT (tests and the lab notebook are not);
a function is every `def` (methods named Class.method, nested functions outer.inner), its length the lines
from its `def` line to its last one (decorators left out, its docstring, comments and nested functions in).
Standard library only: `python3 tools/check_python_function_length.py [--limit N] [files...]`."""
from __future__ import annotations

import ast
import pathlib
import sys

try:  # the command line is the C++ check's: imported as tools.check_..., or run as a script from tools/
    from tools.check_function_length import run_check
except ImportError:
    from check_function_length import run_check

ROOT = pathlib.Path(__file__).resolve().parent.parent
PRODUCT = ("pipeline", "enamel_results", "figures", "bench", "tools")


def product_files(root: pathlib.Path = ROOT) -> list[pathlib.Path]:
    return sorted(f for folder in PRODUCT for f in (root / folder).rglob("*.py"))


def long_functions(path: pathlib.Path, limit: int) -> list[tuple[int, str, int]]:
    """(line of the def, qualified name, length) of each function of `path` over `limit` lines."""
    out = []

    def walk(node: ast.AST, prefix: str) -> None:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                length = child.end_lineno - child.lineno + 1
                if length > limit:
                    out.append((child.lineno, prefix + child.name, length))
                walk(child, f"{prefix}{child.name}.")
            elif isinstance(child, ast.ClassDef):
                walk(child, f"{prefix}{child.name}.")
            else:
                walk(child, prefix)

    walk(ast.parse(path.read_text(), filename=str(path)), "")
    return sorted(out)


def main(argv: list[str]) -> int:
    return run_check(argv, __doc__, "check_python_function_length", product_files, long_functions)


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
