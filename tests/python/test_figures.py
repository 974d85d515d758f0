"""Figure scripts and summary table (issue "Pipeline and figures"): each script runs on result files and writes
a non-empty PDF and PNG, a missing result file is one clear line and a non-zero exit, the summary table has one
row per case with our HDF5 attributes copied exactly, and paper_values.toml quotes the paper verbatim.

The result files come from tiny runs (8 d x 4 d specimen, stopped at Delta_a/d = 1.5, ~2 s each) made once per
module in a temporary runs/ci/ tree, so the tests do not depend on what is in runs/. Scripts run in this process
(runpy) to keep the tests fast; one missing-file test runs a script as a subprocess for the real exit status.
"""
import contextlib
import csv
import io
import math
import pathlib
import re
import runpy
import shutil
import subprocess
import sys
import tomllib

import h5py
import numpy as np
import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]
FIGURES = ROOT / "figures"
sys.path.insert(0, str(FIGURES))
import common  # noqa: E402
import summary_table  # noqa: E402

PYTHON = sys.executable
PAPER_TEXT = pathlib.Path("/work/shared/paper/pro_barthelat_2020_enamel_dem.txt")
MAP_SCRIPTS = ["fig4_decussation.py", "fig5_rod_strength.py", "fig6_stiffness_contrast.py",
               "fig8_statistics_rcurves.py"]
SCRIPTS = MAP_SCRIPTS + ["fig7_summary.py", "fig9_statistics_mean.py", "summary_table.py"]
# Tiny runs: one case of Figs. 4/5/6/7 and one of Figs. 8/9 (it breaks rods).
TINY_CASES = ["theta30_s21.4_e10_cv0", "theta30_s28.5_e10_cv0.3_seed1"]
TINY = ["--preset", "ci", "--set", "w_s_over_d=8", "--set", "h_s_over_d=4", "--set", "stop_da_over_d=1.5",
        "--set", "frames_da_over_d=[0.5, 1.5]", "-q"]
ATTR_RTOL = 1e-9  # CSV values are written with 10 significant digits


@pytest.fixture(scope="module")
def tiny_runs(tmp_path_factory, enamel):
    """runs/ci/<case>/result.h5 for TINY_CASES, plus a copy of the theta_D = 30 run as its half-rate twin
    (the figure only needs the file: this checks the overlay path without a second run)."""
    runs = tmp_path_factory.mktemp("runs")
    for case in TINY_CASES:
        out = runs / "ci" / case
        r = subprocess.run([str(enamel), "run", str(ROOT / "paper_cases" / f"{case}.toml"), "--out", str(out),
                            *TINY], capture_output=True, text=True, timeout=120)
        assert r.returncode == 0, r.stderr
    slow = runs / "ci" / "theta30_s21.4_e10_cv0_slow"
    slow.mkdir()
    shutil.copy(runs / "ci" / "theta30_s21.4_e10_cv0" / "result.h5", slow / "result.h5")
    return runs


def run_script(name, *args):
    """Run a script as __main__ in this process: (exit status, stdout, stderr)."""
    out, err = io.StringIO(), io.StringIO()
    argv = sys.argv
    sys.argv = [str(FIGURES / name), *map(str, args)]
    code = 0
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            runpy.run_path(str(FIGURES / name), run_name="__main__")
    except SystemExit as e:
        code = e.code if isinstance(e.code, int) else (0 if e.code is None else 1)
    finally:
        sys.argv = argv
    return code, out.getvalue(), err.getvalue()


def assert_image_files(out, stem):
    """PDF and PNG exist; the PNG decodes, is a real figure size and is not blank."""
    import matplotlib.image as mpimg
    pdf, png = out / "ci" / f"{stem}.pdf", out / "ci" / f"{stem}.png"
    assert pdf.stat().st_size > 5000, pdf
    assert pdf.read_bytes()[:5] == b"%PDF-"
    img = mpimg.imread(png)
    assert img.shape[0] > 400 and img.shape[1] > 600, img.shape
    assert float(np.std(img[..., :3])) > 0.05, "PNG is (nearly) blank"


