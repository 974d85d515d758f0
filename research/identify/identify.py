#!/usr/bin/env python3
"""`make identify`: the interface-ductility identification study (README.md here).

Runs theta30 (21.4, 10) at Gamma_k_over_sigma0sq = G over specimen sizes and two meshes, then the validation
cases for the candidate values, and writes the report (research/identify/results.md, results.csv, PNG figures).
The plan, the convergence criterion and the selection rule are in research/identify/README.md, written before
any run.

Every completed run is also kept as a small committed record in research/identify/data/ (metrics, R-curve,
broken-element positions); the report reads a run from its folder when present, else from that record.

Every run goes through the solver with --resume and a checkpoint interval, niced, one thread each, at most
--jobs at once; a run whose result.h5 exists (or, except with --only, whose completed record is committed) is skipped, so the command can be stopped (Ctrl-C, SIGKILL) and
re-issued at any time. Runs: runs/identify/<size>_he<h_e>_G<G>/<case>/.

Stages (default "ap"; each only as far as --stop-starting allows):
  a    theta30 (21.4, 10), every G, sizes ci and red, h_e 0.3
  b    the same at red with h_e 0.15 (mesh convergence)
  c    the size `big` (80 x 40 d) for the candidates
  d    the validation cases at red for the candidates
  p    after a, one queue: for each candidate in turn h_e 0.15, big and its validation cases, then h_e 0.15
       for the other values (what the rule needs first)
The candidates are computed from the red h_e 0.3 results present when the stage starts: the G whose R_ss is
nearest 7 and its neighbour in G on the other side of 7 (or the next nearest), preferring mesh-converged values.
"""
from __future__ import annotations

import argparse
import csv
import datetime
import json
import math
import os
import pathlib
import subprocess
import sys
import time

import numpy as np

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from enamel_results.metrics import rcurve_rel_l2  # noqa: E402
from enamel_results.paths import ROOT, run_result  # noqa: E402
from enamel_results.results import MissingResult, load_result  # noqa: E402

HERE = pathlib.Path(__file__).resolve().parent

# --- the plan (README.md): values, sizes, meshes, cases --------------------------------------------------------
G_VALUES = [3, 5, 8, 12, 20, 30]
SIZES = {  # name: (w_s/d, h_s/d, stop Delta_a/d, frames)
    "ci": (16, 8, 5, "[1, 2.5, 5]"),
    "red": (40, 20, 12, "[3, 6, 12]"),
    "big": (80, 40, 12, "[3, 6, 12]"),
}
SIZE_ORDER = ["ci", "red", "big"]
MESHES = [0.3, 0.15]
MAIN_CASE = "theta30_s21.4_e10_cv0"
VALIDATION_CASES = ["theta15_s21.4_e10_cv0", "theta30_s7.1_e10_cv0", "theta30_s28.5_e10_cv0",
                    "theta30_s21.4_e20_cv0"]
PRESET = "reduced"
PAPER_RSS = 7.0        # the rule's target (Sec. 3); Sec. 5 gives ~8 for the same case (reported, not used)
CONVERGED_L2 = 0.05    # the paper's "did not affect the calculation results", read as 5% relative L2
RUNS = ROOT / "runs" / "identify"
# Committed per-run data (README "Changes to the plan" 6): runs/ does not survive the machine, so every completed
# run's metrics, R-curve and broken-element positions are kept here (one small JSON file per run) and the report
# uses them for every run whose folder is absent.
DATA = HERE / "data"
CURVE_DIGITS = 10      # significant digits of the stored R-curves (the L2 distances are reproduced to ~1e-9)


def run_dir(size: str, he: float, G: float, case: str, runs: pathlib.Path = RUNS) -> pathlib.Path:
    return runs / f"{size}_he{he:g}_G{G:g}" / case


def solver_cmd(binary, size, he, G, case, out, threads, checkpoint_every, nice):
    w, h, stop, frames = SIZES[size]
    sets = {"w_s_over_d": w, "h_s_over_d": h, "h_e_over_d": he, "stop_da_over_d": stop,
            "frames_da_over_d": frames, "Gamma_k_over_sigma0sq": G, "threads": threads}
    cmd = ["nice", "-n", str(nice)] if nice else []
    cmd += [str(binary), "run", str(ROOT / "paper_cases" / f"{case}.toml"), "--preset", PRESET, "--out", str(out),
            "--force", "--resume", "--checkpoint-every", str(checkpoint_every)]
    for k, v in sets.items():
        cmd += ["--set", f"{k}={v}"]
    return cmd


