#!/usr/bin/env python3
"""`make bench-paper`: one `paper`-preset case run to Delta_a/d = 30 with the fastest scheme that stays within
the bench's error bound at this size, its time and R-curve reported.

The case is the bench's first (Fig. 4's theta_D = 30, sigma_ru/sigma0 = 21.4, Er/kd = 10) at the `paper`
preset (200 d x 200 d, h_e = 0.3 d, 1.39 M DOF, v_app = 1e-3 c_d, stop at Delta_a = 30 d), integrator
`lumped` with dt_factor 0.22 and damping_cap 0.5, started from the static elastic solution at 0.95 of the
first-damage displacement, at the preset's loading rate (VARIANT below: twice the rate gave the same R-curve at
100 x 100 d by `enamel_results.metrics.same_rcurve`, but not at this size), on 2 threads. It takes hours, so it
is resumable: Ctrl-C (or SIGTERM) writes a checkpoint and stops; the same command again continues from it (the
result is the same, bit for bit at the same thread count). A checkpoint is also written every
--checkpoint-every seconds.

Then it writes bench/paper_preset.md (committed: the README quotes it) and bench/out/paper_preset.{pdf,png}:
the R-curve against the same case at the `reduced` size (the `paper` scheme and the same fast scheme, from
`make bench`, when their runs are there) and the paper's value, and the process zone at the last frame.
An unfinished run is reported as such (how far it got, how long it took so far). The report also says:
- the run against the goal of Delta_a = 30 d in at most 15 min of stepping on 2 cores (GOAL_STEPPING_S): met or
  not, and how many of its steps fit in 15 min at its own mean rate of steps;
- whether its R-curve is the same as that of the committed record of this case at this size (--against, default
  AGAINST: a run at the default model; the record names its solver commit), by
  `enamel_results.metrics.same_rcurve` at the speed tolerance: what a faster variant (--set) must keep.
A variant's --set overrides name its run's folder (RUNS/CASE__<sets>); a folder that holds a run of another
command (its log's first line) is refused with a message naming both, and nothing in it is touched.
"""
import argparse
import datetime
import math
import pathlib
import signal
import subprocess
import sys


import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

import bench  # noqa: E402
from bench import run_bench  # noqa: E402
from bench import records  # noqa: E402
from enamel_results import metrics, paper_values, paths, records as run_records, results  # noqa: E402
from figures import plotting  # noqa: E402
from pipeline.phases import set_tag  # noqa: E402

CASE = run_bench.CASES[0]
# The preset's loading rate, from the static start. Twice the rate was the fastest loading within the bound at
# 100 x 100 d and G = 3 (judged by metrics.same_rcurve: R averaged over (0,30] d +0.7%), but at the paper's size
# and G = 10 it is not: against this variant R over (0,30] d -11.6%, R_init +0.9%, 30 / 31 rods (docs/results.md).
# It takes about twice the steps (345 k).
VARIANT = "lumped cap0.5 dt0.22 static"
PRESET = "paper"
EXTRA_SETS = {}                    # --quick: a tiny specimen at the ci preset (tests); and --set
USER_SETS = []                     # --set KEY=VALUE as given: they name the run's folder
RUNS = bench.PAPER_PRESET_RUNS    # --runs
OUT = bench.HERE                  # --out: paper_preset.md and out/paper_preset.{pdf,png}
GOAL_DA, GOAL_STEPPING_S = 30.0, 15 * 60.0   # Delta_a = 30 d in at most this much stepping, on 2 cores
# The committed record of this case at this size (python3 -m pipeline.records write of a run at the default model,
# G = 9, cut tip, 1.23 h on 2 cores; its /meta names the solver commit): what a faster variant is
# judged by.
AGAINST = bench.HERE / "paper_preset_record.json"


def run_dir() -> pathlib.Path:
    """RUNS/CASE, or RUNS/CASE__<the --set overrides> (as the pipeline names a RUN_SET folder): a variant's own."""
    tag = set_tag(USER_SETS)
    return RUNS / (CASE + (f"__{tag}" if tag else ""))


