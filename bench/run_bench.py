#!/usr/bin/env python3
"""`make bench`: speed against error of the integrators and their knobs, and how the cost grows.

Everything is measured in ONE run of this script, so that every ratio compares runs made on the same
machine in the same state:

1. Speed against error. Each bench case runs at the `reduced` preset, at the solver's default interface fracture
   energy G (or --G; the report's header names it), with the reference scheme (`paper` at
   the preset's loading rate, the slowest rate measured here) and with every fast variant (integrator and
   knobs: time-step factor, stiffness-damping cap, loading rate, threads). For each run: wall time (the whole
   process, set-up included), CPU time, steps, DOF, DOF-updates per second per core, peak memory, and the
   error against the reference of the same case: R-curve relative L2 difference over the common Delta_a
   range, R_init and R_ss differences, broken rod elements. The runs share the cores two at a time
   (--jobs), the long reference runs first.
2. Step profile: `enamel-dem profile` on the `paper` preset's theta_D = 30 case (1.39 M DOF) with the
   fastest lumped knobs, on 1 and on 2 threads: each phase of the real step timed by the step's own timers,
   its time per step and, where counted, the bytes it must move per step and the bandwidth it achieves next to
   a triad measured in the same process (bench/profile.md).
3. Cost growth. Short runs (a fixed number of steps) of the theta_D = 30 case at growing specimen size and
   finer slice spacing h_e, both integrators: wall time per step against DOF and h_e, and from it an estimate
   of the wall time of one whole run, up to the `paper` preset (200 d x 200 d).

Writes bench/results.csv, bench/cost_growth.csv, bench/profile.md, bench/results.md (the README quotes them) and
bench/out/pareto.{pdf,png}, bench/out/cost_growth.{pdf,png}. Runs go to runs/bench/.

Resumable (bench/jobs.py): Ctrl-C or SIGTERM stops every running solver at a checkpoint (each also writes one
every 300 s), and the same command continues; a run already done by the same command and solver binary is kept,
its time read from its record (summed over its pieces), and the report says when its runs started and how many
ran in more than one piece. The step profile is measured again at each sitting. --fresh runs everything again.
"""
import argparse
import csv
import datetime
import math
import os
import pathlib
import shutil
import subprocess
import sys
import time

import numpy as np

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.ticker  # noqa: E402

import bench  # noqa: E402
from enamel_results import metrics, paths, results  # noqa: E402
from bench.jobs import Job, machine, run_resumable, totals  # noqa: E402
from bench.records import history_end  # noqa: E402
from enamel_results.constants import KINETIC_WARN  # noqa: E402  the solver's quasi-static warning bound
from figures import plotting  # noqa: E402

ERROR_BOUND = metrics.TOL_RATE_SPEED   # the measure's tolerance for speed checks (metrics.same_rcurve decides)
PRESET = "reduced"
CASES = ["theta30_s21.4_e10_cv0", "theta30_s28.5_e10_cv0.3_seed1"]
REFERENCE = "paper"
# The physics the speed-against-error and cost runs use beyond their case files: the interface fracture energy
# G = Gamma_i k / sigma0^2 (case key G_KEY), the solver's default unless --G names another, set explicitly on every
# run and named in the report's header (bench_physics). At G = 9 or 10 its `paper` references take ~2 h each (at
# G = 3, --G 3, under 1.5 h). The step profile steps at the default, as `make bench-paper` and bench.profile_pair do.
G_KEY = "Gamma_k_over_sigma0sq"
BENCH_PHYSICS = {}   # set by main(): {G_KEY: G}


def key_defaults(keys_markdown: str) -> dict:
    """{key: default (text)} from `enamel-dem keys` (a Markdown table: | `key` | kind | default | range | ...)."""
    out = {}
    for line in keys_markdown.splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) >= 3 and cells[0].startswith("`") and cells[0].endswith("`"):
            out[cells[0].strip("`")] = cells[2]
    return out


def solver_default(key: str, binary=None) -> float:
    """The solver's default of a numeric case key, as `enamel-dem keys` lists it (one definition: the solver's)."""
    proc = subprocess.run([str(binary or solver()), "keys"], capture_output=True, text=True, check=True)
    defaults = key_defaults(proc.stdout)
    if key not in defaults:
        raise KeyError(f"`enamel-dem keys` lists no key {key}")
    return float(defaults[key])


def bench_physics(G: float | None = None, binary=None) -> dict:
    """The physics keys every speed-against-error and cost run sets: G as given, else the solver's default."""
    return {G_KEY: G if G is not None else solver_default(G_KEY, binary)}

