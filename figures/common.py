"""Shared code of the figure scripts: load a result file, read figures.toml and paper_values.toml, draw the
process-zone map and R-curve panels, save PDF + PNG. Reads only HDF5 results (solver/lib/output.cpp writes them).

Normalisation everywhere: crack advance Delta_a by the rod spacing d, crack resistance R by the interface
fracture energy Gamma_i, rod strength by the interface strength sigma0.
"""
from __future__ import annotations

import argparse
import dataclasses
import math
import pathlib
import re
import sys

import matplotlib

matplotlib.use("Agg")
import h5py  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import paths  # noqa: E402

try:  # Python >= 3.11
    import tomllib as _toml
except ModuleNotFoundError:  # pragma: no cover - older interpreters: Debian python3-tomli or python3-toml
    try:
        import tomli as _toml
    except ModuleNotFoundError:
        _toml = None

# Exit status when a result file is missing (as the solver's MISSING_FILE, solver/lib/exit_codes.hpp).
EXIT_MISSING = 3

# Delta_a/d of the process-zone maps when the paper does not say (it says 15 for Fig. 5, paper_values.toml).
DEFAULT_SNAPSHOT_DA = 15.0

# Interface tags (/geometry/iface_tag) and the map panels drawn from them.
TAG_PLY1, TAG_PLY2, TAG_INTER12, TAG_INTER21 = 0, 1, 2, 3
MAP_PANELS = (  # (title, interface tag, node_ply of the rod elements drawn, None: none)
    ("ply 1 ($+\\theta_D$)", TAG_PLY1, 0),
    ("interlayer 1-2", TAG_INTER12, None),
    ("ply 2 ($-\\theta_D$)", TAG_PLY2, 1),
)
STATE_STYLE = (  # iface_state 0, 1, 2: (label, colour, drawing order)
    ("elastic interface", "#d4d4d4", 1),
    ("inelastic interface (process zone)", "#f28e1c", 2),
    ("failed interface", "#d62728", 3),
)
PAPER_STYLE = dict(color="black", linestyle="--", linewidth=1.0)
PARAM_KEYS = ("theta_D", "sigma_ru_over_sigma0", "Er_over_kd", "cv", "seed")


# ------------------------------------------------------------------------------------------------ TOML
def load_toml(path) -> dict:
    if _toml is None:
        raise SystemExit("no TOML reader: needs Python >= 3.11 (tomllib) or the Debian package python3-tomli")
    with open(path, "rb") as f:
        return _toml.load(f)


def parse_toml(text: str) -> dict:
    if _toml is None:
        raise SystemExit("no TOML reader: needs Python >= 3.11 (tomllib) or the Debian package python3-tomli")
    return _toml.loads(text)


def figure_list() -> dict:
    """paper_cases/figures.toml: {fig: {"cases": [...], "slow": [...]}}."""
    return load_toml(paths.FIGURE_LIST)


def figure_cases(fig: str) -> list[str]:
    return list(figure_list()[fig]["cases"])


def slow_cases(fig: str) -> list[str]:
    return list(figure_list()[fig].get("slow", []))


def paper_values() -> dict:
    """figures/paper_values.toml: {"value": [...], "trend": [...], "snapshot": [...]}."""
    pv = load_toml(paths.PAPER_VALUES)
    pv.setdefault("value", [])
    pv.setdefault("trend", [])
    pv.setdefault("snapshot", [])
    return pv


def values_for_case(case: str, figure: str | None = None, pv: dict | None = None) -> list[dict]:
    """Stated numbers for one case (entries with `case`), optionally only those a figure draws."""
    pv = pv or paper_values()
    return [v for v in pv["value"] if v.get("case") == case and (figure is None or figure in v["figures"])]


def values_for_cv(cv: float, quantity: str | None = None, pv: dict | None = None) -> list[dict]:
    """Stated pooled numbers (entries with `cv`) that apply to one coefficient of variation."""
    pv = pv or paper_values()
    return [v for v in pv["value"] if "cv" in v and any(math.isclose(cv, c) for c in v["cv"])
            and (quantity is None or v["quantity"] == quantity)]


