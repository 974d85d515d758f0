"""Rows of research/identify/suspects.md from runs/suspects/<name>/result.h5.

    /usr/bin/python3 -m research.identify.suspects_table [NAME ...]

R-curve differences are against runs/suspects/default (G = 3) or runs/suspects/G8_default (names starting G8_).
With --bits NAME_A NAME_B: whether two runs' /rcurve, /history and last frame datasets are identical bit for bit.
"""
from __future__ import annotations

import pathlib
import sys

import h5py
import numpy as np

from enamel_results.metrics import rcurve_rel_l2
from enamel_results.results import load_result

RUNS = pathlib.Path("runs/suspects")


def row(name: str) -> str:
    r = load_result(RUNS / name / "result.h5")
    ref_name = "G8_default" if name.startswith("G8_") else "default"
    if name in ("default", "G8_default", "default_base"):
        l2 = "-"
    else:
        ref = load_result(RUNS / ref_name / "result.h5")
        l2 = f"{100 * rcurve_rel_l2(ref.da, ref.R, r.da, r.R):.1f}%"
    ke = float(r.meta.get("max_kinetic_over_strain_while_growing", np.nan))
    warned = " (warned)" if "not quasi-static" in str(r.meta.get("warnings", "")) else ""
    first = "-" if np.isnan(r.da_first_rod_fracture) else f"{r.da_first_rod_fracture:.1f}"
    return (f"| {name} | {r.R_init:.2f} | {r.R_ss:.2f} | {r.R_m:.2f} | {r.broken_rods} | {first} | {l2} | "
            f"{ke:.3f}{warned} | {r.wall_time_s:.0f} | {r.da_max:.1f} | {r.status} |")


def same_bits(a: str, b: str) -> list[str]:
    """Datasets of /rcurve, /history and the last frame that differ between runs a and b (empty: identical)."""
    diff = []
    with h5py.File(RUNS / a / "result.h5", "r") as fa, h5py.File(RUNS / b / "result.h5", "r") as fb:
        groups = ["rcurve", "history"]
        frames = sorted(fa["frames"], key=int)
        if frames:
            groups.append(f"frames/{frames[-1]}")
        for g in groups:
            for k in fa[g]:
                if not isinstance(fa[g][k], h5py.Dataset):
                    continue
                x, y = fa[g][k][()], fb[g][k][()]
                if x.shape != y.shape or x.tobytes() != y.tobytes():
                    diff.append(f"{g}/{k}")
        for k, v in fa["rcurve"].attrs.items():
            if np.asarray(v).tobytes() != np.asarray(fb["rcurve"].attrs[k]).tobytes():
                diff.append(f"rcurve@{k}")
    return diff


def main(argv: list[str]) -> None:
    if argv[:1] == ["--bits"]:
        d = same_bits(argv[1], argv[2])
        print("identical bit for bit" if not d else "differ: " + ", ".join(d))
        return
    names = argv or sorted(p.parent.name for p in RUNS.glob("*/result.h5"))
    print("| run | R_init/Gamma | R_ss/Gamma | R_m/Gamma | broken rod elements | first rod break at Delta_a (d) | "
          "R-curve vs default (rel. L2) | max KE/SE while growing | wall (s) | Delta_a reached (d) | status |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for n in names:
        print(row(n))


if __name__ == "__main__":
    main(sys.argv[1:])
