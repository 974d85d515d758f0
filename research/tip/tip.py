"""The tip-reading identification (README.md here): its runs, their records and the report.

    python3 -m research.tip.tip run NAME --size 80 --G 10 --reading intact --phase 0     # run (resumable), record
    python3 -m research.tip.tip record NAME                                            # record a finished run
    python3 -m research.tip.tip report                                                 # the runs table, from data/
    python3 -m research.tip.tip candidates                                             # the rule applied, from data/
    python3 -m research.tip.tip run NAME ... --rate-factor 0.5                         # a half-rate twin (stage 5)
    python3 -m research.tip.tip twins                                                  # each twin against its run

A run goes to runs/tip/NAME (niced, one thread, checkpointed); its record to data/NAME.json: the case, the keys of
the candidate, the metrics the rule reads (R_init, the (0,30] and (5,25] means, the first rod break and the kinks
before it, statements (i) and (ii)) and the R-curve to 10 digits, so that the report needs no run folder.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import pathlib
import subprocess
import sys

import h5py
import numpy as np

from bench import records
from enamel_results import metrics, paths, results

HERE = pathlib.Path(__file__).resolve().parent
DATA = HERE / "data"
RUNS = paths.RUNS / "tip"
CASE = paths.case_file("theta30_s21.4_e10_cv0")
PRESET = "converged"


def solver_args(binary: str, a: argparse.Namespace, out: pathlib.Path) -> list[str]:
    sets = [f"w_s_over_d={a.size}", f"h_s_over_d={a.size}", f"Gamma_k_over_sigma0sq={a.G}",
            f'crisscross_at_tip="{a.reading}"', f"crisscross_phase={a.phase}", "threads=1"]
    if a.rate_factor != 1.0:
        sets.append(f"rate_factor={a.rate_factor}")
    args = ["nice", "-n", "19", binary, "run", str(CASE), "--preset", PRESET, "--out", str(out), "--resume",
            "--quiet", "--checkpoint-every", "300"]
    for s in sets:
        args += ["--set", s]
    return args


def first_events(h5: pathlib.Path) -> dict:
    """The first rod break (Delta_a at the first history row with a broken rod element), the crack's advance and
    its kinks off the crack plane (history kinked_interfaces) at the row before it, and the threshold of statement
    (i): the first crisscross point at or ahead of the tip whose rods are intact, minus a0_eff, minus h_e."""
    with h5py.File(h5, "r") as f:
        h, g = f["history"], f["geometry"].attrs
        rods, da, kinks = (np.asarray(h[k]) for k in ("broken_rod_elements", "da_over_d", "kinked_interfaces"))
        a0, xc, he = float(g["a0_effective"]), float(g["x_crisscross"]), float(g["h_e"])
        theta = math.radians(float(g["theta_D_deg"]))
    spacing = 1.0 / math.sin(theta)
    first_intact = xc + math.ceil((a0 - he / 4 - xc) / spacing) * spacing   # crossing at or past slice K
    i = int(np.argmax(rods > 0)) if (rods > 0).any() else None
    return dict(first_break_da=None if i is None else float(da[i]),
                da_before_first_break=None if i is None else float(da[max(i - 1, 0)]),
                kinks_before_first_break=None if i is None else int(kinks[max(i - 1, 0)]),
                threshold_da=first_intact - a0 - he)


def statements(rec: dict) -> dict:
    c = metrics.RCurve.of(rec["da"], rec["R"], broken_rods=rec["broken_rods"])
    m525 = metrics.advance_mean(c, 5, 25)
    ev = rec["events"]
    kinks_first = ev["first_break_da"] is None or (ev["da_before_first_break"] > 0
                                                    and ev["first_break_da"] >= ev["threshold_da"])
    return dict(mean_0_30=metrics.advance_mean(c, 0, 30), mean_5_25=m525, i_kinks_first=bool(kinks_first),
                ii_rising=bool(rec["R_init"] <= 0.8 * m525))


def record(name: str, out: pathlib.Path, keys: dict | None = None) -> dict:
    h5 = results.load_result(out / "result.h5").path
    rec = records.record_of(h5, name)
    rec["keys"] = keys or json.loads((DATA / f"{name}.json").read_text())["keys"]
    rec["cpu"] = records.cpu_model()
    rec["events"] = first_events(h5)
    rec["statements"] = statements(rec)
    DATA.mkdir(exist_ok=True)
    (DATA / f"{name}.json").write_text(json.dumps(rec, indent=1))
    return rec


def report() -> str:
    recs = [json.loads(p.read_text()) for p in sorted(DATA.glob("*.json"))]
    lines = ["| run | size | G | reading | phase | status | R_init | mean (0,30] | mean (5,25] | first break (d) |"
             " Delta_a before it | kinks off the plane | threshold (d) | (i) | (ii) | wall (h) |", "|" + "---|" * 16]
    for r in recs:
        k, e, s = r["keys"], r["events"], r["statements"]
        fb = "none" if e["first_break_da"] is None else f"{e['first_break_da']:.2f}"
        kb = "-" if e["kinks_before_first_break"] is None else str(e["kinks_before_first_break"])
        db = "-" if e["da_before_first_break"] is None else f"{e['da_before_first_break']:.2f}"
        lines.append(f"| {r['name']} | {k['size']} | {k['G']:g} | {k['reading']} | {k['phase']:g} | "
                     f"{r['meta'].get('status')} | {r['R_init']:.2f} | {s['mean_0_30']:.2f} | {s['mean_5_25']:.2f} | "
                     f"{fb} | {db} | {kb} | {e['threshold_da']:.2f} | {'holds' if s['i_kinks_first'] else 'fails'} | "
                     f"{'holds' if s['ii_rising'] else 'fails'} | {r['meta'].get('wall_time_s', math.nan) / 3600:.2f} |")
    return "\n".join(lines) + "\n"


PHASES = (0.0, 0.25, 0.5, 0.75)   # the averaged reading: phase 0 is the intact run
PAPER_LEVEL = 7.0
READING_MARGIN = 0.05             # another reading replaces intact by (iii) only when nearer 7 by more than this


def rate_of(rec: dict) -> float:
    """The run's rate_factor (1: the preset's loading rate; records before stage 5 have no such key)."""
    return float(rec["keys"].get("rate_factor", 1.0))


def curve(rec: dict) -> metrics.RCurve:
    return metrics.RCurve.of(rec["da"], rec["R"], broken_rods=rec["broken_rods"])


def members(recs: list[dict], G: float, size: int, reading: str) -> list[dict] | None:
    """The records a candidate reads at one size: its run, or for `averaged` the intact run and the phases."""
    def find(rd, ph):
        return next((r for r in recs if r["keys"]["size"] == size and r["keys"]["G"] == G and rate_of(r) == 1.0
                     and r["keys"]["reading"] == rd and abs(r["keys"]["phase"] - ph) < 1e-9), None)
    got = [find(reading, 0.0)] if reading != "averaged" else [find("intact", ph) for ph in PHASES]
    return None if any(r is None for r in got) else got


def judged_at(group: list[dict]) -> dict:
    """One candidate at one size: its R-curve (the phase average for `averaged`), (i) (at least 3 of 4 phases for
    the average), (ii) on that curve's first point, and its (5,25] level."""
    if len(group) == 1:
        c, holds_i = curve(group[0]), group[0]["statements"]["i_kinks_first"]
    else:
        c = metrics.phase_average([curve(r) for r in group]).curve
        holds_i = sum(r["statements"]["i_kinks_first"] for r in group) >= 3
    level = metrics.advance_mean(c, 5, 25)
    return dict(curve=c, i=bool(holds_i), ii=bool(float(c.R[0]) <= 0.8 * level), level=level)