# --- metrics ---------------------------------------------------------------------------------------------------
def rod_break_positions(r) -> dict:
    """Where the deleted rod elements are: x relative to the pre-crack tip in crisscross spacings p = d/sin(theta),
    crisscross offset (y distance to the nearest other-ply rod in the element's first slice, over s/2), and the
    median spacing of groups of broken elements (the sawtooth period)."""
    out = dict(xx_offset_median=math.nan, xx_offset_mean=math.nan, xx_offset_near_median=math.nan, sawtooth_period=math.nan, x_breaks="")
    g = r.geometry
    theta = math.radians(float(r.param("theta_D")))
    if g is None or not r.frames or theta == 0:
        return out
    broken = np.flatnonzero(r.frames[-1].beam_broken > 0)
    if broken.size == 0:
        return out
    pos, ply = g.node_position, g.node_ply
    xc = float(g.attrs.get("x_crisscross", g.attrs.get("a0", math.nan)))  # first crisscross point on the mid-plane
    p = 1.0 / math.sin(theta)
    half_s = 0.5 / math.cos(theta)
    offs, offs2, xs = [], [], []

    def offset(n):
        other = (ply != ply[n]) & (np.abs(pos[:, 0] - pos[n, 0]) < 1e-6)
        return float(np.min(np.abs(pos[other, 1] - pos[n, 1]))) / half_s if other.any() else math.nan

    for b in broken:
        n1, n2 = g.beam_nodes[b]
        offs.append(offset(n1))
        offs2.append(min(offset(n1), offset(n2)))
        xs.append(0.5 * (pos[n1, 0] + pos[n2, 0]))
    xs = np.sort(np.array(xs))
    groups, cur = [], [xs[0]]
    for x in xs[1:]:
        if x - cur[-1] > 0.5:
            groups.append(np.mean(cur))
            cur = [x]
        else:
            cur.append(x)
    groups.append(np.mean(cur))
    out["xx_offset_median"] = float(np.median(offs)) if offs else math.nan
    out["xx_offset_mean"] = float(np.mean(offs)) if offs else math.nan
    # post hoc (added after the first results were seen, NOT used by the README's statement 5): the offset at
    # the nearer end of the element; the first-node offset moves by 4 h_e sin(theta)/d (0.6 at h_e 0.3, theta 30)
    # from one element to the next, so the element nearest a crisscross point has a first-node offset up to 0.6
    out["xx_offset_near_median"] = float(np.nanmedian(offs2)) if offs2 else math.nan
    if len(groups) > 1:
        out["sawtooth_period"] = float(np.median(np.diff(groups)))
    out["x_breaks"] = " ".join(f"{(x - xc) / p:.2f}" for x in groups)  # group centres, in p from x_crisscross
    return out


def metrics(size, he, G, case, runs=RUNS) -> dict | None:
    d = run_dir(size, he, G, case, runs)
    path = run_result(d)
    if path is None:
        return None
    try:
        r = load_result(path, case=case, full=True)
    except Exception as e:  # a partial file being rewritten
        print(f"identify: cannot read {path}: {e}", file=sys.stderr)
        return None
    w, h, stop, _ = SIZES[size]
    ET = float(r.meta.get("E_transverse_over_Er", math.nan))
    er_kd = float(r.param("Er_over_kd"))
    delta0 = float(r.params.get("delta0_over_d", 0.1))
    row = dict(size=size, w_s=w, h_s=h, h_e=he, G=G, case=case, status=r.status, da_max=r.da_max,
               R_init=r.R_init, R_ss=r.R_ss, R_m=r.R_m,
               R_at3=float(np.interp(3.0, r.da, r.R)) if r.da.size and r.da[-1] >= 3 else math.nan,
               R_end=float(r.R[-1]) if r.R.size else math.nan,
               broken_rods=r.broken_rods, da_first_rod=r.da_first_rod_fracture,
               E_T=ET, l_over_d=ET * er_kd * G, delta_f_over_d=(G + 1) * delta0,
               wall_s=r.wall_time_s,
               path=str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path))
    row.update(rod_break_positions(r))
    row.update(da=np.asarray(r.da, float), R=np.asarray(r.R, float), breaks=break_points(r),
               theta_D=float(r.param("theta_D")), sigma_ru=float(r.param("sigma_ru_over_sigma0")),
               source="run folder",
               written=f"{str(r.meta.get('written_utc', ''))[:16].replace('T', ' ')} UTC, solver "
                       f"{str(r.meta.get('git_hash', '?'))[:12]}")
    return row


def break_points(r) -> dict | None:
    """What breaks.png needs of a run: the midpoints and plies of the deleted rod elements (final frame) and the
    crisscross lattice's origin."""
    g = r.geometry
    if g is None or not r.frames:
        return None
    b = np.flatnonzero(r.frames[-1].beam_broken > 0)
    mid = 0.5 * (g.node_position[g.beam_nodes[b, 0]] + g.node_position[g.beam_nodes[b, 1]])
    return dict(x_crisscross=float(g.attrs["x_crisscross"]), y_crack_plane=float(g.attrs["y_crack_plane"]),
                w_s=float(g.attrs["w_s"]), x=[round(float(v), 6) for v in mid[:, 0]],
                y=[round(float(v), 6) for v in mid[:, 1]], ply=[int(v) for v in g.node_ply[g.beam_nodes[b, 0]]])


# --- committed data: one JSON file per run (research/identify/data/) -----------------------------------------------
ROW_KEYS = ["size", "w_s", "h_s", "h_e", "G", "case", "status", "da_max", "R_init", "R_ss", "R_m", "R_at3", "R_end",
            "broken_rods", "da_first_rod", "xx_offset_median", "xx_offset_mean", "xx_offset_near_median",
            "sawtooth_period", "x_breaks", "E_T", "l_over_d", "delta_f_over_d", "wall_s"]


def data_path(size: str, he: float, G: float, case: str, data: pathlib.Path = DATA) -> pathlib.Path:
    return data / f"{size}_he{he:g}_G{G:g}__{case}.json"


def _num(v):
    return None if isinstance(v, float) and math.isnan(v) else v


def _sig(v: float) -> float:
    return float(f"{v:.{CURVE_DIGITS}g}")


