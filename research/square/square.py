"""The interface-ductility identification on square specimens (README.md here: the plan, the measure and the rule,
committed before the runs).

    python3 -m research.square.square run S G [--he H] [--rate F]   # one run (one thread) and its record
    python3 -m research.square.square run S G --case CASE           # a validation run of another paper case
    python3 -m research.square.square record RUN_DIR                # the record of a finished run
    python3 -m research.square.square report                        # README's Results and rcurves.png from the records

A run's folder is runs/square/<name>/ (not kept); its record is data/<name>.json (kept): metrics, status, steps,
wall time, the R-curve to 10 digits and the crack advance of every rod break, so the report regenerates without
the runs.
"""
from __future__ import annotations

import argparse
import json
import math
import pathlib
import subprocess
import sys

import h5py
import numpy as np

from enamel_results import cases, metrics, paper_values, paths, results
from bench import records
from figures import summary_table

HERE = pathlib.Path(__file__).resolve().parent
DATA = HERE / "data"
RUNS = paths.RUNS / "square"
CASE = "theta30_s21.4_e10_cv0"
PAPER_LEVEL = 7.0            # the paper's R/Gamma_i "at Delta_a ~ 15 d" for this case (the rule's target)
SELECT_WINDOW = (5.0, 25.0)  # the rule's mean
# The paper's open readings (the rule's second part), each a case key whose default is today's reading.
READING_KEYS = ("shear_strength_ratio", "grip_constraint", "grip_profile", "crisscross_phase")
READING_FIRST_BREAK = 2.0    # the paper: no rod break before the first crisscross point, d/sin(theta_D) = 2 d
READING_LEVEL_TOL = 0.15     # and the (5,25] mean kept within 15% of PAPER_LEVEL
READING_MIN_SIZE = 80.0      # at a converged size (80 x 80 d and larger)
NUMERICS = {"integrator": '"lumped"', "dt_factor": "0.22", "damping_cap": "0.5", "static_start": "0.95"}


def run_name(size: float, G: float, he: float = 0.3, rate: float = 1.0, extra: str = "", case: str = CASE) -> str:
    """s80_he0.3_G10[_rate0.5][_extra] for the study's case; <case>_s80_he0.3_G10... for a validation case."""
    name = (f"{case}_" if case != CASE else "") + f"s{size:g}_he{he:g}_G{G:g}" + (f"_rate{rate:g}" if rate != 1.0 else "")
    return name + (f"_{extra}" if extra else "")


def solver_args(binary, size, G, he, rate, out, sets=(), case: str = CASE) -> list[str]:
    over = {"w_s_over_d": f"{size:g}", "h_s_over_d": f"{size:g}", "Gamma_k_over_sigma0sq": f"{G:g}",
            "h_e_over_d": f"{he:g}", "rate_factor": f"{rate:g}", **NUMERICS, "threads": "1",
            "checkpoint_interval_s": "600"}
    over.update(dict(s.split("=", 1) for s in sets))
    args = [str(binary), "run", str(paths.case_file(case)), "--preset", "paper", "--resume", "-o", str(out)]
    for k, v in over.items():
        args += ["--set", f"{k}={v}"]
    return args


def rod_breaks(result_h5: pathlib.Path) -> list[float]:
    """Crack advance at each rod element's deletion, from /history (one entry per element)."""
    with h5py.File(result_h5, "r") as f:
        h = f["history"]
        da, broken = np.asarray(h["da_over_d"]), np.asarray(h["broken_rod_elements"]).astype(int)
    out, prev = [], 0
    for d, b in zip(da, broken):
        out += [float(d)] * max(b - prev, 0)
        prev = max(prev, b)
    return out


