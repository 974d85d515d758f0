"""The margin-rule study and the velocity-correction study (README.md here): runs, records and reports.

    python3 -m research.rate.rate run --preset reduced --case theta30_s21.4_e10_cv0 --candidate margin8
    python3 -m research.rate.rate all --preset reduced      # every case and candidate in the README's order
    python3 -m research.rate.rate report                    # the table, from data/
    python3 -m research.rate.rate check                     # study 2: this build against study 1's records
    python3 -m research.rate.rate all --study 2             # study 2's runs; report --study 2: its table

A run goes to runs/rate/PRESET/CASE/CANDIDATE (niced, one thread, checkpointed, --resume); its record to
data/PRESET__CASE__CANDIDATE.json: the keys, steps, the solver's wall and core seconds, the machine, phi at the
events (statement S3) and the R-curve to 10 digits, so that the report (S1, S2 against phi1) needs no run folder.
A recorded candidate is not run again.
"""
from __future__ import annotations

import argparse
import json
import os
import pathlib
import resource
import subprocess
import sys
import time

import h5py
import numpy as np

from bench import records
from bench.converged_cost import event_rows, ringing_holds
from enamel_results import metrics, paths

HERE = pathlib.Path(__file__).resolve().parent
DATA = HERE / "data"
RUNS = paths.RUNS / "rate"
CASES = ("theta30_s21.4_e10_cv0", "theta15_s21.4_e10_cv0")
CANDIDATES = {   # README.md, Candidates; the order is the README's
    "phi1": {"rate_adapt_max": 1},
    "margin8": {"rate_adapt_rule": '"margin"', "rate_adapt_max": 8, "rate_adapt_horizon": 10},
    "energy8": {"rate_adapt_rule": '"energy"', "rate_adapt_max": 8},
    "margin4": {"rate_adapt_rule": '"margin"', "rate_adapt_max": 4, "rate_adapt_horizon": 10},
    "margin16": {"rate_adapt_rule": '"margin"', "rate_adapt_max": 16, "rate_adapt_horizon": 10},
    "energy4": {"rate_adapt_rule": '"energy"', "rate_adapt_max": 4},
    "energy16": {"rate_adapt_rule": '"energy"', "rate_adapt_max": 16},
}
QS = '"quasi_static"'


def margin(phi_max: float, horizon: float, velocity: str | None = QS) -> dict:
    """The keys of a margin-rule candidate (velocity None: the default, keep)."""
    keys = {"rate_adapt_rule": '"margin"', "rate_adapt_max": phi_max, "rate_adapt_horizon": horizon}
    return keys if velocity is None else {**keys, "rate_adapt_velocity": velocity}


STUDY2 = {   # README.md, Study 2, Candidates; the order is its run order
    "margin8_h40_qs": margin(8, 40), "margin8_h10_qs": margin(8, 10),
    "margin4_h40_qs": margin(4, 40), "margin4_h10_qs": margin(4, 10),
    "energy8_qs": {"rate_adapt_rule": '"energy"', "rate_adapt_max": 8, "rate_adapt_velocity": QS},
    "energy4_qs": {"rate_adapt_rule": '"energy"', "rate_adapt_max": 4, "rate_adapt_velocity": QS},
    "margin8_h40_keep": margin(8, 40, None), "margin4_h40_keep": margin(4, 40, None),
}
STUDY3 = {"margin8_h20_qs": margin(8, 20), "margin16_h20_qs": margin(16, 20)}   # README.md, Study 3
# README.md, Study 4: the converged check at the default model (G = 9, cut tip); its reference is the converged
# set's own record of the case (records/converged/CASE.json: the same keys at phi = 1, the same build)
STUDY4 = {"s4_margin8_h20_qs": margin(8, 20), "s4_margin4_h10_qs": margin(4, 10)}
# README.md, Study 5: study 4's choice with the energy part's bounds raised (rate_adapt_rho_high), at converged,
# against the same references; run order rho 0.04 (both cases), then rho 0.02
STUDY5 = {f"s5_margin4_h10_qs_rho{tag}": {**margin(4, 10), "rate_adapt_rho_high": rho}
          for tag, rho in (("04", 0.04), ("02", 0.02))}