def store(m: dict, data: pathlib.Path = DATA) -> pathlib.Path:
    """Write (or replace) the committed record of a run read from its folder. A record of an earlier run of the
    same key is kept in "previous" (its metrics and when it was made), so a re-run never loses what was measured."""
    path = data_path(m["size"], m["h_e"], m["G"], m["case"], data)
    previous = []
    if path.is_file():
        old = json.loads(path.read_text())
        if old.get("written") == m["written"]:
            previous = old.get("previous", [])
        else:
            previous = old.get("previous", []) + [{"written": old.get("written"), "metrics": old.get("metrics")}]
    rec = {"written": m["written"],
           "metrics": {k: _num(m[k]) for k in ROW_KEYS},
           "theta_D": m["theta_D"], "sigma_ru_over_sigma0": m["sigma_ru"],
           "rcurve": {"da_over_d": [_sig(v) for v in m["da"]], "R_over_Gamma": [_sig(v) for v in m["R"]]},
           "breaks": m["breaks"], "previous": previous}
    data.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(rec, indent=1, allow_nan=False) + "\n")
    return path


def stored(size: str, he: float, G: float, case: str, data: pathlib.Path = DATA) -> dict | None:
    """A run's row from its committed record (None: no record). Records of the first round (runs made before the
    data were kept) hold the metrics only: no R-curve (da/R None) and no broken-element positions."""
    path = data_path(size, he, G, case, data)
    if not path.is_file():
        return None
    rec = json.loads(path.read_text())
    row = {k: (math.nan if v is None else v) for k, v in rec["metrics"].items()}
    row["x_breaks"] = row.get("x_breaks") or ""
    for k in ("broken_rods", "w_s", "h_s"):
        row[k] = int(row[k])
    rc = rec.get("rcurve")
    row.update(da=np.asarray(rc["da_over_d"], float) if rc else None,
               R=np.asarray(rc["R_over_Gamma"], float) if rc else None,
               breaks=rec.get("breaks"), theta_D=float(rec["theta_D"]), sigma_ru=float(rec["sigma_ru_over_sigma0"]),
               R_at_stored=rec.get("R_at", {}), source="committed data", written=rec["written"],
               path=str(path.relative_to(ROOT)) if path.is_relative_to(ROOT) else str(path))
    return row


def row_for(size, he, G, case, runs=RUNS, data=DATA) -> dict | None:
    """The run's row from its folder when present (and not less complete than the committed record), else from
    the committed data."""
    m = metrics(size, he, G, case, runs)
    if m and m["status"] == "completed":
        return m
    s = stored(size, he, G, case, data)
    return s if s and (not m or s["status"] == "completed") else m


def recorded(job: tuple, data: pathlib.Path = DATA) -> bool:
    """Whether a completed run of this job is in the committed data (the stages skip it; --only re-runs it)."""
    s = stored(*job, data=data)
    return bool(s) and s["status"] == "completed"


def has_curve(m: dict | None) -> bool:
    return bool(m) and m["da"] is not None and m["da"].size >= 2


def l2(a: dict | None, ref: dict | None) -> float:
    if not has_curve(a) or not has_curve(ref):
        return math.nan
    return rcurve_rel_l2(ref["da"], ref["R"], a["da"], a["R"])


# --- the plan as jobs ------------------------------------------------------------------------------------------
def stage_jobs(stage: str, runs: pathlib.Path) -> list[tuple]:
    if stage == "a":
        return [(s, 0.3, G, MAIN_CASE) for G in G_VALUES for s in ("red", "ci")]
    if stage == "b":
        return [("red", 0.15, G, MAIN_CASE) for G in G_VALUES]
    if stage == "c":
        return [("big", 0.3, G, MAIN_CASE) for G in candidates(runs)]
    if stage == "d":
        return [("red", 0.3, G, c) for G in candidates(runs) for c in VALIDATION_CASES]
    if stage == "p":  # after a: one queue, most needed first (the rule needs mesh and size for the candidates)
        cand = candidates(runs)
        jobs = []
        for G in cand:  # per candidate: mesh, size, then its validation cases (so the first one is complete)
            jobs += [("red", 0.15, G, MAIN_CASE), ("big", 0.3, G, MAIN_CASE)]
            jobs += [("red", 0.3, G, c) for c in VALIDATION_CASES]
        jobs += [("red", 0.15, G, MAIN_CASE) for G in G_VALUES if G not in cand]
        return jobs
    raise SystemExit(f"identify: unknown stage {stage!r} (a, b, c, d, p)")


def candidates(runs: pathlib.Path, n: int = 2) -> list[float]:
    """The G values whose red (h_e 0.3) R_ss brackets 7 most closely; mesh-converged ones first when known."""
    rows = {G: row_for("red", 0.3, G, MAIN_CASE, runs) for G in G_VALUES}
    rows = {G: m for G, m in rows.items() if m and m["status"] == "completed"}
    if not rows:
        return []

    def key(G):
        fine = row_for("red", 0.15, G, MAIN_CASE, runs)
        mesh = l2(rows[G], fine) if fine and fine["status"] == "completed" else math.nan
        unconverged = 1 if (not math.isnan(mesh) and mesh > CONVERGED_L2) else 0
        return (unconverged, abs(rows[G]["R_ss"] - PAPER_RSS))

    order = sorted(rows, key=key)
    best = order[0]
    pick = [best]
    side = np.sign(rows[best]["R_ss"] - PAPER_RSS)
    other = [G for G in order[1:] if np.sign(rows[G]["R_ss"] - PAPER_RSS) == -side]
    pick.append(other[0] if other else (order[1] if len(order) > 1 else None))
    return [G for G in pick if G is not None][:n]


