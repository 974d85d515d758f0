"""paper_cases/: every case file parses and builds at the ci preset, and the figure tables (figures/figN_*.toml)
name only existing cases, covering the paper's grid."""
import pathlib

import pytest

from enamel_results import cases

ROOT = pathlib.Path(__file__).resolve().parents[2]
PAPER_CASES = ROOT / "paper_cases"
CASE_FILES = sorted(PAPER_CASES.glob("*.toml"))


def test_figure_list_names_existing_cases():
    figures = cases.figure_list()
    assert list(figures) == ["fig4", "fig5", "fig6", "fig7", "fig8", "fig9"]
    names = {p.stem for p in CASE_FILES}
    used = set()
    for fig, entry in figures.items():
        for c in entry["cases"] + entry.get("slow", []):
            assert c in names, (fig, c)
            used.add(c)
    assert used == names, "every case file is used by a figure"
    assert len(figures["fig7"]["cases"]) == 3 * 4 * 3
    assert len(figures["fig8"]["cases"]) == 1 + 3 * 5


@pytest.mark.parametrize("case", CASE_FILES, ids=lambda p: p.stem)
def test_case_parses_and_builds(run, case):
    r = run("info", case, "--preset", "ci")
    assert r.returncode == 0, r.stderr
    assert "DOF" in r.stdout
