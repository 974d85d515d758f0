#!/usr/bin/env python3
"""`make bench-converged`: what a converged run costs, an older solver's build against this one.

Three cases (CASES: theta_D = 30 and 15 at sigma_ru/sigma0 = 21.4, Er/kd = 10, and theta_D = 30 at 28.5 with
strengths scattered by cv = 0.3, seed 1) run at the `converged` preset (80 x 80 d, to Delta_a = 30 d) by three
roles of solver:
- the baseline, the build of the commit --baseline names (default BASELINE_COMMIT; built once, from a detached
  git worktree, into build/baseline-<commit>/, and reused): what the cost is compared with;
- the new solver (build/enamel-dem, or ENAMEL_BINARY) with the --set overrides that make "the new default";
- the reference, the new solver with --reference-set (its speed levers off; none: its defaults): what the new
  R-curve is compared with. The baseline's model need not be this one (the default baseline's pre-crack tip rule
  is another, so its R-curve differs at equal numerics), so the R-curve is judged against this model at the preset's
  numerics, and the baseline's R-curve is reported beside it. When the reference's command is the new one's
  (no --set and no --reference-set), the new run is its own reference and is not run twice.
One thread a run, --jobs runs at once: case by case the baseline's run and the new one (so that at two jobs the
runs of a ratio run at the same time or close to it), then the reference's.

Per run: core-seconds (the solver process's own CPU time, user + system, from os.wait4, summed over the pieces
of a resumed run), wall seconds, steps and DOF (the result file's /meta), the machine (CPU model), the start of
each piece (UTC) and the solver's commit. Per case: the ratio of core-seconds (baseline / new), its two factors
(fewer steps; cheaper steps), and "the same R-curve" by enamel_results.metrics.same_rcurve at the rate-and-speed
tolerance (R averaged over (0,30] d and R_init within 2%, broken rods within 20%; the pointwise L2 reported,
not deciding) against the reference, computed as `make bench` computes it (bench.run_bench.speed_comparison);
the levers' own ratio (reference / new core-seconds) and the baseline's R-curve against the new one beside it;
the new run's share of steps at loading-rate multiplier phi = 1 and the ratio / that share, which bounds what a
higher phi_max of an adaptive rate could reach while the steps near events stay at phi = 1.
The verdict: the ratio at least --goal (3) and the same R-curve as the reference; a case that misses says what
it reached and by which factor.

Resumable: each run goes to RUNS/<preset>/<role>_<solver commit>[_<sets>]/<case>/ with the solver's checkpoints
(--checkpoint-every) and its --resume; Ctrl-C or SIGTERM stops every run at a checkpoint, and the same command
continues. A run whose result.h5 is complete and whose record (bench/jobs.py: its command, the binary's SHA-256
and the CPU time of each piece) matches the command and the binary is not run again; --fresh deletes the runs
first.

Writes bench/converged_cost.md and bench/converged_cost.csv at the `converged` preset; at another preset (a
quick check: --preset ci) they go to the runs folder instead, so a check never stands for the table.
"""
from __future__ import annotations

import argparse
import datetime
import math
import os
import pathlib
import re
import shutil
import subprocess
import sys
import tomllib

import h5py
import numpy as np

import bench
from bench import jobs as bench_jobs
from bench import run_bench
from enamel_results import metrics, paths, results
from enamel_results import constants
from pipeline.phases import set_tag

CASES = ("theta30_s21.4_e10_cv0", "theta15_s21.4_e10_cv0", "theta30_s28.5_e10_cv0.3_seed1")
BASELINE_COMMIT = "c09beab"
PRESET = "converged"
RATIO_GOAL = 3.0
TOLERANCE = metrics.TOL_RATE_SPEED
FAR_ROWS = 40   # ringing_holds: an interval at phi = 1 whose next event is more rows ahead is "far from events"
RUNS = bench.RUNS / "converged_cost"
TABLE = "converged_cost"             # OUT/converged_cost.md and .csv
CHECKPOINT_EVERY_S = 300.0
# One thread a run, the static start's factorisation included: CHOLMOD's BLAS (OpenBLAS's pthread build) would
# otherwise start a thread per core. Set for every solver the harness starts, baseline and new alike.
ONE_THREAD_ENV = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}