def record_of(run_dir: pathlib.Path, name: str) -> dict:
    """enamel_results.records.record_of, plus the study's keys, the crack advance of every rod break and the CPU."""
    path = paths.run_result(run_dir)
    if path is None:
        raise results.MissingResult(pathlib.Path(run_dir) / paths.RESULT_NAMES["completed"])
    rec = records.record_of(path, name)
    r = results.load_result(path)
    rec["params"] = {k: r.param(k) for k in ("w_s_over_d", "h_s_over_d", "h_e_over_d", "Gamma_k_over_sigma0sq",
                                             "rate_factor")}
    rec["readings"] = {k: (str(r.params[k]) if isinstance(r.params[k], (str, bytes)) else float(r.params[k]))
                       for k in READING_KEYS if k in r.params}
    rec["rod_da"] = [float(f"{x:.6g}") for x in rod_breaks(path)]
    rec["cpu"] = records.cpu_model()
    return rec


def store(rec: dict, data: pathlib.Path = DATA) -> pathlib.Path:
    data.mkdir(parents=True, exist_ok=True)
    out = data / f"{rec['name']}.json"
    out.write_text(json.dumps(rec, indent=1) + "\n")
    return out


def load_records(data: pathlib.Path = DATA) -> dict[str, dict]:
    return {p.stem: json.loads(p.read_text()) for p in sorted(data.glob("*.json"))}


def curve(rec: dict) -> metrics.RCurve:
    return metrics.RCurve.of(rec["da"], rec["R"], rec.get("rod_da"), rec.get("broken_rods"))


def level(rec: dict, lo: float, hi: float) -> float:
    return metrics.advance_mean(curve(rec), lo, hi)


# ------------------------------------------------------------------------------------------------ the report
def fmt(v, spec=".3g") -> str:
    return "-" if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, spec)


def pct(v) -> str:
    return "-" if v is None or math.isnan(v) else f"{100 * v:+.1f}%"


def first_break(rec: dict) -> float:
    return rec["rod_da"][0] if rec.get("rod_da") else math.nan


