"""figures/paper_values.toml: every number the paper states, with its sentence, and the look-ups the figures and
the summary table make in it."""
from __future__ import annotations

import math

from enamel_results import paths
from enamel_results.cases import load_toml

# Delta_a/d of the process-zone maps when the paper does not say (it says 15 for Fig. 5, paper_values.toml).
DEFAULT_SNAPSHOT_DA = 15.0


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


RELATION_SYMBOL = {"=": "=", "~": "≈", ">=": "≥"}


def paper_value_text(v: dict) -> str:
    """'≈ 7', '= 4/3', '≈ 5.95 (on the order of 50% below 11.9)' for a paper_values.toml entry."""
    sym = RELATION_SYMBOL.get(v.get("relation", "~"), v.get("relation", ""))
    text = str(v.get("value_text", v["value"])).replace("approx ", "")
    if v.get("derived"):
        return f"{sym} {float(v['value']):.3g} ({text})"
    return f"{sym} {text}"