def solver_command(threads: int, checkpoint_every: float) -> list:
    out = run_dir()
    sets, _ = run_bench.VARIANTS[VARIANT]
    # not --quiet: progress lines (with an ETA) go to the terminal and the log
    flags = ["--checkpoint-every", str(checkpoint_every), "--force", "--resume"]
    return run_bench.run_args(paths.case_file(CASE), PRESET, {**sets, **EXTRA_SETS}, threads, out, flags)


def result_file(out: pathlib.Path) -> pathlib.Path:
    """The run's result: result.h5 once completed, else the partial (running, interrupted) or failed one."""
    return paths.run_result(out) or out / paths.RESULT_NAMES["completed"]


def run(threads: int, checkpoint_every: float) -> int:
    """Run the case, or continue it from its checkpoint; progress to the terminal and to DIR/log.txt."""
    out = run_dir()
    out.mkdir(parents=True, exist_ok=True)
    result = out / "result.h5"
    cmd = solver_command(threads, checkpoint_every)
    first = next(iter(log_commands(out)), None)
    if first is not None and first != " ".join(cmd) and (result.exists() or (out / "checkpoint.bin").exists()):
        print(f"paper_preset.py: {out} holds a run of another command ({first}); this one is {' '.join(cmd)}: "
              "pass --runs DIR for a folder of its own, or delete that one", file=sys.stderr)
        return 2
    if result.exists():
        try:
            status = results.load_result(result, case=CASE).status
        except (OSError, KeyError):
            status = "unreadable"
        if status == "completed":
            print(f"paper_preset.py: {result} is complete; reporting it (delete it to run again)")
            return 0
    restart = (out / "checkpoint.bin").exists()
    # Ctrl-C or SIGTERM: passed on to the solver (which writes its checkpoint and stops), never raised here, so
    # every line it writes up to its exit reaches the log.
    children = []
    forward = lambda signum, frame: [c.send_signal(signum) for c in children]  # noqa: E731
    previous = {s: signal.signal(s, forward) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        with open(out / "log.txt", "a") as log:
            log.write(f"# {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC: {' '.join(cmd)}\n")
            log.flush()
            print(("continuing from the checkpoint: " if restart else "") + " ".join(cmd), flush=True)
            proc = subprocess.Popen(cmd, stderr=subprocess.PIPE, text=True, bufsize=1)
            children.append(proc)
            for line in proc.stderr:
                sys.stderr.write(line)
                log.write(line)
                log.flush()
            rc = proc.wait()
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)
    if rc != 0:
        print(f"paper_preset.py: the solver exited {rc}; run `make bench-paper` again to continue from the "
              f"last checkpoint ({out / 'checkpoint.bin'})", file=sys.stderr)
    return rc


def bench_row(variant: str) -> dict:
    """The bench's row for this case and variant (bench/results.csv), or {}."""
    try:
        rows = run_bench.read_csv(bench.HERE / "results.csv")
    except OSError:
        return {}
    return next((r for r in rows if r["case"] == CASE and r["variant"] == variant), {})


def reduced_results() -> dict:
    """{label: Result} of this case at the `reduced` size from `make bench`'s runs, where they are."""
    out = {}
    for variant in (run_bench.REFERENCE, VARIANT):
        p = run_bench.variant_dir(bench.RUNS, CASE, variant) / "result.h5"
        try:
            out[f"reduced 40 d x 20 d, {variant}"] = results.load_result(p, case=CASE)
        except (results.MissingResult, OSError):
            pass
    return out


def cost_estimate_steps(r: results.Result) -> float:
    """The cost-growth table's step estimate for the paper-preset size at the paper rate, rescaled to this
    run's dt (the table's runs use the bench's dt_factor 0.1)."""
    try:
        rows = run_bench.read_csv(bench.HERE / "cost_growth.csv")
    except OSError:
        return math.nan
    row = next((c for c in rows if c.get("integrator") == "lumped" and c.get("w_s") == r.param("w_s_over_d")
                and c.get("h_s") == r.param("h_s_over_d") and c.get("h_e") == r.param("h_e_over_d")), None)
    return row["est_steps_per_run_at_1e-3"] * row["dt"] / r.meta["dt"] if row else math.nan