# README.md, Study 6: the Rayleigh damping ratio zeta (which sets how fast a burst's ringing decays), at phi = 1
# (its own effect) and with study 4's choice; stage A at reduced against s6_phi1 (zeta 0.2, this build), in this order
STUDY6 = {"s6_phi1": {"rate_adapt_max": 1}, "s6_phi1_z05": {"rate_adapt_max": 1, "zeta": 0.5},
          "s6_phi1_z10": {"rate_adapt_max": 1, "zeta": 1.0}, "s6_m4": margin(4, 10),
          "s6_m4_z05": {**margin(4, 10), "zeta": 0.5}, "s6_m4_z10": {**margin(4, 10), "zeta": 1.0}}
STUDY6_REFERENCE = "s6_phi1"
# stage D: the damping where the rate does not move the R-curve (theta30's phases 1/2 and 3/4), against stage 7's runs
# of research/tip at zeta 0.2
STUDY6D = {f"s6_phi1_z05_p{phase:g}": {"rate_adapt_max": 1, "zeta": 0.5, "crisscross_phase": phase}
           for phase in (0.5, 0.75)}
TIP_DATA = HERE.parent / "tip" / "data"
# study 2's candidates whose keys are a study 1 candidate's: its record stands for them when `check` passes
STUDY1_AS = {"phi1_s2": "phi1", "margin8_h10_keep": "margin8", "margin4_h10_keep": "margin4",
             "energy8_keep": "energy8", "energy4_keep": "energy4"}
STUDY2_ALL = ("phi1_s2", *STUDY2, "margin8_h10_keep", "margin4_h10_keep", "energy8_keep", "energy4_keep")
STUDY1 = tuple(CANDIDATES)
CANDIDATES.update(STUDY2)
CANDIDATES.update(STUDY3)
CANDIDATES.update(STUDY4)
CANDIDATES.update(STUDY5)
CANDIDATES.update(STUDY6)
CANDIDATES.update(STUDY6D)
CANDIDATES.update({name: CANDIDATES[old] for name, old in STUDY1_AS.items()})
# reduced starts as converged does (its preset's own 0.95); the ci smoke run as its preset
STATIC_START = {"reduced": 0.95, "converged": 0.95, "ci": 0.0}


def solver_args(binary: str, case: str, preset: str, candidate: str, out: pathlib.Path) -> list[str]:
    sets = {"threads": 1, "static_start": STATIC_START[preset], **CANDIDATES[candidate]}
    args = ["nice", "-n", "5", binary, "run", str(paths.case_file(case)), "--preset", preset, "--out", str(out),
            "--resume", "--quiet", "--checkpoint-every", "120"]
    for k, v in sets.items():
        args += ["--set", f"{k}={v}"]
    return args


def events_at_phi(h5: pathlib.Path) -> dict:
    """Statement S3: phi at both ends of the history interval of the first rod break and of the first interface
    failure, and how many intervals with an event (a rod broke or an interface failed in it) have phi = 1 at
    both ends."""
    with h5py.File(h5, "r") as f:
        h = f["history"]
        rods, failed, phi = (np.asarray(h[k]) for k in ("broken_rod_elements", "failed_interfaces", "rate_multiplier"))
    rows = event_rows(rods, failed)   # row i: the event in (row i-1, row i]

    def ends(count):
        i = int(np.argmax(count > 0)) if (count > 0).any() else None
        return None if i is None or i == 0 else [float(phi[i - 1]), float(phi[i])]
    at_one = int(sum(phi[i - 1] == 1 and phi[i] == 1 for i in rows))
    return dict(first_rod_break=ends(rods), first_interface_failure=ends(failed), intervals=int(len(rows)),
                intervals_at_one=at_one, phi_max_reached=float(phi.max()))


def s3_holds(ev: dict) -> bool:
    return all(e is None or e == [1.0, 1.0] for e in (ev["first_rod_break"], ev["first_interface_failure"]))


