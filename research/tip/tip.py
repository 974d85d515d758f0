"""The tip-reading identification (README.md here): its runs, their records and the report.

    python3 -m research.tip.tip run NAME --size 80 --G 10 --reading intact --phase 0     # run (resumable), record
    python3 -m research.tip.tip record NAME                                            # record a finished run
    python3 -m research.tip.tip report                                                 # the runs table, from data/
    python3 -m research.tip.tip candidates                                             # the rule applied, from data/
    python3 -m research.tip.tip run NAME ... --rate-factor 0.5                         # a half-rate twin (stage 5)
    python3 -m research.tip.tip twins                                                  # each twin against its run
    python3 -m research.tip.tip phases                                                 # stage 7: phase averages
    python3 -m research.tip.tip phases --stage 8                                       # stage 8: 8 phases, paired

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
    recs = load_records()
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


def load_records() -> list[dict]:
    """Every run's record in data/, by name."""
    return [json.loads(p.read_text()) for p in sorted(DATA.glob("*.json"))]


def run_at(recs: list[dict], keys: dict, rate: float) -> dict | None:
    """The record of the run with the same size, G, reading and phase as `keys`, at rate factor `rate`."""
    return next((r for r in recs if rate_of(r) == rate and abs(r["keys"]["phase"] - keys["phase"]) < 1e-9
                 and all(r["keys"][k] == keys[k] for k in ("size", "G", "reading"))), None)


def members(recs: list[dict], G: float, size: int, reading: str) -> list[dict] | None:
    """The records a candidate reads at one size: its run, or for `averaged` the intact run and the phases."""
    def find(rd, ph):
        return run_at(recs, dict(size=size, G=G, reading=rd, phase=ph), 1.0)
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
    """Each run at another rate_factor against the run of the same keys (phase included) at the preset's rate, by
    the measure at the rate-and-speed tolerance (metrics.same_rcurve, TOL_RATE_SPEED: 2 %)."""
    recs = load_records()
    lines = ["| twin | of | rate factor | mean (0,30] rel | R_init rel | rods | L2 | the same R-curve (2 %) |",
             "|" + "---|" * 8]
    for t in (r for r in recs if rate_of(r) != 1.0):
        base = run_at(recs, t["keys"], 1.0)
        if not base:
            lines.append(f"| {t['name']} | none recorded | {rate_of(t):g} | | | | | |")
            continue
        c = metrics.same_rcurve(curve(base), curve(t), metrics.TOL_RATE_SPEED)
        lines.append(f"| {t['name']} | {base['name']} | {rate_of(t):g} | {c.mean_rel:+.2%} | {c.init_rel:+.2%} | "
                     f"{c.rods_a} / {c.rods_b} | {c.l2:.3f} | {'yes' if c.same else 'no'} |")
    return "\n".join(lines) + "\n"


STAGE7 = dict(size=80, G=9.0, reading="cut")   # README, stages 7 and 8: phases k/N at rate factors 1 and 0.5
STAGE7_RATES = (1.0, 0.5)
STAGE8_PHASES = tuple(k / 8 for k in range(8))  # README, stage 8: the even phases are stage 7's


def phase_set(recs: list[dict], rate: float, phases: tuple = PHASES) -> list[dict | None]:
    """The runs of stages 7 and 8 at one rate, by phase (None where not recorded)."""
    return [run_at(recs, dict(STAGE7, phase=ph), rate) for ph in phases]


def phase_summary(group: list[dict]) -> dict:
    """The phase average of complete group (metrics.phase_average) and the spread of the phases' (0,30] means m_k:
    s their standard deviation, se = s / sqrt(N) the standard error of their mean."""
    avg = metrics.phase_average([curve(r) for r in group]).curve
    m = np.array([metrics.advance_mean(curve(r), 0, 30) for r in group])
    s = float(np.std(m, ddof=1))
    return dict(curve=avg, means=m, s=s, se=s / math.sqrt(len(m)), mean=metrics.advance_mean(avg, 0, 30))


def phase_rows(group: list[dict | None], rate: float, summary: dict | None, phases: tuple = PHASES) -> list[str]:
    """Each phase's row at one rate, then (summary: phase_summary of a complete group) the average and spread."""
    lines = []
    for ph, r in zip(phases, group):
        if r is None:
            lines.append(f"| {rate:g} | {ph:g} | not recorded | | | | | | |")
            continue
        st, ev = r["statements"], r["events"]
        fb = "none" if ev["first_break_da"] is None else f"{ev['first_break_da']:.2f}"
        lines.append(f"| {rate:g} | {ph:g} | {r['name']} | {r['R_init']:.3f} | {st['mean_0_30']:.3f} | "
                     f"{st['mean_5_25']:.2f} | {fb} | {r['broken_rods']} | "
                     f"{'holds' if st['i_kinks_first'] else 'fails'} / {'holds' if st['ii_rising'] else 'fails'} |")
    if summary is not None:
        p = summary
        lines.append(f"| {rate:g} | average | | {float(p['curve'].R[0]):.3f} | {p['mean']:.3f} | "
                     f"{metrics.advance_mean(p['curve'], 5, 25):.2f} | | | |")
        lines.append(f"| {rate:g} | spread | m_k {p['means'].min():.3f} to {p['means'].max():.3f} | | "
                     f"s {p['s']:.3f} ({p['s'] / p['mean']:.1%}), se {p['se']:.3f} | | | | |")
    return lines