def goal_line(r: results.Result, steps: int, wall: float, threads: int) -> str:
    """The run against the goal: Delta_a = 30 d in at most GOAL_STEPPING_S of stepping on 2 cores."""
    met = r.completed and r.da_max >= GOAL_DA and wall <= GOAL_STEPPING_S and threads <= 2
    fit = steps / wall * GOAL_STEPPING_S
    return (f"- against the goal (Delta_a = {GOAL_DA:g} d in at most {GOAL_STEPPING_S / 60:g} min of stepping on 2 cores): "
            f"**{'met' if met else 'not met'}**, {wall / 60:.0f} min ({wall / GOAL_STEPPING_S:.2f}x the goal); at its "
            f"mean {steps / wall:.1f} steps/s, {GOAL_STEPPING_S / 60:g} min hold {fit:,.0f} of its {steps:,} steps")


def against_line(r: results.Result, record: pathlib.Path) -> str:
    """This run's R-curve against a committed record of the case (the reference) by metrics.same_rcurve at the
    speed tolerance, or why it cannot be compared."""
    try:
        ref = run_records.load(record, case=CASE)
    except (results.MissingResult, run_records.MalformedRecord) as e:
        return f"- against the record {record}: none to compare with ({e})"
    if ref.da.size < 2 or r.da.size < 2:
        return f"- against the record {record}: no R-curve to compare"
    c = metrics.same_rcurve(metrics.rcurve_of(ref), metrics.rcurve_of(r), metrics.TOL_RATE_SPEED)
    head = (f"- against the committed record `{record.name}` (solver {ref.meta.get('git_hash', '?')}, the reference; "
            f"`enamel_results.metrics.same_rcurve` at {metrics.TOL_RATE_SPEED:.0%}): ")
    if not c.comparable:
        return head + (f"not comparable (the common range (0, {c.hi:.1f}] d is shorter than "
                       f"{metrics.MIN_RANGE_OVER_D:g} d)")
    return head + (f"the same R-curve: **{c.same}** (R mean over (0, {c.hi:.1f}] d {c.mean_a:.4g} / {c.mean_b:.4g}, "
                   f"{c.mean_rel:+.2%}; R_init {c.init_rel:+.2%}; broken rods {c.rods_a} / {c.rods_b}; pointwise L2 "
                   f"{c.l2:.2%}, not deciding)")


def figure(r: results.Result, reduced: dict, title: str) -> list[pathlib.Path]:
    fig, (ax, *maps) = plt.subplots(1, 4, figsize=(17, 4.6), gridspec_kw=dict(width_ratios=[1.3, 1, 1, 1]),
                                   layout="constrained")
    size = f"{r.param('w_s_over_d'):g} d x {r.param('h_s_over_d'):g} d"
    plotting.draw_rcurve(ax, r, label=f"{PRESET} preset {size}, {VARIANT}", color="C3")
    for (label, rr), color in zip(reduced.items(), ("k", "C0")):
        plotting.draw_rcurve(ax, rr, label=label, color=color, markersize=1.5, linewidth=0.9)
    stated = paper_values.values_for_case(CASE)
    plotting.draw_paper_values(ax, [v for v in stated if v["quantity"] == "R_ss_over_Gamma"])
    plotting.format_rcurve_axes(ax, f"{plotting.case_label(r)}{plotting.status_flag(r)}")
    ax.legend(fontsize=7, loc="lower right")
    if not r.frames:   # no frame written yet: the R-curve alone
        for axm in maps:
            axm.set_axis_off()
        maps[1].text(0.5, 0.5, "no process-zone frame yet", ha="center", transform=maps[1].transAxes)
    frame = r.frames[-1] if r.frames else None
    a = r.geometry.attrs
    x0, yc = float(a["a0"]), float(a["y_crack_plane"])
    for axm, (name, tag, ply) in zip(maps if frame else [], plotting.MAP_PANELS):
        plotting.draw_process_zone(axm, r, frame, tag, ply, title=f"{name} at $\\Delta a/d$ = {frame.da:.1f}")
        # the crack-tip region (the specimen is 200 d), within the specimen
        x_lo, x_hi = max(0.0, x0 - 5), min(float(a["w_s"]), x0 + max(35.0, frame.da + 10))
        half = 0.5 * (x_hi - x_lo)
        axm.set_xlim(x_lo, x_hi)
        axm.set_ylim(max(0.0, yc - half), min(float(a["h_s"]), yc + half))
    if frame:
        maps[-1].legend(handles=plotting.map_legend_handles(), fontsize=6.5, loc="lower right")
    fig.suptitle(title, fontsize=10)
    return plotting.save_to(fig, OUT / "out", "paper_preset")