def run_rows(recs: dict) -> list[str]:
    lines = ["| run | status | steps | wall min | Delta_a max | R_init | R (0,30] | (0,10] | (10,20] | (20,30] | "
             "**(5,25]** | broken rods | first break at | KE/SE max | balance | machine |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for name, rec in recs.items():
        m = rec["meta"]
        lines.append(f"| {name} | {m.get('status')} | {m.get('steps')} | {fmt(m.get('wall_time_s', math.nan) / 60, '.0f')} | "
                     f"{rec['da_max']:.1f} | {rec['R_init']:.3f} | {fmt(level(rec, 0, 30))} | "
                     + " | ".join(fmt(level(rec, a, b)) for a, b in metrics.WINDOWS_OVER_D)
                     + f" | **{fmt(level(rec, *SELECT_WINDOW))}** | {rec['broken_rods']} | {fmt(first_break(rec), '.2f')} | "
                     f"{fmt(m.get('max_kinetic_over_strain_while_growing'), '.3f')} | {fmt(m.get('balance_end'), '.1e')} | "
                     f"{rec.get('cpu', '')} |")
    return lines


def comparison_row(what: str, ref: str, other: str, tol: float, a: metrics.RCurve, b: metrics.RCurve,
                   note: str = "") -> tuple[str, bool]:
    """One table row of the measure (same_rcurve of b against a) and its verdict; `note` follows the verdict."""
    c = metrics.same_rcurve(a, b, tol)
    verdict = ("**same**" if c.same else ("not comparable" if not c.comparable else "**differ**")) + note
    wins = ", ".join(pct((wb - wa) / wa) for _, _, wa, wb in c.windows) or "-"
    return (f"| {what} | {ref} | {other} | {tol:.0%} | (0,{c.hi:.1f}] | {pct(c.mean_rel)} | {pct(c.init_rel)} | "
            f"{c.rods_a} / {c.rods_b} | {wins} | {100 * c.l2:.1f}% | {verdict} |", c.same)


def compare_line(what: str, ref: str, other: str, recs: dict, tol: float) -> tuple[str, bool]:
    unfinished = [n for n in (ref, other) if recs[n]["meta"].get("status") != "completed"]
    # compared over the common range, as the measure allows, and said
    note = (f" (over the common range: {', '.join(unfinished)} {recs[unfinished[0]]['meta'].get('status')})"
            if unfinished else "")
    return comparison_row(what, ref, other, tol, curve(recs[ref]), curve(recs[other]), note)


PAIR_HEAD = ["| check | reference | other | tolerance | range | R mean | R_init | broken rods | windows | L2 (reported) | verdict |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]


def pairs(recs: dict) -> list[tuple[str, str, str, float, float]]:
    """(check, reference, other, tolerance, G) for every pair the records allow: size (the two largest square sizes
    at h_e 0.3 and the preset's rate), mesh (h_e 0.3 / 0.15 at one size), rate (half-rate twin); a faster loading
    at a size also run at the preset's rate, or only at a larger size, is reported beside them."""
    out, by = [], {}
    for name, rec in recs.items():
        p = rec["params"]
        by[(p["w_s_over_d"], p["h_e_over_d"], p["Gamma_k_over_sigma0sq"], p["rate_factor"], name)] = name
    Gs = sorted({k[2] for k in by})
    for G in Gs:
        plain = sorted((k[0], n) for k, n in by.items() if k[2] == G and k[1] == 0.3 and k[3] == 1.0
                       and n == run_name(k[0], G))
        if len(plain) >= 2:
            out.append(("size", plain[-2][1], plain[-1][1], metrics.TOL_MESH_SIZE, G))
        for k, n in by.items():
            if k[2] == G and k[1] != 0.3 and n == run_name(k[0], G, he=k[1]) and run_name(k[0], G) in recs:
                out.append(("mesh", run_name(k[0], G), n, metrics.TOL_MESH_SIZE, G))
            # the rule's rate twin is a slower loading; a faster one at the same size is reported (it decides
            # whether that loading may stand in for the preset's, e.g. for the paper-size run), not decisive
            if k[2] == G and k[3] != 1.0 and run_name(k[0], G) in recs and n == run_name(k[0], G, rate=k[3]):
                kind = f"rate x{k[3]:g}" if k[3] < 1.0 else f"reported: faster loading x{k[3]:g}"
                out.append((kind, run_name(k[0], G), n, metrics.TOL_RATE_SPEED, G))
            # a larger size run only at a faster rate (the paper's size, `make bench-paper`): reported against the
            # largest size at the preset's rate, not part of the rule's size check (which is at the preset's rate)
            larger = plain and k[0] > plain[-1][0]
            if k[2] == G and k[1] == 0.3 and k[3] != 1.0 and larger and n == run_name(k[0], G, rate=k[3]):
                out.append((f"reported: larger size at rate x{k[3]:g}", plain[-1][1], n, metrics.TOL_MESH_SIZE, G))
    return out


def selection(recs: dict, checks: list) -> tuple[list[str], float | None]:
    """The rule: converged (size, mesh and a rate twin, each the same) and nearest PAPER_LEVEL by the (5,25] mean of
    the size pair, rods breaking. The table and the selected G (None: none yet)."""
    lines = ["| G | size | mesh | rate twin | (5,25] mean of the size pair | rods break | converged |", "|---|---|---|---|---|---|---|"]
    best = None
    for G in sorted({c[4] for c in checks} | {r["params"]["Gamma_k_over_sigma0sq"] for r in recs.values()}):
        mine = [c for c in checks if c[4] == G]
        verdicts = [(c[0], compare_line(*c[:3], recs, c[3])[1]) for c in mine]
        got = {kind: [ok for k, ok in verdicts if k.startswith(kind)] for kind in ("size", "mesh", "rate")}
        size_pair = [c for c in mine if c[0] == "size"]
        level_G = (np.mean([level(recs[n], *SELECT_WINDOW) for n in size_pair[0][1:3]]) if size_pair else math.nan)
        rods = bool(size_pair) and all(recs[n]["broken_rods"] > 0 for n in size_pair[0][1:3])
        status = {k: ("-" if not v else ("yes" if all(v) else "no")) for k, v in got.items()}
        conv = all(status[k] == "yes" for k in ("size", "mesh", "rate"))
        lines.append(f"| {G:g} | {status['size']} | {status['mesh']} | {status['rate']} | {fmt(level_G)} | "
                     f"{'yes' if rods else '-'} | {'**yes**' if conv else 'no'} |")
        if conv and rods and (best is None or abs(level_G - PAPER_LEVEL) < abs(best[1] - PAPER_LEVEL)):
            best = (G, level_G)
    tried = ", ".join(f"{g:g}" for g in sorted({r["params"]["Gamma_k_over_sigma0sq"] for r in recs.values()}))
    lines += ["", f"**Selected by the records so far: G = {best[0]:g}** ((5,25] mean {best[1]:.2f} against the paper's "
              f"~{PAPER_LEVEL:g}; values recorded: {tried})."
              if best else "**Selected: none yet** (no G is converged in size, mesh and rate by the records so far)."]
    return lines, (best[0] if best else None)


# ------------------------------------------------------------------------------------------- the validation
# The paper's statements (figures/paper_values.toml) at the selected G, each at the largest size run for its case
# (README, "Changes to the plan": '~' within 20%, '=' within 3%, '>=' as stated; trends by the summary table's rule).
VALIDATION_TOL = {"~": 0.20, "=": 0.03}
OURS = {"R_ss_over_Gamma": "(5,25] mean", "R_init_over_Gamma": "R_init", "da_first_rod_fracture_over_d": "first rod break"}


class Level:
    """A record as figures.summary_table.check_trends reads a result: params, R_init, and R_ss = the (5,25] mean."""
    def __init__(self, rec: dict):
        self.params, self.R_init, self.R_ss = cases.params_from_name(rec["case"]), rec["R_init"], level(rec, *SELECT_WINDOW)

    def param(self, key: str) -> float:
        return float(self.params[key])


def ours(rec: dict, quantity: str) -> float:
    if quantity == "R_ss_over_Gamma":
        return level(rec, *SELECT_WINDOW)
    if quantity == "R_init_over_Gamma":
        return rec["R_init"]
    return first_break(rec) if rec.get("rod_da") else math.inf   # no rod broke: none before any advance


ZONE_WARNING = "inelastic zone reached"   # the solver's warning when the zone comes within 2 d of the loaded edges


def zone_note(recs: list[dict]) -> str:
    """' (...)' naming the runs whose inelastic zone reached the loaded edges (their R may depend on the size),
    or ''."""
    hit = [r["name"] for r in recs if ZONE_WARNING in r.get("warnings", "")]
    return f" (inelastic zone at the loaded edges in {', '.join(hit)}: R may depend on the size)" if hit else ""


def value_verdict(v: dict, x: float) -> str:
    if v["relation"] == ">=":
        return "reproduced" if x >= v["value"] else "**not reproduced**"
    rel, tol = (x - v["value"]) / v["value"], VALIDATION_TOL[v["relation"]]
    return f"{'reproduced' if abs(rel) <= tol else '**not reproduced**'} ({pct(rel)}; tolerance {tol:.0%})"


def largest_per_case(recs: dict, G: float) -> dict[str, dict]:
    """{case: the record at G, h_e 0.3, the preset's rate and the largest size} of every case run at G."""
    out = {}
    for name, rec in recs.items():
        p = rec["params"]
        if (p["Gamma_k_over_sigma0sq"] == G and p["h_e_over_d"] == 0.3 and p["rate_factor"] == 1.0
                and name == run_name(p["w_s_over_d"], G, case=rec["case"])
                and p["w_s_over_d"] >= out.get(rec["case"], {}).get("params", {}).get("w_s_over_d", 0)):
            out[rec["case"]] = rec
    return out


def validation(recs: dict, G: float) -> list[str]:
    """The statements table and the trends at G, from the records."""
    pv, at = paper_values.paper_values(), largest_per_case(recs, G)
    lines = [f"At G = {G:g}, each case at the largest size run for it (the (5,25] mean stands for R_ss, as in the "
             "selection; theta30 (21.4, 10)'s R_ss ~ 7 is the selection's target, not a validation).", "",
             "| statement | paper | ours | run | verdict |", "|---|---|---|---|---|"]
    for v in pv["value"]:
        if v.get("case") in at and v["quantity"] in OURS:
            rec = at[v["case"]]
            fitted = " (the selection's own quantity: not a validation)" if (
                v["case"] == CASE and v["quantity"] == "R_ss_over_Gamma") else ""
            lines.append(f"| {v['id']}: {OURS[v['quantity']]} | {paper_values.paper_value_text(v)} | "
                         f"{fmt(ours(rec, v['quantity']))} | {rec['name']} | {value_verdict(v, ours(rec, v['quantity']))}{fitted}{zone_note([rec])} |")
    trends = {"trend": [t for t in pv["trend"] if t["quantity"] in ("R_init_over_Gamma", "R_ss_over_Gamma")]}
    rows = [f"| {t['id']} ({t['quantity']} against {t['against']}) | {label} | "
            f"{', '.join(f'{x:g}: {y:.3g}' for x, y in pts)} | {verdict} |"
            for t, series in summary_table.check_trends({n: Level(r) for n, r in at.items()}, trends)
            for label, pts, verdict in series if len(pts) >= 2]
    return (lines + pooled_rm_lines(at, pv)
            + (["", "| trend | series | points (x: y) | verdict |", "|---|---|---|---|"] + rows if rows else []))


CV_SERIES = dict(theta_D=30.0, sigma_ru_over_sigma0=28.5, Er_over_kd=10.0)   # Figs. 8-9's series


def pooled_rm_lines(at: dict, pv: dict) -> list[str]:
    """Fig. 9's pooled R_m (metrics.pooled_rm: all R points with 0 < Delta_a/d < 30 of the realisations run) of
    each cv group the paper states it for, from the largest-size records of the series' cases; one row per group,
    with the realisations it pools (a group of fewer realisations than the paper's five says how many)."""
    rows = []
    for v in pv["value"]:
        if v["quantity"] != "R_m_pooled_over_Gamma":
            continue
        group = [rec for case, rec in sorted(at.items())
                 if (p := cases.params_from_name(case)) and all(p[k] == x for k, x in CV_SERIES.items())
                 and any(math.isclose(p["cv"], c) for c in v["cv"])]
        if not group:
            continue
        rm, _, _ = metrics.pooled_rm([metrics.RCurve.of(r["da"], r["R"]) for r in group])
        cvs = ", ".join(f"{c:g}" for c in v["cv"])
        rows.append(f"| {v['id']}: pooled R_m (cv {cvs}; {len(group)} realisation{'s' * (len(group) != 1)}) | "
                    f"{paper_values.paper_value_text(v)} | {fmt(rm)} | {', '.join(r['name'] for r in group)} | "
                    f"{value_verdict(v, rm)}{zone_note(group)} |")
    return rows


def reading_of(rec: dict) -> str:
    """What a record changes from today's readings ("today's" when nothing), from the keys it recorded."""
    changed = [f"{k} = {v}" for k, v in rec.get("readings", {}).items()
               if v != READING_DEFAULTS.get(k, v)]
    return ", ".join(changed) if changed else "today's"


READING_DEFAULTS = {"shear_strength_ratio": 1.0, "grip_constraint": "uy", "grip_profile": "to_right_edge",
                    "crisscross_phase": 0.0}


def readings(recs: dict, G: float) -> list[str]:
    """The rule's second part at G: every theta30 (21.4, 10) run at G, h_e 0.3 and the preset's rate (today's
    readings and each changed one), with its first rod break and (5,25] mean. A reading qualifies when its first
    rod break is at or past READING_FIRST_BREAK and its mean within READING_LEVEL_TOL of PAPER_LEVEL."""
    lines = [f"At G = {G:g}, theta30 (21.4, 10), h_e 0.3, the preset's rate. A reading qualifies (README, Selection "
             f"rule) when the first rod break is at or past {READING_FIRST_BREAK:g} d and the (5,25] mean within "
             f"{READING_LEVEL_TOL:.0%} of {PAPER_LEVEL:g} ({PAPER_LEVEL * (1 - READING_LEVEL_TOL):.2f} to "
             f"{PAPER_LEVEL * (1 + READING_LEVEL_TOL):.2f}).", "",
             "| reading | run | size | first rod break | >= 2 d | **(5,25]** | within 15% of 7 | R_init | broken rods | qualifies |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    rows = []
    for name, rec in recs.items():
        p = rec["params"]
        if not (p["Gamma_k_over_sigma0sq"] == G and p["h_e_over_d"] == 0.3 and p["rate_factor"] == 1.0
                and p["w_s_over_d"] >= READING_MIN_SIZE and rec.get("case", CASE) == CASE
                and rec["meta"].get("status") == "completed"):
            continue
        plain = name == run_name(p["w_s_over_d"], G)
        if not plain and "readings" not in rec:
            continue    # a run with a change the record does not name: not a reading
        fb, lv = ours(rec, "da_first_rod_fracture_over_d"), level(rec, *SELECT_WINDOW)
        breaks_late = fb >= READING_FIRST_BREAK
        near = abs(lv - PAPER_LEVEL) <= READING_LEVEL_TOL * PAPER_LEVEL
        what = "today's" if plain else reading_of(rec)
        verdict = "-" if what == "today's" else ("**yes**" if breaks_late and near else "no")
        rows.append((what != "today's", what, p["w_s_over_d"], name,
                     f"| {what} | {name} | {p['w_s_over_d']:g} d | {fmt(fb)} | {'yes' if breaks_late else 'no'} | "
                     f"**{fmt(lv)}** | {'yes' if near else 'no'} ({pct((lv - PAPER_LEVEL) / PAPER_LEVEL)}) | "
                     f"{rec['R_init']:.3g} | {rec['broken_rods']} | "
                     f"{verdict} |"))
    if not any(r[0] for r in rows):
        return []
    good = [r[1] for r in rows if r[-1].endswith("| **yes** |")]
    end = (f"**Qualifying so far: {'; '.join(good)}.**" if good else
           "**No reading run so far qualifies: today's readings stay.**")
    return lines + [r[-1] for r in sorted(rows)] + ["", end]


def figure(recs: dict, out: pathlib.Path) -> None:
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 4.5))
    Gs = sorted({rec["params"]["Gamma_k_over_sigma0sq"] for rec in recs.values()})
    for name, rec in recs.items():   # colour: G; line: solid 100 d and larger, dashed smaller
        p = rec["params"]
        ls = "-" if p["w_s_over_d"] >= 100 else ("--" if p["w_s_over_d"] >= 80 else ":")
        ax.plot(rec["da"], rec["R"], ls, lw=1, label=name, color=f"C{Gs.index(p['Gamma_k_over_sigma0sq'])}")
    ax.axhline(PAPER_LEVEL, color="k", lw=0.8, ls=":", label=f"paper ~{PAPER_LEVEL:g}")
    ax.set_xlabel(r"$\Delta a / d$")
    ax.set_ylabel(r"$R / \Gamma_i$")
    ax.set_title("theta30 (21.4, 10), square specimens (records of research/square)")
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)