# ------------------------------------------------------------------------------------------------ solvers
def baseline_build(commit: str, jobs: int, root: pathlib.Path = paths.ROOT) -> pathlib.Path:
    """The enamel-dem of `commit`, built once into build/baseline-<commit>/build/ from a detached git worktree in
    build/baseline-<commit>/src/ (Release, ccache when there is one); an existing binary is reused."""
    base = root / "build" / f"baseline-{commit}"
    binary = base / "build" / "enamel-dem"
    if binary.exists():
        return binary
    src = base / "src"
    if not (src / "CMakeLists.txt").exists():
        subprocess.run(["git", "worktree", "prune"], cwd=root, check=True)
        subprocess.run(["git", "worktree", "add", "--detach", str(src), commit], cwd=root, check=True)
    configure = ["cmake", "-S", str(src), "-B", str(base / "build"), "-DCMAKE_BUILD_TYPE=Release"]
    if shutil.which("ccache"):
        configure.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
    subprocess.run(configure, check=True)
    subprocess.run(["cmake", "--build", str(base / "build"), "-j", str(jobs), "--target", "enamel-dem"], check=True)
    return binary


def solver_commit(binary: pathlib.Path) -> str:
    """The commit a solver binary was built from, as `enamel-dem --version` prints it: `0.1.0 (77c6627724a3)`."""
    out = subprocess.run([str(binary), "--version"], capture_output=True, text=True, check=True).stdout
    m = re.search(r"\(([^)]+)\)", out)
    return m.group(1) if m else "unknown"


ROLES = ("baseline", "reference", "new")


class Variant:
    """One solver with its --set overrides: role (one of ROLES), binary, sets (["key=value", ...]). `same_as`: the
    variant whose runs stand for this one's (the reference whose command is the new one's), else None."""

    def __init__(self, role: str, binary: pathlib.Path, sets: list[str], same_as: "Variant | None" = None):
        self.role, self.binary, self.sets, self.same_as = role, pathlib.Path(binary), list(sets), same_as
        self.commit = solver_commit(self.binary)
        tag = re.sub(r"[^\w.-]", "", set_tag(self.sets))
        self.label = same_as.label if same_as else f"{role}_{self.commit}" + (f"_{tag}" if tag else "")


def variants_of(base_binary: pathlib.Path, binary: pathlib.Path, set_both: list[str], new_sets: list[str],
                reference_sets: list[str]) -> list[Variant]:
    """The three roles in ROLES's order; the reference is the new variant itself when their commands agree."""
    base = Variant("baseline", base_binary, set_both)
    new = Variant("new", binary, set_both + new_sets)
    ref_sets = set_both + reference_sets
    return [base, Variant("reference", binary, ref_sets, same_as=new if ref_sets == new.sets else None), new]


def solver_args(v: Variant, case: str, preset: str, out: pathlib.Path, checkpoint_every: float) -> list[str]:
    """The run's command (one thread; the solver continues from its checkpoint when it is this build's)."""
    args = [str(v.binary), "run", str(paths.case_file(case)), "--preset", preset, "--out", str(out), "--resume",
            "--quiet", "--checkpoint-every", f"{checkpoint_every:g}", "--set", "threads=1"]
    for s in v.sets:
        args += ["--set", s]
    return args


# ---------------------------------------------------------------------------------------------------- runs
def run_all(variants: list[Variant], cases, preset: str, runs: pathlib.Path, jobs: int, nice: int,
            checkpoint_every: float) -> None:
    """Every case by every variant, `jobs` at once, in run_order's order; Ctrl-C / SIGTERM: every running solver
    writes its checkpoint and stops, its piece is recorded, and nothing more starts (bench.jobs.run_resumable)."""
    todo = []
    order = run_order([v for v in variants if v.same_as is None], cases)
    for rank, (v, case) in enumerate(order):
        out = runs / preset / v.label / case
        cmd = solver_args(v, case, preset, out, checkpoint_every)
        wrapped = (["nice", "-n", str(nice)] if nice else []) + cmd   # nice execs: wait4 sees the solver
        todo.append((bench_jobs.Job(case=case, variant=v.label, args=wrapped, cores=1, out=out,
                                    expected_s=float(len(order) - rank)), cmd))  # run_jobs starts the largest first
    bench_jobs.run_resumable(todo, jobs)


