"""The square study's report (research/square/square.py) from records alone: the runs table, the checks by the
measure, and the selection rule (converged in size, mesh and rate; nearest 7 by the (5,25] mean, rods breaking)."""
import json

import numpy as np

from research.square import square

DA = np.arange(0.15, 30.16, 0.3)


def record(name, size, G, level, he=0.3, rate=1.0, rods=(2, 4, 6, 8)):
    R = level + 0.5 * np.sin(DA)
    R[0] = 5.0
    return dict(name=name, case=square.CASE, cpu="test", meta=dict(status="completed", steps=1, wall_time_s=60.0),
                params=dict(w_s_over_d=size, h_s_over_d=size, h_e_over_d=he, Gamma_k_over_sigma0sq=G,
                            rate_factor=rate),
                R_init=5.0, da_max=float(DA[-1]), broken_rods=len(rods), rod_da=list(rods),
                da=DA.tolist(), R=R.tolist())


def write(tmp_path, recs):
    data = tmp_path / "data"
    data.mkdir()
    for r in recs:
        (data / f"{r['name']}.json").write_text(json.dumps(r))
    readme = tmp_path / "README.md"
    readme.write_text("# plan\n\nthe rule\n\n## Results\nold text\n")
    return data, readme


def test_the_rule_selects_the_converged_G_nearest_7(tmp_path):
    n = square.run_name
    recs = [record(n(80, 8), 80, 8, 8.0), record(n(100, 8), 100, 8, 7.9),          # size only: not converged
            record(n(80, 10), 80, 10, 6.6), record(n(100, 10), 100, 10, 6.8),
            record(n(40, 10), 40, 10, 6.5), record(n(40, 10, he=0.15), 40, 10, 6.9, he=0.15),
            record(n(80, 10, rate=0.5), 80, 10, 6.65, rate=0.5),
            record(n(80, 12), 80, 12, 5.0), record(n(100, 12), 100, 12, 6.0)]     # size differs by 20%
    data, readme = write(tmp_path, recs)
    text = square.report(data, readme)
    out = readme.read_text()
    assert out.startswith("# plan\n\nthe rule\n\n## Results\n") and "old text" not in out   # the plan is kept
    assert "**Selected by the records so far: G = 10**" in text
    assert "| 8 | yes | - | - |" in text and "| 12 | no | - | - |" in text
    assert "| 10 | yes | yes | yes |" in text
    assert (tmp_path / "rcurves.png").stat().st_size > 1000


def test_nothing_is_selected_without_a_converged_G(tmp_path):
    n = square.run_name
    data, readme = write(tmp_path, [record(n(80, 8), 80, 8, 8.0), record(n(100, 8), 100, 8, 7.9)])
    assert "**Selected: none yet**" in square.report(data, readme)


def test_a_faster_loading_is_reported_and_a_slow_twin_decides(tmp_path):
    n = square.run_name
    base = [record(n(80, 10), 80, 10, 6.6), record(n(100, 10), 100, 10, 6.7),
            record(n(40, 10), 40, 10, 6.5), record(n(40, 10, he=0.15), 40, 10, 6.9, he=0.15),
            record(n(100, 10, rate=2), 100, 10, 5.5, rate=2)]                    # x2 differs by 18%: reported
    (tmp_path / "a").mkdir()
    data, readme = write(tmp_path / "a", base + [record(n(40, 10, rate=0.5), 40, 10, 6.52, rate=0.5)])
    text = square.report(data, readme)
    assert "| reported: faster loading x2 |" in text and "**Selected by the records so far: G = 10**" in text
    (tmp_path / "b").mkdir()
    data, readme = write(tmp_path / "b", base + [record(n(40, 10, rate=0.5), 40, 10, 6.0, rate=0.5)])
    assert "**Selected: none yet**" in square.report(data, readme)                 # the half-rate twin differs


