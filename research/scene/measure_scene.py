#!/usr/bin/env python3
"""Measure the scene: how far from the crack the material
leaves its elastic range, frame by frame, in finished (or partial) result files.

For each frame of each result file given (/frames/<n>: interface state, rod stress; /geometry):
  - band_iface: the largest |y - y_c| of an inelastic or failed interface (y_c the crack plane, y of the
    interface's Voronoi-edge midpoint): beyond it every interface is still elastic;
  - band_rod: the largest |y - y_c| of a rod element whose stress reached `--rod-fraction` (default 0.5) of its
    strength (y of the element's midpoint), deleted elements included;
  - path_iface, path_rod: the same distances measured from the crack path instead of the plane (the nearest
    failed interface or deleted rod element in the x-y plane; the pre-crack's mid-plane behind the tip
    counts as path);
  - ahead: how far ahead of the crack tip (x beyond a0 + Delta_a) inelastic interfaces reach.
A reduced far field (a coarser or elastic model away from the crack) is safe where these bands stay inside
its full region with a margin; the report says what each measured case needs.

Writes a Markdown table (stdout, or --md) and a CSV (--csv). Run from the repository root:
    /usr/bin/python3 -m research.scene.measure_scene runs/reduced/theta30_s21.4_e10_cv0/result.h5 ... \\
        --csv research/scene/scene.csv --md research/scene/scene.md
"""
from __future__ import annotations

import argparse
import csv
import pathlib
import sys

import numpy as np

from enamel_results import results


def nearest_distance(points: np.ndarray, targets: np.ndarray) -> np.ndarray:
    """For each point (n, 2), the distance to the nearest target (m, 2); inf when there are no targets."""
    if len(targets) == 0:
        return np.full(len(points), np.inf)
    out = np.empty(len(points))
    chunk = max(1, 2_000_000 // len(targets))   # ~50 MB of differences at a time
    for i in range(0, len(points), chunk):
        p = points[i:i + chunk, None, :]
        out[i:i + chunk] = np.sqrt(((p - targets[None, :, :]) ** 2).sum(axis=2)).min(axis=1)
    return out


def frame_scene(r: results.Result, f: results.Frame, rod_fraction: float) -> dict:
    """The scene of one frame (see the module doc)."""
    g = r.geometry
    yc = float(g.attrs["y_crack_plane"])
    a0 = float(g.attrs["a0_effective"])  # the tip Delta_a is measured from (docs/model.md)
    h_e = float(g.attrs["h_e"])
    tip = a0 + f.da
    mid = g.iface_midpoint[:, :2]
    inelastic = f.iface_state >= 1
    failed = f.iface_state == 2
    beam_mid = 0.5 * (g.node_position[g.beam_nodes[:, 0], :2] + g.node_position[g.beam_nodes[:, 1], :2])
    if f.beam_stress is not None:
        hot = (f.beam_stress >= rod_fraction * g.beam_strength) | (f.beam_broken == 1)
    else:
        hot = f.beam_broken == 1
    # the crack path: failed interfaces, deleted rod elements, and the pre-crack's plane behind the tip
    precrack = np.column_stack([np.arange(0.0, a0 + 1e-9, h_e), np.full(int(a0 / h_e) + 1, yc)])
    path = np.vstack([mid[failed], beam_mid[f.beam_broken == 1], precrack])
    band = lambda y: float(np.abs(y - yc).max()) if len(y) else 0.0  # noqa: E731
    far = lambda d: float(d.max()) if len(d) else 0.0  # noqa: E731
    return dict(
        case=r.case, preset=r.params.get("description", ""), w_s=float(g.attrs["w_s"]), h_s=float(g.attrs["h_s"]),
        frame=f.index, target_da=f.target_da, da=f.da, step=f.step,
        inelastic=int(inelastic.sum()), failed=int(failed.sum()), hot_rods=int(hot.sum()),
        broken_rods=int((f.beam_broken == 1).sum()),
        band_iface=band(mid[inelastic, 1]), band_rod=band(beam_mid[hot, 1]),
        path_iface=far(nearest_distance(mid[inelastic], path)),
        path_rod=far(nearest_distance(beam_mid[hot], path)),
        ahead=float(max(0.0, mid[inelastic, 0].max() - tip)) if inelastic.any() else 0.0,
        rod_stress_known=f.beam_stress is not None)


COLUMNS = ["case", "w_s", "h_s", "frame", "target_da", "da", "step", "inelastic", "failed", "broken_rods",
           "hot_rods", "band_iface", "band_rod", "path_iface", "path_rod", "ahead"]


def markdown(rows: list[dict], rod_fraction: float) -> str:
    head = ("| case | specimen (d) | Delta_a (d) | inelastic / failed interfaces | rods >= "
            f"{rod_fraction:g} sigma_ru (broken) | band: interfaces, rods (d from the plane) | "
            "from the path: interfaces, rods (d) | ahead of the tip (d) |\n|---|---|---|---|---|---|---|---|\n")
    lines = []
    for r in rows:
        rods = f"{r['hot_rods']} ({r['broken_rods']})" + ("" if r["rod_stress_known"] else " (no stress in file)")
        lines.append(f"| {r['case']} | {r['w_s']:g} x {r['h_s']:g} | {r['da']:.2f} | {r['inelastic']} / {r['failed']} | "
                     f"{rods} | {r['band_iface']:.2f}, {r['band_rod']:.2f} | {r['path_iface']:.2f}, "
                     f"{r['path_rod']:.2f} | {r['ahead']:.2f} |")
    return head + "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("results", nargs="+", type=pathlib.Path, help="result files (result.h5 or result.partial.h5)")
    ap.add_argument("--rod-fraction", type=float, default=0.5,
                    help="a rod element counts when its stress reached this fraction of its strength (default 0.5)")
    ap.add_argument("--csv", type=pathlib.Path, help="write the rows here")
    ap.add_argument("--md", type=pathlib.Path, help="write the Markdown table here (default: stdout)")
    a = ap.parse_args(argv)
    rows = []
    for path in a.results:
        try:
            r = results.load_result(path, full=True)
        except results.MissingResult as e:
            print(f"measure_scene.py: no result file {e.path}", file=sys.stderr)
            return 2
        # the final-state frame repeats the last targeted one when the run stopped right after it
        frames = [f for i, f in enumerate(r.frames) if not (f.target_da < 0 and i > 0 and r.frames[i - 1].step == f.step)]
        rows += [frame_scene(r, f, a.rod_fraction) for f in frames]
    if a.csv:
        with open(a.csv, "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=COLUMNS, extrasaction="ignore")
            w.writeheader()
            w.writerows(rows)
    md = markdown(rows, a.rod_fraction)
    if a.md:
        a.md.write_text(md)
    else:
        print(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
