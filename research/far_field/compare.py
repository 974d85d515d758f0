"""The reduced far field (docs/solver.md, "Reduced far field") against the full
model at 80 x 80 d, theta_D = 30 (21.4, 10), `make bench-paper`'s variant (lumped, dt_factor 0.22, damping_cap
0.5, static_start 0.95), 1 thread, to Delta_a = 30 d.

    python3 -m research.far_field.compare --run-all BINARY [--only NAME ...]   # the runs (resumable) and records
    python3 -m research.far_field.compare --run full=RUN_DIR --run m4_h22=RUN_DIR ...   # records from runs
    python3 -m research.far_field.compare --elastic BINARY      # the elastic table: static solves, ~5 min
    python3 -m research.far_field.compare                       # the report from the records

Each run leaves a record (record_<name>.json: metrics and the whole R-curve, research/bench_experiments/check_100's
format); the elastic table (elastic.json) holds, per far field, the static elastic solution's stiffness load/U
and the first-damage displacement U_c against the full model's. README.md here is made from them, so the
report regenerates without the runs (commands in README.md).
"""
from __future__ import annotations

import argparse
import json
import math
import pathlib
import subprocess
import sys
import tempfile

import numpy as np

from research.bench_experiments.check_100.compare import result_file  # the result-file fallback: to enamel_results' one resolver
from enamel_results import metrics
from bench import records as run_records
from bench.records import R_at
from enamel_results.paths import PAPER_CASES, run_result

HERE = pathlib.Path(__file__).resolve().parent
CASE = "theta30_s21.4_e10_cv0"
CV_CASE = "theta30_s28.5_e10_cv0.3_seed1"  # the bench's cv = 0.3 realisation
SIZE = ["w_s_over_d=80", "h_s_over_d=80"]
VARIANT = ['integrator="lumped"', "dt_factor=0.22", "damping_cap=0.5", "threads=1"] + SIZE
ELASTIC_FIELDS = [(1, 0), (2, 22), (4, 22), (8, 22)]   # (far_field_slices, full_half_height_over_d)


def far_field_sets(slices: int, half_height: float) -> list[str]:
    return [] if slices == 1 else [f"far_field_slices={slices}", f"full_half_height_over_d={half_height:g}"]


# The study's runs: name -> (case, --set on top of VARIANT and the static start). Per case the `full` (or
# `<prefix>_full`) run is the reference; each run ~45-65 min on one core of this machine.
RUNS = {
    "full": (CASE, []),
    "full_dt0.2": (CASE, ["dt_factor=0.2"]),
    "m2_h22": (CASE, far_field_sets(2, 22)),
    "m4_h22": (CASE, far_field_sets(4, 22)),
    "cv03_full": (CV_CASE, []),
    "cv03_full_dt0.2": (CV_CASE, ["dt_factor=0.2"]),
    "cv03_m2_h22": (CV_CASE, far_field_sets(2, 22)),  # stops at Delta_a = 1.95 d: a rod breaks 23 d from the plane
    "cv03_m2_h22_allow": (CV_CASE, far_field_sets(2, 22) + ['far_field_rod_breaks="allow"']),
}
RUNS_DIR = pathlib.Path("runs") / "far_field"


def finished(name: str) -> pathlib.Path | None:
    """The run's final result: result.h5, or result.failed.h5 of a run that stopped itself (the edge check's stop
    is a measurement too); None while it has neither."""
    return run_result(RUNS_DIR / name, kinds=("completed", "failed"))


def run_command(binary: pathlib.Path, name: str) -> list[str]:
    case, sets = RUNS[name]
    args = [str(binary), "run", str(PAPER_CASES / f"{case}.toml"), "--preset", "paper", "--out", str(RUNS_DIR / name),
            "--resume", "--checkpoint-every", "300", "--quiet"]
    for s in VARIANT + ["static_start=0.95"] + sets:
        args += ["--set", s]
    return args


def run_all(binary: pathlib.Path, names: list[str], jobs: int) -> int:
    """Run the study's runs `jobs` at a time (niced; each resumes from its checkpoint, a finished one is skipped)
    and return the number that left no final result."""
    from concurrent.futures import ThreadPoolExecutor

    def one(name: str) -> bool:
        if finished(name):
            print(f"far_field: {name}: done already ({finished(name)})", flush=True)
            return True
        print(f"far_field: {name}: " + " ".join(run_command(binary, name)), flush=True)
        rc = subprocess.run(["nice", "-n", "10"] + run_command(binary, name)).returncode
        print(f"far_field: {name}: exit {rc}", flush=True)
        return finished(name) is not None

    with ThreadPoolExecutor(max_workers=jobs) as pool:
        return sum(not done for done in pool.map(one, names))