def test_run_arguments_are_the_plans():
    args = square.solver_args("enamel-dem", 100, 10, 0.3, 1.0, "out")
    sets = {args[i + 1].split("=")[0]: args[i + 1].split("=", 1)[1] for i, a in enumerate(args) if a == "--set"}
    assert args[3:5] == ["--preset", "paper"] and "--resume" in args
    assert sets["w_s_over_d"] == sets["h_s_over_d"] == "100" and sets["Gamma_k_over_sigma0sq"] == "10"
    assert sets["integrator"] == '"lumped"' and sets["dt_factor"] == "0.22" and sets["damping_cap"] == "0.5"
    assert sets["static_start"] == "0.95" and sets["threads"] == "1" and sets["rate_factor"] == "1"


def test_a_check_against_an_unfinished_run_says_so(tmp_path):
    n = square.run_name
    short = record(n(40, 10, he=0.15), 40, 10, 6.6, he=0.15)
    short["meta"]["status"] = "interrupted"
    keep = np.array(short["da"]) <= 15
    short["da"], short["R"] = list(np.array(short["da"])[keep]), list(np.array(short["R"])[keep])
    data, readme = write(tmp_path, [record(n(40, 10), 40, 10, 6.5), short])
    text = square.report(data, readme)
    assert "**same** (over the common range: s40_he0.15_G10 interrupted)" in text and "| (0,14.8] |" in text


def test_validation_cases_are_named_and_judged_at_the_selected_G(tmp_path):
    n = square.run_name
    assert n(80, 9) == "s80_he0.3_G9" and n(80, 9, case="theta15_s21.4_e10_cv0") == "theta15_s21.4_e10_cv0_s80_he0.3_G9"
    converged = [record(n(80, 10), 80, 10, 6.6), record(n(100, 10), 100, 10, 6.8), record(n(40, 10), 40, 10, 6.5),
                 record(n(40, 10, he=0.15), 40, 10, 6.9, he=0.15), record(n(80, 10, rate=0.5), 80, 10, 6.65, rate=0.5)]
    val = []
    for case, lvl in (("theta15_s21.4_e10_cv0", 7.3), ("theta0_s21.4_e10_cv0", 1.5),
                      ("theta30_s7.1_e10_cv0", 2.0), ("theta30_s28.5_e10_cv0", 9.0)):
        r = record(n(80, 10, case=case), 80, 10, lvl)
        r["case"] = case
        val.append(r)
    val[1]["R_init"] = 1.35                       # theta_D = 0: R_init within 3% of 4/3, the level 12% above it
    val[0]["rod_da"] = [5.0, 6.0]                  # theta15: no rod break before 3.86 d
    converged[1]["rod_da"] = [0.3, 4.0]            # theta30 at 100 d: a rod break before 2 d
    data, readme = write(tmp_path, converged + val)
    text = square.report(data, readme)
    assert "**Selected by the records so far: G = 10**" in text      # the validation cases do not enter the rule
    line = {l.split(":")[0].strip("| "): l for l in text.splitlines() if l.startswith("| fig")}
    assert "| reproduced (+4.0%; tolerance 20%) |" in line["fig4_theta15_R_ss"]  # (5,25] mean of the test curve 7.28
    assert "| reproduced |" in line["fig4_theta15_no_rod_fracture_before_crisscross"]
    assert "reproduced (+1.3%; tolerance 3%)" in line["fig4_theta0_R_init"]
    assert "**not reproduced**" in line["fig4_theta0_R_ss"] and "tolerance 3%" in line["fig4_theta0_R_ss"]
    assert "not a validation" in line["fig4_theta30_R_ss"] and "**not reproduced**" in line[
        "fig4_theta30_no_rod_fracture_before_crisscross"]
    rod_strength = [l for l in text.splitlines() if l.startswith("| fig5_R_ss_increases_with_rod_strength")]
    assert len(rod_strength) == 1 and "| 7.1: 1.98, 21.4: 6.78, 28.5: 8.98 | holds |" in rod_strength[0]