# Variants: name -> (--set overrides, threads). `paper` is the reference. dt_factor is dt over the smallest
# period of the integrator's own system (lumped: stable up to ~0.187 with damping_cap 1, ~0.236 with 0.5).
def lumped(dt_factor=0.1, damping_cap=1.0, rate_factor=1.0, static_start=0.0, rate_adapt_max=1.0) -> dict:
    return {"integrator": '"lumped"', "dt_factor": dt_factor, "damping_cap": damping_cap, "rate_factor": rate_factor,
            "static_start": static_start, "rate_adapt_max": rate_adapt_max}


# Every knob is set explicitly, so that a preset that changes one does not change the bench.
VARIANTS = {
    "paper": ({"integrator": '"paper"', "dt_factor": 0.1, "rate_factor": 1.0, "static_start": 0.0,
               "rate_adapt_max": 1.0}, 1),
    "lumped": (lumped(), 1),
    "lumped dt0.15": (lumped(dt_factor=0.15), 1),
    "lumped dt0.18": (lumped(dt_factor=0.18), 1),
    "lumped cap0.5 dt0.22": (lumped(dt_factor=0.22, damping_cap=0.5), 1),
    "lumped rate2": (lumped(rate_factor=2), 1),
    "lumped rate4": (lumped(rate_factor=4), 1),
    "lumped dt0.18 rate2": (lumped(dt_factor=0.18, rate_factor=2), 1),
    "lumped dt0.18 rate4": (lumped(dt_factor=0.18, rate_factor=4), 1),
    "lumped cap0.5 dt0.22 rate1.25": (lumped(dt_factor=0.22, damping_cap=0.5, rate_factor=1.25), 1),
    "lumped cap0.5 dt0.22 rate1.5": (lumped(dt_factor=0.22, damping_cap=0.5, rate_factor=1.5), 1),
    "lumped cap0.5 dt0.22 rate2": (lumped(dt_factor=0.22, damping_cap=0.5, rate_factor=2), 1),
    "lumped cap0.5 dt0.22 rate4": (lumped(dt_factor=0.22, damping_cap=0.5, rate_factor=4), 1),
    # fewer steps: the static elastic start, the adaptive loading rate, both
    "lumped cap0.5 dt0.22 static": (lumped(dt_factor=0.22, damping_cap=0.5, static_start=0.95), 1),
    "lumped cap0.5 dt0.22 adapt4": (lumped(dt_factor=0.22, damping_cap=0.5, rate_adapt_max=4), 1),
    "lumped cap0.5 dt0.22 static rate2": (lumped(dt_factor=0.22, damping_cap=0.5, static_start=0.95, rate_factor=2),
                                          1),
    "lumped cap0.5 dt0.22 static adapt4": (lumped(dt_factor=0.22, damping_cap=0.5, static_start=0.95,
                                                  rate_adapt_max=4), 1),
    "lumped 2 threads": (lumped(), 2),
}
TWO_THREAD_CASES = CASES[:1]   # the 2-thread variant runs on the first case only (it needs both cores)

# Cost growth: (w_s, h_s, h_e) at the base case; steps per run are chosen so each takes ~10-20 s.
COST_CASE = CASES[0]
COST_SIZES = [(16, 8, 0.3), (24, 12, 0.3), (40, 20, 0.3), (80, 40, 0.3), (200, 200, 0.3),
              (40, 20, 0.2), (40, 20, 0.15)]
COST_PAPER_MAX_DOF = 150_000   # the paper scheme's factorisation beyond this is left out (memory, minutes)
COST_WORK = {"lumped": 3e8, "paper": 6e7}   # DOF x steps per cost run


# The last line of each report this writes: what wrote it (tools/check_dates.py reads the marker).
GENERATED_BY = "<!-- generated by: make bench (bench/run_bench.py) -->"

# Step profile: the paper preset's case with the fastest lumped knobs (what `make bench-paper` steps).
PROFILE_CASE = CASES[0]
PROFILE_SETS = {"integrator": '"lumped"', "dt_factor": 0.22, "damping_cap": 0.5}