def size_figure(recs: dict, G: float, out: pathlib.Path) -> bool:
    """The R-curves of the study's case at G, h_e 0.3 d and no changed reading, at 80 x 80 d and larger (the paper's
    size among them when it has run): the size convergence at one glance. False when there are none."""
    shown = sorted(((rec["params"]["w_s_over_d"], name, rec) for name, rec in recs.items()
                    if rec["params"]["Gamma_k_over_sigma0sq"] == G and rec["params"]["h_e_over_d"] == 0.3
                    and rec["params"]["w_s_over_d"] >= READING_MIN_SIZE
                    and name == run_name(rec["params"]["w_s_over_d"], G, rate=rec["params"]["rate_factor"])))
    if not shown:
        return False
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 4.5))
    for i, (size, name, rec) in enumerate(shown):
        rate = rec["params"]["rate_factor"]
        label = f"{size:g} x {size:g} d" + (f", rate x{rate:g}" if rate != 1.0 else "") + \
            f": (0,30] mean {level(rec, 0.0, 30.0):.2f}, (5,25] {level(rec, *SELECT_WINDOW):.2f}"
        ax.plot(rec["da"], rec["R"], lw=1.2, color=f"C{i}", label=label)
    ax.axhline(PAPER_LEVEL, color="k", lw=0.8, ls=":", label=f"paper ~{PAPER_LEVEL:g}")
    ax.set_xlabel(r"$\Delta a / d$")
    ax.set_ylabel(r"$R / \Gamma_i$")
    ax.set_ylim(bottom=0)
    ax.set_title(f"theta30 (21.4, 10) at G = {G:g}, h_e = 0.3 d: square specimens of {len(shown)} sizes")
    ax.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return True