def report(against: pathlib.Path = AGAINST) -> int:
    h5 = result_file(run_dir())
    try:
        r = results.load_result(h5, case=CASE, full=True)
    except results.MissingResult:
        print(f"paper_preset.py: no result {h5}: run `make bench-paper` first", file=sys.stderr)
        return results.EXIT_MISSING
    m, end = r.meta, records.history_end(h5)
    reduced = reduced_results()
    row = bench_row(VARIANT)
    steps, wall, threads, dof = int(m["steps"]), float(m["wall_time_s"]), int(m["threads"]), int(m["dof"])
    est = cost_estimate_steps(r)
    date = datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    L = [f"# One `{PRESET}`-preset case (`make bench-paper`, report {date})", "",
         f"Case `{CASE}` at the `{PRESET}` preset ({r.param('w_s_over_d'):g} d x {r.param('h_s_over_d'):g} d, "
         f"h_e = {r.param('h_e_over_d'):g} d, {dof:,} DOF, v_app = {r.param('v_app_over_cd'):g} c_d), "
         f"variant `{VARIANT}`"
         + (" with " + ", ".join(f"`{k}={v}`" for k, v in EXTRA_SETS.items()) if EXTRA_SETS else "")
         + f" ({m['integrator_details']}), {threads} threads. "
         f"Machine: {run_bench.machine()}. Solver {m['git_hash']}.", "",
         f"- status: **{r.status}**" + (f" ({m['stop_reason']})" if m.get("stop_reason") else "") +
         ("" if r.completed else " — not finished: `make bench-paper` continues it"),
         f"- crack advance reached: {r.da_max:.2f} d of {r.param('stop_da_over_d'):g} d",
         f"- wall time of the stepping: **{wall / 3600:.2f} h** ({wall:.0f} s; summed over the run's "
         f"{max(1, len(log_commands(run_dir())))} pieces (starts and continuations), the work redone after a stop between "
         "checkpoints left out; it counts whatever else shared the machine meanwhile)",
         f"- steps: {steps:,} (dt = {m['dt']:.4g} d/c_r); {steps / wall:.1f} steps/s; "
         f"{dof * steps / wall / threads / 1e6:.1f} M DOF-updates/s per core",
         f"- the cost-growth estimate (bench/cost_growth.csv, 200 x 200 d row at 1e-3 c_d, rescaled to this dt): "
         f"{est:,.0f} steps to a 12 d crack" if math.isfinite(est) else "- no cost-growth estimate (run `make bench`)",
         f"- peak memory {m['peak_memory_mb']:.0f} MB; broken rod elements {r.broken_rods}; "
         f"max KE/SE while the crack grows {m['max_kinetic_over_strain_while_growing']:.3g}; "
         f"energy balance error at the end {end['balance_end']:.2e}",
         f"- warnings: {m['warnings'].strip() or 'none'}",
         goal_line(r, steps, wall, threads), against_line(r, against), ""]
    if row:
        L += [f"The variant on the reduced case (bench/results.md): {float(row['speedup_wall']):.1f}x faster than "
              f"`paper`, R-curve L2 {float(row['rcurve_rel_l2']):.2%}.", ""]
    L += ["| run | R_init/Gamma | R_ss/Gamma | R_m/Gamma | Delta_a max (d) | broken rod elements |",
          "|---|---|---|---|---|---|",
          f"| {PRESET} preset, {VARIANT} | {r.R_init:.3g} | {r.R_ss:.3g} | {r.R_m:.3g} | {r.da_max:.3g} | "
          f"{r.broken_rods} |"]
    for label, rr in reduced.items():
        L.append(f"| {label} | {rr.R_init:.3g} | {rr.R_ss:.3g} | {rr.R_m:.3g} | {rr.da_max:.3g} | {rr.broken_rods} |")
    for v in paper_values.values_for_case(CASE):
        if v["quantity"] == "R_ss_over_Gamma":
            L.append(f"| paper (Pro & Barthelat 2020, {v['id']}) | | {paper_values.paper_value_text(v)} | | | |")
    L += ["", "R_ss is the mean R over the last 20% of the crack advance reached and R_m the mean over "
          "0 < Delta_a/d < 30 (README, \"Solver\"), so the two sizes average different ranges.", ""]
    title = f"enamel-dem, one {PRESET}-preset case ({VARIANT}), {date}"
    if EXTRA_SETS:  # a variant's overrides, on a line of their own
        title += "\n" + ", ".join(f"{k}={v}" for k, v in EXTRA_SETS.items())
    figure(r, reduced, title)
    md = OUT / "paper_preset.md"
    md.write_text("\n".join([*L, "<!-- generated by: make bench-paper (bench/paper_preset.py) -->", ""]))
    print(md)
    return 0


