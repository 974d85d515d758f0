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


def crafted(size, G, reading, phase, R_init, level, kinks_first):
    """A record as tip.record writes it, with a flat R-curve at `level` after its first point at 0.5 d."""
    da = [0.5] + [1.0 + 0.5 * i for i in range(60)]
    return dict(keys=dict(size=size, G=G, reading=reading, phase=phase), da=da, R=[R_init] + [level] * 60,
                broken_rods=10, R_init=R_init, statements=dict(i_kinks_first=kinks_first))


def test_candidates_apply_the_rule_to_the_size_pairs():
    recs = [crafted(s, 10, "cut", 0, 3.0, 6.0, True) for s in (80, 100)]
    recs += [crafted(s, 10, "intact", 0, 5.0, 6.0, False) for s in (80, 100)]
    recs += [crafted(s, 12, "cut", 0, 3.0, 6.9 if s == 80 else 8.0, True) for s in (80, 100)]  # +15.9 %: not converged
    cands = {(c["G"], c["reading"]): c for c in tip.candidates(recs)}
    assert set(cands) == {(10, "cut"), (10, "intact"), (12, "cut")}   # no average without all four phases
    assert cands[10, "cut"]["converged"] and cands[10, "cut"]["i"] and cands[10, "cut"]["ii"]
    assert not cands[10, "intact"]["i"] and not cands[10, "intact"]["ii"]       # 5.0 > 0.8 x 6.0
    assert not cands[12, "cut"]["converged"]
    best, how = tip.select(list(cands.values()))
    assert (best["G"], best["reading"]) == (10, "cut") and how.startswith("(i)")


def test_select_keeps_intact_unless_another_reading_is_nearer_7_by_more_than_5_percent():
    def cand(reading, level):
        return dict(G=10, reading=reading, converged=True, i=False, ii=False, level=level)
    best, how = tip.select([cand("intact", 6.0), cand("cut", 6.3)])           # nearer by 0.3 <= 0.35
    assert best["reading"] == "intact" and "(iii)" in how
    best, _ = tip.select([cand("intact", 6.0), cand("cut", 6.5)])             # nearer by 0.5 > 0.35
    assert best["reading"] == "cut"


def test_the_averaged_reading_needs_kinks_first_in_three_of_four_phases():
    recs = []
    for s in (80, 100):
        for ph, ok in zip(tip.PHASES, (False, False, True, True)):
            recs.append(crafted(s, 10, "intact", ph, 3.0, 6.0, ok))
    avg = next(c for c in tip.candidates(recs) if c["reading"] == "averaged")
    assert avg["converged"] and avg["ii"] and not avg["i"]


def test_a_half_rate_twin_is_no_candidate_and_is_judged_against_its_run(tmp_path, monkeypatch):
    monkeypatch.setattr(tip, "DATA", tmp_path)
    recs = [crafted(s, 10, "cut", 0, 3.0, 6.0, True) for s in (80, 100)]
    twin = crafted(80, 10, "cut", 0, 3.0, 6.3, True)          # +5 % over (5,25]: not the same at 2 %
    twin["keys"]["rate_factor"] = 0.5
    cands = tip.candidates(recs + [twin])
    assert len(cands) == 1 and cands[0]["levels"] == (6.0, 6.0)     # the twin is not the 80 d run
    for i, r in enumerate(recs + [twin]):
        r["name"] = f"r{i}"
        (tmp_path / f"r{i}.json").write_text(json.dumps(r))
    rows = [l for l in tip.twins_report().splitlines() if l.startswith("| r2 ")]
    assert len(rows) == 1 and "| r0 | 0.5 |" in rows[0] and rows[0].rstrip().endswith("| no |")