def candidates(recs: list[dict]) -> list[dict]:
    """Every candidate (G, reading) with both sizes recorded: the size pair by the measure (metrics.same_rcurve
    at TOL_MESH_SIZE), (i) and (ii) at both sizes, and the level (iii): the mean of the pair's (5,25] levels."""
    out = []
    for G in sorted({r["keys"]["G"] for r in recs}):
        for reading in ("intact", "cut", "averaged"):
            small, large = members(recs, G, 80, reading), members(recs, G, 100, reading)
            if small is None or large is None:
                continue
            a, b = judged_at(small), judged_at(large)
            cmp = metrics.same_rcurve(a["curve"], b["curve"], metrics.TOL_MESH_SIZE)
            out.append(dict(G=G, reading=reading, converged=bool(cmp.same), mean_rel=cmp.mean_rel,
                            init_rel=cmp.init_rel, i=a["i"] and b["i"], ii=a["ii"] and b["ii"],
                            level=(a["level"] + b["level"]) / 2, levels=(a["level"], b["level"])))
    return out


def select(cands: list[dict]) -> tuple[dict | None, str]:
    """The rule (README, "Selection rule"): among the converged candidates meeting (i) and (ii), the level nearest
    7; if none meets both, by (iii) among the converged ones, intact kept unless another is nearer 7 by > 5 %."""
    conv = [c for c in cands if c["converged"]]
    meeting = [c for c in conv if c["i"] and c["ii"]]
    if meeting:
        return min(meeting, key=lambda c: abs(c["level"] - PAPER_LEVEL)), "(i), (ii), then (iii)"
    if not conv:
        return None, "no candidate is converged"
    best = min(conv, key=lambda c: abs(c["level"] - PAPER_LEVEL))
    intact = [c for c in conv if c["reading"] == "intact"]
    if intact and best["reading"] != "intact":
        keep = min(intact, key=lambda c: abs(c["level"] - PAPER_LEVEL))
        if abs(keep["level"] - PAPER_LEVEL) - abs(best["level"] - PAPER_LEVEL) <= READING_MARGIN * PAPER_LEVEL:
            best = keep
    return best, "none meets (i) and (ii): (iii) alone"