def run_all(plan, args) -> None:
    """Run the jobs of plan() in order, at most args.jobs at once, none started after args.stop_starting; skip
    finished ones. plan() is re-evaluated each time a slot frees, so a queue that depends on results (stage p:
    the candidates) uses every run finished by then; a run that failed is not retried in this invocation."""
    running, tried = [], set()

    def too_late():
        return bool(args.stop_starting) and datetime.datetime.now().strftime("%H:%M") >= args.stop_starting

    def todo():
        busy = {j for j, *_ in running}
        late = bool(args.no_long_after) and datetime.datetime.now().strftime("%H:%M") >= args.no_long_after
        return [j for j in plan() if j not in busy and j not in tried
                and not (run_dir(*j, runs=args.runs) / "result.h5").is_file()
                and not (args.only is None and recorded(j, args.data))
                and not (late and (j[0] == "big" or j[1] < 0.3))]

    while True:
        if len(running) < args.jobs and not too_late():
            for j in todo()[: args.jobs - len(running)]:
                tried.add(j)
                d = run_dir(*j, runs=args.runs)
                d.mkdir(parents=True, exist_ok=True)
                cmd = solver_cmd(args.binary, *j, d, args.threads, args.checkpoint_every, args.nice)
                log = open(d / "log.txt", "a")
                log.write(f"== {datetime.datetime.now():%F %T} identify: {' '.join(cmd)}\n")
                log.flush()
                print(f"identify: {datetime.datetime.now():%H:%M} start {d.relative_to(ROOT)}", flush=True)
                running.append((j, subprocess.Popen(cmd, stdout=log, stderr=log), time.time(), log))
        if not running:
            left = todo()
            if left:
                print(f"identify: not starting {len(left)} runs after {args.stop_starting}", flush=True)
            break
        time.sleep(5)
        for item in list(running):
            j, p, t0, log = item
            if p.poll() is not None:
                running.remove(item)
                log.close()
                print(f"identify: {datetime.datetime.now():%H:%M} {'done' if p.returncode == 0 else f'exit {p.returncode}'} "
                      f"{run_dir(*j, runs=args.runs).relative_to(ROOT)} ({time.time() - t0:.0f} s)", flush=True)


# --- the report ------------------------------------------------------------------------------------------------
def fmt(v, spec=".3g"):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "-"
    return format(v, spec) if isinstance(v, (int, float)) else str(v)


def pct(v):
    return "-" if v is None or math.isnan(v) else f"{100 * v:.1f}%"


def collect(runs, data=DATA) -> list[dict]:
    """Every run: from its folder under `runs` when present, else from its committed record under `data`."""
    keys = set()
    for d in runs.glob("*_he*_G*/*"):
        size, he, G = d.parent.name.split("_")
        keys.add((size, float(he[2:]), float(G[1:]), d.name))
    for f in data.glob("*_he*_G*__*.json"):
        run, case = f.stem.split("__")
        size, he, G = run.split("_")
        keys.add((size, float(he[2:]), float(G[1:]), case))
    rows = [m for m in (row_for(*k, runs=runs, data=data) for k in sorted(keys)) if m]
    for m in rows:  # G as the plan writes it (3, not 3.0)
        m["G"] = int(m["G"]) if float(m["G"]).is_integer() else m["G"]
    order = {s: i for i, s in enumerate(SIZE_ORDER)}
    rows.sort(key=lambda m: (m["case"] != MAIN_CASE, m["case"], m["G"], order.get(m["size"], 9), -m["h_e"]))
    return rows


def run_key(m: dict) -> str:
    return f"{m['size']}_he{m['h_e']:g}_G{m['G']:g}"


def read_pairs(data: pathlib.Path = DATA) -> dict:
    """Committed distances between two runs' R-curves that can no longer be computed (data/pairs.csv: the runs of
    the first round, whose curves were not kept): (run, reference run) -> (L2, mean-R difference, when made)."""
    out = {}
    f = data / "pairs.csv"
    if f.is_file():
        with open(f, newline="") as fh:
            for r in csv.DictReader(fh):
                out[(r["run"], r["ref"])] = (float(r["l2"]), float(r["dmean"]), r["written"])
    return out


def dmean(a: dict | None, ref: dict | None) -> float:
    """Supplementary (not the rule): relative difference of mean R over the common Delta_a range."""
    if not has_curve(a) or not has_curve(ref):
        return math.nan
    grid = np.linspace(max(a["da"][0], ref["da"][0]), min(a["da"][-1], ref["da"][-1]), 50)
    ma, mr = np.interp(grid, a["da"], a["R"]).mean(), np.interp(grid, ref["da"], ref["R"]).mean()
    return (ma - mr) / mr