def snapshot_da(figure: str, pv: dict | None = None) -> float:
    """The Delta_a/d of a figure's process-zone maps: the paper's where stated, else DEFAULT_SNAPSHOT_DA."""
    pv = pv or paper_values()
    for s in pv["snapshot"]:
        if s["figure"] == figure:
            return float(s["da_over_d"])
    return DEFAULT_SNAPSHOT_DA


# ------------------------------------------------------------------------------------------------ results
class MissingResult(Exception):
    def __init__(self, path: pathlib.Path):
        super().__init__(str(path))
        self.path = pathlib.Path(path)


@dataclasses.dataclass
class Frame:
    index: int
    target_da: float        # requested Delta_a/d (-1: the final state)
    da: float               # Delta_a/d reached when it was written
    step: int
    iface_state: np.ndarray     # 0 elastic, 1 inelastic, 2 failed (per interface)
    iface_damage: np.ndarray    # 1 - secant stiffness / k
    beam_broken: np.ndarray     # 1 = rod element deleted
    node_displacement: np.ndarray  # (nodes, 6): ux uy uz rx ry rz, d and rad


@dataclasses.dataclass
class Geometry:
    node_position: np.ndarray   # (nodes, 3), d
    node_ply: np.ndarray
    beam_nodes: np.ndarray      # (beams, 2)
    beam_strength: np.ndarray   # (beams,), sigma0
    iface_nodes: np.ndarray     # (ifaces, 2)
    iface_tag: np.ndarray
    iface_midpoint: np.ndarray  # (ifaces, 3), d
    iface_zshift: np.ndarray
    attrs: dict                 # w_s, h_s, a0, y_crack_plane, theta_D_deg, ...


@dataclasses.dataclass
class Result:
    path: pathlib.Path
    case: str
    params: dict            # the effective case (parsed /meta case_toml)
    meta: dict              # /meta attributes
    da: np.ndarray          # /rcurve/da_over_d
    R: np.ndarray           # /rcurve/R_over_Gamma
    R_init: float
    R_ss: float
    R_m: float
    dR_m: float
    da_max: float
    broken_rods: int        # last /history/broken_rod_elements
    da_first_rod_fracture: float  # Delta_a/d at the first history row with a broken rod element (nan: none)
    geometry: Geometry | None = None
    frames: list[Frame] | None = None

    @property
    def status(self) -> str:
        return str(self.meta.get("status", "unknown"))

    @property
    def completed(self) -> bool:
        return self.status == "completed"

    @property
    def wall_time_s(self) -> float:
        return float(self.meta.get("wall_time_s", math.nan))

    def param(self, key: str) -> float:
        return float(self.params[key])

    def frame_near(self, da: float) -> Frame:
        """The written frame whose requested Delta_a/d is nearest `da` (the final-state frame if none)."""
        targeted = [f for f in self.frames if f.target_da >= 0]
        if not targeted:
            return self.frames[-1]
        return min(targeted, key=lambda f: (abs(f.target_da - da), -f.target_da))


def _attrs(obj) -> dict:
    out = {}
    for k, v in obj.attrs.items():
        if isinstance(v, bytes):
            v = v.decode()
        elif isinstance(v, np.generic):
            v = v.item()
        out[k] = v
    return out


def params_from_name(case: str) -> dict:
    """Parameters from a paper case name, e.g. theta30_s28.5_e10_cv0.1_seed2 (fallback when /meta lacks them)."""
    m = re.match(r"theta([\d.]+)_s([\d.]+)_e([\d.]+)_cv([\d.]+)(?:_seed(\d+))?", case)
    if not m:
        return {}
    return dict(theta_D=float(m[1]), sigma_ru_over_sigma0=float(m[2]), Er_over_kd=float(m[3]), cv=float(m[4]),
                seed=int(m[5] or 1))


