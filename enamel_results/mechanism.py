"""Measures of the fracture mechanism, each a pure function of a loaded R-curve or of one frame of a run: how far
the crack advances before R levels off, the inelastic zone, the kinks along the rods at the tip, the crack's
offset from its plane, the crack path's segments and rod breaks far from the crack.

Where the frames come from: a result file (results.load_result(path, full=True)) holds every frame the run wrote
with each interface's state and damage; a run record (records.load_record(path, full=True)) holds the frame nearest
each figure's snapshot (Delta_a ~ 15 d) with each interface's state only, and only the interfaces of ply 1, ply 2
and interlayer 1-2 (records.MAP_TAGS). Every measure here reads the state alone (0 elastic, 1 inelastic: past
delta0 and softening, 2 failed), so it gives the same number from a run's file and from its record, over the tags
the record holds. Positions are the interfaces' midpoints (x: the slice's), in d; the crack plane is
/geometry's y_crack_plane and the tip is a0_effective + Delta_a (crack_tip_x).

In a ply, all rods run at one angle (ply 1 at +theta_D, ply 2 at -theta_D) and every interface of that ply lies on
the gap between two neighbouring rods: a straight line y = c + x tan(+-theta_D) through the slices. A crack in a
ply that breaks no rod runs along such a gap: a kink. The crack path in a ply is thus a chain of runs, each a run
of failed interfaces in consecutive slices along one gap, joined where rods break (gap_runs).
"""
from __future__ import annotations

import dataclasses
import math

import numpy as np

from enamel_results.metrics import RCurve, advance_mean
from enamel_results.results import TAG_PLY1, TAG_PLY2

INELASTIC, FAILED = 1, 2        # interface states (results.Frame.iface_state)
GAP_TOL = 1e-3                  # interfaces within this (d) of one gap line are on it (gaps are ~d apart)
ON_PLANE_TOL = 1e-6             # a node within this of the crack plane counts as above it (docs/model.md)


# ------------------------------------------------------------------------------------------ the R-curve
def rise_length(curve: RCurve, frac: float = 0.9, level: tuple = (5.0, 25.0)) -> float:
    """The crack advance at which R first reaches `frac` of its level, the mean of R over crack advance over
    (level[0], level[1]] (metrics.advance_mean), R linear between the curve's points (a step, two points at one
    Delta_a, crosses at that Delta_a). nan when the curve does not cover the window (it starts after level[0] or
    ends before level[1]) or never reaches frac x the level."""
    lo, hi = level
    if curve.da[0] > lo or curve.da[-1] < hi:
        return math.nan
    target = frac * advance_mean(curve, lo, hi)
    reached = np.flatnonzero(curve.R >= target)
    if reached.size == 0:
        return math.nan
    i = int(reached[0])
    if i == 0:
        return float(curve.da[0])
    r0, r1, a0, a1 = curve.R[i - 1], curve.R[i], curve.da[i - 1], curve.da[i]
    return float(a0 + (target - r0) / (r1 - r0) * (a1 - a0))


def interface_advance(curve: RCurve, first_rod_da: float) -> float:
    """The crack advance reached before the first rod element broke (first_rod_da; nan: none broke), that is
    through interfaces alone: the largest Delta_a of the curve below first_rod_da (0 when the first rod broke
    before the crack advanced; the curve's last Delta_a when no rod broke)."""
    if math.isnan(first_rod_da):
        return float(curve.da[-1])
    before = curve.da[curve.da < first_rod_da]
    return float(before.max()) if before.size else 0.0


# ------------------------------------------------------------------------------------------ one frame
def crack_tip_x(frame, geometry) -> float:
    """The crack tip's x in d: the pre-crack's tip a0_effective plus the frame's crack advance."""
    return float(geometry.attrs["a0_effective"]) + float(frame.da)


def _interfaces(frame, geometry, tags=None, states=(INELASTIC, FAILED)) -> np.ndarray:
    """Indices of the interfaces of `tags` (default: every tag the geometry has) in one of `states`."""
    keep = np.isin(frame.iface_state, states)
    if tags is not None:
        keep &= np.isin(geometry.iface_tag, tags)
    return np.flatnonzero(keep)


@dataclasses.dataclass(frozen=True)
class Zone:
    """The inelastic zone of one frame: the interfaces past delta0 (inelastic or failed)."""
    count: int
    height: float       # the largest |y - y_crack_plane| of them (d; 0 when there are none)
    ahead: float        # how far the farthest of them lies ahead of the tip along x (d; 0 when none is ahead)
    x_min: float        # their extent along x (d; nan when there are none)
    x_max: float


