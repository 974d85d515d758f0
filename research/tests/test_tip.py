"""research/tip: the first events of a run and the statements the rule reads, on a ci run of each reading."""
import json
import math

from conftest import PAPER_CASES
from research.tip import tip


def run_reading(run, tmp_path, reading):
    out = tmp_path / reading
    r = run("run", PAPER_CASES / "theta30_s21.4_e10_cv0.toml", "--preset", "ci", "--out", out, "--quiet",
            "--set", f'crisscross_at_tip="{reading}"', timeout=900)
    assert r.returncode == 0, r.stderr
    return out


def test_cut_reading_advances_before_its_first_break_and_records(run, tmp_path, monkeypatch):
    monkeypatch.setattr(tip, "DATA", tmp_path / "data")
    out = run_reading(run, tmp_path, "cut")
    rec = tip.record("ci_cut", out, dict(size=16, G=10, reading="cut", phase=0))
    ev, st = rec["events"], rec["statements"]
    spacing = 1 / math.sin(math.radians(30))
    # the cut reading's first intact crisscross: one spacing past the cut one at a0_eff - h_e/2; less h_e for (i)
    assert abs(ev["threshold_da"] - (spacing - 0.5 * 16 / 53 - 16 / 53)) < 1e-9
    assert ev["first_break_da"] >= ev["da_before_first_break"] > 0
    assert st["i_kinks_first"] == (ev["first_break_da"] >= ev["threshold_da"])
    assert st["ii_rising"] == (rec["R_init"] <= 0.8 * st["mean_5_25"])
    saved = json.loads((tmp_path / "data" / "ci_cut.json").read_text())
    assert saved["events"] == ev and saved["keys"]["reading"] == "cut"
    assert "| ci_cut | 16 | 10 | cut |" in tip.report()
