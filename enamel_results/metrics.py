"""Numbers computed from loaded results: R-curve differences (bench, reference tests) and Fig. 9's pooled R_m."""
from __future__ import annotations

import dataclasses
import math

import numpy as np


def rcurve_rel_l2(da_ref, R_ref, da, R, points: int = 50) -> float:
    """Relative L2 difference of an R-curve from a reference one over their common Delta_a range."""
    da_ref, R_ref, da, R = map(np.asarray, (da_ref, R_ref, da, R))
    grid = np.linspace(max(da_ref[0], da[0]), min(da_ref[-1], da[-1]), points)
    a, b = np.interp(grid, da_ref, R_ref), np.interp(grid, da, R)
    return float(np.sqrt(np.mean((a - b) ** 2)) / np.sqrt(np.mean(a ** 2)))


def pooled_rm(results: list, lo: float = 0.0, hi: float = 30.0) -> tuple[float, float, int]:
    """Fig. 9: mean and standard deviation of all R points with lo < Delta_a/d < hi, pooled over realisations
    (each a results.Result)."""
    pts = np.concatenate([r.R[(r.da > lo) & (r.da < hi)] for r in results]) if results else np.array([])
    if pts.size == 0:
        return math.nan, math.nan, 0
    return float(pts.mean()), float(pts.std()), int(pts.size)


# --- "The same R-curve" (docs/results.md, the measure) --------------------------------------
# Two sawtooth R-curves are compared by their level over the crack advance, not pointwise: the pointwise L2 is
# dominated by where the teeth fall. One definition, used by the studies, the bench and the tests.

RANGE_OVER_D = (0.0, 30.0)      # the advance over which R is averaged
MIN_RANGE_OVER_D = 10.0         # shorter common ranges are "not comparable"
WINDOWS_OVER_D = ((0.0, 10.0), (10.0, 20.0), (20.0, 30.0))   # reported beside the decision, never deciding
ROD_REL_TOL, ROD_ABS_TOL = 0.2, 2   # broken rod elements over the range: within 20%, or within 2 elements
TOL_MESH_SIZE, TOL_RATE_SPEED = 0.10, 0.02
TOTAL_COUNTS_WITHIN_OVER_D = 1.0   # a record's total broken rods counts up to hi when its curve ends this close past hi


@dataclasses.dataclass(frozen=True)
class RCurve:
    """An R-curve: R/Gamma_i at crack advance da (Delta_a/d, non-decreasing), and the crack advance at which each
    rod element broke (rod_da; None when only the total `broken_rods` up to da[-1] is known)."""
    da: np.ndarray
    R: np.ndarray
    rod_da: np.ndarray | None = None
    broken_rods: int | None = None

    @staticmethod
    def of(da, R, rod_da=None, broken_rods=None) -> "RCurve":
        da, R = np.asarray(da, dtype=float), np.asarray(R, dtype=float)
        if da.ndim != 1 or da.shape != R.shape or da.size < 2 or np.any(np.diff(da) < 0):
            raise ValueError("an R-curve needs >= 2 points with Delta_a non-decreasing")
        return RCurve(da, R, None if rod_da is None else np.asarray(rod_da, dtype=float), broken_rods)

    def rods_up_to(self, hi: float) -> int | None:
        """Rod elements broken by crack advance hi. When only the total is known, it stands for the count up to hi
        if the curve ends within TOTAL_COUNTS_WITHIN_OVER_D past hi (the runs that stop at 30 d end at 30.1-30.6 d);
        otherwise None (unknown)."""
        if self.rod_da is not None:
            return int(np.count_nonzero(self.rod_da <= hi))
        return self.broken_rods if self.da[-1] - hi <= TOTAL_COUNTS_WITHIN_OVER_D else None


def rcurve_of(result) -> RCurve:
    """The R-curve of a loaded result (results.Result), with its broken rod elements up to its last point."""
    return RCurve.of(result.da, result.R, broken_rods=result.broken_rods)


def advance_mean(c: RCurve, lo: float, hi: float) -> float:
    """R averaged over crack advance over (lo, hi]: the integral of the piecewise-linear R(Delta_a) over the part
    of (lo, hi] the curve covers, divided by that length (nan when it covers none)."""
    a, b = max(lo, float(c.da[0])), min(hi, float(c.da[-1]))
    if not b > a:
        return math.nan
    inside = (c.da > a) & (c.da < b)
    x = np.concatenate(([a], c.da[inside], [b]))
    y = np.concatenate(([_interp(c, a)], c.R[inside], [_interp(c, b)]))
    return float(np.trapz(y, x) / (b - a))