def record(preset: str, case: str, candidate: str, out: pathlib.Path, core_s: float | None) -> dict:
    h5 = out / "result.h5"
    rec = records.record_of(h5, f"{preset}__{case}__{candidate}")
    rec.update(preset=preset, candidate=candidate, keys=CANDIDATES[candidate], cpu=records.cpu_model(),
               core_seconds=core_s, recorded=time.strftime("%Y-%m-%d"), events=events_at_phi(h5))
    DATA.mkdir(exist_ok=True)
    (DATA / f"{rec['name']}.json").write_text(json.dumps(rec, indent=1))
    return rec


def run_one(binary: str, preset: str, case: str, candidate: str) -> int:
    name = f"{preset}__{case}__{candidate}"
    if (DATA / f"{name}.json").exists():
        print(f"rate: {name} is recorded")
        return 0
    out = RUNS / preset / case / candidate
    out.mkdir(parents=True, exist_ok=True)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    with open(out / "log.txt", "a") as log:
        rc = subprocess.run(solver_args(binary, case, preset, candidate, out), stderr=log).returncode
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if rc != 0:
        print(f"rate: {name} exited with status {rc} (log: {out / 'log.txt'})", file=sys.stderr)
        return rc
    resumed = "resuming from checkpoint" in (out / "log.txt").read_text()
    core = None if resumed else after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime
    r = record(preset, case, candidate, out, core)
    print(f"rate: {name}: {r['meta']['steps']} steps, {core} core s, events {r['events']}")
    return 0


def curve(rec: dict) -> metrics.RCurve:
    return metrics.RCurve.of(rec["da"], rec["R"], broken_rods=rec["broken_rods"])


def rows() -> list[dict]:
    """Each study 1 record against the phi1 record of its preset and case: S1, S2 (the measure's numbers), S3."""
    recs = {p.stem: json.loads(p.read_text()) for p in sorted(DATA.glob("*__*__*.json"))}
    recs = {name: r for name, r in recs.items() if r["candidate"] in STUDY1}
    out = []
    for name, r in recs.items():
        ref = recs.get(f"{r['preset']}__{r['case']}__phi1")
        row = dict(name=name, preset=r["preset"], case=r["case"], candidate=r["candidate"], steps=r["meta"]["steps"],
                   core_s=r["core_seconds"], cpu=r["cpu"], s3=s3_holds(r["events"]), events=r["events"])
        if ref is not None:
            c = metrics.same_rcurve(curve(ref), curve(r), metrics.TOL_RATE_SPEED)
            row.update(steps_ratio=ref["meta"]["steps"] / r["meta"]["steps"],
                       core_ratio=(ref["core_seconds"] / r["core_seconds"]) if ref["core_seconds"] and r["core_seconds"] else None,
                       mean_rel=c.mean_rel, init_rel=c.init_rel, rods=(c.rods_a, c.rods_b), l2=c.l2, hi=c.hi,
                       comparable=c.comparable, same=c.same)
        out.append(row)
    return out


STUDY_NAMES = {2: STUDY2_ALL, 3: ("phi1_s2", *STUDY3)}
CHECK = "check_study2.json"   # data/: whether this build reproduces study 1's records (README.md, Study 2)


def check(binary: str, preset: str = "reduced", case: str = CASES[0], names=("phi1", "margin8")) -> dict:
    """Run study 1's `names` of `case` again with this build (into runs/rate/check/) and compare steps and every
    R-curve point (10 digits) with their records; writes data/check_study2.json and returns it."""
    out = {"binary": binary, "case": case, "preset": preset, "recorded": time.strftime("%Y-%m-%d"), "same": {}}
    for name in names:
        folder = RUNS / "check" / preset / case / name
        folder.mkdir(parents=True, exist_ok=True)
        with open(folder / "log.txt", "a") as log:
            rc = subprocess.run(solver_args(binary, case, preset, name, folder), stderr=log).returncode
        if rc != 0:
            raise SystemExit(f"rate: check run {name} exited with status {rc} (log: {folder / 'log.txt'})")
        new = records.record_of(folder / "result.h5", name)
        old = json.loads((DATA / f"{preset}__{case}__{name}.json").read_text())
        same = new["meta"]["steps"] == old["meta"]["steps"] and new["da"] == old["da"] and new["R"] == old["R"]
        out["same"][name] = bool(same)
        print(f"rate: check {name}: steps {new['meta']['steps']} (record {old['meta']['steps']}), same {same}")
    out["reuse_study1"] = all(out["same"].values())
    DATA.mkdir(exist_ok=True)
    (DATA / CHECK).write_text(json.dumps(out, indent=1))
    return out