def report(data: pathlib.Path = DATA, readme: pathlib.Path = HERE / "README.md") -> str:
    """Rewrite everything below README's "## Results" from the records; the figure goes next to the README."""
    recs = load_records(data)
    study = {n: r for n, r in recs.items() if r.get("case", CASE) == CASE}   # the rest: validation cases
    checks = pairs(study)
    chosen, G = selection(study, checks)
    lines = ["", "Generated by `python3 -m research.square.square report` from `data/*.json`. R is R/Gamma_i averaged over",
             "crack advance in each window (d); the (5,25] mean decides the selection. The earlier studies' records",
             "judged by the same measure: [rejudged.md](rejudged.md).", "", "### Runs", ""]
    lines += run_rows(recs) + ["", "### Convergence checks (the measure; L2 and windows reported only)", ""]
    lines += PAIR_HEAD + [compare_line(*c[:3], recs, c[3])[0] for c in checks]
    lines += ["", "### Selection", ""] + chosen + [""]
    if G is not None and readings(study, G):   # (none until a changed reading has run)
        lines += ["### Readings (the selection rule's second part)", ""] + readings(study, G) + [""]
    if G is not None:
        lines += ["### Validation (reported, never fitted)", ""] + validation(recs, G) + [""]
    if study:
        figure(study, readme.parent / "rcurves.png")
        lines += ["![R-curves](rcurves.png)", ""]
    if G is not None and size_figure(study, G, readme.parent / "rcurves_sizes.png"):
        lines += ["At the selected G, the sizes side by side:", "", "![R-curves by size](rcurves_sizes.png)", ""]
    text = readme.read_text()
    head = text.split("\n## Results\n", 1)[0]
    readme.write_text(head + "\n## Results\n" + "\n".join(lines))
    return "\n".join(lines)


