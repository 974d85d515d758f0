"""The issue "Performance" check at 100 x 100 d: `make bench-paper`'s variant (lumped, dt_factor 0.22,
damping_cap 0.5, static_start 0.95) against the same scheme from rest (the unaccelerated lumped run), theta_D = 30
(21.4, 10), to Delta_a = 30 d.

    python3 -m bench.experiments.check_100.compare --rest RUN_DIR --static RUN_DIR   # from two runs: records
    python3 -m bench.experiments.check_100.compare                                  # the report from the records

The runs (commands in README.md here) are not kept; each leaves a record (record_<name>.json: metrics and the
whole R-curve to 10 digits) from which README.md's table and rcurves.png are made, so the report regenerates
without them.
"""
from __future__ import annotations

import argparse
import json
import math
import pathlib
import sys

import numpy as np

from bench.run_bench import history_end
from enamel_results import metrics, results

HERE = pathlib.Path(__file__).resolve().parent
NAMES = ("rest", "static")


def record_of(run_dir: pathlib.Path, name: str) -> dict:
    r = results.load_result(pathlib.Path(run_dir) / "result.h5", case="theta30_s21.4_e10_cv0")
    m = r.meta
    keep = ("status", "stop_reason", "steps", "dof", "threads", "wall_time_s", "dt",
            "max_kinetic_over_strain_while_growing", "peak_memory_mb", "git_hash", "static_start")
    meta = {k: (m[k].item() if hasattr(m.get(k), "item") else m.get(k)) for k in keep if k in m}
    meta.update(history_end(pathlib.Path(run_dir) / "result.h5"))
    return dict(name=name, meta=meta,
                R_init=r.R_init, R_ss=r.R_ss, R_m=r.R_m, da_max=r.da_max, broken_rods=r.broken_rods,
                warnings=str(m.get("warnings", "")),
                da=[float(f"{x:.10g}") for x in r.da], R=[float(f"{x:.10g}") for x in r.R])


def report(records: dict) -> str:
    a, b = records["rest"], records["static"]
    l2 = metrics.rcurve_rel_l2(np.array(a["da"]), np.array(a["R"]), np.array(b["da"]), np.array(b["R"]))
    lines = ["| run | status | steps | wall s (stepping) | R_init/Gamma | R_ss/Gamma | R_m/Gamma | Delta_a max/d | broken rods | KE/SE max | balance |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for rec in (a, b):
        m = rec["meta"]
        lines.append(f"| {rec['name']} | {m.get('status')} | {m.get('steps')} | {m.get('wall_time_s', math.nan):.0f} | "
                     f"{rec['R_init']:.4f} | {rec['R_ss']:.4f} | {rec['R_m']:.4f} | {rec['da_max']:.2f} | {rec['broken_rods']} | "
                     f"{m.get('max_kinetic_over_strain_while_growing', math.nan):.3g} | {m.get('balance_end', math.nan):.2g} |")
    steps = a["meta"].get("steps", 0) / max(b["meta"].get("steps", 1), 1)
    wall = a["meta"].get("wall_time_s", 0) / max(b["meta"].get("wall_time_s", 1), 1e-9)
    lines += ["", f"R-curve relative L2 (static start against from rest, common Delta_a range): **{l2:.3g}** "
              f"(bound 0.02: {'within' if l2 <= 0.02 else 'OUTSIDE'}); R_init {b['R_init'] / a['R_init'] - 1:+.2e}, "
              f"R_ss {b['R_ss'] / a['R_ss'] - 1:+.2e}, broken rods {b['broken_rods'] - a['broken_rods']:+d}; "
              f"steps from rest / static {steps:.3f}, stepping wall time {wall:.3f}."]
    return "\n".join(lines)


def plot(records: dict, out: pathlib.Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5.5, 3.6))
    for name, style in (("rest", "-"), ("static", "--")):
        rec = records[name]
        ax.plot(rec["da"], rec["R"], style, label={"rest": "lumped from rest", "static": "static start 0.95 (bench-paper's)"}[name])
    ax.set_xlabel(r"$\Delta a / d$")
    ax.set_ylabel(r"$R / \Gamma_i$")
    ax.set_title(r"100 x 100 d, $\theta_D$ = 30 (21.4, 10)", fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out, dpi=110)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rest", type=pathlib.Path, help="run folder of the run from rest (writes record_rest.json)")
    ap.add_argument("--static", type=pathlib.Path, help="run folder of the static-start run (writes record_static.json)")
    ap.add_argument("--out", type=pathlib.Path, default=HERE, help="folder of the records and the report")
    args = ap.parse_args(argv)
    for name in NAMES:
        run = getattr(args, name)
        if run is not None:
            (args.out / f"record_{name}.json").write_text(json.dumps(record_of(run, name), indent=1) + "\n")
    try:
        records = {n: json.loads((args.out / f"record_{n}.json").read_text()) for n in NAMES}
    except FileNotFoundError as e:
        print(f"compare: missing record {e.filename}: run with --rest and --static first", file=sys.stderr)
        return 3
    text = report(records)
    plot(records, args.out / "rcurves.png")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