def study2_record(preset: str, case: str, name: str) -> dict | None:
    """Study 2's record of a candidate: its own, else (when the check passed) study 1's of the same keys."""
    own = DATA / f"{preset}__{case}__{name}.json"
    if own.exists():
        return json.loads(own.read_text())
    reuse = (DATA / CHECK).exists() and json.loads((DATA / CHECK).read_text())["reuse_study1"]
    old = DATA / f"{preset}__{case}__{STUDY1_AS.get(name, '')}.json"
    return json.loads(old.read_text()) if reuse and name in STUDY1_AS and old.exists() else None


def judged_row(preset: str, case: str, name: str, r: dict, ref: dict | None) -> dict:
    """One candidate's record against its reference's (None: no reference): S1 in steps, S2 (the measure's numbers),
    S3."""
    row = dict(preset=preset, case=case, candidate=name, steps=r["meta"]["steps"], core_s=r["core_seconds"],
               s3=s3_holds(r["events"]), events=r["events"])
    if ref is not None:
        c = metrics.same_rcurve(curve(ref), curve(r), metrics.TOL_RATE_SPEED)
        row.update(steps_ratio=ref["meta"]["steps"] / r["meta"]["steps"], mean_rel=c.mean_rel,
                   init_rel=c.init_rel, rods=(c.rods_a, c.rods_b), l2=c.l2, comparable=c.comparable,
                   same=c.same)
    return row


def judged_table(rws: list[dict], core_ratio: bool = False) -> list[str]:
    """The rows of judged_row as a Markdown table (with core_ratio: the core seconds' ratio to the reference's
    beside them)."""
    core = "core s (ratio to the record's)" if core_ratio else "core s"
    lines = [f"| case | candidate | steps | steps ratio (S1) | {core} | mean R rel | R_init rel | rods ref/cand | L2 |"
             " same (S2) | first break / failure phi (S3) | event intervals at phi 1 |", "|" + "---|" * 12]
    fmt = lambda e: "-" if e is None else "/".join(f"{x:.3g}" for x in e)
    for w in rws:
        ev = w["events"]
        same = "yes" if w.get("same") else ("no" if w.get("comparable") else "not comparable")
        core_s = f"{w['core_s'] or float('nan'):.0f}" + (f" ({w['core_ratio']:.2f})" if core_ratio else "")
        lines.append(f"| {w['case'].split('_')[0]} | {w['candidate']} | {w['steps']} | {w.get('steps_ratio', float('nan')):.2f} | "
                     f"{core_s} | {100 * w.get('mean_rel', float('nan')):+.2f} % | "
                     f"{100 * w.get('init_rel', float('nan')):+.2f} % | {'/'.join(map(str, w.get('rods', ('-', '-'))))} | "
                     f"{w.get('l2', float('nan')):.3f} | {same} | {fmt(ev['first_rod_break'])}, "
                     f"{fmt(ev['first_interface_failure'])} ({'holds' if w['s3'] else 'fails'}) | "
                     f"{ev['intervals_at_one']}/{ev['intervals']} |")
    return lines


def rows2(preset: str = "reduced", names=STUDY2_ALL) -> list[dict]:
    """Study 2's (or 3's) candidates against study 2's reference (phi1_s2, or study 1's phi1 when the check
    passed)."""
    out = []
    for case in CASES:
        ref = study2_record(preset, case, "phi1_s2")
        for name in names:
            r = study2_record(preset, case, name)
            if r is not None:
                out.append(judged_row(preset, case, name, r, ref))
    return out


def best(rws: list[dict], above: float = 0.0) -> tuple[str, float] | None:
    """README.md, Study 2, Decision rule: of the candidates with (S2) on both cases (and a smaller-of-two (S1) above
    `above`: study 3's rule), the largest smaller-of-two (S1); ties to the smaller phi_max, then quasi_static."""
    by = {}
    for w in rws:
        by.setdefault(w["candidate"], []).append(w)
    ok = {n: min(x["steps_ratio"] for x in ws) for n, ws in by.items()
          if n != "phi1_s2" and len(ws) == len(CASES) and all(x.get("same") for x in ws)}
    ok = {n: s for n, s in ok.items() if s > above}
    if not ok:
        return None
    phi_max = lambda n: CANDIDATES[n]["rate_adapt_max"]
    name = max(ok, key=lambda n: (round(ok[n], 6), -phi_max(n), n.endswith("_qs")))
    return name, ok[name]