def load_result(path, case: str | None = None, full: bool = False) -> Result:
    """Read one result.h5. `full` also reads /geometry and every /frames/<n> (for maps and VTK export)."""
    path = pathlib.Path(path)
    if not path.is_file():
        raise MissingResult(path)
    with h5py.File(path, "r") as f:
        meta = _attrs(f["meta"])
        rc = _attrs(f["rcurve"])
        case = case or meta.get("case_source", path.parent.name)
        case = pathlib.Path(case).stem if case.endswith(".toml") else case
        params = params_from_name(case)
        try:
            params.update({k: v for k, v in parse_toml(meta.get("case_toml", "")).items()})
        except Exception:  # a damaged case_toml: keep the name's parameters
            pass
        h = f["history"]
        broken = h["broken_rod_elements"][:]
        hda = h["da_over_d"][:]
        first = float(hda[np.argmax(broken > 0)]) if broken.size and broken.max() > 0 else math.nan
        res = Result(path=path, case=case, params=params, meta=meta,
                     da=f["rcurve/da_over_d"][:], R=f["rcurve/R_over_Gamma"][:],
                     R_init=float(rc.get("R_init_over_Gamma", math.nan)),
                     R_ss=float(rc.get("R_ss_over_Gamma", math.nan)),
                     R_m=float(rc.get("R_m_over_Gamma", math.nan)),
                     dR_m=float(rc.get("dR_m_over_Gamma", math.nan)),
                     da_max=float(rc.get("da_max_over_d", math.nan)),
                     broken_rods=int(broken[-1]) if broken.size else 0,
                     da_first_rod_fracture=first)
        if full:
            g = f["geometry"]
            res.geometry = Geometry(
                node_position=g["node_position"][:], node_ply=g["node_ply"][:], beam_nodes=g["beam_nodes"][:],
                beam_strength=g["beam_strength_over_sigma0"][:], iface_nodes=g["iface_nodes"][:],
                iface_tag=g["iface_tag"][:], iface_midpoint=g["iface_midpoint"][:],
                iface_zshift=g["iface_zshift"][:], attrs=_attrs(g))
            frames = []
            for name in sorted(f["frames"], key=int):
                fg = f["frames"][name]
                a = _attrs(fg)
                frames.append(Frame(index=int(name), target_da=float(a["target_da_over_d"]),
                                    da=float(a["da_over_d"]), step=int(a["step"]),
                                    iface_state=fg["iface_state"][:], iface_damage=fg["iface_damage"][:],
                                    beam_broken=fg["beam_broken"][:],
                                    node_displacement=fg["node_displacement"][:]))
            res.frames = frames
    return res


def rcurve_rel_l2(da_ref, R_ref, da, R, points: int = 50) -> float:
    """Relative L2 difference of an R-curve from a reference one over their common Delta_a range."""
    da_ref, R_ref, da, R = map(np.asarray, (da_ref, R_ref, da, R))
    grid = np.linspace(max(da_ref[0], da[0]), min(da_ref[-1], da[-1]), points)
    a, b = np.interp(grid, da_ref, R_ref), np.interp(grid, da, R)
    return float(np.sqrt(np.mean((a - b) ** 2)) / np.sqrt(np.mean(a ** 2)))


def pooled_rm(results: list[Result], lo: float = 0.0, hi: float = 30.0) -> tuple[float, float, int]:
    """Fig. 9: mean and standard deviation of all R points with lo < Delta_a/d < hi, pooled over realisations."""
    pts = np.concatenate([r.R[(r.da > lo) & (r.da < hi)] for r in results]) if results else np.array([])
    if pts.size == 0:
        return math.nan, math.nan, 0
    return float(pts.mean()), float(pts.std()), int(pts.size)


