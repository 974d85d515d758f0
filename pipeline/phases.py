"""One case over N evenly spaced phases of the crisscross lattice at the pre-crack tip, and its phase-averaged
R-curve (docs/results.md, "Phase-averaged R-curves").

    python3 -m pipeline.phases paper_cases/theta30_s21.4_e10_cv0.toml --preset converged --phases 4 --jobs 2
    python3 -m pipeline.phases CASE.toml --preset ci --phases 4 --set Gamma_k_over_sigma0sq=8
    python3 -m pipeline.phases CASE.toml --preset ci --phases 4 --report-only

Phase k of N runs the case with `crisscross_phase = k/N` (the tip's place in the crisscross lattice, in units of
the crisscross spacing d/sin(theta_D): docs/model.md) into RUNS/<preset>/<case>[__<sets>]/phase_<k>of<N>/. The
same command again reruns nothing that completed and continues an unfinished run from its checkpoint (the
solver's --resume). The report goes next to the runs: phase_average.md (each phase's R_init, means and first rod
break, and the average with its spread), phase_average.csv (R at equal crack advance: mean, low, high and each
phase) and phase_average.png. Exit status 0 when every phase completed, 1 otherwise (the report then covers the
phases that completed, and says which did not).
"""
from __future__ import annotations

import argparse
import concurrent.futures
import csv
import math
import os
import pathlib
import subprocess
import sys

from enamel_results import metrics, paths, results

RUNS = paths.RUNS / "phases"
PHASE_KEY = "crisscross_phase"


def set_tag(sets: list[str]) -> str:
    """The folder suffix of --set overrides, as the Makefile's RUN_SET folders name them."""
    return "_".join(s.replace("=", "-").replace('"', "").replace("'", "").replace("/", "-") for s in sets)


def run_root(runs: pathlib.Path, preset: str, case: pathlib.Path, sets: list[str]) -> pathlib.Path:
    tag = set_tag(sets)
    return runs / preset / (case.stem + (f"__{tag}" if tag else ""))


def phase_dir(root: pathlib.Path, k: int, n: int) -> pathlib.Path:
    return root / f"phase_{k}of{n}"


def solver_args(binary, case, preset: str, sets: list[str], k: int, n: int, out: pathlib.Path) -> list[str]:
    args = [str(binary), "run", str(case), "--preset", preset, "--out", str(out), "--resume", "--quiet",
            "--checkpoint-every", "60"]
    for s in [*sets, f"{PHASE_KEY}={k / n!r}"]:
        args += ["--set", s]
    return args


def run_phase(args: list[str], out: pathlib.Path) -> int:
    """One phase's run, unless it completed already; its stderr appended to out/log.txt. Returns its status."""
    if (out / paths.RESULT_NAMES["completed"]).is_file():
        return 0
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "log.txt", "a") as log:
        return subprocess.run(args, stdout=subprocess.DEVNULL, stderr=log).returncode


def run_all(binary, case, preset, sets, n, root, jobs) -> dict[int, int]:
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {k: pool.submit(run_phase, solver_args(binary, case, preset, sets, k, n, phase_dir(root, k, n)),
                                  phase_dir(root, k, n)) for k in range(n)}
        return {k: f.result() for k, f in futures.items()}


def load_phases(root: pathlib.Path, n: int) -> dict[int, results.Result]:
    """The completed phases' results, by phase index."""
    done = {}
    for k in range(n):
        p = phase_dir(root, k, n) / paths.RESULT_NAMES["completed"]
        if p.is_file():
            done[k] = results.load_result(p)
    return done


def phase_rows(done: dict[int, results.Result], n: int) -> list[dict]:
    rows = []
    for k, r in sorted(done.items()):
        c = metrics.rcurve_of(r)
        rows.append(dict(phase=f"{k}/{n}", R_init=float(r.R[0]), mean_0_30=metrics.advance_mean(c, 0, 30),
                         mean_5_25=metrics.advance_mean(c, 5, 25), first_break=r.da_first_rod_fracture,
                         rods=r.broken_rods, da_max=r.da_max))
    return rows


def average_row(avg: metrics.PhaseAverage) -> dict:
    c = avg.curve
    return dict(phase="average", R_init=float(c.R[0]), mean_0_30=metrics.advance_mean(c, 0, 30),
                mean_5_25=metrics.advance_mean(c, 5, 25), first_break=math.nan, rods=c.broken_rods,
                da_max=float(c.da[-1]))