def inelastic_zone(frame, geometry, tip_x: float | None = None, margin: float = 0.0, tags=None) -> Zone:
    """The inelastic zone: every interface past delta0 (state inelastic or failed) of `tags` (default: all the
    geometry has), leaving out those within `margin` d of the specimen's edges (x = 0, x = w_s, y = 0, y = h_s:
    interfaces that soften at the loaded edges, apart from the crack's zone). tip_x defaults to crack_tip_x."""
    tip_x = crack_tip_x(frame, geometry) if tip_x is None else tip_x
    idx = _interfaces(frame, geometry, tags)
    x, y = geometry.iface_midpoint[idx, 0], geometry.iface_midpoint[idx, 1]
    if margin > 0:
        w, h = float(geometry.attrs["w_s"]), float(geometry.attrs["h_s"])
        inside = (x >= margin) & (x <= w - margin) & (y >= margin) & (y <= h - margin)
        x, y = x[inside], y[inside]
    if x.size == 0:
        return Zone(0, 0.0, 0.0, math.nan, math.nan)
    yc = float(geometry.attrs["y_crack_plane"])
    return Zone(int(x.size), float(np.abs(y - yc).max()), float(max(x.max() - tip_x, 0.0)), float(x.min()),
                float(x.max()))


@dataclasses.dataclass(frozen=True)
class Offset:
    """Where a frame's failed interfaces lie about the crack plane: their mean signed offset y - y_crack_plane
    (near 0 for a crack symmetric about its plane, two mirrored kinks; far from 0 for one that runs off to one
    side), the largest |offset|, and how many there are."""
    mean: float
    max_abs: float
    count: int


def crack_offset(frame, geometry, tags=None) -> Offset:
    """The offset of the failed interfaces of `tags` (default: all) from the crack plane (nan when none failed)."""
    idx = _interfaces(frame, geometry, tags, states=(FAILED,))
    if idx.size == 0:
        return Offset(math.nan, math.nan, 0)
    off = geometry.iface_midpoint[idx, 1] - float(geometry.attrs["y_crack_plane"])
    return Offset(float(off.mean()), float(np.abs(off).max()), int(idx.size))


def far_rod_breaks(frame, geometry, tip_x: float, distance: float) -> int:
    """The deleted rod elements farther than `distance` (d) from the crack's straight line, the crack plane from
    the left edge to the tip (tip_x): rods broken away from the main crack while it keeps near its plane (daughter
    cracks). An element stands at the midpoint of its two nodes."""
    broken = np.asarray(frame.beam_broken) > 0
    if not broken.any():
        return 0
    nodes = geometry.beam_nodes[broken]
    mid = 0.5 * (geometry.node_position[nodes[:, 0], :2] + geometry.node_position[nodes[:, 1], :2])
    dx = np.maximum(mid[:, 0] - tip_x, 0.0)
    dy = mid[:, 1] - float(geometry.attrs["y_crack_plane"])
    return int(np.count_nonzero(np.hypot(dx, dy) > distance))


# ------------------------------------------------------------------------------------------ runs along the gaps
@dataclasses.dataclass(frozen=True)
class Run:
    """A run of interfaces of one ply in consecutive slices along one gap between two rods."""
    gap: float          # the gap line's intercept c (y = c + slope x), d
    x_start: float      # the first and last interface's x (slices), d
    x_end: float
    y_start: float      # their y offsets from the crack plane, d
    y_end: float
    count: int


def ply_slope(geometry, tag: int) -> float:
    """dy/dx of the rods, and so of the gaps, of a ply: +tan(theta_D) for ply 1, -tan(theta_D) for ply 2."""
    t = math.tan(math.radians(float(geometry.attrs["theta_D_deg"])))
    return {TAG_PLY1: t, TAG_PLY2: -t}[tag]


def gap_runs(frame, geometry, tag: int, states=(FAILED,)) -> list[Run]:
    """The runs of one ply's interfaces in `states`: grouped by gap line (intercepts within GAP_TOL), split where
    a slice is missing; in order of x_start."""
    idx = _interfaces(frame, geometry, (tag,), states)
    if idx.size == 0:
        return []
    slope, yc = ply_slope(geometry, tag), float(geometry.attrs["y_crack_plane"])
    x, y = geometry.iface_midpoint[idx, 0], geometry.iface_midpoint[idx, 1]
    c, k = y - slope * x, np.asarray(geometry.iface_slice)[idx]
    by_c = np.argsort(c, kind="stable")
    gap = np.empty(idx.size, dtype=np.int64)
    gap[by_c] = np.cumsum(np.concatenate(([True], np.diff(c[by_c]) > GAP_TOL)))
    order = np.lexsort((k, gap))
    gap, c, k, x, y = gap[order], c[order], k[order], x[order], y[order]
    cut = np.flatnonzero(np.concatenate(([True], (np.diff(gap) != 0) | (np.diff(k) != 1))))
    ends = np.append(cut[1:], idx.size)
    runs = [Run(float(c[a:b].mean()), float(x[a]), float(x[b - 1]), float(y[a] - yc), float(y[b - 1] - yc), b - a)
            for a, b in zip(cut, ends)]
    return sorted(runs, key=lambda r: (r.x_start, r.gap))


