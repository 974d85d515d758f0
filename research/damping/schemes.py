"""The rods' damping in the fast scheme: `lumped` with the paper's full b K taken implicitly (rod_damping =
implicit, the default) against `lumped` with the capped explicit b' (rod_damping = capped) and against the
reference `paper` (Newmark, consistent mass, H = M + dt/2 C), on the same cases at one preset; and `interfaces`:
implicit with the step set by the interfaces alone (step_rule = interfaces, dt_factor 0.1, physical rotary inertia).

    /usr/bin/python3 -m research.damping.schemes run --preset ci [--jobs 2] [--schemes paper,implicit,capped]
    /usr/bin/python3 -m research.damping.schemes report --preset ci

Runs go to runs/research_damping/<preset>/<case>/<scheme>/ (resumable: a completed run is not rerun); each
finished run's numbers are recorded in research/damping/data/<preset>.csv (with date, machine and commit), and the
report (research/damping/data/<preset>.md) compares each scheme with `paper` by enamel_results.metrics.same_rcurve
(one configuration: shown, not deciding).
"""
from __future__ import annotations

import argparse
import concurrent.futures
import csv
import datetime
import math
import pathlib
import platform
import subprocess
import sys

from enamel_results import metrics, paths, results

HERE = pathlib.Path(__file__).resolve().parent
DATA = HERE / "data"
CASES = ("theta30_s21.4_e10_cv0", "theta15_s21.4_e10_cv0", "theta30_s21.4_e20_cv0", "theta30_s28.5_e10_cv0.3_seed1")
SCHEMES = {
    "paper": ['integrator="paper"'],
    "implicit": ['integrator="lumped"', 'rod_damping="implicit"'],
    "capped": ['integrator="lumped"', 'rod_damping="capped"'],
    "interfaces": ['integrator="lumped"', 'rod_damping="implicit"', 'step_rule="interfaces"', "dt_factor=0.1"],
}
# the lumped runs keep the preset's dt_factor (and damping_cap for capped); paper runs at its own dt_factor 0.1
PAPER_SETS = ["dt_factor=0.1", "static_start=0"]
COLUMNS = ("preset", "case", "scheme", "status", "R_init", "R_mean", "da_max", "broken_rods", "da_first_rod",
           "wall_s", "steps", "date", "machine", "commit")


def run_dir(preset: str, case: str, scheme: str) -> pathlib.Path:
    return paths.RUNS / "research_damping" / preset / case / scheme


def run_one(binary: pathlib.Path, preset: str, case: str, scheme: str) -> int:
    out = run_dir(preset, case, scheme)
    if (out / paths.RESULT_NAMES["completed"]).is_file():
        return 0
    out.mkdir(parents=True, exist_ok=True)
    args = [str(binary), "run", str(paths.ROOT / "paper_cases" / f"{case}.toml"), "--preset", preset, "--out",
            str(out), "--resume", "--quiet", "--checkpoint-every", "60", "--set", "threads=1"]
    for s in SCHEMES[scheme] + (PAPER_SETS if scheme == "paper" else []):
        args += ["--set", s]
    with open(out / "log.txt", "a") as log:
        return subprocess.run(args, stdout=subprocess.DEVNULL, stderr=log).returncode


def machine() -> str:
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return platform.processor() or "unknown"


def row_of(preset: str, case: str, scheme: str) -> dict | None:
    f = run_dir(preset, case, scheme) / paths.RESULT_NAMES["completed"]
    if not f.is_file():
        return None
    r = results.load_result(f, case)
    c = metrics.rcurve_of(r)
    return {"preset": preset, "case": case, "scheme": scheme, "status": r.status, "R_init": r.R_init,
            "R_mean": metrics.advance_mean(c, *metrics.RANGE_OVER_D), "da_max": r.da_max,
            "broken_rods": r.broken_rods, "da_first_rod": r.da_first_rod_fracture, "wall_s": r.wall_time_s,
            "steps": r.meta.get("steps", ""), "date": datetime.date.today().isoformat(), "machine": machine(),
            "commit": str(r.meta.get("git_hash", ""))}


def record(preset: str) -> list[dict]:
    rows = [row for case in CASES for scheme in SCHEMES if (row := row_of(preset, case, scheme))]
    DATA.mkdir(exist_ok=True)
    path = DATA / f"{preset}.csv"
    old = {(r["case"], r["scheme"]): r for r in csv.DictReader(open(path))} if path.is_file() else {}
    for row in rows:  # a run already recorded keeps its row (its date and machine)
        key = (row["case"], row["scheme"])
        if key in old and old[key]["R_mean"] == f"{row['R_mean']}":
            row.update({k: old[key][k] for k in ("date", "machine")})
        old[key] = row
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, COLUMNS)
        w.writeheader()
        for key in sorted(old):
            w.writerow({k: old[key].get(k, "") for k in COLUMNS})
    return list(old.values())


