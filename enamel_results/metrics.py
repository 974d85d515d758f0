"""Numbers computed from loaded results: R-curve differences (bench, reference tests) and Fig. 9's pooled R_m."""
from __future__ import annotations

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