def decision(rws: list[dict], above: float = 0.0) -> str:
    b = best(rws, above)
    if b is None:
        return "none meets (S2) on both cases" + (f" with (S1) above {above:.2f}" if above else "") + \
            ": none goes to the converged check"
    return f"{b[0]} goes to the converged check (S1 {b[1]:.2f}, the smaller of its two cases)"


def report2(preset: str = "reduced", names=STUDY2_ALL) -> str:
    rws = rows2(preset, names)
    study2 = best(rows2(preset)) if names != STUDY2_ALL else None   # study 3: above study 2's choice
    lines = judged_table(rws)
    above = f" (study 3's rule: above study 2's {study2[0]}, {study2[1]:.2f})" if study2 else ""
    return "\n".join(lines) + f"\n\nDecision{above}: " + decision(rws, study2[1] if study2 else 0.0) + "\n"


def all2(binary: str, preset: str = "reduced", names=STUDY2_ALL) -> int:
    """Study 2's (or 3's) runs in the README's order, skipping recorded ones (and study 1's stand-ins when the
    check passed)."""
    for case in CASES:
        for name in names:
            if study2_record(preset, case, name) is not None:
                continue
            rc = run_one(binary, preset, case, name)
            if rc != 0:
                return rc
    return 0


def converged_reference(case: str) -> dict:
    """Study 4's phi = 1 reference: the converged set's record of the case, in this folder's record form (the
    R-curve, its steps and the solver's wall seconds; one thread, as the candidates)."""
    from enamel_results import records as result_records
    r = result_records.load(paths.record_file("converged", case), case)
    return dict(meta=dict(steps=int(r.meta["steps"]), git_hash=r.meta["git_hash"]), da=list(map(float, r.da)),
                R=list(map(float, r.R)), broken_rods=int(r.broken_rods), core_seconds=float(r.meta["wall_time_s"]))


def rows4(names=tuple(STUDY4)) -> list[dict]:
    """Study 4's (or 5's) candidates against the converged set's records (judged_row; eligible (same) only with S3
    too; core seconds against the record's wall seconds, indicative only: not run side by side)."""
    out = []
    for case in CASES:
        ref = converged_reference(case)
        for name in names:
            own = DATA / f"converged__{case}__{name}.json"
            if not own.exists():
                continue
            row = judged_row("converged", case, name, json.loads(own.read_text()), ref)
            row.update(core_ratio=ref["core_seconds"] / row["core_s"] if row["core_s"] else float("nan"),
                       same=row["same"] and row["s3"])
            out.append(row)
    return out


def report4() -> str:
    rws = rows4()
    return "\n".join(judged_table(rws, core_ratio=True)) + "\n\nDecision: " + \
        decision(rws).replace("goes to the converged check", "is bench-converged's CONVERGED_SET") + "\n"


STUDY4_CHOICE = "s4_margin4_h10_qs"


def decision5(rws: list[dict]) -> str:
    """README.md, Study 5, Decision: the eligible candidate with the largest smaller-of-two (S1), if above study 4's
    choice's; else study 4's choice stays."""
    s4 = best([w for w in rws if w["candidate"] == STUDY4_CHOICE])
    above = s4[1] if s4 else 0.0
    b = best([w for w in rws if w["candidate"] != STUDY4_CHOICE], above)
    if b:
        return (f"{b[0]} replaces {STUDY4_CHOICE} as bench-converged's CONVERGED_SET (S1 {b[1]:.2f} against "
                f"{above:.2f}, the smaller of the two cases)")
    return f"none is eligible with (S1) above {STUDY4_CHOICE}'s {above:.2f}: it stays bench-converged's CONVERGED_SET"