# ------------------------------------------------------------------------------------------ paper values
def test_paper_values_entries_are_well_formed():
    pv = tomllib.loads((FIGURES / "paper_values.toml").read_text())
    cases = {p.stem for p in (ROOT / "paper_cases").glob("*.toml")}
    ids = [v["id"] for v in pv["value"] + pv["trend"]]
    assert len(ids) == len(set(ids)), "ids are unique"
    quantities = {"R_init_over_Gamma", "R_ss_over_Gamma", "R_m_pooled_over_Gamma", "dR_m_pooled_over_Gamma",
                  "da_first_rod_fracture_over_d", "da_R_plateau_end_over_d"}
    for v in pv["value"]:
        assert v["quantity"] in quantities, v["id"]
        assert v["relation"] in ("=", "~", ">="), v["id"]
        assert ("case" in v) != ("cv" in v), v["id"]
        if "case" in v:
            assert v["case"] in cases, v["id"]
        assert set(v["figures"]) <= {"fig4", "fig5", "fig6", "fig7", "fig8", "fig9"}, v["id"]
        assert math.isfinite(float(v["value"])), v["id"]
    for t in pv["trend"]:
        assert t["direction"] in ("increasing", "decreasing", "constant", "maximum_at_first"), t["id"]
    # the values the brief names: 4/3 at theta_D = 0, ~7 at 15 and 30 deg, ~8 and ~6 at Er/kd = 10, 20, ~11.9
    by_id = {v["id"]: v for v in pv["value"]}
    assert by_id["fig4_theta0_R_init"]["value"] == pytest.approx(4 / 3, rel=1e-15)
    assert by_id["fig4_theta15_R_ss"]["value"] == by_id["fig4_theta30_R_ss"]["value"] == 7.0
    assert (by_id["fig6_e10_R_ss"]["value"], by_id["fig6_e20_R_ss"]["value"]) == (8.0, 6.0)
    assert by_id["fig9_R_m_low_cv"]["value"] == 11.9


@pytest.mark.skipif(not PAPER_TEXT.exists(), reason="paper text not on this machine")
def test_paper_values_quote_the_paper_verbatim():
    norm = lambda s: re.sub(r"\s+", " ", s).strip()  # noqa: E731 - line breaks of the text do not matter
    text = norm(PAPER_TEXT.read_text())
    pv = tomllib.loads((FIGURES / "paper_values.toml").read_text())
    for v in pv["value"] + pv["trend"] + pv["snapshot"]:
        assert norm(v["quote"]) in text, v.get("id", v.get("figure"))
        if "value_text" in v and not v.get("derived"):
            number = v["value_text"].replace("approx ", "")
            assert number in v["quote"], (v["id"], number)


# ------------------------------------------------------------------------------------------ scripts
@pytest.mark.parametrize("script", SCRIPTS + ["../pipeline/export_vtk.py"])
def test_help(script):
    code, out, err = run_script(script, "--help")
    assert code == 0, err
    assert "usage:" in out
    if script != "../pipeline/export_vtk.py":
        assert "--preset" in out and "reduced" in out