def rate_reading(one: dict, half: dict) -> str:
    """README stage 7, reading 2: the two phase averages by the measure (2 %), else within 2 sqrt(se1^2 + se2^2)."""
    c = metrics.same_rcurve(one["curve"], half["curve"], metrics.TOL_RATE_SPEED)
    bound = 2 * math.hypot(one["se"], half["se"])
    diff = half["mean"] - one["mean"]
    head = (f"half rate against the preset's rate, phase averages: mean (0,30] {c.mean_rel:+.2%}, R_init "
            f"{c.init_rel:+.2%}, rods {c.rods_a} / {c.rods_b}; difference {diff:+.3f} against 2 sqrt(se_1^2 + "
            f"se_0.5^2) = {bound:.3f}: ")
    if c.same:
        return head + "the same R-curve (2 %): the half rate holds for the phase-averaged R-curve."
    if abs(diff) <= bound:
        n = len(one["means"])
        return head + f"not the same (2 %), but within the phases' noise: not decidable with {n} phases."
    return head + "not the same, and beyond the phases' noise: the rate is not converged at the preset."


def paired_reading(one: dict, half: dict) -> str:
    """README stage 8, reading 2: the two phase averages by the measure (2 %): holds; else the paired differences
    d_k = m'_k - m_k of the same phases: |dbar| > 2 se_d (se_d = s_d / sqrt N) fails, else not decided, with the
    bound |dbar| + 2 se_d on the rate's effect."""
    c = metrics.same_rcurve(one["curve"], half["curve"], metrics.TOL_RATE_SPEED)
    d = half["means"] - one["means"]
    dbar, s_d = float(d.mean()), float(np.std(d, ddof=1))
    se_d = s_d / math.sqrt(len(d))
    head = (f"paired: d_k = m'_k - m_k over {len(d)} phases: dbar {dbar:+.3f} ({dbar / one['mean']:+.2%} of the "
            f"rate-1 average), s_d {s_d:.3f}, se_d {se_d:.3f}, 2 se_d {2 * se_d:.3f}; phase averages: mean (0,30] "
            f"{c.mean_rel:+.2%}, R_init {c.init_rel:+.2%}: ")
    if c.same:
        return head + "the same R-curve (2 %): the half rate holds for the phase-averaged R-curve."
    if abs(dbar) > 2 * se_d:
        return head + ("not the same (2 %), and the paired difference is resolved (|dbar| > 2 se_d): the rate is "
                       "not converged at the preset.")
    bound = abs(dbar) + 2 * se_d
    return head + (f"not the same (2 %), and the paired difference is not resolved (|dbar| <= 2 se_d): not decided "
                   f"at {len(d)} phases; the rate's effect is at most {bound:.3f} ({bound / one['mean']:.2%}).")


def phases_report(phases: tuple = PHASES) -> str:
    """Stage 7 (phases k/4) or stage 8 (phases k/8; README): each phase's run at both rates, the phase averages and
    their spread, and the rate's readings once both sets are complete (stage 8: the paired one deciding, the
    unpaired one of stage 7 beside it)."""
    recs = load_records()
    lines = ["| rate factor | phase | run | R_init | mean (0,30] | (5,25] | first break (d) | rods | (i) / (ii) |",
             "|" + "---|" * 9]
    groups = {rate: phase_set(recs, rate, phases) for rate in STAGE7_RATES}
    summaries = {rate: phase_summary(g) if None not in g else None for rate, g in groups.items()}
    for rate in STAGE7_RATES:
        lines += phase_rows(groups[rate], rate, summaries[rate], phases)
    if None not in summaries.values():
        pair = [summaries[rate] for rate in STAGE7_RATES]
        if phases == PHASES:
            lines += ["", rate_reading(*pair)]
        else:
            lines += ["", "unpaired (beside, not deciding): " + rate_reading(*pair), "", paired_reading(*pair)]
    return "\n".join(lines) + "\n"


def candidates_report() -> str:
    recs = load_records()
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
    ph = sub.add_parser("phases", help="stages 7 and 8: the phase averages at rate factors 1 and 0.5, from data/")
    ph.add_argument("--stage", type=int, choices=(7, 8), default=7, help="7: phases k/4 (default); 8: phases k/8")
    a = ap.parse_args(argv)
    if a.cmd in ("report", "candidates", "twins", "phases"):
        def phases():
            return phases_report(PHASES if a.stage == 7 else STAGE8_PHASES)
        print(dict(report=report, candidates=candidates_report, twins=twins_report, phases=phases)[a.cmd](), end="")
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