def twins_report() -> str:
    """Each run at another rate_factor against the run of the same keys at the preset's rate, by the measure at
    the rate-and-speed tolerance (metrics.same_rcurve, TOL_RATE_SPEED: 2 %)."""
    recs = [json.loads(p.read_text()) for p in sorted(DATA.glob("*.json"))]
    lines = ["| twin | of | rate factor | mean (0,30] rel | R_init rel | rods | L2 | the same R-curve (2 %) |",
             "|" + "---|" * 8]
    for t in (r for r in recs if rate_of(r) != 1.0):
        k = t["keys"]
        base = members(recs, k["G"], k["size"], k["reading"]) if k["phase"] == 0 else None
        if not base:
            lines.append(f"| {t['name']} | none recorded | {rate_of(t):g} | | | | | |")
            continue
        c = metrics.same_rcurve(curve(base[0]), curve(t), metrics.TOL_RATE_SPEED)
        lines.append(f"| {t['name']} | {base[0]['name']} | {rate_of(t):g} | {c.mean_rel:+.2%} | {c.init_rel:+.2%} | "
                     f"{c.rods_a} / {c.rods_b} | {c.l2:.3f} | {'yes' if c.same else 'no'} |")
    return "\n".join(lines) + "\n"


def candidates_report() -> str:
    recs = [json.loads(p.read_text()) for p in sorted(DATA.glob("*.json"))]
    cands = candidates(recs)
    lines = ["| G | reading | 80 vs 100 d: mean (0,30] | R_init | converged | (i) both | (ii) both | level (5,25] 80 / 100 "
             "| level of the pair |", "|" + "---|" * 9]
    for c in cands:
        lines.append(f"| {c['G']:g} | {c['reading']} | {c['mean_rel']:+.1%} | {c['init_rel']:+.1%} | "
                     f"{'yes' if c['converged'] else 'no'} | {'holds' if c['i'] else 'fails'} | "
                     f"{'holds' if c['ii'] else 'fails'} | {c['levels'][0]:.2f} / {c['levels'][1]:.2f} | "
                     f"{c['level']:.2f} |")
    best, how = select(cands)
    chosen = "none" if best is None else f"G = {best['G']:g}, {best['reading']}"
    lines += ["", f"Selected so far: {chosen} ({how})."]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python3 -m research.tip.tip", description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    run = sub.add_parser("run", help="run one candidate (resumable) and record it")
    run.add_argument("name")
    run.add_argument("--size", type=int, required=True)
    run.add_argument("--G", type=float, required=True)
    run.add_argument("--reading", choices=("intact", "cut"), required=True)
    run.add_argument("--phase", type=float, default=0.0)
    run.add_argument("--rate-factor", type=float, default=1.0, help="rate_factor (0.5: the half-rate twin)")
    run.add_argument("--binary", default=os.environ.get("ENAMEL_BINARY", str(paths.SOLVER)))
    rec = sub.add_parser("record", help="record a finished run of runs/tip/NAME")
    rec.add_argument("name")
    sub.add_parser("report", help="the runs table from data/")
    sub.add_parser("candidates", help="the candidates with both sizes recorded, judged by the rule, from data/")
    sub.add_parser("twins", help="each run at another rate_factor against its run at the preset's rate")
    a = ap.parse_args(argv)
    if a.cmd in ("report", "candidates", "twins"):
        print(dict(report=report, candidates=candidates_report, twins=twins_report)[a.cmd](), end="")
        return 0
    out = RUNS / a.name
    if a.cmd == "record":
        record(a.name, out)
        return 0
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "log.txt", "a") as log:
        rc = subprocess.run(solver_args(a.binary, a, out), stderr=log).returncode
    if rc != 0:
        print(f"tip: {a.name} exited with status {rc} (log: {out / 'log.txt'})", file=sys.stderr)
        return rc
    keys = dict(size=a.size, G=a.G, reading=a.reading, phase=a.phase)
    r = record(a.name, out, keys if a.rate_factor == 1.0 else dict(keys, rate_factor=a.rate_factor))
    print(f"{a.name}: {r['statements']}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