def report_text(case: str, preset: str, sets: list[str], n: int, rows: list[dict], missing: list[int]) -> str:
    fmt = lambda x: "-" if x is None or (isinstance(x, float) and math.isnan(x)) else (  # noqa: E731
        f"{x:.3f}" if isinstance(x, float) else str(x))
    lines = [f"# {case}: phase-averaged R-curve ({n} phases, preset {preset})", "",
             f"Written by `python3 -m pipeline.phases` from the runs next to this file; phase k runs "
             f"`{PHASE_KEY} = k/{n}`" + (f", with {' '.join('--set ' + s for s in sets)}" if sets else "") + ".",
             "The average is R at equal crack advance over the completed phases (enamel_results.metrics."
             "phase_average), over the range every phase covers.", "",
             "| phase | R_init | mean R (0,30] d | mean R (5,25] d | first rod break (d) | broken rods | Delta_a reached (d) |",
             "|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append("| " + " | ".join(fmt(r[k]) for k in ("phase", "R_init", "mean_0_30", "mean_5_25",
                                                             "first_break", "rods", "da_max")) + " |")
    phases = [r for r in rows if r["phase"] != "average"]
    if len(phases) >= 2:
        for key, label in (("mean_0_30", "mean R over (0,30] d"), ("R_init", "R_init")):
            vals = [r[key] for r in phases]
            mid = sum(vals) / len(vals)
            lines.append(f"\nSpread of the phases' {label}: {min(vals):.3f} to {max(vals):.3f} "
                         f"({(max(vals) - min(vals)) / mid:+.1%} of their mean {mid:.3f}).")
    if missing:
        lines.append(f"\n**Not completed**: phase(s) {', '.join(f'{k}/{n}' for k in missing)}; the average is over "
                     "the others.")
    return "\n".join(lines) + "\n"


def write_csv(path: pathlib.Path, avg: metrics.PhaseAverage, labels: list[str]) -> None:
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["da_over_d", "R_mean", "R_low", "R_high", *[f"R_phase_{s}" for s in labels]])
        for i, da in enumerate(avg.curve.da):
            w.writerow([f"{da:.6g}", f"{avg.curve.R[i]:.6g}", f"{avg.low[i]:.6g}", f"{avg.high[i]:.6g}",
                        *[f"{avg.each[j, i]:.6g}" for j in range(len(labels))]])


def plot(path: pathlib.Path, avg: metrics.PhaseAverage, labels: list[str], title: str) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    da = avg.curve.da
    ax.fill_between(da, avg.low, avg.high, color="0.85", label="phases' range")
    for j, s in enumerate(labels):
        ax.plot(da, avg.each[j], lw=0.7, label=f"phase {s}")
    ax.plot(da, avg.curve.R, color="k", lw=2, label="average")
    ax.set_xlabel("crack advance Delta_a / d")
    ax.set_ylabel("R / Gamma_i")
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def report(root: pathlib.Path, case: pathlib.Path, preset: str, sets: list[str], n: int) -> str:
    done = load_phases(root, n)
    missing = [k for k in range(n) if k not in done]
    rows = phase_rows(done, n)
    if len(done) >= 2:
        labels = [f"{k}/{n}" for k in sorted(done)]
        avg = metrics.phase_average([metrics.rcurve_of(done[k]) for k in sorted(done)])
        rows.append(average_row(avg))
        write_csv(root / "phase_average.csv", avg, labels)
        plot(root / "phase_average.png", avg, labels, f"{case.stem}, preset {preset}, {n} phases")
    text = report_text(case.stem, preset, sets, n, rows, missing)
    (root / "phase_average.md").write_text(text)
    return text


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(prog="python3 -m pipeline.phases", description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("case", type=pathlib.Path, help="case file (TOML)")
    ap.add_argument("--preset", default="reduced", help="solver preset (default reduced)")
    ap.add_argument("--phases", type=int, default=4, help="N evenly spaced phases k/N, k = 0..N-1 (default 4)")
    ap.add_argument("--set", dest="sets", action="append", default=[], metavar="KEY=VALUE",
                    help="a key override on every phase's run (repeatable)")
    ap.add_argument("--jobs", type=int, default=1, help="phases run at once (default 1)")
    ap.add_argument("--runs", type=pathlib.Path, default=RUNS, help=f"root of the runs (default {RUNS})")
    ap.add_argument("--binary", default=os.environ.get("ENAMEL_BINARY", str(paths.SOLVER)),
                    help="the solver (default $ENAMEL_BINARY, else build/enamel-dem)")
    ap.add_argument("--report-only", action="store_true", help="no runs: the report from the runs there are")
    a = ap.parse_args(argv)
    if not 2 <= a.phases <= 64:
        ap.error(f"--phases = {a.phases}: allowed range [2, 64]")
    if any(s.split("=", 1)[0].strip() == PHASE_KEY for s in a.sets):
        ap.error(f"--set {PHASE_KEY}=...: the phases set it; give --phases instead")
    if not a.case.is_file():
        ap.error(f"case file {a.case} not found")
    root = run_root(a.runs, a.preset, a.case, a.sets)
    status = {} if a.report_only else run_all(a.binary, a.case, a.preset, a.sets, a.phases, root, a.jobs)
    root.mkdir(parents=True, exist_ok=True)
    print(report(root, a.case, a.preset, a.sets, a.phases), end="")
    failed = [k for k, rc in status.items() if rc != 0]
    for k in failed:
        print(f"phases: phase {k}/{a.phases} exited with status {status[k]} "
              f"(log: {phase_dir(root, k, a.phases) / 'log.txt'})", file=sys.stderr)
    return 1 if failed or len(load_phases(root, a.phases)) < a.phases else 0


if __name__ == "__main__":
    sys.exit(main())