# ---------------------------------------------------------------------------------------------------- main
def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    sub = ap.add_subparsers(dest="cmd", required=True)
    r = sub.add_parser("run", help="run one case (one thread) and record it")
    r.add_argument("size", type=float, help="w_s = h_s, in d")
    r.add_argument("G", type=float, help="Gamma_k_over_sigma0sq")
    r.add_argument("--he", type=float, default=0.3, help="h_e_over_d (default 0.3)")
    r.add_argument("--rate", type=float, default=1.0, help="rate_factor (default 1)")
    r.add_argument("--set", action="append", default=[], help="further key=value for the solver (named in the run)")
    r.add_argument("--name", default="", help="suffix of the run's name (required with --set)")
    r.add_argument("--case", default=CASE, help=f"paper case (default {CASE}; another one is a validation run)")
    r.add_argument("--binary", default=str(paths.SOLVER))
    rec = sub.add_parser("record", help="record a finished run")
    rec.add_argument("run_dir", type=pathlib.Path)
    rec.add_argument("--name", default="", help="the record's name (default: the run folder's name)")
    sub.add_parser("report", help="README Results and rcurves.png from the records")
    a = ap.parse_args(argv)
    if a.cmd == "run":
        if a.set and not a.name:
            ap.error("--set needs --name (the run's name must say what differs)")
        if not paths.case_file(a.case).exists():
            ap.error(f"--case {a.case}: no such paper case ({paths.case_file(a.case)} missing)")
        name = run_name(a.size, a.G, a.he, a.rate, a.name, a.case)
        out = RUNS / name
        out.mkdir(parents=True, exist_ok=True)
        rc = subprocess.call(solver_args(a.binary, a.size, a.G, a.he, a.rate, out, a.set, a.case))
        print(f"square: solver exit {rc}; recorded {store(record_of(out, name))}")
        return rc
    if a.cmd == "record":
        print(store(record_of(a.run_dir, a.name or a.run_dir.name)))
        return 0
    print(report())
    return 0


if __name__ == "__main__":
    sys.exit(main())