def _interp(c: RCurve, x: float) -> float:
    return float(np.interp(x, c.da, c.R))


@dataclasses.dataclass(frozen=True)
class Comparison:
    """Curve b against reference a by the measure; `same` decides, the windows and `l2` are reported only."""
    tol: float
    hi: float               # the common range is (lo, hi]
    comparable: bool        # hi - lo >= MIN_RANGE_OVER_D
    mean_a: float
    mean_b: float
    mean_rel: float         # (mean_b - mean_a) / mean_a
    init_rel: float         # (R_init_b - R_init_a) / R_init_a
    rods_a: int | None      # broken rod elements over the common range
    rods_b: int | None
    rods_ok: bool
    windows: tuple          # ((lo, hi, mean_a, mean_b), ...) of WINDOWS_OVER_D within the common range
    l2: float               # pointwise relative L2 over the common range
    same: bool


def same_rcurve(a: RCurve, b: RCurve, tol: float, lo: float = RANGE_OVER_D[0],
                hi: float = RANGE_OVER_D[1]) -> Comparison:
    """"The same R-curve" for single configurations: over the common range of (lo, hi] (at least
    MIN_RANGE_OVER_D), R averaged over crack advance and R_init (the first point) within `tol` (relative to a), and
    the broken rod elements over the range within ROD_REL_TOL (or ROD_ABS_TOL elements). Whether two settings give
    the same R-curve a single configuration never decides (its curve moves with the tip's phase in the lattice):
    paired_phase_comparison does, over phases; this comparison is shown beside it."""
    top = min(hi, float(a.da[-1]), float(b.da[-1]))
    comparable = top - lo >= MIN_RANGE_OVER_D - 1e-9
    ma, mb = advance_mean(a, lo, top), advance_mean(b, lo, top)
    mean_rel, init_rel = (mb - ma) / ma, (float(b.R[0]) - float(a.R[0])) / float(a.R[0])
    ra, rb = a.rods_up_to(top), b.rods_up_to(top)
    rods_ok = ra is not None and rb is not None and abs(ra - rb) <= max(ROD_REL_TOL * max(ra, rb), ROD_ABS_TOL)
    windows = tuple((w0, w1, advance_mean(a, w0, w1), advance_mean(b, w0, w1))
                    for w0, w1 in WINDOWS_OVER_D if w1 <= top + 1e-9)
    l2 = rcurve_rel_l2(a.da, a.R, b.da, b.R)
    same = bool(comparable and abs(mean_rel) <= tol and abs(init_rel) <= tol and rods_ok)
    return Comparison(tol, top, comparable, ma, mb, mean_rel, init_rel, ra, rb, rods_ok, windows, l2, same)


# --- The phase average: one case over N phases of the crisscross lattice at the tip -------------------------------
# One configuration's R-curve moves with where its large jumps fall; averaged at equal crack advance over evenly
# spaced phases of the microstructure at the tip (the case key crisscross_phase = k / N), it is the
# microstructure's R-curve, with the phases' spread beside it (docs/results.md).

PHASE_GRID_STEP_OVER_D = 0.1


@dataclasses.dataclass(frozen=True)
class PhaseAverage:
    """R at equal crack advance over the phases: `curve` the mean (an RCurve; its broken_rods the phases' mean
    count up to the grid's end, rounded), `low`/`high` the smallest and largest phase at each grid point, `each`
    every phase's R on the grid. Two settings are compared phase by phase (paired_phase_comparison), not by their
    averages alone."""
    curve: RCurve
    low: np.ndarray
    high: np.ndarray
    each: np.ndarray        # (phases, grid points)


def phase_average(curves: list[RCurve], step: float = PHASE_GRID_STEP_OVER_D) -> PhaseAverage:
    """The R-curves of one case at N phases averaged at equal Delta_a on a grid of `step` from the last of their
    first points to the first of their last points (the range every phase covers; R between a curve's points
    linear, as advance_mean reads it)."""
    if len(curves) < 2:
        raise ValueError("a phase average needs the R-curves of at least two phases")
    lo, hi = max(float(c.da[0]) for c in curves), min(float(c.da[-1]) for c in curves)
    if not hi > lo:
        raise ValueError(f"the phases' R-curves share no range of crack advance ({lo:g} to {hi:g} d)")
    grid = np.append(np.arange(lo, hi, step), hi)
    each = np.array([np.interp(grid, c.da, c.R) for c in curves])
    rods = [c.rods_up_to(hi) for c in curves]
    mean_rods = None if any(r is None for r in rods) else int(round(sum(rods) / len(rods)))
    return PhaseAverage(RCurve.of(grid, each.mean(axis=0), broken_rods=mean_rods), each.min(axis=0),
                        each.max(axis=0), each)


