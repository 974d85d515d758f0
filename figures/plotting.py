"""Plotting shared by the figure scripts (and bench/): process-zone map and R-curve panels, the paper's numbers on
them, figure layouts, PDF + PNG output. Loading results, paths, case lists, paper values and metrics are in the
package enamel_results; this module only draws.
"""
from __future__ import annotations

import pathlib

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

from enamel_results import cases, cli, paths  # noqa: E402
from enamel_results.paper_values import (RELATION_SYMBOL, paper_value_text, paper_values, snapshot_da,  # noqa: E402
                                         values_for_case)
from enamel_results.results import TAG_INTER12, TAG_PLY1, TAG_PLY2, Frame, Result, convergence_label  # noqa: E402

# The map panels drawn from the interface tags.
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
    # the extent of the nodes only where the file has no w_s, h_s (a record's geometry holds few nodes, or none)
    ws = float(a["w_s"]) if "w_s" in a else float(g.node_position[:, 0].max())
    hs = float(a["h_s"]) if "h_s" in a else float(g.node_position[:, 1].max())
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
    a0, yc = a["a0_effective"], a.get("y_crack_plane")  # the tip Delta_a is measured from
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


def draw_paper_values(ax, values: list[dict]) -> None:
    """Paper numbers on an R-curve panel: R levels as horizontal dashed lines (a marker at the stated
    Delta_a where there is one), Delta_a events as vertical dotted lines. Every label starts with 'paper'."""
    for v in values:
        q, val, rel = v["quantity"], float(v["value"]), v.get("relation", "~")
        sym = RELATION_SYMBOL.get(rel, rel)
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


def preset_text(preset: str, results) -> str:
    """'preset ci, NOT size-converged (...)' for a figure's title: which preset, and whether its runs are
    size-converged (enamel_results.results.size_converged)."""
    return f"preset {preset}, {convergence_label(results)}"


def map_figure(script: str, fig_key: str, description: str, row_keys: tuple, suptitle: str) -> None:
    """Figs. 4, 5, 6: one row per case of the figure's table (figures/figN_<name>.toml): three process-zone maps and the R-curve,
    with the half-rate twin and the paper's numbers on the R-curve."""
    parser = cli.argument_parser(description, maps=True)
    args = parser.parse_args()
    names = cases.figure_cases(fig_key)
    results = cli.load_cases(script, args, names, full=True)
    slows = cli.load_cases(script, args, [c for c in cases.slow_cases(fig_key) if c in results], slow=True)
    pv = paper_values()
    da = args.da if args.da is not None else snapshot_da(fig_key, pv)
    shown = [c for c in names if c in results]
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
    fig.suptitle(f"{suptitle} ({preset_text(args.preset, results.values())};\nmaps at the frame nearest "
                 f"$\\Delta a/d$ = {da:g})",
                 fontsize=11)
    save(fig, args.preset, pathlib.Path(script).stem, args.out)