def write_phase_records(folder, phases, levels_1, levels_half):
    """Crafted records of the phase runs at rate factors 1 and 0.5 in `folder` (the ones there before removed),
    named r<rate>_p<phase>, each flat at its level."""
    for f in folder.glob("*.json"):
        f.unlink()
    for rate, levels in ((1.0, levels_1), (0.5, levels_half)):
        for ph, level in zip(phases, levels):
            r = crafted(80, 9.0, "cut", ph, 3.0, level, True)
            r["keys"]["rate_factor"] = rate
            r.update(name=f"r{rate:g}_p{ph:g}", events=dict(first_break_da=2.0),
                     statements=dict(mean_0_30=level, mean_5_25=level, i_kinks_first=True, ii_rising=True))
            (folder / f"{r['name']}.json").write_text(json.dumps(r))


def test_stage7_reads_the_rate_from_the_phase_averages(tmp_path, monkeypatch):
    """Stage 7: the half rate's phase average against the preset rate's, by the measure (2 %), else against twice
    the combined standard error of the phases' means; each twin is judged against its own phase's run."""
    monkeypatch.setattr(tip, "DATA", tmp_path)

    def write(levels_1, levels_half):
        write_phase_records(tmp_path, tip.PHASES, levels_1, levels_half)
        return tip.phases_report()

    same = write([6.0, 6.2, 6.1, 6.3], [6.05, 6.2, 6.1, 6.3])
    assert "| 1 | average |" in same and "the same R-curve (2 %)" in same.splitlines()[-1]
    noisy = write([5.0, 7.0, 5.2, 6.8], [5.4, 7.2, 5.6, 7.0])            # +5 %, the phases' spread ~1 R each
    assert "within the phases' noise" in noisy.splitlines()[-1]
    apart = write([6.0, 6.1, 6.0, 6.1], [6.6, 6.7, 6.6, 6.7])            # +10 %, spread 0.06
    assert "beyond the phases' noise" in apart.splitlines()[-1]
    rows = [l for l in tip.twins_report().splitlines() if l.startswith("| r0.5_p0.25 ")]
    assert len(rows) == 1 and "| r1_p0.25 | 0.5 |" in rows[0]
    (tmp_path / "r0.5_p0.5.json").unlink()
    partial = tip.phases_report()
    assert "| 0.5 | 0.5 | not recorded |" in partial and "rate is" not in partial and "| 0.5 | average |" not in partial


def test_stage8_decides_the_rate_by_the_paired_differences(tmp_path, monkeypatch):
    """Stage 8: the phase averages by the measure (2 %) hold; else the paired differences d_k of the same phases
    decide: |dbar| > 2 se_d fails, else not decided with the bound |dbar| + 2 se_d; the unpaired test beside."""
    monkeypatch.setattr(tip, "DATA", tmp_path)

    def write(levels_1, levels_half):
        write_phase_records(tmp_path, tip.STAGE8_PHASES, levels_1, levels_half)
        return tip.phases_report(tip.STAGE8_PHASES)

    base = [5.0, 7.0, 5.2, 6.8, 5.1, 6.9, 5.3, 6.7]                          # one configuration's noise ~1 R
    same = write(base, [x + 0.05 for x in base])
    assert "| 0.5 | 0.875 |" in same and "holds for the phase-averaged" in same.splitlines()[-1]
    shifted = write(base, [x + 0.3 + 0.01 * (-1) ** k for k, x in enumerate(base)])   # +5 %, each phase alike
    last = shifted.splitlines()[-1]
    assert "the paired difference is resolved" in last and "dbar +0.297" in last     # (0,30] means: 0.5 d at R_init
    assert "within the phases' noise" in shifted        # the unpaired test cannot see it; the paired one does
    scattered = write(base, [x + (0.9 if k % 2 else -0.3) for k, x in enumerate(base)])   # dbar 0.3, s_d 0.64
    last = scattered.splitlines()[-1]
    assert "not decided at 8 phases" in last and "at most 0.747" in last   # 0.297 + 2 x 0.636 / sqrt 8
    (tmp_path / "r0.5_p0.375.json").unlink()
    partial = tip.phases_report(tip.STAGE8_PHASES)
    assert "| 0.5 | 0.375 | not recorded |" in partial and "paired" not in partial