@pytest.mark.parametrize("script", SCRIPTS)
def test_missing_result_is_one_clear_line(script, tmp_path):
    code, _, err = run_script(script, "--preset", "ci", "--runs", tmp_path / "runs", "--out", tmp_path / "out")
    assert code == common.EXIT_MISSING, (code, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert str(tmp_path / "runs" / "ci") in lines[0] and "result.h5" in lines[0]
    assert "make runs PRESET=ci" in lines[0]
    assert not (tmp_path / "out").exists(), "nothing is written when a result is missing"


def test_missing_result_exit_status_in_a_subprocess(tmp_path):
    r = subprocess.run([PYTHON, str(FIGURES / "fig4_decussation.py"), "--preset", "ci", "--runs",
                        str(tmp_path)], capture_output=True, text=True, timeout=60)
    assert r.returncode == common.EXIT_MISSING
    assert len(r.stderr.strip().splitlines()) == 1 and "make runs PRESET=ci" in r.stderr


# fig5 and fig6 are fig4's code (common.map_figure) with other cases: --help and the missing-file test cover them.
@pytest.mark.parametrize("script", ["fig4_decussation.py", "fig8_statistics_rcurves.py", "fig7_summary.py",
                                    "fig9_statistics_mean.py"])
def test_figure_scripts_draw_available_results(script, tiny_runs, tmp_path):
    code, out, err = run_script(script, "--preset", "ci", "--runs", tiny_runs, "--out", tmp_path,
                                "--allow-missing")
    assert code == 0, err
    stem = pathlib.Path(script).stem
    assert_image_files(tmp_path, stem)
    assert str(tmp_path / "ci" / f"{stem}.png") in out
    assert "warning: skipping missing" in err  # the tiny tree lacks most cases, and says so


# ------------------------------------------------------------------------------------------ summary table
def test_summary_table_rows_columns_and_values(tiny_runs, tmp_path):
    code, _, err = run_script("summary_table.py", "--preset", "ci", "--runs", tiny_runs, "--out", tmp_path,
                              "--allow-missing")
    assert code == 0, err
    with open(tmp_path / "ci" / "summary.csv") as f:
        reader = csv.DictReader(f)
        assert list(reader.fieldnames) == list(summary_table.COLUMNS)
        rows = list(reader)
    figs = tomllib.loads((ROOT / "paper_cases" / "figures.toml").read_text())
    unique = {c for e in figs.values() for c in e["cases"]}
    base = [row for row in rows if row["loading"] == "preset"]
    assert sorted(row["case"] for row in base) == sorted(unique), "one row per case of every figure"
    assert [row["case"] for row in rows if row["loading"] == "half rate"] == ["theta30_s21.4_e10_cv0_slow"]
    by_case = {row["case"]: row for row in rows}
    for case in TINY_CASES:
        row = by_case[case]
        with h5py.File(tiny_runs / "ci" / case / "result.h5", "r") as h:
            rc, meta = h["rcurve"].attrs, h["meta"].attrs
            assert row["status"] == meta["status"]
            for col in ("R_init_over_Gamma", "R_ss_over_Gamma", "R_m_over_Gamma", "dR_m_over_Gamma",
                        "da_max_over_d"):
                assert float(row[col]) == pytest.approx(float(rc[col]), rel=ATTR_RTOL), (case, col)
            assert int(row["broken_rod_elements"]) == int(h["history/broken_rod_elements"][-1])
        assert float(row["theta_D"]) == common.params_from_name(case)["theta_D"]
    assert by_case["theta0_s14.3_e5_cv0"]["status"] == "missing"
    assert float(by_case["theta0_s21.4_e10_cv0"]["paper_R_init_over_Gamma"]) == pytest.approx(4 / 3, rel=1e-5)
    assert by_case["theta0_s21.4_e10_cv0"]["paper_R_m_pooled_over_Gamma"] == "", "pooled values: Figs. 8/9 only"
    assert by_case["theta30_s21.4_e10_cv0"]["paper_R_ss_over_Gamma"] == "7;8"
    assert by_case["theta30_s28.5_e10_cv0.3_seed1"]["paper_R_m_pooled_over_Gamma"] == "5.95"
    md = (tmp_path / "ci" / "summary.md").read_text()
    assert "| theta30_s21.4_e10_cv0 |" in md and "Trends the paper states" in md


def test_summary_table_without_allow_missing_fails(tiny_runs, tmp_path):
    code, _, err = run_script("summary_table.py", "--preset", "ci", "--runs", tiny_runs, "--out", tmp_path)
    assert code == common.EXIT_MISSING
    assert "make runs PRESET=ci" in err


# ------------------------------------------------------------------------------------------ common.py
def test_loaded_result_matches_file_and_pooled_rm_matches_solver(tiny_runs):
    path = tiny_runs / "ci" / "theta30_s28.5_e10_cv0.3_seed1" / "result.h5"
    r = common.load_result(path, full=True)
    assert r.case == "theta30_s28.5_e10_cv0.3_seed1"
    assert (r.param("theta_D"), r.param("sigma_ru_over_sigma0"), r.param("cv"), r.param("seed")) == (30, 28.5, 0.3, 1)
    assert len(r.da) == len(r.R) > 0
    assert r.geometry.iface_midpoint.shape == (len(r.geometry.iface_tag), 3)
    assert all(f.iface_state.shape == r.geometry.iface_tag.shape for f in r.frames)
    # Python's pooled mean/std over one realisation = the solver's R_m, dR_m (same definition, output.cpp)
    m, s, n = common.pooled_rm([r])
    assert n == np.count_nonzero((r.da > 0) & (r.da < 30))
    assert m == pytest.approx(r.R_m, rel=1e-12) and s == pytest.approx(r.dR_m, rel=1e-9, abs=1e-12)
    # pooling two copies: same mean and std, twice the points
    assert common.pooled_rm([r, r])[:2] == pytest.approx((m, s), rel=1e-12)
    # the first broken rod: where the history's count first becomes positive
    with h5py.File(path, "r") as h:
        broken, da = h["history/broken_rod_elements"][:], h["history/da_over_d"][:]
    assert broken[-1] > 0, "this tiny case breaks rods"
    assert r.da_first_rod_fracture == da[np.argmax(broken > 0)]
    # frame_near: the frame with the nearest requested advance
    assert r.frame_near(0.4).target_da == 0.5 and r.frame_near(100).target_da == 1.5


def test_trend_verdicts():
    v = summary_table.series_verdict
    assert v("increasing", [1, 2, 3]) == "holds" and v("increasing", [1, 3, 2]) == "does NOT hold"
    assert v("decreasing", [3, 2, 1]) == "holds" and v("decreasing", [3, 3, 1]) == "does NOT hold"
    assert v("constant", [10, 10.9]) == "holds" and v("constant", [10, 11.2]) == "does NOT hold"
    assert v("maximum_at_first", [5, 4, 4.9]) == "holds" and v("maximum_at_first", [5, 5, 1]) == "does NOT hold"
    assert v("increasing", [1]) == "not enough data"


def test_unfinished_run_is_drawn_and_flagged(tiny_runs, tmp_path):
    """A result whose /meta status is not 'completed' is still used, and flagged in the table and the titles."""
    runs = tmp_path / "runs"
    case = "theta30_s21.4_e10_cv0"
    (runs / "ci" / case).mkdir(parents=True)
    shutil.copy(tiny_runs / "ci" / case / "result.h5", runs / "ci" / case / "result.h5")
    with h5py.File(runs / "ci" / case / "result.h5", "r+") as h:
        h["meta"].attrs["status"] = "interrupted"
    r = common.load_result(runs / "ci" / case / "result.h5")
    assert not r.completed and "NOT COMPLETED: interrupted" in common.status_flag(r)
    code, _, err = run_script("summary_table.py", "--preset", "ci", "--runs", runs, "--out", tmp_path / "out",
                              "--allow-missing")
    assert code == 0, err
    with open(tmp_path / "out" / "ci" / "summary.csv") as f:
        row = next(row for row in csv.DictReader(f) if row["case"] == case)
    assert row["status"] == "interrupted" and float(row["R_init_over_Gamma"]) == pytest.approx(r.R_init, rel=ATTR_RTOL)
    md = (tmp_path / "out" / "ci" / "summary.md").read_text()
    assert any(line.startswith(f"| {case} |") and "**interrupted**" in line for line in md.splitlines())