def log_commands(out: pathlib.Path) -> list[str]:
    """The solver command of each piece of the run (each start or continuation), from its log's header lines
    (`# DATE UTC: COMMAND`); [] without a log."""
    try:
        return [line.split(" UTC: ", 1)[1].strip() for line in open(out / "log.txt")
                if line.startswith("# ") and " UTC: " in line]
    except OSError:
        return []


def main(argv=None) -> int:
    global PRESET, EXTRA_SETS, USER_SETS, RUNS, OUT
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--threads", type=int, default=2, help="solver threads (default 2; keep it for a restart)")
    ap.add_argument("--checkpoint-every", type=float, default=600.0,
                    help="seconds of wall time between checkpoints (default 600)")
    ap.add_argument("--report", action="store_true", help="run nothing: report the result as it is")
    ap.add_argument("--runs", type=pathlib.Path, default=RUNS, help=f"where the run goes (default {RUNS})")
    ap.add_argument("--out", type=pathlib.Path, default=OUT,
                    help=f"where paper_preset.md and out/paper_preset.png go (default {OUT})")
    ap.add_argument("--quick", action="store_true",
                    help="a small smoke run (tests): an 8 d x 4 d specimen at the ci preset, to Delta_a = 1 d")
    ap.add_argument("--against", type=pathlib.Path, default=AGAINST,
                    help=f"the committed record whose R-curve the run must keep (default {AGAINST})")
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                    help="one more solver override (tests, experiments; a restart needs the same ones)")
    a = ap.parse_args(argv)
    RUNS, OUT = a.runs, a.out
    if a.quick:
        PRESET, EXTRA_SETS = "ci", {"w_s_over_d": 8, "h_s_over_d": 4, "stop_da_over_d": 1}
    for kv in a.set:
        key, eq, value = kv.partition("=")
        if not eq:
            ap.error(f"--set {kv}: expected KEY=VALUE")
        EXTRA_SETS = {**EXTRA_SETS, key: value}
    USER_SETS = list(a.set)
    sys.stdout.reconfigure(line_buffering=True)
    if not a.report:
        if not run_bench.solver().exists():
            print(f"paper_preset.py: solver binary {run_bench.solver()} not found: run `make build`",
                  file=sys.stderr)
            return 2
        rc = run(a.threads, a.checkpoint_every)
        if not result_file(run_dir()).exists():
            return rc
        reported = report(a.against)   # an interrupted or failed run is reported too, and its exit status kept
        return rc or reported
    return report(a.against)


if __name__ == "__main__":
    sys.exit(main())
