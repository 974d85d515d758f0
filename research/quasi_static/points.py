"""How much of an R-curve is read while the specimen is not quasi-static (README.md here).

    python3 -m research.quasi_static.points write [--runs runs/converged]   # data/points.csv from the run folders
    python3 -m research.quasi_static.points report                          # the README's table, from data/

Each R point of a run (/rcurve) is matched to the first /history row at which the crack advance reached it, and
that row's quasi-static ratio is the solver's (solver/lib/runner.cpp quasiStaticRatio: past the elastic start,
the kinetic energy beyond the loading's motion over the strain energy, and once the crack has advanced the larger
of that and the whole kinetic energy over the strain energy); a point is "warned" when it exceeds the warning's
bound (enamel_results.constants KINETIC_WARN). Per run: the points and warned points over (0, 30] d, the share of
the advance over (0, 30] d whose segment ends at a warned point, R averaged over crack advance over (0, 30] d
(metrics.advance_mean) of the whole curve and of the curve through the unwarned points only, and the run's
largest ratio over its rows (/meta max_quasi_static_ratio, which this checks, is the largest over every row but the
last: the solver appends the row at the stop without passing it to the warning).
"""
from __future__ import annotations

import argparse
import csv
import pathlib
import sys

import h5py
import numpy as np

from enamel_results import metrics, paths, results
from enamel_results.constants import KINETIC_WARN

HERE = pathlib.Path(__file__).resolve().parent
CSV = HERE / "data" / "points.csv"
LO, HI = 0.0, 30.0
COLUMNS = ("run", "points", "warned", "advance_warned", "mean", "mean_unwarned", "rel", "max_ratio")


def row_ratios(h) -> np.ndarray:
    """The solver's quasiStaticRatio of every /history row (runner.cpp)."""
    strain = h["strain_energy_beams"][:] + h["strain_energy_interfaces"][:]
    da = h["da_over_d"][:]
    past = (h["inelastic_interfaces"][:] > 0) | (h["broken_rod_elements"][:] > 0) | (da > 0)
    safe = np.where(strain > 0, strain, 1.0)
    beyond = np.where(strain > 0, h["kinetic_energy_beyond_loading"][:] / safe, 0.0)
    whole = np.where((strain > 0) & (da > 0), h["kinetic_energy"][:] / safe, 0.0)
    return np.where(past, np.maximum(beyond, whole), 0.0)


def point_ratios(h, da_points: np.ndarray, ratios: np.ndarray) -> np.ndarray:
    """The ratio (row_ratios of h) at the first history row whose crack advance reached each R point's."""
    reached = np.maximum.accumulate(h["da_over_d"][:])
    idx = np.minimum(np.searchsorted(reached, da_points, side="left"), len(reached) - 1)
    return ratios[idx]


def run_row(result_h5: pathlib.Path) -> dict:
    r = results.load_result(result_h5)
    with h5py.File(result_h5, "r") as f:
        h = f["history"]
        every = row_ratios(h)
        ratios = point_ratios(h, r.da, every)
    largest, recorded = float(every.max()), float(r.meta.get("max_quasi_static_ratio", np.nan))
    if not np.isclose(float(every[:-1].max()), recorded, rtol=1e-9, atol=1e-12):   # the solver's leaves out the last row
        raise ValueError(f"{result_h5}: largest ratio {every[:-1].max()} is not the solver's {recorded}")
    inside = (r.da > LO) & (r.da <= HI)
    warned = ratios > KINETIC_WARN
    seg = np.diff(np.concatenate(([LO], np.clip(r.da, LO, HI))))   # the advance each point ends
    whole = metrics.advance_mean(metrics.rcurve_of(r), LO, HI)
    keep = ~warned
    unwarned = (metrics.advance_mean(metrics.RCurve.of(r.da[keep], r.R[keep]), LO, HI)
                if np.count_nonzero(keep) >= 2 else float("nan"))
    return dict(run=result_h5.parent.name, points=int(inside.sum()), warned=int((inside & warned).sum()),
                advance_warned=float(seg[inside & warned].sum() / max(seg[inside].sum(), 1e-300)),
                mean=whole, mean_unwarned=unwarned, rel=unwarned / whole - 1.0, max_ratio=largest)


def write(runs: pathlib.Path, out: pathlib.Path = CSV) -> list[dict]:
    rows = [run_row(p) for p in sorted(runs.glob(f"*/{paths.RESULT_NAMES['completed']}"))]
    out.parent.mkdir(parents=True, exist_ok=True)
    with open(out, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=COLUMNS)
        w.writeheader()
        for row in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in row.items()})
    return rows


def report(path: pathlib.Path = CSV) -> str:
    rows = list(csv.DictReader(open(path)))
    lines = ["| run | R points in (0, 30] d | warned | advance at warned points | mean (0, 30] | through unwarned points "
             "| difference | largest ratio |", "|---|---|---|---|---|---|---|---|"]
    for w in rows:
        lines.append(f"| {w['run']} | {w['points']} | {w['warned']} | {100 * float(w['advance_warned']):.0f} % | "
                     f"{float(w['mean']):.3f} | {float(w['mean_unwarned']):.3f} | {100 * float(w['rel']):+.1f} % | "
                     f"{float(w['max_ratio']):.3f} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    w = sub.add_parser("write", help="data/points.csv from the run folders")
    w.add_argument("--runs", type=pathlib.Path, default=paths.RUNS / "converged")
    sub.add_parser("report", help="the README's table, from data/points.csv")
    a = ap.parse_args(argv)
    if a.cmd == "write":
        write(a.runs)
    print(report())
    return 0


if __name__ == "__main__":
    sys.exit(main())
