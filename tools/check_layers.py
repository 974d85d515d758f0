#!/usr/bin/env python3
"""The include layers of solver/lib (docs/contributing.md). The layers are the folders of solver/lib, in the
order of LAYERS below (lowest first), with the command line (solver/app) on top; a file's layer is its folder,
and it may include only files of its own layer or a lower one. Every include of a library file names it by its
path under solver/lib (`#include "laws/beam.hpp"`, the one include directory), so the include says its layer.

Reads every `#include "..."` line of solver/lib/*/*.{hpp,cpp} and solver/app/*.cpp and prints each include that
goes up a layer or names a library file by another path, each file outside a layer folder, each folder of
solver/lib that is not in LAYERS and each layer without its folder; exits 1 if there is any, else prints how
many includes it checked and exits 0. Standard library only: `python3 tools/check_layers.py [FILE...]`."""
from __future__ import annotations

import pathlib
import re
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent

# The one definition of the layer order, lowest first: each name is a folder of solver/lib, except the last,
# "app", the command line (solver/app).
LAYERS = ["base", "laws", "case", "geometry", "data", "kernels", "integrators", "simulation", "io", "run", "app"]
APP = "app"
RANK = {name: i for i, name in enumerate(LAYERS)}
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"')
SUFFIXES = (".hpp", ".cpp")


def lib_of(root: pathlib.Path) -> pathlib.Path:
    return root / "solver" / "lib"


def sources(root: pathlib.Path = ROOT) -> list[pathlib.Path]:
    lib = lib_of(root)
    return sorted([*(f for f in lib.rglob("*") if f.suffix in SUFFIXES), *root.glob("solver/app/*.cpp")])


def layer_of(path: pathlib.Path, root: pathlib.Path = ROOT) -> str | None:
    """A file's layer: its folder under solver/lib ("app" under solver/app); None for a file directly in
    solver/lib or elsewhere."""
    path = path.resolve()
    lib = lib_of(root).resolve()
    if path.is_relative_to(lib):
        parts = path.relative_to(lib).parts
        return parts[0] if len(parts) > 1 else None
    if path.parent == (root / "solver" / APP).resolve():
        return APP
    return None


def included_layer(including: pathlib.Path, include: str, root: pathlib.Path = ROOT) -> tuple[str | None, bool]:
    """(layer of `#include "include"` in file `including`, whether the include names the file by its path under
    solver/lib). Looked for as the compiler does, beside the including file first, then under solver/lib; an
    include found nowhere is taken as a path under solver/lib (its first folder its layer)."""
    beside = including.parent / include
    if beside.is_file() and beside.resolve() != (lib_of(root) / include).resolve():
        return layer_of(beside, root), False
    parts = pathlib.PurePosixPath(include).parts
    return (parts[0] if len(parts) > 1 else None), True


def tree_problems(root: pathlib.Path = ROOT) -> list[str]:
    """Files directly in solver/lib, its folders that are not layers, and layers without their folder."""
    lib = lib_of(root)
    folders = {d.name for d in lib.iterdir() if d.is_dir()}
    out = [f"solver/lib/{f.name}: not in a layer folder (move it into the folder of its layer)"
           for f in sorted(lib.iterdir()) if f.is_file() and f.suffix in SUFFIXES]
    out += [f"solver/lib/{d}/: not a layer (add it to LAYERS of tools/check_layers.py, in its place)"
            for d in sorted(folders - set(LAYERS))]
    out += [f"layer {name!r} of tools/check_layers.py has no folder solver/lib/{name}/"
            for name in LAYERS if name != APP and name not in folders]
    return out


def violations(files: list[pathlib.Path], root: pathlib.Path = ROOT) -> tuple[list[str], int]:
    """(messages, number of includes checked) for the includes of `files` (in the tree at `root`)."""
    out, checked = [], 0
    for f in files:
        mine = layer_of(f, root)
        if mine not in RANK:
            out.append(f"{f.name}: not in a layer folder of solver/lib (tools/check_layers.py LAYERS)")
            continue
        for n, line in enumerate(f.read_text(errors="replace").splitlines(), 1):
            m = INCLUDE.match(line)
            if not m:
                continue
            checked += 1
            other, by_path = included_layer(f, m[1], root)
            where = f"{mine}/{f.name}:{n}: includes {m[1]}"
            if other not in RANK:
                out.append(f"{where}, which is in no layer folder")
            elif not by_path:
                out.append(f"{where}: name it by its path under solver/lib ({other}/{pathlib.Path(m[1]).name})")
            elif RANK[other] > RANK[mine]:
                out.append(f"{where} (layer {RANK[other]} {other!r}) from layer {RANK[mine]} {mine!r}: "
                           "an include from a lower layer to a higher one")
    return out, checked


def main(argv: list[str]) -> int:
    files = [pathlib.Path(a) for a in argv] or sources()
    bad, checked = violations(files)
    if not argv:
        bad = tree_problems() + bad
    for b in bad:
        print(b)
    if bad:
        return 1
    print(f"check_layers: {checked} includes in {len(files)} files, none from a lower layer to a higher one "
          f"(layers: {' < '.join(LAYERS)})")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