def profile_markdown(preset: str, threads_list=(1, 2), extra_sets: dict | None = None) -> str:
    """`enamel-dem profile` of PROFILE_CASE at `preset`, once per thread count, as Markdown sections."""
    out = []
    for threads in threads_list:
        sets = dict(PROFILE_SETS, threads=threads, **(extra_sets or {}))
        args = [str(solver()), "profile", str(paths.PAPER_CASES / f"{PROFILE_CASE}.toml"), "--preset", preset]
        for k, v in sets.items():
            args += ["--set", f"{k}={v}"]
        t0 = time.perf_counter()
        proc = subprocess.run(args, capture_output=True, text=True)
        if proc.returncode != 0:
            out.append(f"### {threads} thread(s)\n\nprofile failed (exit {proc.returncode}): {proc.stderr.strip()}\n")
            continue
        out.append(f"### {threads} thread(s) ({time.perf_counter() - t0:.0f} s with set-up)\n\n{proc.stdout}")
    return "\n".join(out)


def solver() -> pathlib.Path:
    return pathlib.Path(os.environ.get("ENAMEL_BINARY", paths.SOLVER))


def variant_dir(runs: pathlib.Path, case: str, variant: str) -> pathlib.Path:
    """Where one bench run of a case and variant goes (and is read back from)."""
    return runs / case / variant.replace(" ", "_")


# A bench run continues from its checkpoint when it was stopped (bench/jobs.py: its record decides whether it runs).
RUN_FLAGS = ("--resume", "--quiet", "--checkpoint-every", "300")


def run_args(case_file, preset, sets: dict, threads: int, out: pathlib.Path, flags=RUN_FLAGS) -> list:
    a = [str(solver()), "run", str(case_file), "--preset", preset, "--out", str(out), *flags]
    for k, v in {**sets, "threads": threads}.items():
        a += ["--set", f"{k}={v}"]
    return a


def run_pieces(jobs: list[Job], cores: int) -> None:
    """Run the jobs that are not done yet (bench.jobs.run_resumable), then give every job its cost over all its
    pieces, earlier sittings included: wall and CPU seconds summed, the last piece's exit status."""
    run_resumable([(j, j.args) for j in jobs], cores)
    for j in jobs:
        t = totals(j.out)
        j.wall_s, j.cpu_s, j.returncode = t["wall_s"], t["cpu_s"], t["exit"]


def sittings_note(jobs: list[Job]) -> str:
    """How the bench's runs were made: in this sitting, or (resumed) with pieces from earlier ones."""
    t = [totals(j.out) for j in jobs]
    starts = sorted(x["started_utc"] for x in t if x["started_utc"])
    several = sum(x["pieces"] > 1 for x in t)
    if not starts:
        return ""
    return (f"Its {len(jobs)} runs started from {starts[0]} to {starts[-1]} UTC; {several} of them in more than one "
            "piece (stopped at a checkpoint and continued: wall and CPU time summed over the pieces, the set-up "
            "counted in each).")


def speed_comparison(ref, r) -> metrics.Comparison | None:
    """Result r against reference ref by "the same R-curve" at the rate-and-speed tolerance (metrics.same_rcurve
    with TOL_RATE_SPEED: R averaged over (0,30] d and R_init within 2%, broken rods within 20%); None when
    either curve has fewer than two points."""
    if r.da.size < 2 or ref.da.size < 2:
        return None
    return metrics.same_rcurve(metrics.rcurve_of(ref), metrics.rcurve_of(r), metrics.TOL_RATE_SPEED)


# ------------------------------------------------------------------------------------------- speed vs error
def speed_error_jobs(cases, variants, preset, runs: pathlib.Path, extra_sets: dict) -> list[Job]:
    jobs = []
    for case in cases:
        for name, (sets, threads) in variants.items():
            if threads > 1 and case not in TWO_THREAD_CASES:
                continue
            out = variant_dir(runs, case, name)
            expected = 100.0 if name == REFERENCE else 1.0 / threads
            jobs.append(Job(case=case, variant=name, cores=threads, out=out, expected_s=expected,
                            args=run_args(paths.case_file(case), preset, {**sets, **BENCH_PHYSICS, **extra_sets},
                                          threads, out)))
    return jobs