def convergence(rows, pairs: dict | None = None) -> list[dict]:
    pairs = pairs or {}

    def get(size, he, G, case=MAIN_CASE):
        for m in rows:
            if (m["size"], m["h_e"], m["G"], m["case"]) == (size, he, G, case) and m["status"] == "completed":
                return m
        return None

    out = []
    for G in sorted({m["G"] for m in rows if m["case"] == MAIN_CASE}):
        notes = []

        def dist(a, ref, what):
            """(L2, mean-R difference) of a against ref: from the curves, else from a committed pair."""
            if not a or not ref:
                return math.nan, math.nan
            if has_curve(a) and has_curve(ref):
                return l2(a, ref), dmean(a, ref)
            p = pairs.get((run_key(a), run_key(ref)))
            if p is None:
                return math.nan, math.nan
            notes.append(f"{what} (runs of {p[2]})")
            return p[0], p[1]

        coarse, fine = get("red", 0.3, G), get("red", 0.15, G)
        sizes = [s for s in SIZE_ORDER if get(s, 0.3, G)]
        mesh, mesh_drss = dist(coarse, fine, "mesh")
        l2_ci_red, ci_red_drss = dist(get("ci", 0.3, G), get("red", 0.3, G), "ci/red")
        l2_red_big, red_big_drss = dist(get("red", 0.3, G), get("big", 0.3, G), "red/big")
        if len(sizes) >= 2:
            small, large = sizes[-2], sizes[-1]
            size_l2, size_drss = {"ci/red": (l2_ci_red, ci_red_drss), "red/big": (l2_red_big, red_big_drss),
                                  "ci/big": dist(get("ci", 0.3, G), get("big", 0.3, G), "ci/big")}[f"{small}/{large}"]
            pair = f"{small}/{large}"
        else:
            size_l2, size_drss, pair = math.nan, math.nan, "-"
        largest = get(sizes[-1], 0.3, G) if sizes else None
        conv = (not math.isnan(mesh) and not math.isnan(size_l2) and mesh <= CONVERGED_L2
                and size_l2 <= CONVERGED_L2)
        status = ("converged" if conv else
                  "not established" if math.isnan(mesh) or math.isnan(size_l2) else "not converged")
        out.append(dict(G=G, mesh_l2=mesh, mesh_dRss=mesh_drss, size_dRss=size_drss, size_pair=pair,
                        size_l2=size_l2, l2_ci_red=l2_ci_red,
                        l2_red_big=l2_red_big, largest=sizes[-1] if sizes else "-",
                        R_ss_largest=largest["R_ss"] if largest else math.nan, status=status,
                        note=", ".join(notes)))
    return out


def select(conv) -> dict | None:
    ok = [c for c in conv if c["status"] == "converged"]
    return min(ok, key=lambda c: abs(c["R_ss_largest"] - PAPER_RSS)) if ok else None


def validation(rows, G) -> list[tuple[str, str, str]]:
    """The README's validation statements 1-7 for one G at red h_e 0.3: (statement, our numbers, verdict)."""
    def get(case):
        for m in rows:
            if (m["size"], m["h_e"], m["G"], m["case"]) == ("red", 0.3, G, case) and m["status"] == "completed":
                return m
        return None

    def within(v, ref, tol=0.2):
        return abs(v - ref) <= tol * ref

    def verdict(ok):
        return "reproduced" if ok else "not reproduced"

    out = []
    t15, m, lo, hi, e20 = (get("theta15_s21.4_e10_cv0"), get(MAIN_CASE), get("theta30_s7.1_e10_cv0"),
                           get("theta30_s28.5_e10_cv0"), get("theta30_s21.4_e20_cv0"))
    missing = "not run"
    out.append(("1. theta15 (21.4, 10) R_ss ~ 7",
                f"R_ss {t15['R_ss']:.2f}" if t15 else "-",
                verdict(within(t15["R_ss"], 7)) if t15 else missing))
    if m and e20:
        ok = within(m["R_ss"], 8) and within(e20["R_ss"], 6)
        out.append(("2a. theta30 (21.4): R_ss ~ 8 at Er/kd 10, ~ 6 at 20",
                    f"{m['R_ss']:.2f} / {e20['R_ss']:.2f}", verdict(ok)))
        out.append(("2b. R_ss falls from Er/kd 10 to 20", f"{m['R_ss']:.2f} -> {e20['R_ss']:.2f}",
                    verdict(e20["R_ss"] < m["R_ss"])))
    else:
        out += [("2a. theta30 (21.4): R_ss ~ 8 at Er/kd 10, ~ 6 at 20", "-", missing),
                ("2b. R_ss falls from Er/kd 10 to 20", "-", missing)]
    if m and hi:
        ok = abs(hi["R_init"] - m["R_init"]) <= 0.1 * m["R_init"]
        out.append(("3. R_init plateau: theta30 Er/kd 10, R_init(21.4) = R_init(28.5) within 10%",
                    f"{m['R_init']:.2f} / {hi['R_init']:.2f}", verdict(ok)))
    else:
        out.append(("3. R_init plateau (21.4 vs 28.5)", "-", missing))
    if lo and m and hi:
        out.append(("4. R_ss increases with rod strength (7.1 < 21.4 < 28.5)",
                    f"{lo['R_ss']:.2f}, {m['R_ss']:.2f}, {hi['R_ss']:.2f}",
                    verdict(lo["R_ss"] < m["R_ss"] < hi["R_ss"])))
    else:
        out.append(("4. R_ss increases with rod strength", "-", missing))
    if m:
        p = 2.0
        ok = (m["broken_rods"] > 0 and not math.isnan(m["xx_offset_median"]) and m["xx_offset_median"] <= 0.25
              and not math.isnan(m["sawtooth_period"]) and abs(m["sawtooth_period"] - p) <= 0.25 * p)
        out.append(("5. theta30 (21.4, 10): rods break at crisscross points, sawtooth period d/sin = 2 d",
                    f"{m['broken_rods']} broken, median offset {fmt(m['xx_offset_median'], '.2f')}, "
                    f"period {fmt(m['sawtooth_period'], '.2f')} d", verdict(ok)))
        ok6 = math.isnan(m["da_first_rod"]) or m["da_first_rod"] >= 2.0
        s6 = f"theta30 first rod at {fmt(m['da_first_rod'], '.2f')} d"
        if t15:
            ok6 = ok6 and (math.isnan(t15["da_first_rod"]) or t15["da_first_rod"] >= 3.86)
            s6 += f", theta15 at {fmt(t15['da_first_rod'], '.2f')} d"
        out.append(("6. no rod breaks before Delta_a = d/sin(theta_D) (2 d at 30, 3.86 d at 15)", s6,
                    verdict(ok6) + ("" if m["broken_rods"] else " (vacuous: no rod breaks)")))
    if hi:
        if has_curve(hi):
            R2, R4, R6 = (float(np.interp(a, hi["da"], hi["R"])) for a in (2, 4, 6))
        else:  # a committed record without its curve: the values the first round's report gave
            R2, R4, R6 = (float(hi["R_at_stored"].get(k, math.nan)) for k in ("2", "4", "6"))
        out.append(("7. theta30 (28.5, 10): R flat to ~4 d, rising after", f"R(2,4,6 d) = {R2:.2f}, {R4:.2f}, {R6:.2f}",
                    verdict(R4 - R2 < R6 - R4)))
    else:
        out.append(("7. theta30 (28.5, 10) plateau end ~4 d", "-", missing))
    return out


