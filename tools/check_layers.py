#!/usr/bin/env python3
"""The include layers of solver/lib (docs/contributing.md): each file may include only files of its own layer or
a lower one. Reads every `#include "..."` line of solver/lib/**/*.{hpp,cpp} and solver/app/*.cpp; prints each
include that goes up a layer (and each file missing from the table) and exits 1 if there is any, else prints
how many includes it checked and exits 0. A file is named by its path under solver/lib without the suffix
(`integrators/lumped`); an include is looked for beside the including file first, then under solver/lib.
Standard library only: `python3 tools/check_layers.py`."""
from __future__ import annotations

import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent

# Lowest first. A file's layer is that of its name (foo.hpp and foo.cpp share one).
LAYERS = [
    ("base", ["version", "exit_codes", "errors", "git_hash", "file_io", "choices"]),
    ("pointwise laws and input", ["beam", "cohesive", "strength", "case_params"]),
    ("geometry", ["geometry", "far_field"]),
    ("plain data", ["state", "step_timers"]),
    ("loops over the data", ["kernels", "node_blocks", "loading_rate", "measurements", "static_solve"]),
    ("schemes and set-up", ["integrators", "integrators/step_parts", "integrators/node_rows",
                            "integrators/slice_outputs", "integrators/newmark", "integrators/lumped",
                            "integrators/schemes", "integrators/registry", "setup"]),
    ("the simulation", ["simulation", "resources"]),   # resources: estimates from blocks of the case's model
    ("files and tools", ["output", "checkpoint", "profile"]),
    ("the run", ["runner", "shared_constants"]),
    ("the command line", ["enamel_dem"]),
]
LAYER_OF = {stem: i for i, (_, stems) in enumerate(LAYERS) for stem in stems}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')


def sources(root: pathlib.Path = ROOT) -> list[pathlib.Path]:
    lib = root / "solver" / "lib"
    return sorted([*lib.glob("**/*.hpp"), *lib.glob("**/*.cpp"), *root.glob("solver/app/*.cpp")])


def name_of(path: pathlib.Path) -> str:
    """A file's name in the table: its path under solver/lib without the suffix, else its stem."""
    lib = ROOT / "solver" / "lib"
    path = path.resolve()
    return path.relative_to(lib).with_suffix("").as_posix() if path.is_relative_to(lib) else path.stem


def included_name(including: pathlib.Path, include: str) -> str:
    """The table name of `#include "include"` in file `including`: beside it first, then under solver/lib."""
    for base in (including.parent, ROOT / "solver" / "lib"):
        if (base / include).is_file():
            return name_of(base / include)
    return pathlib.PurePosixPath(include).with_suffix("").as_posix()


def violations(files: list[pathlib.Path]) -> tuple[list[str], int]:
    """(messages, number of includes checked)."""
    out, checked = [], 0
    for f in files:
        me = name_of(f)
        if me not in LAYER_OF:
            out.append(f"{f.name}: not in the layer table of tools/check_layers.py")
            continue
        mine = LAYER_OF[me]
        for n, line in enumerate(f.read_text(errors="replace").splitlines(), 1):
            m = INCLUDE.match(line)
            if not m:
                continue
            checked += 1
            other = included_name(f, m[1])
            if other not in LAYER_OF:
                out.append(f"{f.name}:{n}: includes {m[1]}, which is not in the layer table")
            elif LAYER_OF[other] > mine:
                out.append(f"{f.name}:{n}: includes {m[1]} (layer {LAYER_OF[other]} {LAYERS[LAYER_OF[other]][0]!r}) "
                           f"from layer {mine} {LAYERS[mine][0]!r}: an include from a lower layer to a higher one")
    return out, checked


def main(argv: list[str]) -> int:
    files = [pathlib.Path(a) for a in argv] or sources()
    bad, checked = violations(files)
    for b in bad:
        print(b)
    if bad:
        return 1
    print(f"check_layers: {checked} includes in {len(files)} files, none from a lower layer to a higher one")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