# ------------------------------------------------------------------------------------------------ CLI
def argument_parser(description: str, maps: bool = False) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(description=description,
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--preset", default="reduced",
                   help="preset whose results are read: runs/PRESET/<case>/result.h5 (default: reduced)")
    p.add_argument("--runs", type=pathlib.Path, default=None,
                   help=f"root of the result files instead of {paths.RUNS} (tests)")
    p.add_argument("--out", type=pathlib.Path, default=None,
                   help=f"root of the output instead of {paths.FIGURES_OUT}; files go to OUT/PRESET/")
    p.add_argument("--allow-missing", action="store_true",
                   help="draw what exists and skip missing result files (default: a missing file is an error)")
    if maps:
        p.add_argument("--da", type=float, default=None,
                       help="Delta_a/d of the process-zone maps: the frame written nearest this advance "
                            "(default: the paper's, or %g)" % DEFAULT_SNAPSHOT_DA)
    return p


def fail_missing(script: str, missing: list[pathlib.Path], preset: str) -> None:
    """One clear line on stderr naming the missing file and the command that produces it; exit non-zero."""
    script = pathlib.Path(script).name
    more = f" (and {len(missing) - 1} more)" if len(missing) > 1 else ""
    print(f"{script}: missing result file {missing[0]}{more}: run `{paths.make_command(preset)}` to produce it",
          file=sys.stderr)
    sys.exit(EXIT_MISSING)


def load_cases(script: str, args, cases: list[str], full: bool = False, slow: bool = False) -> dict:
    """{case: Result} for the cases that exist; a missing file ends the script unless --allow-missing
    (slow twins are optional: missing ones are skipped silently)."""
    out, missing = {}, []
    for c in cases:
        p = paths.result_file(args.preset, c, slow=slow, runs=args.runs)
        try:
            out[c] = load_result(p, case=c, full=full)
        except MissingResult:
            missing.append(p)
    if missing and not slow:
        if args.allow_missing:
            for p in missing:
                print(f"{pathlib.Path(script).name}: warning: skipping missing {p}", file=sys.stderr)
        else:
            fail_missing(script, missing, args.preset)
    if not out and not slow:
        fail_missing(script, missing, args.preset)
    return out


def status_flag(r: Result) -> str:
    return "" if r.completed else f" [NOT COMPLETED: {r.status}]"


def case_label(r: Result, keys=("theta_D", "sigma_ru_over_sigma0", "Er_over_kd")) -> str:
    names = dict(theta_D="$\\theta_D$ = %g°", sigma_ru_over_sigma0="$\\sigma_{ru}/\\sigma_0$ = %g",
                 Er_over_kd="$E_r/kd$ = %g", cv="cv = %g", seed="seed %d")
    return ", ".join(names[k] % r.params[k] for k in keys if k in r.params)


def save(fig, preset: str, stem: str, out=None) -> list[pathlib.Path]:
    return save_to(fig, paths.figure_dir(preset, out), stem)


def save_to(fig, directory: pathlib.Path, stem: str) -> list[pathlib.Path]:
    """Write fig as DIRECTORY/STEM.pdf and .png (150 dpi), close it, print and return the paths."""
    directory.mkdir(parents=True, exist_ok=True)
    written = []
    for ext in ("pdf", "png"):
        p = directory / f"{stem}.{ext}"
        fig.savefig(p, dpi=150 if ext == "png" else None, bbox_inches="tight")
        written.append(p)
    plt.close(fig)
    for p in written:
        print(p)
    return written