def report5() -> str:
    """Study 5's table (study 4's choice beside its candidates) and its decision."""
    rws = rows4((STUDY4_CHOICE, *STUDY5))
    return "\n".join(judged_table(rws, core_ratio=True)) + "\n\nDecision: " + decision5(rws) + "\n"


def rows6(preset: str = "reduced") -> list[dict]:
    """Study 6's stage A: each of its runs against s6_phi1 of the same case and preset."""
    out = []
    for case in CASES:
        ref = DATA / f"{preset}__{case}__{STUDY6_REFERENCE}.json"
        ref = json.loads(ref.read_text()) if ref.exists() else None
        for name in STUDY6:
            own = DATA / f"{preset}__{case}__{name}.json"
            if own.exists():
                out.append(judged_row(preset, case, name, json.loads(own.read_text()), ref))
    return out


def decision6(rws: list[dict]) -> list[str]:
    """README.md, Study 6, Decision A: the margin candidates with a raised zeta that meet (S2) and (S3) on both cases
    go to the converged check, the larger zeta first; the phi = 1 rows are the damping's own effect, reported."""
    go = []
    for name in ("s6_m4_z10", "s6_m4_z05"):
        ws = [w for w in rws if w["candidate"] == name]
        if len(ws) == len(CASES) and all(w.get("same") and w["s3"] for w in ws):
            go.append(name)
    return go


def decision6d(rws: list[dict]) -> str:
    """README.md, Study 6, stage D's reading: both phases not the same: the damping is not arbitrary at 80 d; both
    the same: stage C's shift is phase 0's own sensitivity; otherwise undecided."""
    same = [bool(w.get("same")) for w in rws]
    if len(same) < len(STUDY6D):
        return "Stage D: not complete"
    if not any(same):
        return "Stage D: both phases move: the damping's choice is not arbitrary at 80 x 80 d"
    if all(same):
        return "Stage D: both phases the same: stage C's shift is phase 0's own sensitivity; arbitrary for these phases"
    return "Stage D: one phase moves and one does not: undecided"


def report6(preset: str = "reduced") -> str:
    """Stage A's table and decision; then, once a converged run is recorded, stage B's (study 5's table and rule)."""
    rws = rows6(preset)
    go = decision6(rws)
    out = "\n".join(judged_table(rws)) + "\n\nDecision A: " + (
        ", ".join(go) + " go" + ("es" if len(go) == 1 else "") + " to the converged check" if go else
        "no raised zeta keeps the R-curve on both cases: none goes to the converged check") + "\n"
    stage_b = rows4((STUDY4_CHOICE, "s6_m4_z10", "s6_m4_z05"))
    if any(w["candidate"] != STUDY4_CHOICE for w in stage_b):
        out += "\n" + "\n".join(judged_table(stage_b, core_ratio=True)) + "\n\nDecision B: " + decision5(stage_b) + "\n"
    stage_d = []
    for name, keys in STUDY6D.items():
        own = DATA / f"converged__{CASES[0]}__{name}.json"
        if own.exists():
            ref = json.loads((TIP_DATA / f"s80_G9_cut_p{keys['crisscross_phase']:g}.json").read_text())
            stage_d.append(judged_row("converged", CASES[0], name, json.loads(own.read_text()), ref))
    if stage_d:
        out += ("\nStage D (theta30's phases 1/2 and 3/4, phi = 1, zeta 0.5 against research/tip's stage 7 "
                "runs):\n\n" + "\n".join(judged_table(stage_d)) + "\n\n" + decision6d(stage_d) + "\n")
    stage_c = rows4(("s6_phi1_z05",))
    if stage_c:   # README.md, Study 6, stage C: the damping's own effect at converged, against the records
        out += "\nStage C (phi = 1, zeta 0.5 against the converged records at zeta 0.2):\n\n" + \
            "\n".join(judged_table(stage_c, core_ratio=True)) + "\n\n" + "\n".join(
                f"- {w['case']}: the damping's choice is {'arbitrary' if w['same'] else 'not arbitrary'} at 80 x 80 d"
                for w in stage_c) + "\n"
    return out