def figures(rows, conv, out_dir: pathlib.Path) -> list[str]:
    made = []
    main = [m for m in rows if m["case"] == MAIN_CASE]
    panels = [("ci", 0.3), ("red", 0.3), ("red", 0.15), ("big", 0.3)]
    missing = [m for m in main if not has_curve(m)]
    nocurve = ("" if not missing else "\nnot drawn (committed without their curve, runs of the first round: "
               "see data/round1/): " + ", ".join(f"{m['size']} h_e {m['h_e']:g} G {m['G']:g}" for m in missing))
    fig, axes = plt.subplots(1, 4, figsize=(16, 4.2), sharey=True)
    cmap = plt.get_cmap("viridis")
    for ax, (size, he) in zip(axes, panels):
        for m in main:
            if (m["size"], m["h_e"]) != (size, he) or not has_curve(m):
                continue
            i = G_VALUES.index(int(m["G"])) if int(m["G"]) in G_VALUES else 0
            ls = "-" if m["status"] == "completed" else ":"
            ax.plot(m["da"], m["R"], ls, color=cmap(i / (len(G_VALUES) - 1)), label=f"G = {m['G']:g} ({m['broken_rods']} rods)")
        ax.axhline(PAPER_RSS, color="k", ls="--", lw=0.8)
        w, h, _, _ = SIZES[size]
        ax.set_title(f"{size}: {w} x {h} d, h_e = {he} d")
        ax.set_xlabel(r"$\Delta a/d$")
        if ax.get_legend_handles_labels()[0]:
            ax.legend(fontsize=7)
    axes[0].set_ylabel(r"$R/\Gamma_i$")
    fig.suptitle(r"theta30 ($\sigma_{ru}/\sigma_0$ = 21.4, $E_r/kd$ = 10): R-curves per ductility G = "
                 r"$\Gamma_i k/\sigma_0^2$ (dashed: paper $R_{ss}\approx 7$; dotted curves: unfinished runs)" + nocurve)
    fig.tight_layout()
    fig.savefig(out_dir / "rcurves.png", dpi=90)
    plt.close(fig)
    made.append("rcurves.png")

    # where the rods break: broken elements over the crisscross lattice (theta30 (21.4, 10), every G, red and big)
    brk = [m for m in main if m["h_e"] == 0.3 and m["size"] in ("red", "big") and m["broken_rods"] and m["breaks"]]
    if brk:
        fig, axes = plt.subplots(len(brk), 1, figsize=(12, 1.6 * len(brk) + 0.6), squeeze=False)
        for ax, m in zip(axes[:, 0], brk):
            bk = m["breaks"]
            th = math.radians(m["theta_D"])
            p, s = 1 / math.sin(th), 1 / math.cos(th)
            xc, yc = bk["x_crisscross"], bk["y_crack_plane"]
            xmax = (bk["w_s"] - xc) / p
            xmin = -xc / p
            n = np.arange(math.floor(2 * xmin), math.ceil(2 * xmax) + 1)
            for k in n:
                ys = (np.arange(-4, 5) + (0.5 if k % 2 else 0.0)) * s
                ax.plot(np.full(ys.size, k / 2), ys, ".", color="0.75", ms=3)
            mid = np.column_stack([bk["x"], bk["y"]]).reshape(-1, 2)
            ply = np.asarray(bk["ply"], int)
            for pl, mk, col in ((0, "^", "C3"), (1, "v", "C0")):
                sel = ply == pl
                ax.plot((mid[sel, 0] - xc) / p, mid[sel, 1] - yc, mk, color=col, ms=6,
                        label=f"ply {pl + 1} ({'+' if pl == 0 else '-'}theta)")
            ax.axhline(0, color="k", lw=0.5)
            ax.set_xlim(-1, (m["da_max"] / p) + 1.5)
            ax.set_ylim(-3.5, 3.5)
            ax.set_ylabel("y - y_crack (d)", fontsize=8)
            ax.set_title(f"{m['size']} G = {m['G']:g}: {m['broken_rods']} broken rod elements, median crisscross offset "
                         f"{fmt(m['xx_offset_median'], '.2f')} (grey: crisscross points)", fontsize=9)
            ax.legend(fontsize=7, loc="upper right")
        axes[-1, 0].set_xlabel("(x - x_c) / (d / sin theta_D): crisscross spacing along the mid-plane")
        fig.tight_layout()
        fig.savefig(out_dir / "breaks.png", dpi=80)
        plt.close(fig)
        made.append("breaks.png")

    val = [m for m in rows if m["case"] != MAIN_CASE or (m["size"], m["h_e"]) == ("red", 0.3)]
    Gs = sorted({m["G"] for m in val if m["case"] != MAIN_CASE})
    if Gs:
        fig, axes = plt.subplots(1, len(Gs), figsize=(6 * len(Gs), 4.2), squeeze=False)
        for ax, G in zip(axes[0], Gs):
            for m in val:
                if m["G"] != G or m["size"] != "red" or m["h_e"] != 0.3 or not has_curve(m):
                    continue
                ax.plot(m["da"], m["R"], "-" if m["status"] == "completed" else ":",
                        label=f"{m['case']} ({m['broken_rods']} rods)")
            ax.axhline(7, color="k", ls="--", lw=0.8)
            ax.set_title(f"validation cases, red 40 x 20 d, G = {G:g}")
            ax.set_xlabel(r"$\Delta a/d$")
            ax.set_ylabel(r"$R/\Gamma_i$")
            if ax.get_legend_handles_labels()[0]:
                ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(out_dir / "validation_rcurves.png", dpi=90)
        plt.close(fig)
        made.append("validation_rcurves.png")

        # map: ductility x sigma_ru/sigma0 (theta30, Er/kd 10, red): broken rods and R_ss
        pts = [m for m in rows if (m["size"], m["h_e"]) == ("red", 0.3) and m["case"].startswith("theta30_")
               and m["case"].endswith("_e10_cv0")]
        fig, ax = plt.subplots(figsize=(6, 4.2))
        for m in pts:
            s = m["sigma_ru"]
            ax.scatter(m["G"], s, s=40 + 10 * m["broken_rods"], c="C3" if m["broken_rods"] else "C0")
            ax.annotate(f"{m['R_ss']:.1f} / {m['broken_rods']}", (m["G"], s), textcoords="offset points",
                        xytext=(5, 5), fontsize=7)
        ax.set_xscale("log")
        ax.set_xlabel(r"G = $\Gamma_i k/\sigma_0^2$")
        ax.set_ylabel(r"$\sigma_{ru}/\sigma_0$")
        ax.set_title("theta30, Er/kd 10, red: R_ss / broken rods (red: rods break)", fontsize=9)
        fig.tight_layout()
        fig.savefig(out_dir / "map.png", dpi=90)
        plt.close(fig)
        made.append("map.png")
    return made