def speed_error_rows(jobs: list[Job]) -> list[dict]:
    reference = {j.case: j for j in jobs if j.variant == REFERENCE}
    rows = []
    for j in jobs:
        case, ref_job = j.case, reference[j.case]
        row = dict(case=case, variant=j.variant, exit_code=j.returncode, wall_s=j.wall_s, cpu_s=j.cpu_s)
        try:
            r = results.load_result(j.out / "result.h5", case=case)
            ref = results.load_result(ref_job.out / "result.h5", case=case)
            m = {**r.meta, **history_end(j.out / "result.h5")}
        except (results.MissingResult, OSError, KeyError) as e:
            row.update(status=f"no result ({e})")
            rows.append(row)
            continue
        threads = int(m["threads"])
        same = speed_comparison(ref, r)
        row.update(peak_memory_mb=m["peak_memory_mb"],
            status=r.status, integrator=m["integrator"], threads=threads, dt=m["dt"], steps=int(m["steps"]),
            dof=int(m["dof"]), stepping_s=m["wall_time_s"],
            dof_updates_per_s_per_core=m["dof"] * m["steps"] / m["wall_time_s"] / threads,
            dt_factor=r.param("dt_factor"), damping_cap=r.param("damping_cap"),
            rate_factor=r.param("rate_factor"), added_rotary_inertia=m["added_rotary_inertia"],
            speedup_wall=ref_job.wall_s / j.wall_s, speedup_cpu=ref_job.cpu_s / j.cpu_s,
            rcurve_rel_l2=(metrics.rcurve_rel_l2(ref.da, ref.R, r.da, r.R)
                           if r.da.size > 1 and ref.da.size > 1 else math.nan),
            R_mean_rel_diff=same.mean_rel if same else math.nan, R_mean_range=same.hi if same else math.nan,
            same_rcurve=bool(same and same.same),
            R_init=r.R_init, R_ss=r.R_ss, R_init_rel_diff=r.R_init / ref.R_init - 1,
            R_ss_rel_diff=r.R_ss / ref.R_ss - 1, da_max=r.da_max,
            broken_rods=r.broken_rods, broken_rods_diff=r.broken_rods - ref.broken_rods,
            max_kinetic_over_strain=m["max_kinetic_over_strain_while_growing"],
            energy_balance_end=m["balance_end"], warnings=" | ".join(str(m.get("warnings", "")).split("\n")[:-1]),
            U_end=m["U_end"], t_end=m["t_end"], v_app=m["v_app"])
        rows.append(row)
    return rows


# ------------------------------------------------------------------------------------------------- cost
def cost_jobs(runs: pathlib.Path, sizes, integrators, extra_sets: dict) -> list[Job]:
    jobs = []
    for w, h, he in sizes:
        dof_est = 27840 * (w * h) / 800.0 * 0.3 / he   # DOF ~ w h / h_e (27 840 at 40 x 20 d, h_e 0.3 d)
        for integ in integrators:
            if integ == "paper" and dof_est > COST_PAPER_MAX_DOF:
                continue
            steps = int(min(20000, max(50 if integ == "paper" else 100, COST_WORK[integ] / dof_est)))
            out = runs / "cost" / f"{integ}_w{w}_h{h}_he{he}"
            sets = {**VARIANTS[integ][0], "w_s_over_d": w, "h_s_over_d": h, "h_e_over_d": he,
                    "max_steps": steps, **BENCH_PHYSICS, **extra_sets}
            jobs.append(Job(case="cost", variant=integ, cores=1, out=out, expected_s=dof_est * 1e-9,
                            args=run_args(paths.case_file(COST_CASE), PRESET, sets, 1, out)))
    return jobs


def cost_rows(jobs: list[Job], run_model: dict) -> list[dict]:
    """Per step and per run. A whole run's steps are estimated as T_run / dt with T_run = ramp + U_end / v_app
    and U_end = U_end(reference run) x sqrt(h_s / h_s(reference)) (the initiation displacement grows as
    sqrt(h_s) for this grip loading); this leaves out that the paper preset's crack goes 30 d, not 12 d."""
    rows = []
    for j in jobs:
        row = dict(integrator=j.variant, exit_code=j.returncode, wall_s=j.wall_s, cpu_s=j.cpu_s)
        try:
            r = results.load_result(j.out / "result.h5")
        except (results.MissingResult, OSError) as e:
            row.update(status=f"no result ({e})")
            rows.append(row)
            continue
        m = r.meta
        w, h, he = (r.param(k) for k in ("w_s_over_d", "h_s_over_d", "h_e_over_d"))
        per_step = m["wall_time_s"] / m["steps"]
        row.update(peak_memory_mb=m["peak_memory_mb"], status=m["status"], w_s=w, h_s=h, h_e=he, dof=int(m["dof"]), steps=int(m["steps"]),
                   dt=m["dt"], setup_s=j.wall_s - m["wall_time_s"], s_per_step=per_step,
                   dof_updates_per_s=m["dof"] / per_step)
        if run_model:
            c_d = m["c_d_over_cr"]
            U_end = run_model["U_end"] * math.sqrt(h / run_model["h_s"])
            for suffix, v in (("", run_model["v_app_over_cd"]), ("_at_1e-3", 1e-3)):
                T = r.param("ramp_transits") * h / c_d + U_end / (v * c_d)
                row[f"est_steps_per_run{suffix}"] = T / m["dt"]
                row[f"est_run_s{suffix}"] = row["setup_s"] + per_step * T / m["dt"]
        rows.append(row)
    return rows