def run_order(variants: list[Variant], cases) -> list[tuple[Variant, str]]:
    """Case by case the baseline's run and then the new one, so that at two jobs the runs whose core-seconds make a
    ratio run at the same time or close to it (a machine whose speed drifts during the bench moves both); the
    reference's runs (the R-curve's, not the cost's) after them."""
    cost = [(v, c) for c in cases for v in variants if v.role != "reference"]
    return cost + [(v, c) for c in cases for v in variants if v.role == "reference"]


# ---------------------------------------------------------------------------------------------------- rows
def run_row(out: pathlib.Path) -> dict:
    """One run's numbers: core-seconds and wall seconds summed over its pieces, steps, DOF, commit, machines."""
    t = bench_jobs.totals(out)
    r = results.load_result(out / paths.RESULT_NAMES["completed"])
    return dict(core_s=t["cpu_s"], wall_s=t["wall_s"], pieces=t["pieces"], steps=int(r.meta["steps"]),
                dof=int(r.meta["dof"]), threads=int(r.meta["threads"]), git=str(r.meta["git_hash"]),
                G=r.param(run_bench.G_KEY), machines=t["machines"], started_utc=t["started_utc"], result=r)


def verdict(ratio: float, same: bool | None, goal: float = RATIO_GOAL, why: str = "") -> tuple[bool, str]:
    """(met, words): met when the ratio of core-seconds is at least `goal` and the R-curve is the same; `why`
    says how the R-curves differ."""
    if same is None or ratio is None or not math.isfinite(ratio):
        return False, "no comparison (a run is missing or incomplete)"
    misses = (([] if ratio >= goal else [f"ratio {ratio:.2f} < {goal:g}"])
              + ([] if same else ["not the same R-curve" + (f" ({why})" if why else "")]))
    return (not misses), ("met" if not misses else "not met: " + ", ".join(misses))


def differences(c: metrics.Comparison) -> str:
    """Which of same_rcurve's conditions a comparison fails, in words."""
    if not c.comparable:
        return f"common range (0, {c.hi:.1f}] d shorter than {metrics.MIN_RANGE_OVER_D:g} d: not comparable"
    out = [f"{name} {rel:+.1%}" for name, rel in (("R mean", c.mean_rel), ("R_init", c.init_rel))
           if abs(rel) > c.tol]
    return ", ".join(out + ([] if c.rods_ok else [f"rods {c.rods_a} / {c.rods_b}"]))


def unit_rate_share(result_file: pathlib.Path) -> float | None:
    """The share of a run's steps in history intervals with the loading-rate multiplier phi = 1 at both ends
    (/history/rate_multiplier; None for a solver without that column). With an adaptive rate those are the steps
    it could not take faster (approaching and following events), so ratio / share bounds the cost ratio that any
    higher phi_max could reach while the same steps stay at phi = 1."""
    with h5py.File(result_file, "r") as f:
        h = f["history"]
        if "rate_multiplier" not in h:
            return None
        step, phi = np.asarray(h["step"], dtype=float), np.asarray(h["rate_multiplier"])
    if step.size < 2 or step[-1] <= step[0]:
        return None
    at_one = (phi[:-1] == 1) & (phi[1:] == 1)
    return float(np.diff(step)[at_one].sum() / (step[-1] - step[0]))


def event_rows(rods: np.ndarray, failed: np.ndarray) -> np.ndarray:
    """The history rows i whose interval (row i-1, row i] holds an event (a rod broke or an interface failed)."""
    return np.nonzero((np.diff(rods) > 0) | (np.diff(failed) > 0))[0] + 1


def ringing_decay_rates(time: np.ndarray, kinetic: np.ndarray, events: np.ndarray, quiet_rows: int = 30) -> np.ndarray:
    """The decay rate of the kinetic energy beyond the loading, -d ln K / dt by least squares, over each quiet
    stretch: from the largest K within 10 rows after an event row to the row before the next event, at least
    `quiet_rows` rows between the two events and 20 rows fitted. A mass-proportional damping a M alone makes K
    decay at the rate a."""
    rates = []
    for k, j in zip(events[:-1], events[1:]):
        if j - k < quiet_rows:
            continue
        i0 = k + int(np.argmax(kinetic[k:k + 10]))
        t, y = time[i0:j - 1], kinetic[i0:j - 1]
        if len(t) >= 20 and (y > 0).all():
            rates.append(-np.polyfit(t, np.log(y), 1)[0])
    return np.asarray(rates)