def test_a_reading_qualifies_only_with_a_late_first_break_and_the_level_kept(tmp_path):
    n = square.run_name
    base = [record(n(80, 10), 80, 10, 6.6), record(n(100, 10), 100, 10, 6.8),
            record(n(40, 10), 40, 10, 6.5), record(n(40, 10, he=0.15), 40, 10, 6.9, he=0.15),
            record(n(80, 10, rate=0.5), 80, 10, 6.65, rate=0.5)]
    late_high = record(n(80, 10, extra="beta0.5"), 80, 10, 10.0, rods=(3.1, 5, 7))      # +43%: level lost
    late_high["readings"] = dict(square.READING_DEFAULTS, shear_strength_ratio=0.5)
    early = record(n(80, 10, extra="phase0.9"), 80, 10, 7.0, rods=(1.8, 4))             # breaks before 2 d
    early["readings"] = dict(square.READING_DEFAULTS, crisscross_phase=0.9)
    data, readme = write(tmp_path, base + [late_high, early])
    text = square.report(data, readme)
    rows = {line.split(" | ")[1]: line for line in text.splitlines() if line.startswith("| ") and "_G10" in line}
    assert "shear_strength_ratio = 0.5 |" in rows[n(80, 10, extra="beta0.5")]
    assert rows[n(80, 10, extra="beta0.5")].endswith("| no |") and rows[n(80, 10, extra="phase0.9")].endswith("| no |")
    assert n(40, 10) not in [r for r in rows if "today's" in rows[r]]             # 40 d is not a converged size
    assert "**No reading run so far qualifies: today's readings stay.**" in text
    good = record(n(80, 10, extra="uxuy"), 80, 10, 7.5, rods=(2.2, 4))
    good["readings"] = dict(square.READING_DEFAULTS, grip_constraint="uxuy")
    (tmp_path / "two").mkdir()
    data2, readme2 = write(tmp_path / "two", base + [late_high, early, good])
    assert "**Qualifying so far: grip_constraint = uxuy.**" in square.report(data2, readme2)


def test_pooled_rm_is_judged_per_cv_group_of_the_series(tmp_path):
    n = square.run_name
    converged = [record(n(80, 10), 80, 10, 6.6), record(n(100, 10), 100, 10, 6.8), record(n(40, 10), 40, 10, 6.5),
                 record(n(40, 10, he=0.15), 40, 10, 6.9, he=0.15), record(n(80, 10, rate=0.5), 80, 10, 6.65, rate=0.5)]
    val = []
    for case, lvl in (("theta30_s28.5_e10_cv0", 12.0), ("theta30_s28.5_e10_cv0.3_seed1", 9.0),
                      ("theta30_s21.4_e10_cv0.2_seed1", 1.0)):     # not the Figs. 8-9 series: not pooled
        r = record(n(80, 10, case=case), 80, 10, lvl)
        r["case"] = case
        val.append(r)
    data, readme = write(tmp_path, converged + val)
    line = {l.split(":")[0].strip("| "): l for l in square.report(data, readme).splitlines() if l.startswith("| fig9")}
    # the test curve's points over (0,30): level + 0.5 sin(da), the first point 5.0
    low = np.r_[5.0, 12.0 + 0.5 * np.sin(DA[1:])][DA < 30].mean()
    assert f"| {low:.3g} | theta30_s28.5_e10_cv0_s80_he0.3_G10 | reproduced" in line["fig9_R_m_low_cv"]
    assert "(cv 0, 0.1; 1 realisation)" in line["fig9_R_m_low_cv"]
    assert "theta30_s21.4" not in line["fig9_R_m_high_cv"] and "**not reproduced**" in line["fig9_R_m_high_cv"]
    assert "inelastic zone" not in line["fig9_R_m_low_cv"]
    val[0]["warnings"] = "inelastic zone reached 38.2 d from the crack plane at step 1, within 2 d of the loaded edges\n"
    (tmp_path / "zone").mkdir()
    data, readme = write(tmp_path / "zone", converged + val)
    line = {l.split(":")[0].strip("| "): l for l in square.report(data, readme).splitlines() if l.startswith("| fig9")}
    assert line["fig9_R_m_low_cv"].endswith(
        "(inelastic zone at the loaded edges in theta30_s28.5_e10_cv0_s80_he0.3_G10: R may depend on the size) |")
    assert "inelastic zone" not in line["fig9_R_m_high_cv"]