# ---------------------------------------------------------------------------------------------- outputs
def write_csv(rows: list[dict], path: pathlib.Path) -> None:
    keys = []
    for r in rows:
        keys += [k for k in r if k not in keys]
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        for r in rows:
            w.writerow({k: (f"{v:.6g}" if isinstance(v, float) else v) for k, v in r.items()})
    print(path)


def within_bound(row) -> bool:
    """Completed, the same R-curve as the reference by `metrics.same_rcurve` at the rate and speed tolerance (R
    averaged over crack advance and R_init within 2%, broken rods within 20% or 2, over at least 10 d), and no
    quasi-static warning. The pointwise L2 is reported, not deciding."""
    return (row.get("status") == "completed" and str(row.get("same_rcurve")) == "True"
            and float(row.get("max_kinetic_over_strain", math.inf)) <= KINETIC_WARN)


def pareto_figure(rows, out_dir: pathlib.Path, title: str) -> list[pathlib.Path]:
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8), sharey=True)
    for ax, speed_key, xlabel in ((axes[0], "speedup_wall", "speed-up over `paper` (wall time, same run)"),
                                  (axes[1], "dof_updates_per_s_per_core", "DOF-updates per second per core")):
        for case, marker in zip(dict.fromkeys(r["case"] for r in rows), "os^D"):
            pts = [r for r in rows if r["case"] == case and "R_mean_rel_diff" in r]
            xs = np.array([r[speed_key] for r in pts])
            ys = np.array([max(abs(r["R_mean_rel_diff"]), 1e-4) * 100 for r in pts])
            ax.scatter(xs, ys, marker=marker, label=case, zorder=3)
            # Pareto front: no other point both faster and more accurate; only its points are labelled
            order = np.argsort(-xs)
            front, best = [], math.inf
            for i in order:
                if ys[i] < best:
                    front.append(i)
                    best = ys[i]
            ax.plot(xs[front], ys[front], lw=0.8, alpha=0.6)
            for i in front:
                ax.annotate(pts[i]["variant"], (xs[i], ys[i]), fontsize=6.5, xytext=(3, 3 if marker == "o" else -9),
                            textcoords="offset points")
        ax.axhline(ERROR_BOUND * 100, color="k", ls="--", lw=0.8, label=f"error bound {ERROR_BOUND:.0%}")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel(xlabel)
        ax.grid(True, which="both", alpha=0.3)
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    axes[0].set_ylabel("|R averaged over the advance| difference from `paper` (%)\n(reference itself drawn at 0.01%)")
    axes[0].legend(fontsize=7, loc="upper left")
    fig.suptitle(title, fontsize=10)
    return plotting.save_to(fig, out_dir, "pareto")


def cost_figure(rows, out_dir: pathlib.Path, title: str) -> list[pathlib.Path]:
    fig, axes = plt.subplots(1, 2, figsize=(12, 4.8))
    ok = [r for r in rows if r.get("status") == "completed"]
    for integ, color in (("lumped", "C0"), ("paper", "C1")):
        for he, marker in ((0.3, "o"), (0.2, "s"), (0.15, "^")):
            pts = sorted([r for r in ok if r["integrator"] == integ and abs(r["h_e"] - he) < 1e-9],
                         key=lambda r: r["dof"])
            if not pts:
                continue
            dof = np.array([r["dof"] for r in pts])
            label = f"{integ}, h_e = {he} d"
            axes[0].loglog(dof, [r["s_per_step"] for r in pts], marker=marker, color=color,
                           ls="-" if he == 0.3 else "none", label=label)
            if "est_run_s" in pts[0]:
                axes[1].loglog(dof, [r["est_run_s"] / 3600 for r in pts], marker=marker, color=color,
                               ls="-" if he == 0.3 else "none", label=label)
            if "est_run_s_at_1e-3" in pts[0] and he == 0.3:
                axes[1].loglog(dof, [r["est_run_s_at_1e-3"] / 3600 for r in pts], marker=marker, color=color,
                               ls="--", mfc="none", label=f"{integ}, at v_app = 1e-3 c_d (paper preset rate)")
                last = pts[-1]
                axes[1].annotate(f"{last['est_run_s_at_1e-3'] / 3600:.3g} h", (last["dof"],
                                 last["est_run_s_at_1e-3"] / 3600), fontsize=7, xytext=(-30, 6),
                                 textcoords="offset points", color=color)
        size = sorted([r for r in ok if r["integrator"] == integ and abs(r["h_e"] - 0.3) < 1e-9],
                      key=lambda r: r["dof"])
        if len(size) >= 2:
            slope = np.polyfit(np.log([r["dof"] for r in size]), np.log([r["s_per_step"] for r in size]), 1)[0]
            axes[0].text(0.97, 0.10 - 0.06 * (integ == "paper"), f"{integ}: time/step ~ DOF^{slope:.2f}",
                         transform=axes[0].transAxes, color=color, fontsize=8, ha="right")
    axes[0].set_xlabel("DOF")
    axes[0].set_ylabel("wall time per step (s), 1 thread")
    axes[1].set_xlabel("DOF")
    axes[1].set_ylabel("estimated wall time of one run (h), 1 thread")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7, loc="upper left")
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
    fig.suptitle(title, fontsize=10)
    return plotting.save_to(fig, out_dir, "cost_growth")