# ------------------------------------------------------------------------------------------------ panels
def draw_process_zone(ax, r: Result, frame: Frame, tag: int, ply: int | None, title: str = "") -> None:
    """Interfaces of one tag at their midpoints (x horizontal, y vertical, reference configuration) coloured
    by state, and the deleted rod elements of one ply (None: none) as black segments between their nodes."""
    g = r.geometry
    a = g.attrs
    ws, hs = float(a.get("w_s", g.node_position[:, 0].max())), float(a.get("h_s", g.node_position[:, 1].max()))
    sel = g.iface_tag == tag
    mid = g.iface_midpoint[sel]
    state = frame.iface_state[sel]
    ax.set_xlim(0, ws)
    ax.set_ylim(0, hs)
    ax.set_aspect("equal")
    # marker about 0.3 d across (the slice spacing), at least 0.6 pt
    fig = ax.figure
    width_pt = ax.get_position().width * fig.get_figwidth() * 72
    diam = max(0.6, 0.3 * width_pt / ws)
    for s, (label, colour, z) in enumerate(STATE_STYLE):
        m = state == s
        if m.any():
            ax.scatter(mid[m, 0], mid[m, 1], s=diam ** 2, c=colour, marker="o", linewidths=0, zorder=z,
                       rasterized=True)
    if ply is not None:
        bn = g.beam_nodes
        m = (frame.beam_broken > 0) & (g.node_ply[bn[:, 0]] == ply)
        if m.any():
            X = g.node_position
            segs = np.stack([X[bn[m, 0], :2], X[bn[m, 1], :2]], axis=1)
            ax.add_collection(LineCollection(segs, colors="black", linewidths=max(1.2, 0.25 * width_pt / ws),
                                             zorder=4))
    a0, yc = a.get("a0"), a.get("y_crack_plane")
    if a0 is not None and yc is not None:
        ax.plot([0, a0], [yc, yc], color="#1f77b4", linewidth=1.0, zorder=5)
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("$x/d$")
    ax.set_ylabel("$y/d$")
    ax.tick_params(labelsize=7)


def map_legend_handles() -> list:
    hs = [Line2D([], [], marker="o", linestyle="", color=c, label=l, markersize=6) for l, c, _ in STATE_STYLE]
    hs.append(Line2D([], [], color="black", linewidth=2, label="deleted rod element"))
    hs.append(Line2D([], [], color="#1f77b4", linewidth=1, label="pre-crack"))
    return hs


def draw_rcurve(ax, r: Result, label: str | None = None, **style) -> None:
    style = {"marker": "o", "markersize": 2.5, "linewidth": 1.2, **style}
    ax.plot(r.da, r.R, label=label, **style)


def format_rcurve_axes(ax, title: str = "") -> None:
    ax.set_xlabel("crack advance $\\Delta a/d$")
    ax.set_ylabel("crack resistance $R/\\Gamma_i$")
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    if title:
        ax.set_title(title, fontsize=9)


_QLABEL = dict(R_init_over_Gamma="$R_{init}$", R_ss_over_Gamma="$R_{ss}$", R_m_pooled_over_Gamma="$\\bar R_m$",
               dR_m_pooled_over_Gamma="$\\Delta R_m$")


def paper_value_text(v: dict) -> str:
    """'≈ 7', '= 4/3', '≈ 5.95 (on the order of 50% below 11.9)' for a paper_values.toml entry."""
    sym = {"=": "=", "~": "≈", ">=": "≥"}.get(v.get("relation", "~"), v.get("relation", ""))
    text = str(v.get("value_text", v["value"])).replace("approx ", "")
    if v.get("derived"):
        return f"{sym} {float(v['value']):.3g} ({text})"
    return f"{sym} {text}"


def draw_paper_values(ax, values: list[dict]) -> None:
    """Paper numbers on an R-curve panel: R levels as horizontal dashed lines (a marker at the stated
    Delta_a where there is one), Delta_a events as vertical dotted lines. Every label starts with 'paper'."""
    for v in values:
        q, val, rel = v["quantity"], float(v["value"]), v.get("relation", "~")
        sym = {"=": "=", "~": "≈", ">=": "≥"}.get(rel, rel)
        if q.startswith("R_") or q.startswith("dR_"):
            if q.startswith("dR_"):
                continue  # a spread, not a level on the R-curve
            ax.axhline(val, label=f"paper: {_QLABEL.get(q, q)}/$\\Gamma_i$ {paper_value_text(v)}", **PAPER_STYLE)
            ax.update_datalim([(0.0, 1.1 * val)])  # keep the paper's level clear of the top edge
            if "at_da_over_d" in v:
                ax.plot([v["at_da_over_d"]], [val], marker="s", color="black", markerfacecolor="none",
                        linestyle="")
        elif q.startswith("da_"):
            what = {"da_first_rod_fracture_over_d": "first rod fracture",
                    "da_R_plateau_end_over_d": "R rises again"}.get(q, q)
            text = (f"{what} not before $\\Delta a/d$ = {val:.3g}" if rel == ">="
                    else f"{what} at $\\Delta a/d$ {sym} {val:.3g}")
            ax.axvline(val, color="black", linestyle=":", linewidth=1.0, label=f"paper: {text}")