def elastic_table(binary: pathlib.Path) -> list[dict]:
    """Static elastic solutions (a run of one step with static_start 0.95): load/U and U_c per far field."""
    import h5py
    rows = []
    for theta, case in ((0, "theta0_s21.4_e10_cv0"), (30, CASE)):
        for slices, half in ELASTIC_FIELDS:
            with tempfile.TemporaryDirectory() as tmp:
                args = [str(binary), "run", str(PAPER_CASES / f"{case}.toml"), "--preset", "paper", "--out", tmp, "--quiet"]
                for s in VARIANT + ["static_start=0.95", "max_steps=1"] + far_field_sets(slices, half):
                    args += ["--set", s]
                subprocess.run(args, check=True, capture_output=True, text=True)
                with h5py.File(pathlib.Path(tmp) / "result.h5", "r") as f:
                    m, h = f["meta"].attrs, f["history"]
                    rows.append(dict(theta=theta, slices=slices, half_height=half, dof=int(m["dof"]),
                                     stiffness=float(h["load"][0] / h["applied_displacement"][0]),
                                     Uc=float(m["static_start_Uc_over_d"])))
    return rows


def elastic_report(rows: list[dict]) -> str:
    lines = ["| theta_D | far field | DOF | load/U against full | U_c against full |", "|---|---|---|---|---|"]
    for r in rows:
        full = next(x for x in rows if x["theta"] == r["theta"] and x["slices"] == 1)
        name = "full" if r["slices"] == 1 else f"every {r['slices']} slices beyond {r['half_height']:g} d"
        lines.append(f"| {r['theta']} | {name} | {r['dof']} ({r['dof'] / full['dof']:.2f}) | "
                     f"{r['stiffness'] / full['stiffness'] - 1:+.2%} | {r['Uc'] / full['Uc'] - 1:+.2%} |")
    return "\n".join(lines)


CASE_TITLES = {CASE: "theta_D = 30 (21.4, 10)", CV_CASE: "theta_D = 30, cv = 0.3, seed 1 (mean 28.5, 10)"}


def by_case(records: dict) -> dict:
    """The records grouped by case (records older than the case field are theta30's), each group's reference first:
    the record named `full` or `<prefix>_full` (the full model of that case)."""
    groups: dict = {}
    for name, rec in records.items():
        groups.setdefault(rec.get("case", CASE), {})[name] = rec
    out = {}
    for case in sorted(groups, key=lambda c: (c != CASE, c)):
        g = groups[case]
        ref = [n for n in g if n == "full" or n.endswith("_full")]
        if len(ref) != 1:
            raise SystemExit(f"compare: case {case} needs exactly one full-model record (full or <prefix>_full), has {ref}")
        out[case] = {n: g[n] for n in ref + sorted(n for n in g if n != ref[0])}
    return out


def scene_of(run_dir: pathlib.Path) -> dict:
    """Where the damage is at the run's last frame (research/scene/): the distances from the crack plane of the
    deleted rod elements (sorted) and of the interfaces with damage > 0 (largest, 99th percentile)."""
    import h5py
    with h5py.File(result_file(run_dir), "r") as f:
        g, frames = f["geometry"], f["frames"]
        last = frames[max(frames.keys(), key=int)]
        X, y_crack = g["node_position"][:], float(g.attrs["y_crack_plane"])
        nodes = g["beam_nodes"][:]
        mid_y = 0.5 * (X[nodes[:, 0], 1] + X[nodes[:, 1], 1])
        rods = np.sort(np.abs(mid_y[last["beam_broken"][:].astype(bool)] - y_crack))
        damaged = np.abs(g["iface_midpoint"][:, 1][last["iface_damage"][:] > 0] - y_crack)
    return dict(broken_rod_distances=[round(float(d), 2) for d in rods],
                damaged_interface_reach=float(damaged.max()) if damaged.size else 0.0,
                damaged_interface_reach_p99=float(np.percentile(damaged, 99)) if damaged.size else 0.0)


def scene_report(records: dict) -> str:
    """Per record that holds it: how far from the plane the damaged interfaces and the broken rods lie."""
    lines = ["| run | damaged interfaces: farthest, 99% within (d) | broken rods within 2, 5, 10, 20 d, beyond 20 d | "
             "the farthest broken rods (d) |", "|---|---|---|---|"]
    for name, rec in records.items():
        if "broken_rod_distances" not in rec:
            continue
        d = np.array(rec["broken_rod_distances"])
        counts = [int((d <= r).sum()) for r in (2, 5, 10, 20)] + [int((d > 20).sum())]
        lines.append(f"| {name} | {rec['damaged_interface_reach']:.1f}, {rec['damaged_interface_reach_p99']:.1f} | "
                     + ", ".join(map(str, counts)) + " | " + ", ".join(f"{x:.1f}" for x in d[-6:]) + " |")
    return "\n".join(lines) if len(lines) > 2 else ""