def fmt(v, spec=".3g"):
    return "n/a" if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, spec)


def summary_markdown(rows, crows, header: dict) -> str:
    L = [f"# Bench results ({header['date']}, G = {header['G']:g})", "",
         f"Machine: {header['machine']}. Solver {header['git']}. Preset `{header['preset']}`, "
         f"G = {G_KEY} = {header['G']:g} ({header['G_source']}); "
         f"{header['jobs']} runs at a time; this sitting {header['total_min']:.0f} min. {header.get('sittings', '')} "
         f"Reference: `{REFERENCE}` at the preset's rate (the slowest measured). "
         f"Bound: the same R-curve as the reference (`enamel_results.metrics.same_rcurve`: R averaged over crack "
         f"advance over (0,30] d or the common range of at least {metrics.MIN_RANGE_OVER_D:g} d, and R_init, within "
         f"{metrics.TOL_RATE_SPEED:.0%}; broken rods within 20% or 2) and kinetic/strain energy <= {KINETIC_WARN} "
         f"while the crack grows (no quasi-static warning). The pointwise L2 is reported, not deciding.", ""]
    for case in dict.fromkeys(r["case"] for r in rows):
        pts = [r for r in rows if r["case"] == case]
        ok = [r for r in pts if within_bound(r) and r["variant"] != REFERENCE]
        best = max(ok, key=lambda r: r["speedup_wall"]) if ok else None
        L += [f"## {case}", ""]
        if best:
            L += [f"Fastest within the bound: **{best['variant']}**, {best['speedup_wall']:.1f}x faster than "
                  f"`{REFERENCE}` by wall time ({best['speedup_cpu']:.1f}x by CPU time), R mean "
                  f"{best['R_mean_rel_diff']:+.2%} over (0,{best['R_mean_range']:.1f}] d, R-curve L2 "
                  f"{best['rcurve_rel_l2']:.2%}.", ""]
        else:
            L += ["No fast variant within the bound (the same R-curve and no quasi-static warning).", ""]
        L += ["| variant | wall s | CPU s | steps | DOF-upd/s/core | MB | speed-up | R mean diff | R-curve L2 | R_init diff "
              "| R_ss diff | broken rods (diff) | KE/SE max | status |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in pts:
            if "rcurve_rel_l2" not in r:
                L.append(f"| {r['variant']} | {fmt(r['wall_s'], '.0f')} | | | | | | | | | | | | {r.get('status')} |")
                continue
            L.append(f"| {r['variant']} | {r['wall_s']:.0f} | {r['cpu_s']:.0f} | {r['steps']} | "
                     f"{r['dof_updates_per_s_per_core'] / 1e6:.1f} M | {r['peak_memory_mb']:.0f} | "
                     f"{r['speedup_wall']:.1f} | {fmt(r['R_mean_rel_diff'] * 100, '+.2f')}% | {r['rcurve_rel_l2']:.2%} | "
                     f"{r['R_init_rel_diff']:+.1%} | "
                     f"{r['R_ss_rel_diff']:+.1%} | {r['broken_rods']} ({r['broken_rods_diff']:+d}) | "
                     f"{fmt(r['max_kinetic_over_strain'])} | {r['status']} |")
        L.append("")
    if crows:
        L += ["## Cost growth (1 thread, the theta_D = 30 case)", "",
              "| integrator | w_s x h_s (d) | h_e (d) | DOF | dt | s/step | DOF-upd/s | set-up s | MB "
              "| est. steps/run | est. h/run | est. h/run at v_app = 1e-3 c_d |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for r in crows:
            if r.get("status") != "completed":
                L.append(f"| {r['integrator']} | | | | | | | | | | {r.get('status')} |")
                continue
            L.append(f"| {r['integrator']} | {r['w_s']:.0f} x {r['h_s']:.0f} | {r['h_e']} | {r['dof']} | "
                     f"{r['dt']:.3g} | {r['s_per_step']:.3g} | {r['dof_updates_per_s'] / 1e6:.1f} M | "
                     f"{r['setup_s']:.1f} | {r['peak_memory_mb']:.0f} | {fmt(r.get('est_steps_per_run'), '.3g')} | "
                     f"{fmt(r.get('est_run_s', math.nan) / 3600, '.3g')} | "
                     f"{fmt(r.get('est_run_s_at_1e-3', math.nan) / 3600, '.3g')} |")
        L.append("")
        L.append(header.get("cost_note", ""))
    return "\n".join(L) + "\n"


def read_csv(path: pathlib.Path) -> list[dict]:
    def value(v):
        try:
            return int(v)
        except ValueError:
            try:
                return float(v)
            except ValueError:
                return v
    with open(path) as f:
        return [{k: value(v) for k, v in row.items() if v != ""} for row in csv.DictReader(f)]


def replot(out: pathlib.Path) -> int:
    """The figures again from the CSV files of a finished bench (drawing only; the numbers are not touched)."""
    rows = read_csv(out / "results.csv")
    cost = out / "cost_growth.csv"
    crows = read_csv(cost) if cost.exists() else []
    first = (out / "results.md").read_text().splitlines()[0] if (out / "results.md").exists() else ""
    title = f"enamel-dem bench {first.removeprefix('# Bench results').strip()}"
    pareto_figure(rows, out / "out", title)
    if crows:
        cost_figure(crows, out / "out", title)
    return 0


def parser() -> argparse.ArgumentParser:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--jobs", type=int, default=2, help="cores to use: runs at a time (default 2)")
    ap.add_argument("--out", type=pathlib.Path, default=bench.HERE,
                    help=f"where results.csv, cost_growth.csv, results.md and out/ go (default {bench.HERE})")
    ap.add_argument("--runs", type=pathlib.Path, default=bench.RUNS,
                    help=f"where the runs go (default {bench.RUNS})")
    ap.add_argument("--quick", action="store_true",
                    help="a small smoke run (tests): tiny specimens at the ci preset, 3 variants, 2 cost sizes")
    ap.add_argument("--skip-cost", action="store_true", help="only the speed-against-error part")
    ap.add_argument("--G", type=float, default=None,
                    help=f"the interface fracture energy {G_KEY} of every speed-against-error and cost run "
                         "(default: the solver's default, from `enamel-dem keys`)")
    ap.add_argument("--cases", nargs="+", choices=CASES, help="only these cases (default: all)")
    ap.add_argument("--variants", nargs="+", choices=list(VARIANTS),
                    help=f"only these variants (default: all; `{REFERENCE}` is always run: it is the reference)")
    ap.add_argument("--fresh", action="store_true",
                    help="delete this bench's runs first and run them all again (default: runs done by the same "
                         "command and solver binary are kept, stopped ones continue)")
    ap.add_argument("--profile-only", action="store_true",
                    help="only the step profile (bench/profile.md): a few minutes")
    ap.add_argument("--replot", action="store_true",
                    help="run nothing: redraw the figures from OUT/results.csv and OUT/cost_growth.csv")
    return ap


def main(argv=None) -> int:
    a = parser().parse_args(argv)
    sys.stdout.reconfigure(line_buffering=True)   # progress lines reach a log file as they happen
    if a.replot:
        return replot(a.out)
    if not solver().exists():
        print(f"run_bench.py: solver binary {solver()} not found: run `make build`", file=sys.stderr)
        return 2
    global PRESET, BENCH_PHYSICS
    BENCH_PHYSICS = bench_physics(a.G)
    g_source = "set by --G" if a.G is not None else "the solver's default, `enamel-dem keys`"
    variants, cases, sizes, extra = VARIANTS, CASES, COST_SIZES, {}
    if a.cases:
        cases = a.cases
    if a.variants:
        variants = {k: VARIANTS[k] for k in VARIANTS if k == REFERENCE or k in a.variants}
    if a.quick:
        PRESET = "ci"
        variants = {k: VARIANTS[k] for k in ("paper", "lumped", "lumped rate2")}
        cases = CASES[:1]
        sizes = [(8, 4, 0.3), (12, 6, 0.3)]
        extra = {"w_s_over_d": 8, "h_s_over_d": 4, "stop_da_over_d": 1}
    t0 = time.perf_counter()
    date = datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    a.out.mkdir(parents=True, exist_ok=True)
    profile_preset, profile_extra = ("ci", {"w_s_over_d": 8, "h_s_over_d": 4}) if a.quick else ("paper", {})
    profile_md = (f"# Step profile ({date}; {machine()}; `enamel-dem profile`, preset `{profile_preset}`, "
                  f"{PROFILE_CASE}, lumped dt 0.22 cap 0.5)\n\n"
                  + profile_markdown(profile_preset, extra_sets=profile_extra))
    (a.out / "profile.md").write_text(profile_md.rstrip("\n") + "\n\n" + GENERATED_BY + "\n")
    print(a.out / "profile.md")
    if a.profile_only:
        return 0
    if a.fresh:
        for sub in (*CASES, "cost"):   # this bench's runs only: runs/bench/ also holds bench-paper's and bench-converged's
            shutil.rmtree(a.runs / sub, ignore_errors=True)
    try:
        return measure(a, cases, variants, sizes, extra, t0, date, g_source, profile_md)
    except KeyboardInterrupt as e:
        print(f"run_bench.py: {e or 'stopped'}", file=sys.stderr)
        return 130


def measure(a, cases, variants, sizes, extra, t0, date, g_source, profile_md) -> int:
    """The runs (those not done yet), then the tables, the figures and the report."""
    jobs = speed_error_jobs(cases, variants, PRESET, a.runs, extra)
    run_pieces(jobs, a.jobs)
    rows = speed_error_rows(jobs)
    a.out.mkdir(parents=True, exist_ok=True)
    write_csv(rows, a.out / "results.csv")

    crows, cjobs, cost_note = [], [], ""
    if not a.skip_cost:
        ref = next((r for r in rows if r["variant"] == REFERENCE and r.get("status") == "completed"), None)
        run_model = {}
        if ref:
            rr = results.load_result(a.runs / ref["case"] / REFERENCE / "result.h5")
            run_model = dict(U_end=ref["U_end"], h_s=rr.param("h_s_over_d"),
                             v_app_over_cd=rr.param("v_app_over_cd") * rr.param("rate_factor"))
        cjobs = cost_jobs(a.runs, sizes, ("lumped", "paper"), {"stop_da_over_d": 1e3} if not a.quick else {})
        run_pieces(cjobs, 1)   # one at a time: time per step without a neighbour on the other core
        crows = cost_rows(cjobs, run_model)
        write_csv(crows, a.out / "cost_growth.csv")
        cost_note = ("Estimated steps per run = T_run/dt, T_run = ramp + U_end/v_app, U_end = U_end of the "
                     f"`{REFERENCE}` run of {CASES[0]} at `{PRESET}` x sqrt(h_s/h_s,{PRESET}), at the "
                     f"`{PRESET}` rate; the `paper` preset's rate is 1e-3 c_d (x{run_model.get('v_app_over_cd', 0) / 1e-3:.2g} "
                     "more steps) and its crack goes 30 d instead of 12 d (more again): see the README.")
    ref_h5 = next((j.out / "result.h5" for j in jobs if j.variant == REFERENCE), None)
    solver_hash = results.load_result(ref_h5).meta["git_hash"] if ref_h5 and ref_h5.exists() else "unknown"
    header = dict(date=date, machine=machine(), git=solver_hash, preset=PRESET, jobs=a.jobs,
                  G=BENCH_PHYSICS[G_KEY], G_source=g_source,
                  total_min=(time.perf_counter() - t0) / 60, cost_note=cost_note,
                  sittings=sittings_note(jobs + cjobs))
    title = (f"enamel-dem bench, preset {PRESET}, G = {header['G']:g}, {header['date']}, "
             f"{header['machine'].split(',')[0]}")
    pareto_figure(rows, a.out / "out", title)
    if crows:
        cost_figure(crows, a.out / "out", title)
    md = a.out / "results.md"
    md.write_text(summary_markdown(rows, crows, header) + "\n"
                  + profile_md.replace("# Step profile", "## Step profile", 1).rstrip("\n") + "\n\n" + GENERATED_BY + "\n")
    print(md)
    bad = [r for r in rows if r.get("exit_code") != 0]
    for r in bad:
        print(f"run_bench.py: {r['case']} / {r['variant']} exited {r['exit_code']}: see its bench.log",
              file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