# ------------------------------------------------------------------------------------------------ figures
def map_row_layout(rows: int, geometry_attrs: dict):
    """A figure of `rows` rows x (3 maps + 1 R-curve); map panels keep the specimen's aspect ratio."""
    ws, hs = float(geometry_attrs.get("w_s", 2)), float(geometry_attrs.get("h_s", 1))
    map_w = 3.6
    row_h = max(map_w * hs / ws, 2.3) + 0.9
    fig = plt.figure(figsize=(4 * map_w + 0.6, rows * row_h + 0.8), layout="constrained")
    axes = fig.subplots(rows, 4, squeeze=False, gridspec_kw=dict(width_ratios=[1, 1, 1, 1.05]))
    return fig, axes


def draw_map_row(axes_row, r: Result, da: float, row_label: str) -> Frame:
    """Three process-zone maps (ply 1, interlayer 1-2, ply 2) of the frame nearest `da`."""
    frame = r.frame_near(da)
    for ax, (name, tag, ply) in zip(axes_row, MAP_PANELS):
        draw_process_zone(ax, r, frame, tag, ply, title=f"{name} at $\\Delta a/d$ = {frame.da:.2f}")
    axes_row[0].set_ylabel(f"{row_label}\n$y/d$", fontsize=9)
    return frame


def title_with_status(ax, text: str, r: Result) -> None:
    flag = status_flag(r)
    ax.set_title(text + flag, fontsize=9, color="red" if flag else "black")


def map_figure(script: str, fig_key: str, description: str, row_keys: tuple, suptitle: str) -> None:
    """Figs. 4, 5, 6: one row per case of figures.toml [fig_key]: three process-zone maps and the R-curve,
    with the half-rate twin and the paper's numbers on the R-curve."""
    parser = argument_parser(description, maps=True)
    args = parser.parse_args()
    cases = figure_cases(fig_key)
    results = load_cases(script, args, cases, full=True)
    slows = load_cases(script, args, [c for c in slow_cases(fig_key) if c in results], slow=True)
    pv = paper_values()
    da = args.da if args.da is not None else snapshot_da(fig_key, pv)
    shown = [c for c in cases if c in results]
    fig, axes = map_row_layout(len(shown), results[shown[0]].geometry.attrs)
    for row, c in zip(axes, shown):
        r = results[c]
        draw_map_row(row, r, da, case_label(r, row_keys))
        ax = row[3]
        draw_rcurve(ax, r, label=f"{args.preset} preset", color="C0")
        if c in slows:
            draw_rcurve(ax, slows[c], label="half loading rate", color="C1", linestyle="--", marker="x")
        draw_paper_values(ax, values_for_case(c, fig_key, pv))
        format_rcurve_axes(ax)
        title_with_status(ax, case_label(r), r)
        ax.legend(fontsize=7, loc="best")
    fig.legend(handles=map_legend_handles(), loc="upper center", bbox_to_anchor=(0.5, 0.0), ncol=5, fontsize=8,
               frameon=False)
    fig.suptitle(f"{suptitle} (preset {args.preset}; maps at the frame nearest $\\Delta a/d$ = {da:g})",
                 fontsize=11)
    save(fig, args.preset, pathlib.Path(script).stem, args.out)