def ringing_holds(result_file: pathlib.Path, far_rows: int = FAR_ROWS) -> dict | None:
    """What holds an adaptive-rate run at phi = 1 in crack growth (after its first event): the history intervals
    with phi = 1 at both ends whose next event is more than `far_rows` rows ahead (`far`), and how many of those
    end with rho = kinetic energy beyond the loading / strain energy at or above the rule's low bound (`ringing`:
    the energy part holds phi; the rest the forecast or the rise's pace), of them above the high bound
    (`above_high`: the energy part halves phi); the steps in crack growth and those at phi = 1 there; and the
    median decay rate of that kinetic energy between events over the run's Rayleigh a (`decay_over_a`;
    ringing_decay_rates). None without the adaptive-rate column or without an event."""
    with h5py.File(result_file, "r") as f:
        h = f["history"]
        if "rate_multiplier" not in h:
            return None
        get = lambda k: np.asarray(h[k], dtype=float)
        phi, time, kinetic = get("rate_multiplier"), get("time"), get("kinetic_energy_beyond_loading")
        step = get("step")
        strain = get("strain_energy_beams") + get("strain_energy_interfaces")
        events = event_rows(get("broken_rod_elements"), get("failed_interfaces"))
        meta = f["meta"].attrs
        a = float(meta["rayleigh_a"])
        case = tomllib.loads(meta["case_toml"]) if "case_toml" in meta else {}
    if len(events) == 0:
        return None
    rate = constants.LOADING_RATE
    rho_high = float(case.get("rate_adapt_rho_high", rate["rho_high"]))
    rho_low = rate["rho_low_share"] * rho_high
    rows = np.arange(len(phi))
    nxt = np.searchsorted(events, rows + 1)
    to_next = np.where(nxt < len(events), events[np.minimum(nxt, len(events) - 1)] - rows, np.iinfo(np.int64).max)
    i = np.arange(events[0], len(phi) - 1)
    at_one = i[(phi[i] == 1) & (phi[i + 1] == 1)]
    far = at_one[to_next[at_one] > far_rows]
    rho = kinetic[far + 1] / np.maximum(strain[far + 1], np.finfo(float).tiny)
    rates = ringing_decay_rates(time, kinetic, events)
    return dict(growth_steps=int(step[-1] - step[events[0]]), steps_at_one=int((step[at_one + 1] - step[at_one]).sum()),
                far=int(len(far)), ringing=int((rho >= rho_low).sum()), above_high=int((rho > rho_high).sum()),
                quiet_stretches=int(len(rates)),
                decay_over_a=float(np.median(rates) / a) if len(rates) and a > 0 else math.nan)


def case_row(case: str, base: pathlib.Path, ref: pathlib.Path, new: pathlib.Path, goal: float = RATIO_GOAL) -> dict:
    """One case's row: the three runs' numbers (the reference's folder may be the new one's), the ratio of cost
    (baseline / new) and its factors, the levers' own ratio (reference / new), the new R-curve against the
    reference's (deciding) and against the baseline's (reported), and the verdict."""
    row = dict(case=case)
    if not all(bench_jobs.done(d) for d in (base, ref, new)):
        row.update(status="incomplete", verdict=verdict(math.nan, None, goal)[1], met=False)
        return row
    b, r, n = run_row(base), run_row(ref), run_row(new)
    same = run_bench.speed_comparison(r["result"], n["result"])
    was = run_bench.speed_comparison(b["result"], n["result"])
    for prefix, x in (("baseline", b), ("reference", r), ("new", n)):
        row.update({f"{prefix}_{k}": (";".join(v) if k == "machines" else v) for k, v in x.items() if k != "result"})
    ratio = b["core_s"] / n["core_s"]
    row.update(status="complete", ratio=ratio, fewer_steps=b["steps"] / n["steps"],
               cheaper_step=(b["core_s"] / b["steps"] / b["dof"]) / (n["core_s"] / n["steps"] / n["dof"]),
               lever_ratio=r["core_s"] / n["core_s"], reference_is_new=(ref == new))
    share = unit_rate_share(new / paths.RESULT_NAMES["completed"])
    if share:
        row.update(new_unit_rate_share=share, ratio_bound=ratio / share)
    held = ringing_holds(new / paths.RESULT_NAMES["completed"])
    if held:
        row.update(new_far_at_one=held["far"], new_far_ringing=held["ringing"],
                   new_ringing_decay_over_a=held["decay_over_a"])
    if same is not None:
        row.update(range_hi=same.hi, R_mean_reference=same.mean_a, R_mean_new=same.mean_b, R_mean_rel=same.mean_rel,
                   R_init_rel=same.init_rel, rods_reference=same.rods_a, rods_new=same.rods_b, rcurve_l2=same.l2,
                   same_rcurve=same.same)
    if was is not None:
        row.update(R_mean_baseline=was.mean_a, baseline_R_mean_rel=was.mean_rel, baseline_R_init_rel=was.init_rel,
                   rods_baseline=was.rods_a, same_as_baseline=was.same)
    met, words = verdict(ratio, same.same if same else None, goal, differences(same) if same else "")
    return dict(row, met=met, verdict=words)


