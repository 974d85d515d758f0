"""Which figure uses which case (the table next to each figure script, figures/figN_<name>.toml) and the
parameters in a paper case's name."""
from __future__ import annotations

import pathlib
import re
import tomllib

from enamel_results import paths

FIGURES_DIR = paths.ROOT / "figures"
FIGURE_SCRIPT = re.compile(r"^(fig\d+)_\w+$")  # figures/fig4_decussation.py -> figure "fig4"


def load_toml(path) -> dict:
    with open(path, "rb") as f:
        return tomllib.load(f)


def figure_scripts(figures_dir: pathlib.Path = FIGURES_DIR) -> dict[str, str]:
    """{figure: script stem} for every figures/figN_<name>.py, in figure order (fig4 ... fig9, then any added)."""
    found = {}
    for p in figures_dir.glob("fig*_*.py"):
        m = FIGURE_SCRIPT.match(p.stem)
        if m:
            if m[1] in found:
                raise ValueError(f"{figures_dir}: two scripts for {m[1]}: {found[m[1]]}.py and {p.name}")
            found[m[1]] = p.stem
    return dict(sorted(found.items(), key=lambda kv: int(kv[0][3:])))


def figure_list(figures_dir: pathlib.Path = FIGURES_DIR) -> dict:
    """{figure: {"cases": [...], "slow": [...]}} from the table next to each figure script (figN_<name>.toml);
    a script without its table is an error naming the file it needs."""
    tables = {}
    for fig, stem in figure_scripts(figures_dir).items():
        table = figures_dir / f"{stem}.toml"
        if not table.exists():
            raise FileNotFoundError(f"{figures_dir / (stem + '.py')} has no table of cases: {table} is missing")
        tables[fig] = load_toml(table)
    return tables


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