def run_report(records: dict) -> str:
    """One table per case against that case's full model, then the inelastic reach of every run."""
    lines = []
    groups = by_case(records)
    for case, group in groups.items():
        full = next(iter(group.values()))
        fm = full["meta"]
        if lines:
            lines.append("")
        lines += [f"{CASE_TITLES.get(case, case)}:", "",
                  "| model | status | DOF | steps | wall s | DOF-updates | speed-up (wall) | Delta_a max/d | R-curve L2 | "
                  "R_init | R/Gamma at 5, 10, 20 d | broken rods | KE/SE max |",
                  "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for name, rec in group.items():
            m = rec["meta"]
            l2 = metrics.rcurve_rel_l2(np.array(full["da"]), np.array(full["R"]), np.array(rec["da"]), np.array(rec["R"]))
            updates = m["dof"] * m["steps"]
            lines.append(
                f"| {name} | {m.get('status')} | {m['dof']} ({m['dof'] / fm['dof']:.2f}) | {m['steps']} | "
                f"{m['wall_time_s']:.0f} | {updates:.3g} ({fm['dof'] * fm['steps'] / updates:.2f}x fewer) | "
                f"{fm['wall_time_s'] / m['wall_time_s']:.2f} | {rec['da_max']:.2f} | "
                f"{l2:.3g} ({'within' if l2 <= 0.02 else 'outside'} 2%) | "
                f"{rec['R_init'] / full['R_init'] - 1:+.2%} | " + ", ".join(f"{R_at(rec, d):.2f}" for d in (5, 10, 20)) +
                f" | {rec['broken_rods']} ({rec['broken_rods'] - full['broken_rods']:+d}) | "
                f"{m.get('max_kinetic_over_strain_while_growing', math.nan):.3g} |")
    cols = next(iter(next(iter(groups.values())).values()))["reach_at_da"]
    lines += ["", "Inelastic reach from the crack plane (`/history/inelastic_reach_over_d`, d; half-height 40 d):", "",
              "| Delta_a/d | " + " | ".join(f"{d:g}" for d, _ in cols) + " |", "|---|" + "---|" * len(cols)]
    for group in groups.values():
        for name, rec in group.items():
            cells = [f"{r:.1f}" for _, r in rec["reach_at_da"]] + ["-"] * (len(cols) - len(rec["reach_at_da"]))
            lines.append(f"| {name} | " + " | ".join(cells[:len(cols)]) + " |")
    return "\n".join(lines)


def plot(records: dict, out: pathlib.Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    groups = by_case(records)
    fig, axes = plt.subplots(1, len(groups), figsize=(5.5 * len(groups), 3.6), squeeze=False)
    for ax, (case, group) in zip(axes[0], groups.items()):
        for (name, rec), style in zip(group.items(), ("-", "--", ":", "-.", (0, (5, 1)))):
            ax.plot(rec["da"], rec["R"], linestyle=style, label=name)
        ax.set_xlabel(r"$\Delta a / d$")
        ax.set_ylabel(r"$R / \Gamma_i$")
        ax.set_title(f"80 x 80 d, {CASE_TITLES.get(case, case)}: full and reduced far field", fontsize=8)
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=100)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--run", action="append", default=[], metavar="NAME=RUN_DIR",
                    help="a run's folder (writes record_NAME.json); per case, NAME full or PREFIX_full is the reference")
    ap.add_argument("--elastic", type=pathlib.Path, metavar="BINARY", help="compute the elastic table (elastic.json)")
    ap.add_argument("--out", type=pathlib.Path, default=HERE, help="folder of the records and the report")
    ap.add_argument("--run-all", type=pathlib.Path, metavar="BINARY",
                    help=f"run the study's runs into {RUNS_DIR}/NAME (resumable) and write their records: {', '.join(RUNS)}")
    ap.add_argument("--only", nargs="+", choices=list(RUNS), default=list(RUNS), help="with --run-all: these runs only")
    ap.add_argument("--jobs", type=int, default=2, help="with --run-all: runs at a time (each on one thread)")
    args = ap.parse_args(argv)
    if args.run_all:
        failed = run_all(args.run_all, args.only, args.jobs)
        args.run += [f"{n}={RUNS_DIR / n}" for n in args.only if finished(n)]
        if failed:
            print(f"compare: {failed} run(s) did not complete; their records are not written", file=sys.stderr)
    for item in args.run:
        name, _, run = item.partition("=")
        record = run_records.record_of(result_file(pathlib.Path(run)), name)
        record.update(scene_of(pathlib.Path(run)))
        (args.out / f"record_{name}.json").write_text(json.dumps(record, indent=1) + "\n")
    if args.elastic:
        (args.out / "elastic.json").write_text(json.dumps(elastic_table(args.elastic), indent=1) + "\n")
    paths = sorted(args.out.glob("record_*.json"))
    records = {p.stem[len("record_"):]: json.loads(p.read_text()) for p in paths}
    if "full" not in records:
        print("compare: missing record_full.json: run with --run full=RUN_DIR first", file=sys.stderr)
        return 3
    text = run_report(records)
    scene = scene_report(records)
    if scene:
        text += "\n\nWhere the damage is at the last frame (distance from the crack plane):\n\n" + scene
    if (args.out / "elastic.json").exists():
        text += "\n\nElastic response (static solution before any damage), against the full model:\n\n"
        text += elastic_report(json.loads((args.out / "elastic.json").read_text()))
    plot(records, args.out / "rcurves.png")
    print(text)
    return 1 if args.run_all and failed else 0


if __name__ == "__main__":
    sys.exit(main())