# -------------------------------------------------------------------------------------------------- output
def fmt(v, spec=".3g") -> str:
    return "n/a" if v is None or (isinstance(v, float) and not math.isfinite(v)) else format(v, spec)


def markdown(rows: list[dict], header: dict) -> str:
    """The table: a header (date, machine, preset, G, threads, solvers, sets, bound) and one row per case."""
    check = "" if header["preset"] == PRESET else f" -- a `{header['preset']}`-preset check, not the converged table"
    L = [f"# A converged run's cost: {header['baseline']} against {header['new']}{check}", "",
         f"{header['date']} UTC; {header['machine']}; preset `{header['preset']}`{header['both_sets']}; G = "
         f"{header['G']}; 1 thread a run (threads=1, {' '.join(f'{k}=1' for k in ONE_THREAD_ENV)}), "
         f"{header['jobs']} runs at once{header['nice']}; `make bench-converged` "
         f"(bench/converged_cost.py). Baseline: the build of {header['baseline']} (solver {header['baseline_git']}). "
         f"New: solver {header['new_git']}{header['new_sets']}. Reference: {header['reference']}. Core-seconds: the "
         f"solver process's CPU time (user + system) summed over its pieces; ratio = baseline / new = fewer steps x "
         f"cheaper step (core-s per step and DOF); levers = reference / new; at phi = 1: the new run's share of "
         f"steps in history intervals at loading-rate multiplier 1 at both ends, and the ratio / that share, the most "
         f"a higher phi_max could reach while those steps stay at 1 (n/a: no adaptive-rate column); held by the "
         f"ringing: of the new run's intervals at phi = 1 in crack growth whose next event (a rod break or an "
         f"interface failure) is more than {FAR_ROWS} rows ahead, those that end with kinetic energy beyond the "
         f"loading / strain energy at or above the rule's low bound (the energy part holds phi at 1), and the median "
         f"decay rate of that energy between events over the Rayleigh a (mass-proportional damping alone: 1). Same "
         f"R-curve, new "
         f"against the reference (deciding): `enamel_results.metrics.same_rcurve` at {TOLERANCE:.0%} (R averaged "
         f"over (0,30] d and R_init; broken rods within {metrics.ROD_REL_TOL:.0%} or {metrics.ROD_ABS_TOL}); the "
         f"pointwise L2 reported, not deciding; the baseline's R mean against the new one reported beside it (its "
         f"model is not today's). Goal: ratio >= {header['goal']:g} with the same R-curve.", "",
         "| case | baseline core-s | new core-s | **ratio** | fewer steps | cheaper step | levers | at phi = 1 "
         "(bound) | held by the ringing (decay / a) | steps (baseline / new) | DOF | R mean over (0, hi] d: "
         "reference / new (diff) | R_init diff | "
         "broken rods (reference / new) | L2 | same R-curve | baseline's R mean (diff) | verdict |",
         "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    L += [table_line(r) for r in rows]
    L += ["", "Per run (pieces: solver processes of a resumed run; started: the first piece, UTC):", ""]
    for r in rows:
        for role in ROLES if r.get("status") == "complete" else ():
            if role == "reference" and r["reference_is_new"]:
                L.append(f"- {r['case']}, reference: the new run (the same command)")
                continue
            L.append(f"- {r['case']}, {role}: solver {r[f'{role}_git']}, {r[f'{role}_pieces']} piece(s) from "
                     f"{r[f'{role}_started_utc']}, {r[f'{role}_core_s']:.1f} core-s, {r[f'{role}_wall_s']:.1f} s "
                     f"wall, {r[f'{role}_steps']} steps, {r[f'{role}_threads']} thread, G = {r[f'{role}_G']:g}, "
                     f"{r[f'{role}_machines']}")
    L += ["", "<!-- generated by: make bench-converged (bench/converged_cost.py) -->"]
    return "\n".join(L) + "\n"


def pct(v) -> str:
    return fmt(v * 100 if v is not None else None, "+.2f") + "%"


def unit_rate_cell(r: dict) -> str:
    """The share of the new run's steps at phi = 1 and the ratio's bound from it, or n/a."""
    share = r.get("new_unit_rate_share")
    return f"{share:.0%} ({r['ratio_bound']:.2f})" if share else "n/a"


def ringing_cell(r: dict) -> str:
    """Of the new run's intervals at phi = 1 far from events, those the ringing holds, and its decay / a; or n/a."""
    if r.get("new_far_at_one") is None:
        return "n/a"
    return f"{r['new_far_ringing']} / {r['new_far_at_one']} ({fmt(r.get('new_ringing_decay_over_a'), '.2f')})"


def table_line(r: dict) -> str:
    """One case's line of the table."""
    if r.get("status") != "complete":
        return f"| {r['case']} |" + " |" * 16 + f" {r['verdict']} |"
    dof = f"{r['new_dof']}" if r["new_dof"] == r["baseline_dof"] else f"{r['baseline_dof']} / {r['new_dof']}"
    return (f"| {r['case']} | {r['baseline_core_s']:.0f} | {r['new_core_s']:.0f} | **{r['ratio']:.2f}** | "
            f"{r['fewer_steps']:.2f} | {r['cheaper_step']:.2f} | {r['lever_ratio']:.2f} | {unit_rate_cell(r)} | "
            f"{ringing_cell(r)} | "
            f"{r['baseline_steps']} / "
            f"{r['new_steps']} | {dof} | hi {fmt(r.get('range_hi'), '.1f')}: {fmt(r.get('R_mean_reference'), '.4g')} "
            f"/ {fmt(r.get('R_mean_new'), '.4g')} ({pct(r.get('R_mean_rel'))}) | {pct(r.get('R_init_rel'))} | "
            f"{r.get('rods_reference')} / {r.get('rods_new')} | {fmt(r.get('rcurve_l2', math.nan) * 100, '.2f')}% | "
            f"{r.get('same_rcurve')} | {fmt(r.get('R_mean_baseline'), '.4g')} ({pct(r.get('baseline_R_mean_rel'))}) "
            f"| {r['verdict']} |")


def write_table(rows: list[dict], header: dict, out: pathlib.Path) -> list[pathlib.Path]:
    out.mkdir(parents=True, exist_ok=True)
    md, csv_path = out / f"{TABLE}.md", out / f"{TABLE}.csv"
    md.write_text(markdown(rows, header))
    run_bench.write_csv(rows, csv_path)
    return [md, csv_path]


def header_of(rows: list[dict], a, base: Variant, ref: Variant, new: Variant) -> dict:
    gs = sorted({r[f"{role}_G"] for r in rows for role in ROLES if f"{role}_G" in r})
    return dict(date=datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M"),
                machine=bench_jobs.machine(), preset=a.preset, G=", ".join(f"{g:g}" for g in gs) or "n/a",
                jobs=a.jobs, nice=f", nice {a.nice}" if a.nice else "", goal=a.goal,
                baseline=a.baseline if not a.baseline_binary else f"{a.baseline_binary}",
                new=f"{new.binary}" + (f" with {' '.join(a.set)}" if a.set else ""),
                baseline_git=base.commit, new_git=new.commit,
                new_sets=f", --set {' '.join(a.set)}" if a.set else " (no --set: its defaults)",
                reference=("the new run (no lever set)" if ref.same_as else
                           f"solver {ref.commit}" + (f", --set {' '.join(a.reference_set)}" if a.reference_set
                                                     else " (no --set: its defaults)")),
                both_sets=f", both with --set {' '.join(a.set_both)}" if a.set_both else "")


# ---------------------------------------------------------------------------------------------------- main
def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--preset", default=PRESET, help=f"size preset (default {PRESET}; `ci` for a quick check)")
    ap.add_argument("--cases", nargs="+", default=list(CASES), help=f"cases of paper_cases/ (default: {' '.join(CASES)})")
    ap.add_argument("--baseline", default=BASELINE_COMMIT, help=f"the baseline's commit (default {BASELINE_COMMIT})")
    ap.add_argument("--baseline-binary", type=pathlib.Path,
                    help="an enamel-dem binary to use as the baseline instead of building --baseline")
    ap.add_argument("--binary", type=pathlib.Path, default=run_bench.solver(),
                    help="the new solver (default: ENAMEL_BINARY or build/enamel-dem)")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="an override of the new variant only (repeatable): what makes the new default")
    ap.add_argument("--reference-set", action="append", default=[], metavar="KEY=VALUE",
                    help="an override of the reference only (repeatable): the new solver's levers off, when they are "
                         "its defaults (default: none, the reference is the new solver at its defaults)")
    ap.add_argument("--set-both", action="append", default=[], metavar="KEY=VALUE",
                    help="an override of every variant (repeatable; e.g. a smaller specimen for a check)")
    ap.add_argument("--jobs", type=int, default=2, help="runs at once, one thread each (default 2)")
    ap.add_argument("--nice", type=int, default=0, help="run the solvers at this niceness (default 0: not niced)")
    ap.add_argument("--goal", type=float, default=RATIO_GOAL, help=f"the ratio to reach (default {RATIO_GOAL:g})")
    ap.add_argument("--checkpoint-every", type=float, default=CHECKPOINT_EVERY_S,
                    help=f"a checkpoint every this many wall seconds (default {CHECKPOINT_EVERY_S:g})")
    ap.add_argument("--runs", type=pathlib.Path, default=RUNS, help=f"where the runs go (default {RUNS})")
    ap.add_argument("--out", type=pathlib.Path, default=None,
                    help=f"where {TABLE}.md and .csv go (default: {bench.HERE} at the `{PRESET}` preset, else the "
                         "runs folder of the preset)")
    ap.add_argument("--fresh", action="store_true", help="delete this command's runs first and run them all again")
    ap.add_argument("--report-only", action="store_true", help="run nothing: the table from the runs there are")
    return ap