# --- "The same R-curve" between two settings: paired over the phases ---------------------------------------------
# Phase k under setting A and under setting B share where the tip sits in the lattice, so their difference is the
# setting's effect at that phase; the phases' differences, averaged with their standard error, decide.


@dataclasses.dataclass(frozen=True)
class PairedDifference:
    """One quantity's relative differences (B - A) / A over the pairs: `each` per phase, `mean` their mean d, `se`
    its standard error (sample std, ddof=1, over sqrt(N)), `low`/`high` the smallest and largest, and `same`:
    |d| <= tol and |d| <= 2 se."""
    each: tuple
    mean: float
    se: float
    low: float
    high: float
    same: bool


@dataclasses.dataclass(frozen=True)
class PairedComparison:
    """Setting B against reference A, phase by phase (paired_phase_comparison); `same` decides."""
    tol: float
    lo: float
    hi: tuple               # each pair's common range is (lo, hi[k]]
    comparable: bool        # hi[k] - lo >= MIN_RANGE_OVER_D for every pair
    means_a: tuple          # each phase's R averaged over its pair's common range, A and B
    means_b: tuple
    mean_a: float           # the phase-averaged means: the mean of means_a, of means_b
    mean_b: float
    inits_a: tuple          # each phase's R_init (the first point), A and B
    inits_b: tuple
    level: PairedDifference     # of the mean over the common range
    init: PairedDifference      # of R_init (the first point)
    singles: tuple          # each pair by same_rcurve: shown beside, never deciding
    same: bool


def paired_difference(each: list[float], tol: float) -> PairedDifference:
    x = np.asarray(each, dtype=float)
    d, se = float(x.mean()), float(x.std(ddof=1) / math.sqrt(x.size))
    return PairedDifference(tuple(float(v) for v in x), d, se, float(x.min()), float(x.max()),
                            bool(abs(d) + 2 * se <= tol))


def paired_phase_comparison(a: list[RCurve], b: list[RCurve], tol: float, lo: float = RANGE_OVER_D[0],
                            hi: float = RANGE_OVER_D[1]) -> PairedComparison:
    """"The same R-curve" between two settings: a[k] and b[k] are phase k under setting A (the reference) and B.
    Per pair, as same_rcurve computes them over the pair's common range of (lo, hi]: the relative difference of R
    averaged over crack advance, and of R_init (the first point), both relative to A's. For each of the two
    quantities, with d the mean of the N pairs' differences and SE = std(ddof=1) / sqrt(N):

        |d| + 2 SE <= tol      (the difference, with twice its standard error, within the tolerance)

    so a difference is shown to be within tol only where the phases pin it down: a scatter of the pairs too large
    for that leaves B "not shown the same" however small d is, and a precisely measured small d (R_init +0.02 %
    +- 0.00 %) passes. (Reading "within twice its standard error" as |d| <= 2 SE instead, no significant
    difference, would call every precisely measured difference, however small, not the same.) B is the same
    R-curve as A when both quantities pass and every pair's common range is at least
    MIN_RANGE_OVER_D. ValueError for lists of unequal length or fewer than 2 pairs."""
    if len(a) != len(b):
        raise ValueError(f"paired phases need as many curves under each setting ({len(a)} and {len(b)})")
    if len(a) < 2:
        raise ValueError("a paired phase comparison needs at least 2 pairs")
    singles = tuple(same_rcurve(ca, cb, tol, lo, hi) for ca, cb in zip(a, b))
    level = paired_difference([c.mean_rel for c in singles], tol)
    init = paired_difference([c.init_rel for c in singles], tol)
    comparable = all(c.comparable for c in singles)
    means_a, means_b = tuple(c.mean_a for c in singles), tuple(c.mean_b for c in singles)
    return PairedComparison(tol, lo, tuple(c.hi for c in singles), comparable, means_a, means_b,
                            float(np.mean(means_a)), float(np.mean(means_b)), tuple(float(c.R[0]) for c in a),
                            tuple(float(c.R[0]) for c in b), level, init, singles,
                            bool(comparable and level.same and init.same))