def report() -> str:
    lines = ["| preset | case | candidate | steps | steps ratio (S1) | core s | mean R rel | R_init rel | rods ref/cand |"
             " L2 | same (S2) | first break / failure phi (S3) | event intervals at phi 1 |", "|" + "---|" * 13]
    for w in rows():
        ev = w["events"]
        fmt = lambda e: "-" if e is None else "/".join(f"{x:.3g}" for x in e)
        if "steps_ratio" in w:
            cmp_ = (f"{w['steps_ratio']:.2f} | {w['core_s'] or float('nan'):.0f} | {100 * w['mean_rel']:+.2f} % | "
                    f"{100 * w['init_rel']:+.2f} % | {w['rods'][0]}/{w['rods'][1]} | {w['l2']:.3f} | "
                    f"{'yes' if w['same'] else ('no' if w['comparable'] else 'not comparable')}")
        else:
            cmp_ = f"- | {w['core_s'] or float('nan'):.0f} | - | - | - | - | no reference"
        lines.append(f"| {w['preset']} | {w['case']} | {w['candidate']} | {w['steps']} | {cmp_} | "
                     f"{fmt(ev['first_rod_break'])}, {fmt(ev['first_interface_failure'])} "
                     f"({'holds' if w['s3'] else 'fails'}) | {ev['intervals_at_one']}/{ev['intervals']} |")
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python3 -m research.rate.rate", description=__doc__.split("\n\n")[0])
    sub = ap.add_subparsers(dest="cmd", required=True)
    one = sub.add_parser("run", help="run one candidate on one case (resumable) and record it")
    one.add_argument("--preset", default="reduced")
    one.add_argument("--case", choices=CASES, required=True)
    one.add_argument("--candidate", choices=tuple(CANDIDATES), required=True)
    every = sub.add_parser("all", help="every case and candidate in the README's order, skipping recorded ones")
    every.add_argument("--preset", default="reduced")
    for p in (one, every):
        p.add_argument("--binary", default=os.environ.get("ENAMEL_BINARY", str(paths.SOLVER)))
    rep = sub.add_parser("report", help="the table from data/")
    diag = sub.add_parser("held", help="what holds phi at 1 in crack growth, from result files (README.md, Study 6; "
                                       "bench.converged_cost.ringing_holds)")
    diag.add_argument("results", nargs="+", type=pathlib.Path)
    chk = sub.add_parser("check", help="study 2: does this build reproduce study 1's phi1 and margin8 (theta30)?")
    chk.add_argument("--binary", default=os.environ.get("ENAMEL_BINARY", str(paths.SOLVER)))
    for p in (every, rep):
        p.add_argument("--study", type=int, choices=(1, 2, 3, 4, 5, 6), default=1)
    a = ap.parse_args(argv)
    if a.cmd == "report":
        print(report() if a.study == 1 else report4() if a.study == 4 else report5() if a.study == 5 else
              report6() if a.study == 6 else report2(names=STUDY_NAMES[a.study]), end="")
        return 0
    if a.cmd == "held":
        for h5 in a.results:
            print(h5, json.dumps(ringing_holds(h5)))
        return 0
    if a.cmd == "check":
        return 0 if check(a.binary)["reuse_study1"] else 1
    if a.cmd == "run":
        return run_one(a.binary, a.preset, a.case, a.candidate)
    if a.study == 6:   # README.md, Study 6, stage A's order: each case, its runs in the table's order
        return run_each(a.binary, [(a.preset, case, name) for case in CASES for name in STUDY6])
    if a.study in STUDY_NAMES:
        return all2(a.binary, a.preset, STUDY_NAMES[a.study])
    if a.study in (4, 5):   # README.md, Study 4's (5's) order: each candidate on both cases, in the table's order
        return run_each(a.binary, [("converged", case, name) for name in (STUDY4 if a.study == 4 else STUDY5)
                                   for case in CASES])
    return run_each(a.binary, [(a.preset, case, cand) for case in CASES for cand in STUDY1])


def run_each(binary: str, runs: list[tuple[str, str, str]]) -> int:
    """run_one for each (preset, case, candidate) in order; the first failure's status stops the rest."""
    for preset, case, name in runs:
        rc = run_one(binary, preset, case, name)
        if rc != 0:
            return rc
    return 0

if __name__ == "__main__":
    sys.exit(main())
