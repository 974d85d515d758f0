"""One case over N evenly spaced phases of the crisscross lattice at the pre-crack tip, and its phase-averaged
R-curve (docs/results.md, "Phase-averaged R-curves").

    python3 -m pipeline.phases paper_cases/theta30_s21.4_e10_cv0.toml --preset converged --phases 4 --jobs 2
    python3 -m pipeline.phases CASE.toml --preset ci --phases 4 --set Gamma_k_over_sigma0sq=8
    python3 -m pipeline.phases CASE.toml --preset ci --phases 4 --report-only
    python3 -m pipeline.phases CASE.toml --preset converged --phases 4 --compare rate_factor=0.5 [--tol 0.10]

Phase k of N runs the case with `crisscross_phase = k/N` (the tip's place in the crisscross lattice, in units of
the crisscross spacing d/sin(theta_D): docs/model.md) into RUNS/<preset>/<case>[__<sets>]/phase_<k>of<N>/. The
same command again reruns nothing that completed and continues an unfinished run from its checkpoint (the
solver's --resume). The report goes next to the runs: phase_average.md (each phase's R_init, means and first rod
break, and the average with its spread), phase_average.csv (R at equal crack advance: mean, low, high and each
phase) and phase_average.png. Exit status 0 when every phase completed, 1 otherwise (the report then covers the
phases that completed, and says which did not).

Comparing two settings (docs/results.md, "Phase-averaged R-curves"): --compare KEY=VALUE (repeatable) runs the same
N phases with those overrides on top of the --set ones as setting B, beside the plain setting A, and writes
compare.md next to B's runs: each phase's pair (A, B) and the paired verdict of
enamel_results.metrics.paired_phase_comparison at --tol (default metrics.TOL_RATE_SPEED, 2 %; 0.10 for size and
mesh). Its last line, the verdict, is printed too. With --report-only the comparison reads the runs there are.
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


def run_all(binary, case, preset, settings: list[tuple[list[str], pathlib.Path]], n, jobs) -> dict:
    """Every phase of every setting (its --set overrides, its run root), `jobs` at once: {(root, k): status}."""
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        futures = {(root, k): pool.submit(run_phase, solver_args(binary, case, preset, sets, k, n,
                                                                 phase_dir(root, k, n)), phase_dir(root, k, n))
                   for sets, root in settings for k in range(n)}
        return {key: f.result() for key, f in futures.items()}


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


def pct(x: float) -> str:
    return "-" if math.isnan(x) else f"{x:+.2%}"


def verdict_line(p: metrics.PairedComparison | None, extra: list[str], pairs: int) -> str:
    """The paired verdict in one line: B (the --compare overrides) against A."""
    b = " ".join(extra)
    if p is None:
        return f"verdict: none for {b}: {pairs} phase(s) completed under both settings, at least 2 needed"
    why = [f"{label} {q.mean:+.2%} beyond {p.tol * 100:g}%" for label, q in (("mean R", p.level), ("R_init", p.init))
           if abs(q.mean) > p.tol]
    why += [f"{label} {q.mean:+.2%} with 2 SE = {2 * q.se:.2%} reaches past {p.tol * 100:g}%" for label, q in
            (("mean R", p.level), ("R_init", p.init)) if abs(q.mean) <= p.tol < abs(q.mean) + 2 * q.se]
    why += [] if p.comparable else [f"not comparable (a common range under {metrics.MIN_RANGE_OVER_D:g} d)"]
    head = "the same R-curve" if p.same else "NOT the same R-curve"
    return (f"verdict: {b} is {head} as the plain setting at {p.tol * 100:g}%, paired over {pairs} phases (mean R "
            f"{p.level.mean:+.2%} +- {p.level.se:.2%}, R_init {p.init.mean:+.2%} +- {p.init.se:.2%})"
            + (f": {'; '.join(why)}" if why else ""))


def compare_rows(p: metrics.PairedComparison, ks: list[int], n: int) -> list[str]:
    lines = ["", "| phase | A mean R | B mean R | diff | A R_init | B R_init | R_init diff | common range (d) | "
             "alone (same_rcurve, not deciding) |", "|---|---|---|---|---|---|---|---|---|"]
    for j, k in enumerate(ks):
        c = p.singles[j]
        lines.append(f"| {k}/{n} | {c.mean_a:.3f} | {c.mean_b:.3f} | {pct(c.mean_rel)} | "
                     f"{p.inits_a[j]:.3f} | {p.inits_b[j]:.3f} | {pct(c.init_rel)} | "
                     f"({p.lo:g}, {c.hi:.2f}] | {'same' if c.same else 'not the same'} |")
    lines += ["", "| quantity | mean d | SE | band (min to max) | abs(d) within tol | abs(d) + 2 SE within tol |",
              "|---|---|---|---|---|---|"]
    for label, q in (("mean R", p.level), ("R_init", p.init)):
        lines.append(f"| {label} | {pct(q.mean)} | {q.se:.2%} | {pct(q.low)} to {pct(q.high)} | "
                     f"{abs(q.mean) <= p.tol} | {abs(q.mean) + 2 * q.se <= p.tol} |")
    lines.append(f"\nPhase-averaged mean R: A {p.mean_a:.3f}, B {p.mean_b:.3f}.")
    return lines


def compare_report(root_a: pathlib.Path, root_b: pathlib.Path, case: pathlib.Path, preset: str, sets: list[str],
                   extra: list[str], n: int, tol: float) -> str:
    """compare.md in root_b: setting B (sets + extra) against A (sets), paired phase by phase over the phases
    completed under both. Returns its text, whose last line is the verdict."""
    done_a, done_b = load_phases(root_a, n), load_phases(root_b, n)
    ks = sorted(set(done_a) & set(done_b))
    curves = lambda done: [metrics.rcurve_of(done[k]) for k in ks]  # noqa: E731
    p = metrics.paired_phase_comparison(curves(done_a), curves(done_b), tol) if len(ks) >= 2 else None
    a_sets = " ".join(f"--set {s}" for s in sets) or "the case as it is"
    lines = [f"# {case.stem}: {' '.join(extra)} against the plain setting ({n} phases, preset {preset})", "",
             f"Written by `python3 -m pipeline.phases --compare`: setting A ({root_a.name}) runs {a_sets}, setting B "
             f"(the runs next to this file) A with {' '.join('--set ' + s for s in extra)}; phase k runs "
             f"`{PHASE_KEY} = k/{n}` under both.",
             "Rule (enamel_results.metrics.paired_phase_comparison): per phase, the relative difference (B - A) / A "
             "of R averaged over crack advance over the pair's common range of (0, 30] d and of R_init; for each, "
             f"the mean d over the pairs, with twice its standard error (sample std over sqrt(N)), within the "
             f"tolerance {tol * 100:g}%: abs(d) + 2 SE <= {tol * 100:g}%; every common range at least "
             f"{metrics.MIN_RANGE_OVER_D:g} d; at least 2 pairs."]
    if p is not None:
        lines += compare_rows(p, ks, n)
    missing = [k for k in range(n) if k not in ks]
    if missing:
        lines.append(f"\n**Not completed under both settings**: phase(s) {', '.join(f'{k}/{n}' for k in missing)};"
                     " the pairs are the others.")
    lines += ["", verdict_line(p, extra, len(ks))]
    text = "\n".join(lines) + "\n"
    (root_b / "compare.md").write_text(text)
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
    ap.add_argument("--compare", dest="compares", action="append", default=[], metavar="KEY=VALUE",
                    help="setting B: these overrides on top of --set, run beside the plain setting A and compared "
                         "with it phase by phase into compare.md (repeatable)")
    ap.add_argument("--tol", type=float, default=metrics.TOL_RATE_SPEED,
                    help=f"the comparison's tolerance (default {metrics.TOL_RATE_SPEED:g}; 0.10 for size and mesh)")
    a = ap.parse_args(argv)
    check_args(ap, a)
    root = run_root(a.runs, a.preset, a.case, a.sets)
    settings = [(a.sets, root)]
    if a.compares:
        settings.append((a.sets + a.compares, run_root(a.runs, a.preset, a.case, a.sets + a.compares)))
    status = {} if a.report_only else run_all(a.binary, a.case, a.preset, settings, a.phases, a.jobs)
    for _, r in settings:
        r.mkdir(parents=True, exist_ok=True)
    texts = [report(r, a.case, a.preset, sets, a.phases) for sets, r in settings]
    print(compare_report(root, settings[1][1], a.case, a.preset, a.sets, a.compares, a.phases, a.tol)
          if a.compares else texts[0], end="")
    failed = [key for key, rc in status.items() if rc != 0]
    for r, k in failed:
        print(f"phases: phase {k}/{a.phases} of {r.name} exited with status {status[(r, k)]} "
              f"(log: {phase_dir(r, k, a.phases) / 'log.txt'})", file=sys.stderr)
    incomplete = any(len(load_phases(r, a.phases)) < a.phases for _, r in settings)
    return 1 if failed or incomplete else 0


def check_args(ap: argparse.ArgumentParser, a) -> None:
    """Refuse what the phases cannot run: argparse's exit 2 with the reason."""
    if not 2 <= a.phases <= 64:
        ap.error(f"--phases = {a.phases}: allowed range [2, 64]")
    keys = lambda sets: {s.split("=", 1)[0].strip() for s in sets}  # noqa: E731
    if PHASE_KEY in keys(a.sets) | keys(a.compares):
        ap.error(f"--set/--compare {PHASE_KEY}=...: the phases set it; give --phases instead")
    if keys(a.sets) & keys(a.compares):
        ap.error(f"--compare {', '.join(sorted(keys(a.sets) & keys(a.compares)))}: already given by --set (setting "
                 "A); B is A with the --compare overrides")
    if any("=" not in s for s in a.compares):
        ap.error("--compare takes KEY=VALUE")
    if not a.tol > 0:
        ap.error(f"--tol = {a.tol}: a positive fraction (0.02 is 2 %)")
    if not a.case.is_file():
        ap.error(f"case file {a.case} not found")


if __name__ == "__main__":
    sys.exit(main())
