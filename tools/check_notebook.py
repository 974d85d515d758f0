"""The product never depends on the lab notebook (research/, research/README.md): no file outside research/ imports
it or reads a path under it. The notebook may import the product (enamel_results, bench, pipeline, figures).

Checked: Python imports (`import research`, `from research...`, `-m research.`), and any mention of a path under
research/ in code (.py, .cpp, .hpp, .sh, .cmake, CMakeLists.txt, .toml, .ini, Makefile). Prose (.md) may cite the
notebook's records as evidence; the one allowed code line is the Makefile's optional `-include research/research.mk`.

    python3 tools/check_notebook.py        # exit 1 and one line per dependency, if any
"""
import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
NOTEBOOK = "research"
CODE_SUFFIXES = {".py", ".cpp", ".hpp", ".h", ".sh", ".cmake", ".toml", ".ini", ".mk", ".sbatch"}
CODE_NAMES = {"Makefile", "CMakeLists.txt"}
IMPORT = re.compile(rf"^\s*(import|from)\s+{NOTEBOOK}\b|-m\s+{NOTEBOOK}\.")
PATH = re.compile(rf"(?<![\w/.-]){NOTEBOOK}/|[\"']{NOTEBOOK}[\"']")
SELF = pathlib.Path(__file__).resolve()   # names the folder to find it
ALLOWED = {("Makefile", "-include research/research.mk")}


def is_code(path: pathlib.Path) -> bool:
    return path.suffix in CODE_SUFFIXES or path.name in CODE_NAMES


def violations(files: list[pathlib.Path], root: pathlib.Path = ROOT) -> list[str]:
    """One line per line of a product file that imports the notebook or names a path in it."""
    found = []
    for f in files:
        rel = f.relative_to(root) if f.is_relative_to(root) else f
        if rel.parts and rel.parts[0] == NOTEBOOK or not is_code(f) or f.resolve() == SELF:
            continue
        for n, line in enumerate(f.read_text(errors="replace").splitlines(), 1):
            if (f.name, line.strip()) in ALLOWED:
                continue
            if IMPORT.search(line) or PATH.search(line):
                found.append(f"{rel}:{n}: the product depends on the notebook: {line.strip()}")
    return found


def tracked_files(root: pathlib.Path = ROOT) -> list[pathlib.Path]:
    out = subprocess.run(["git", "ls-files"], cwd=root, capture_output=True, text=True, check=True).stdout
    return [root / p for p in out.splitlines() if (root / p).is_file()]


def main() -> int:
    found = violations(tracked_files())
    for line in found:
        print(line)
    print(f"{len(found)} dependencies of the product on {NOTEBOOK}/" if found else
          f"no file outside {NOTEBOOK}/ depends on it")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