BENCH = paths.ROOT / "bench" / "results.csv"


def bench_paper(preset: str, case: str, rows: dict) -> dict | None:
    """`paper` at `reduced` from the bench's record (bench/results.csv: its run of ~2 h per case), where this study's
    capped run repeats the bench's `lumped cap0.5 dt0.22` run (the same R_init and R_ss to 1e-5): R_init, R_ss and rods
    as recorded, the mean as the capped run's over (1 + the bench's relative difference of that variant)."""
    capped = rows.get((case, "capped"))
    if preset != "reduced" or not capped or not BENCH.is_file():
        return None
    bench = {(r["case"], r["variant"]): r for r in csv.DictReader(open(BENCH))}
    paper, lumped = bench.get((case, "paper")), bench.get((case, "lumped cap0.5 dt0.22"))
    if not paper or not lumped or abs(float(lumped["R_init"]) - float(capped["R_init"])) > 1e-5:
        return None
    mean = float(capped["R_mean"]) / (1 + float(lumped["R_mean_rel_diff"]))
    return {"case": case, "scheme": "paper (bench record)", "R_init": paper["R_init"], "R_mean": mean,
            "broken_rods": paper["broken_rods"], "da_first_rod": "nan", "wall_s": paper["wall_s"]}


def pct(x: float) -> str:
    return "n/a" if x is None or (isinstance(x, float) and math.isnan(x)) else f"{100 * x:+.1f} %"


def report(preset: str) -> str:
    rows = {(r["case"], r["scheme"]): r for r in record(preset)}
    lines = [f"# The rods' damping: `lumped` implicit and capped against `paper`, preset `{preset}`", "",
             f"Generated by `/usr/bin/python3 -m research.damping.schemes report --preset {preset}` from "
             f"data/{preset}.csv. R_mean: R/Gamma_i averaged over crack advance over (0, min(30, end)] d; "
             "differences against `paper` over the pair's common range (metrics.same_rcurve; one configuration).", "",
             "| case | scheme | R_init | R_mean | rods | first rod (d) | d R_init | d R_mean | wall (s) |",
             "|---|---|---|---|---|---|---|---|---|"]
    for case in CASES:
        ref = rows.get((case, "paper"))
        recorded = None if ref else bench_paper(preset, case, rows)
        if recorded:
            lines.append(f"| {case} | {recorded['scheme']} | {float(recorded['R_init']):.3f} | "
                         f"{recorded['R_mean']:.3f} | {recorded['broken_rods']} | n/a | | | "
                         f"{float(recorded['wall_s']):.0f} |")
        for scheme in SCHEMES:
            r = rows.get((case, scheme))
            if not r:
                continue
            d_init = d_mean = None
            if recorded and scheme != "paper":
                d_init = float(r["R_init"]) / float(recorded["R_init"]) - 1
                d_mean = float(r["R_mean"]) / recorded["R_mean"] - 1
            if ref and scheme != "paper":
                a = metrics.rcurve_of(results.load_result(run_dir(preset, case, "paper") / paths.RESULT_NAMES["completed"], case))
                b = metrics.rcurve_of(results.load_result(run_dir(preset, case, scheme) / paths.RESULT_NAMES["completed"], case))
                cmp = metrics.same_rcurve(a, b, metrics.TOL_RATE_SPEED)
                d_init, d_mean = cmp.init_rel, cmp.mean_rel
            lines.append(f"| {case} | {scheme} | {float(r['R_init']):.3f} | {float(r['R_mean']):.3f} | "
                         f"{r['broken_rods']} | {float(r['da_first_rod']):.2f} | {pct(d_init)} | {pct(d_mean)} | "
                         f"{float(r['wall_s']):.0f} |")
    text = "\n".join(lines) + "\n"
    (DATA / f"{preset}.md").write_text(text)
    return text


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("command", choices=("run", "report"))
    ap.add_argument("--preset", default="ci")
    ap.add_argument("--jobs", type=int, default=2)
    ap.add_argument("--schemes", default=",".join(SCHEMES))
    ap.add_argument("--cases", default=",".join(CASES))
    a = ap.parse_args(argv)
    if a.command == "run":
        binary = paths.ROOT / "build" / "enamel-dem"
        todo = [(c, s) for c in a.cases.split(",") for s in a.schemes.split(",")]
        with concurrent.futures.ThreadPoolExecutor(a.jobs) as pool:
            codes = list(pool.map(lambda cs: run_one(binary, a.preset, *cs), todo))
        for (c, s), code in zip(todo, codes):
            print(f"{c} {s}: exit {code}")
    print(report(a.preset))
    return 0


if __name__ == "__main__":
    sys.exit(main())