def path_runs_per_d(frame, geometry, tip_x: float | None = None) -> float:
    """How often the crack path in the plies changes gap: the runs of failed interfaces of ply 1 and ply 2 (each
    a kink between rod breaks) per d of crack advance, averaged over the two plies (nan with no advance)."""
    tip_x = crack_tip_x(frame, geometry) if tip_x is None else tip_x
    advance = tip_x - float(geometry.attrs["a0_effective"])
    if advance <= 0:
        return math.nan
    return float(np.mean([len(gap_runs(frame, geometry, tag)) for tag in (TAG_PLY1, TAG_PLY2)]) / advance)


def run_period(runs: list[Run], h_e: float) -> float:
    """The period of a sawtooth path: the median spacing along x of its runs' starts (starts within half a slice
    are one); nan with fewer than two."""
    starts = np.unique(np.round(np.array([r.x_start for r in runs]) / (0.5 * h_e)))
    return float(np.median(np.diff(starts)) * 0.5 * h_e) if starts.size >= 2 else math.nan


# ------------------------------------------------------------------------------------------ kinks
@dataclasses.dataclass(frozen=True)
class Kink:
    """One ply's kink at the crack tip: the run of failed interfaces along one gap that ends nearest the tip, and
    the interfaces past delta0 that continue it along the same gap ahead (softened, not yet failed). Lengths are
    projected on x and resolved to one slice h_e, finer than the crisscross spacing d/sin(theta_D)."""
    tag: int
    count: int              # failed interfaces in the run (0: no kink; the rest nan)
    x_start: float
    x_end: float
    length: float           # x_end - x_start + h_e: each interface stands for its slice
    offset_start: float     # y - y_crack_plane at the run's ends, d
    offset_end: float
    softened_ahead: float   # the projected extent of the inelastic interfaces continuing the run's gap past x_end


def _tip_point(frame, geometry, tip_x: float) -> tuple[float, float]:
    """(x, y) of the crack's farthest failed interface at or behind tip_x (several at that x: the one nearest the
    crack plane); (tip_x, y_crack_plane) when none failed."""
    yc = float(geometry.attrs["y_crack_plane"])
    idx = _interfaces(frame, geometry, None, states=(FAILED,))
    idx = idx[geometry.iface_midpoint[idx, 0] <= tip_x + 1e-9]
    if idx.size == 0:
        return tip_x, yc
    x = geometry.iface_midpoint[idx, 0]
    y = geometry.iface_midpoint[idx[x >= x.max() - 1e-9], 1]
    return float(x.max()), float(y[np.argmin(np.abs(y - yc))])


def _softened_ahead(frame, geometry, tag: int, run: Run, h_e: float) -> float:
    """The projected extent of the inelastic interfaces on run's gap in the slices just past its end."""
    soft = [r for r in gap_runs(frame, geometry, tag, states=(INELASTIC,))
            if abs(r.gap - run.gap) <= GAP_TOL and abs(r.x_start - (run.x_end + h_e)) <= 0.5 * h_e]
    return soft[0].x_end - run.x_end if soft else 0.0


def kinks(frame, geometry, tip_x: float, reach: float | None = None) -> dict:
    """Each ply's kink at the tip (Kink, by tag: TAG_PLY1, TAG_PLY2): of the ply's runs of failed interfaces
    (gap_runs) ending within `reach` behind tip_x (default one crisscross spacing d/sin(theta_D); 2 d at
    theta_D = 0) and not past it, the one whose end lies nearest the crack's tip point (the farthest failed
    interface at or behind tip_x, of several the one nearest the crack plane)."""
    h_e = float(geometry.attrs["h_e"])
    theta = math.radians(float(geometry.attrs["theta_D_deg"]))
    reach = (1.0 / math.sin(theta) if theta > 0 else 2.0) if reach is None else reach
    yc = float(geometry.attrs["y_crack_plane"])
    tx, ty = _tip_point(frame, geometry, tip_x)
    out = {}
    for tag in (TAG_PLY1, TAG_PLY2):
        near = [r for r in gap_runs(frame, geometry, tag)
                if tip_x - reach <= r.x_end <= tip_x + 0.5 * h_e]
        if not near:
            out[tag] = Kink(tag, 0, *(math.nan,) * 6)
            continue
        run = min(near, key=lambda r: (math.hypot(r.x_end - tx, r.y_end + yc - ty), -r.count))
        out[tag] = Kink(tag, run.count, run.x_start, run.x_end, run.x_end - run.x_start + h_e, run.y_start,
                        run.y_end, _softened_ahead(frame, geometry, tag, run, h_e))
    return out