def report(args) -> None:
    data = args.data
    rows = collect(args.runs, data)
    kept = [store(m, data) for m in rows if m["source"] == "run folder" and m["status"] == "completed"]
    if kept:
        print(f"identify: {len(kept)} completed runs kept in {data}", flush=True)
    conv = convergence(rows, read_pairs(data))
    sel = select(conv)
    out = args.report_dir
    out.mkdir(parents=True, exist_ok=True)
    cols = ["size", "w_s", "h_s", "h_e", "G", "case", "status", "da_max", "R_init", "R_ss", "R_m", "R_at3", "R_end",
            "broken_rods", "da_first_rod", "xx_offset_median", "xx_offset_mean", "xx_offset_near_median", "sawtooth_period", "x_breaks",
            "E_T", "l_over_d", "delta_f_over_d", "wall_s", "path", "source", "written"]
    with open(out / "results.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=cols, extrasaction="ignore", lineterminator="\n")
        w.writeheader()
        for m in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in m.items() if k in cols})
    with open(out / "convergence.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(conv[0].keys()) if conv else ["G"], lineterminator="\n")
        w.writeheader()
        for c in conv:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in c.items()})
    made = figures(rows, conv, out)

    L = [f"# Identification study: results (generated by `make identify`, {datetime.datetime.now():%F %H:%M})", "",
         "Plan, metrics and the rule: `README.md` (written first). Every number below is from a run folder "
         "under `runs/identify/` (not committed) when present, else from the run's committed record in `data/` "
         "(column \"from\": *committed*, with when and with which solver the run was made; README \"Changes to the plan\" 6); "
         "`results.csv` and `convergence.csv` hold them all.", "",
         "## Runs", "",
         "| case | size | h_e | G | l/d | delta_f/d | status | Delta_a | R_init | R(3 d) | R_ss | R_m | broken | "
         "first rod at | crisscross offset (median; nearer end, post hoc) | sawtooth period / d | break groups ((x - x_c)/(d/sin)) | wall s | from |",
         "|" + "---|" * 19]
    for m in rows:
        L.append(f"| {m['case']} | {m['size']} {m['w_s']}x{m['h_s']} | {m['h_e']:g} | {m['G']:g} | {fmt(m['l_over_d'])} | "
                 f"{fmt(m['delta_f_over_d'])} | {m['status']} | {fmt(m['da_max'])} | {fmt(m['R_init'])} | "
                 f"{fmt(m['R_at3'])} | {fmt(m['R_ss'])} | {fmt(m['R_m'])} | {m['broken_rods']} | "
                 f"{fmt(m['da_first_rod'])} | {fmt(m['xx_offset_median'], '.2f')}; {fmt(m['xx_offset_near_median'], '.2f')} | "
                 f"{fmt(m['sawtooth_period'])} | "
                 f"{m['x_breaks'] or '-'} | {fmt(m['wall_s'], '.0f')} | "
                 f"{'run folder' if m['source'] == 'run folder' else 'committed'}: {m['written']} |")
    L += ["", "l = E_T Gamma_i/sigma0^2 (E_T: /meta E_transverse_over_Er); delta_f = (G + 1) sigma0/k. "
          "R_ss: mean R over the last 20% of the advance reached. Unfinished runs (status running/interrupted) "
          "are listed but never used by the rule.", "",
          "## Convergence (theta30 (21.4, 10), relative L2 of R-curves, common Delta_a range)", "",
          "| G | mesh: red h_e 0.3 vs 0.15 | size: ci vs red | size: red vs big | rule's size pair | size L2 used | "
          "largest size | R_ss there | status | mean-R diff over the common range, mesh / size (not the rule) |",
          "|---|---|---|---|---|---|---|---|---|---|"]
    for c in conv:
        L.append(f"| {c['G']:g} | {pct(c['mesh_l2'])} | {pct(c['l2_ci_red'])} | "
                 f"{pct(c['l2_red_big'])} | {c['size_pair']} | {pct(c['size_l2'])} | "
                 f"{c['largest']} | {fmt(c['R_ss_largest'])} | {c['status']} | "
                 f"{pct(c['mesh_dRss'])} / {pct(c['size_dRss'])} |")
    notes = [f"G = {c['G']:g}: {c['note']}" for c in conv if c["note"]]
    if notes:
        L += ["", "Distances taken from the committed `data/pairs.csv` (a run of the pair has no kept curve, so "
              "the pair's distance is the one its own round measured): " + "; ".join(notes) + "."]
    L += ["", "## Selection (the README's rule, applied as written)", ""]
    if sel:
        L.append(f"**Selected: G = {sel['G']:g}** (converged; theta30 (21.4, 10) R_ss {sel['R_ss_largest']:.2f} at "
                 f"{sel['largest']}, |R_ss - 7| = {abs(sel['R_ss_largest'] - 7):.2f}; the paper's Sec. 5 value 8: "
                 f"|R_ss - 8| = {abs(sel['R_ss_largest'] - 8):.2f}).")
    else:
        L.append("**No value selected**: no value of G is converged in both mesh and size by the 5% criterion "
                 "(see the table above for what is measured and what is missing).")
    Gs = sorted({m["G"] for m in rows if m["case"] != MAIN_CASE})
    for G in Gs:
        L += ["", f"## Validation at G = {G:g} (red 40 x 20 d, h_e 0.3)", "", "| statement | ours | verdict |",
              "|---|---|---|"]
        for s, v, ok in validation(rows, G):
            L.append(f"| {s} | {v} | {ok} |")
    L += ["", "## Figures", ""] + [f"![{p}]({p})" for p in made]
    (out / "results.md").write_text("\n".join(L) + "\n")
    print(f"identify: report {out.relative_to(ROOT) if out.is_relative_to(ROOT) else out}/results.md "
          f"({len(rows)} runs; selected: {sel['G'] if sel else 'none'})")


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--stages", default="ap", help="stages to run, in order (default ap; '' = report only)")
    p.add_argument("--jobs", type=int, default=2, help="runs at once (default 2)")
    p.add_argument("--threads", type=int, default=1, help="solver threads per run (default 1)")
    p.add_argument("--nice", type=int, default=19, help="nice level of the runs (default 19; 0 = not niced)")
    p.add_argument("--checkpoint-every", type=float, default=60, help="checkpoint interval, s (default 60)")
    p.add_argument("--stop-starting", default=os.environ.get("IDENTIFY_STOP_STARTING", ""),
                   help="HH:MM: start no run at or after this local time (default: none)")
    p.add_argument("--no-long-after", default=os.environ.get("IDENTIFY_NO_LONG_AFTER", ""),
                   help="HH:MM: from this time on start no long run (big size or h_e < 0.3, ~45 min each here), "
                        "only the others (default: none)")
    p.add_argument("--only", nargs="*", default=None,
                   help="explicit runs SIZE:H_E:G:CASE instead of the stages (e.g. big:0.3:8:theta30_s21.4_e10_cv0)")
    p.add_argument("--binary", type=pathlib.Path,
                   default=pathlib.Path(os.environ.get("ENAMEL_BINARY", ROOT / "build" / "enamel-dem")))
    p.add_argument("--runs", type=pathlib.Path, default=RUNS, help="run folder root (default runs/identify)")
    p.add_argument("--report-dir", type=pathlib.Path, default=HERE, help="report folder (default research/identify)")
    p.add_argument("--data", type=pathlib.Path, default=DATA,
                   help="committed per-run records, read for runs without a folder and written for every completed "
                        "run folder (default research/identify/data)")
    p.add_argument("--dry-run", action="store_true", help="print the runs that would be made, run nothing")
    args = p.parse_args(argv)
    if args.only is not None:
        fixed = [(sz, float(h), float(G), c) for sz, h, G, c in (o.split(":") for o in args.only)]
        plan = lambda: fixed  # noqa: E731
    else:
        plan = lambda: [j for st in args.stages for j in stage_jobs(st, args.runs)]  # noqa: E731
    if args.dry_run:
        for j in plan():
            print(run_dir(*j, runs=args.runs).relative_to(ROOT),
                  " ".join(solver_cmd(args.binary, *j, "OUT", args.threads, args.checkpoint_every, args.nice)))
        return 0
    run_all(plan, args)
    if not args.dry_run:
        report(args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
