"""Which figure uses which case (paper_cases/figures.toml) and the parameters in a paper case's name."""
from __future__ import annotations

import re
import tomllib

from enamel_results import paths

PARAM_KEYS = ("theta_D", "sigma_ru_over_sigma0", "Er_over_kd", "cv", "seed")


def load_toml(path) -> dict:
    with open(path, "rb") as f:
        return tomllib.load(f)


def figure_list() -> dict:
    """paper_cases/figures.toml: {fig: {"cases": [...], "slow": [...]}}."""
    return load_toml(paths.FIGURE_LIST)


def figure_cases(fig: str) -> list[str]:
    return list(figure_list()[fig]["cases"])


def slow_cases(fig: str) -> list[str]:
    return list(figure_list()[fig].get("slow", []))


def params_from_name(case: str) -> dict:
    """Parameters from a paper case name, e.g. theta30_s28.5_e10_cv0.1_seed2 (fallback when /meta lacks them)."""
    m = re.match(r"theta([\d.]+)_s([\d.]+)_e([\d.]+)_cv([\d.]+)(?:_seed(\d+))?", case)
    if not m:
        return {}
    return dict(theta_D=float(m[1]), sigma_ru_over_sigma0=float(m[2]), Er_over_kd=float(m[3]), cv=float(m[4]),
                seed=int(m[5] or 1))
