"""research/rate: a ci run of two candidates through the study's script (solver arguments, record, report): phi at
the first events (S3), the steps ratio and the measure against phi1 (S1, S2), resumable (a recorded candidate is
not run again)."""
import json
import subprocess

import pytest

from research.rate import rate


def test_two_candidates_record_and_report(enamel, tmp_path, monkeypatch):
    keys = subprocess.run([str(enamel), "keys"], capture_output=True, text=True, check=True).stdout
    if "`rate_adapt_rule`" not in keys:
        pytest.skip("this solver has no margin rule (rate_adapt_rule): its code is at commit 5c3135f, README.md here")
    monkeypatch.setattr(rate, "DATA", tmp_path / "data")
    monkeypatch.setattr(rate, "RUNS", tmp_path / "runs")
    case = "theta30_s21.4_e10_cv0"
    for cand in ("phi1", "margin8"):
        assert rate.run_one(str(enamel), "ci", case, cand) == 0
    ref = json.loads((tmp_path / "data" / f"ci__{case}__phi1.json").read_text())
    rec = json.loads((tmp_path / "data" / f"ci__{case}__margin8.json").read_text())
    assert rec["keys"] == rate.CANDIDATES["margin8"] and rec["core_seconds"] > 0 and rec["cpu"]
    ev = rec["events"]
    assert ref["events"]["phi_max_reached"] == 1.0 and 4 < ev["phi_max_reached"] <= 8
    assert ev["first_interface_failure"] == [1.0, 1.0]          # measured: the first failure runs at phi = 1
    assert rate.s3_holds(ref["events"])
    assert rate.s3_holds(ev) == (ev["first_rod_break"] in (None, [1.0, 1.0]))
    rows = {w["candidate"]: w for w in rate.rows()}
    assert rows["phi1"]["steps_ratio"] == 1.0 and rows["phi1"]["mean_rel"] == 0.0
    assert rows["margin8"]["steps_ratio"] > 2 and not rows["margin8"]["comparable"]   # ci: 5 d < the measure's 10 d
    assert "| ci | theta30_s21.4_e10_cv0 | margin8 |" in rate.report()
    # resumable: a recorded candidate is not run again (the run folder is not touched)
    log = tmp_path / "runs" / "ci" / case / "margin8" / "log.txt"
    before = log.stat().st_mtime_ns
    assert rate.run_one(str(enamel), "ci", case, "margin8") == 0
    assert log.stat().st_mtime_ns == before


def test_study2_decision_takes_the_largest_smaller_saving_of_those_same_on_both_cases():
    """README.md, Study 2, Decision rule, on rows of two cases: a candidate the same on one case only does not go,
    whatever its saving; of those the same on both, the largest smaller-of-two steps ratio; a tie goes to the
    smaller phi_max."""
    def rows(name, ratios, same):
        return [dict(candidate=name, case=c, steps_ratio=r, same=s) for c, r, s in zip(rate.CASES, ratios, same)]
    rws = (rows("margin8_h10_qs", (3.0, 2.5), (True, False)) + rows("margin8_h40_qs", (1.8, 2.2), (True, True))
           + rows("margin4_h40_qs", (2.0, 1.7), (True, True)))
    assert rate.decision(rws).startswith("margin8_h40_qs goes")       # min 1.8 against margin4's 1.7
    tie = rows("margin8_h40_qs", (1.8, 2.2), (True, True)) + rows("margin4_h40_qs", (1.8, 1.9), (True, True))
    assert rate.decision(tie).startswith("margin4_h40_qs goes")       # the same 1.8: the smaller phi_max
    assert rate.decision(rows("margin8_h10_qs", (3.0, 2.5), (True, False))).startswith("none meets")


def test_study5_replaces_study4s_choice_only_when_eligible_and_saving_more():
    """README.md, Study 5, Decision: a candidate replaces study 4's choice only when it is the same on both cases and
    its smaller-of-two steps ratio is above the choice's."""
    def rows(name, ratios, same):
        return [dict(candidate=name, case=c, steps_ratio=r, same=s) for c, r, s in zip(rate.CASES, ratios, same)]
    s4 = rows(rate.STUDY4_CHOICE, (1.74, 1.71), (True, True))
    rho04, rho02 = rate.STUDY5
    assert rate.decision5(s4 + rows(rho04, (2.6, 2.2), (True, True)) + rows(rho02, (2.0, 1.9), (True, True))) \
        .startswith(f"{rho04} replaces")
    assert rate.decision5(s4 + rows(rho04, (2.6, 2.2), (True, False)) + rows(rho02, (2.0, 1.9), (True, True))) \
        .startswith(f"{rho02} replaces")                                 # rho 0.04 not the same on theta15
    assert rate.decision5(s4 + rows(rho04, (2.6, 1.6), (True, True))).startswith("none is eligible")   # 1.6 < 1.71
    assert rate.CANDIDATES[rho04]["rate_adapt_rho_high"] == 0.04


def test_study6_sends_only_a_raised_zeta_the_same_on_both_cases():
    """README.md, Study 6, Decision A: a margin candidate with a raised zeta goes to the converged check only when it
    meets (S2) and (S3) on both cases; the phi = 1 rows decide nothing; the larger zeta first."""
    def rows(name, same, s3=(True, True)):
        return [dict(candidate=name, case=c, same=x, s3=y) for c, x, y in zip(rate.CASES, same, s3)]
    rws = rows("s6_phi1_z10", (False, False)) + rows("s6_m4_z05", (True, True)) + rows("s6_m4_z10", (True, True))
    assert rate.decision6(rws) == ["s6_m4_z10", "s6_m4_z05"]
    assert rate.decision6(rows("s6_m4_z10", (True, False)) + rows("s6_m4_z05", (True, True), (True, False))) == []
    assert rate.CANDIDATES["s6_m4_z05"] == {**rate.CANDIDATES["s4_margin4_h10_qs"], "zeta": 0.5}


def test_study6_stage_d_reading():
    """README.md, Study 6, stage D: both phases moved: not arbitrary; both the same: phase 0's sensitivity; else
    undecided; fewer than both: not complete."""
    row = lambda same: dict(same=same)
    assert "not arbitrary" in rate.decision6d([row(False), row(False)])
    assert "phase 0's own sensitivity" in rate.decision6d([row(True), row(True)])
    assert "undecided" in rate.decision6d([row(True), row(False)])
    assert "not complete" in rate.decision6d([row(False)])
    assert rate.CANDIDATES["s6_phi1_z05_p0.75"] == {"rate_adapt_max": 1, "zeta": 0.5, "crisscross_phase": 0.75}