def main(argv=None) -> int:
    a = parser().parse_args(argv)
    sys.stdout.reconfigure(line_buffering=True)
    bad = [c for c in a.cases if not paths.case_file(c).exists()]
    if bad or not a.binary.exists():
        print(f"converged_cost.py: no case file for {bad}" if bad else
              f"converged_cost.py: solver binary {a.binary} not found: run `make build`", file=sys.stderr)
        return 2
    base_binary = a.baseline_binary or baseline_build(a.baseline, a.jobs)
    variants = variants_of(base_binary, a.binary, a.set_both, a.set, a.reference_set)
    if a.fresh:
        for v in variants:
            shutil.rmtree(a.runs / a.preset / v.label, ignore_errors=True)
    if not a.report_only:
        os.environ.update(ONE_THREAD_ENV)   # the solvers inherit it
        try:
            run_all(variants, a.cases, a.preset, a.runs, a.jobs, a.nice, a.checkpoint_every)
        except KeyboardInterrupt as e:
            print(f"converged_cost.py: {e or 'stopped'}", file=sys.stderr)
            return 130
    rows = [case_row(c, *(a.runs / a.preset / v.label / c for v in variants), a.goal) for c in a.cases]
    out = a.out or (bench.HERE if a.preset == PRESET else a.runs / a.preset)
    print(write_table(rows, header_of(rows, a, *variants), out)[0])   # write_csv names the .csv
    return 0 if all(r["status"] == "complete" for r in rows) else 1   # the verdicts are in the table


if __name__ == "__main__":
    sys.exit(main())
