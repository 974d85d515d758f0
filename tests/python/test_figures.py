"""Figure scripts and summary table: each script runs on result files and writes
a non-empty PDF and PNG, a missing result file is one clear line and a non-zero exit, the summary table has one
row per case with our HDF5 attributes copied exactly, and each number of paper_values.toml is what its quote says.

The result files come from tiny runs (8 d x 4 d specimen, stopped at Delta_a/d = 1.5, ~2 s each) made once per
pytest run (conftest.tiny_run) in a temporary runs/ci/ tree, so the tests do not depend on what is in runs/.
Scripts run in this process (runpy, as `python3 -m figures.<script>` runs them) to keep the tests fast; one
missing-file test runs a script as a subprocess for the real exit status.
"""
import contextlib
import csv
import fractions
import io
import math
import pathlib
import re
import runpy
import shutil
import subprocess
import sys
import tomllib
import warnings

import h5py
import numpy as np
import pytest

from enamel_results import cases
from enamel_results.cases import params_from_name
from enamel_results.metrics import pooled_rm
from enamel_results.results import EXIT_MISSING, load_result, seal_result_file
from figures import plotting, summary_table

ROOT = pathlib.Path(__file__).resolve().parents[2]
FIGURES = ROOT / "figures"
PYTHON = sys.executable
# Every figure script figures/figN_<name>.py with its table figN_<name>.toml, as the Makefile finds them.
SCRIPTS = list(cases.figure_scripts().values()) + ["summary_table"]
# Tiny runs: one case of Figs. 4/5/6/7 and one of Figs. 8/9 (it breaks rods).
TINY_CASES = ["theta30_s21.4_e10_cv0", "theta30_s28.5_e10_cv0.3_seed1"]
ATTR_RTOL = 1e-9  # CSV values are written with 10 significant digits


@pytest.fixture(scope="module")
def tiny_runs(tiny_run):
    """The runs/ root holding runs/ci/<case>/result.h5 for TINY_CASES, plus a copy of the theta_D = 30 run as its
    half-rate twin (the figure only needs the file: this checks the overlay path without a second run)."""
    for case in TINY_CASES:
        tiny_run(case)
    slow = tiny_run.root / "ci" / "theta30_s21.4_e10_cv0_slow"
    slow.mkdir(exist_ok=True)
    shutil.copy(tiny_run(TINY_CASES[0]), slow / "result.h5")
    return tiny_run.root


def run_script(name, *args):
    """Run figures.<name> as __main__ in this process: (exit status, stdout, stderr)."""
    module = f"figures.{name}"
    out, err = io.StringIO(), io.StringIO()
    argv = sys.argv
    sys.argv = [module, *map(str, args)]
    code = 0
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err), warnings.catch_warnings():
            # a module the tests imported too (summary_table) runs as a fresh copy, as `python3 -m` runs it
            warnings.filterwarnings("ignore", r".* found in sys\.modules", RuntimeWarning)
            runpy.run_module(module, run_name="__main__", alter_sys=True)
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
    # the paper's values (figures/paper_values.toml): 4/3 at theta_D = 0, ~7 at 15 and 30 deg, ~8 and ~6 at Er/kd = 10, 20, ~11.9
    by_id = {v["id"]: v for v in pv["value"]}
    assert by_id["fig4_theta0_R_init"]["value"] == pytest.approx(4 / 3, rel=1e-15)
    assert by_id["fig4_theta15_R_ss"]["value"] == by_id["fig4_theta30_R_ss"]["value"] == 7.0
    assert (by_id["fig6_e10_R_ss"]["value"], by_id["fig6_e20_R_ss"]["value"]) == (8.0, 6.0)
    assert by_id["fig9_R_m_low_cv"]["value"] == 11.9


def quoted_number(relation, number):
    """The pattern of a number as the paper's text writes it after its relation: '\approx 7', '= 4/3'."""
    sign = {"~": r"\\approx\s*", "=": r"=\s*"}[relation]
    return sign + re.escape(number) + r"(?![\d./])"


def test_paper_values_state_what_their_quotes_say():
    """Each number in paper_values.toml is the number its quoted sentence states, with the sentence's relation:
    value == value_text == the text after '\approx' or '=' in the quote; a derived value is its derivation from
    the quote. (Whether each quote is verbatim in the paper was checked against the paper's text when the
    entries were written; the repository does not ship that text, so the tests cannot re-read it.)"""
    pv = tomllib.loads((FIGURES / "paper_values.toml").read_text())
    for v in pv["value"] + pv["trend"] + pv["snapshot"]:
        assert len(v["quote"].split()) >= 5, v
    for v in pv["value"]:
        quote, text, value = v["quote"], v["value_text"], float(v["value"])
        if not v.get("derived"):
            number = text.replace("approx ", "")
            assert value == pytest.approx(float(fractions.Fraction(number)), rel=1e-15), v["id"]
            assert re.search(quoted_number(v["relation"], number), quote), (v["id"], number)
        elif text == "d/sin(theta_D)":  # the crisscross spacing along x, for the case's theta_D
            theta = params_from_name(v["case"])["theta_D"]
            assert value == pytest.approx(1 / math.sin(math.radians(theta)), rel=1e-12), v["id"]
            assert r"\frac{d}{\sin(\theta_D)}" in quote, v["id"]
        else:  # '... on the order of 50% below X': half of X, both numbers in the quote
            m = re.fullmatch(r"on the order of (\d+)% below ([\d.]+)", text)
            assert m, (v["id"], text)
            assert value == pytest.approx(float(m[2]) * (1 - float(m[1]) / 100), rel=1e-12), v["id"]
            assert f"{m[1]}%" in quote and re.search(quoted_number("~", m[2]), quote), v["id"]
    for snap in pv["snapshot"]:
        assert re.search(quoted_number("=", f"{float(snap['da_over_d']):g}"), snap["quote"]), snap


# ------------------------------------------------------------------------------------------ scripts
@pytest.mark.parametrize("script", SCRIPTS)  # pipeline.export_vtk's: test_vtk.py
def test_help(script):
    code, out, err = run_script(script, "--help")
    assert code == 0, err
    assert "usage:" in out
    assert "--preset" in out and "reduced" in out


@pytest.mark.parametrize("script", SCRIPTS)
def test_missing_result_is_one_clear_line(script, tmp_path):
    code, _, err = run_script(script, "--preset", "ci", "--runs", tmp_path / "runs", "--out", tmp_path / "out")
    assert code == EXIT_MISSING, (code, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert str(tmp_path / "runs" / "ci") in lines[0] and "result.h5" in lines[0]
    assert "make runs PRESET=ci" in lines[0]
    assert not (tmp_path / "out").exists(), "nothing is written when a result is missing"


def test_missing_result_exit_status_in_a_subprocess(tmp_path):
    r = subprocess.run([PYTHON, "-m", "figures.fig4_decussation", "--preset", "ci", "--runs", str(tmp_path)],
                       capture_output=True, text=True, timeout=60, cwd=ROOT)
    assert r.returncode == EXIT_MISSING
    assert len(r.stderr.strip().splitlines()) == 1 and "make runs PRESET=ci" in r.stderr


# ------------------------------------------------------------------------------------------ a new figure
NEW_FIGURE = '''"""Fig. 99 (test only): the R-curves of its table's cases."""
import sys

from enamel_results import cli


def main(argv=None):
    print("fig99 drawn")
    return 0


if __name__ == "__main__":
    sys.exit(main())
'''


def test_a_new_figure_script_is_discovered(tmp_path):
    """A new figure is one script and its table next to it: copied beside the real ones into a figures folder
    of its own, a test-only fig99_test.py + fig99_test.toml joins the figure list, the scripts the tests run,
    and the Make variables (pipeline.make_rules) without any list being edited; without its table it is an
    error naming the missing file."""
    figs = tmp_path / "figures"
    shutil.copytree(FIGURES, figs, ignore=shutil.ignore_patterns("out", "__pycache__"))
    (figs / "fig99_test.py").write_text(NEW_FIGURE)
    with pytest.raises(FileNotFoundError, match="fig99_test.toml"):
        cases.figure_list(figs)
    (figs / "fig99_test.toml").write_text('cases = ["theta0_s21.4_e10_cv0"]\nslow = ["theta0_s21.4_e10_cv0"]\n')
    assert cases.figure_scripts(figs)["fig99"] == "fig99_test"
    assert list(cases.figure_list(figs)) == [*cases.figure_list(), "fig99"]
    assert cases.figure_list(figs)["fig99"]["cases"] == ["theta0_s21.4_e10_cv0"]
    mk = tmp_path / "figures.mk"
    from pipeline import make_rules
    make_rules.main([str(mk), "--figures-dir", str(figs)])
    text = mk.read_text()
    assert "FIG99_CASES := theta0_s21.4_e10_cv0" in text and "FIG99_SLOW := theta0_s21.4_e10_cv0" in text
    assert re.search(r"^FIGURES := fig4 fig5 fig6 fig7 fig8 fig9 fig99$", text, re.M)
    assert re.search(r"^ALL_SLOW := .*theta0_s21.4_e10_cv0", text, re.M)


# fig5 and fig6 are fig4's code (plotting.map_figure) with other cases: --help and the missing-file test cover them.
@pytest.mark.parametrize("script", ["fig4_decussation", "fig8_statistics_rcurves", "fig7_summary",
                                    "fig9_statistics_mean"])
def test_figure_scripts_draw_available_results(script, tiny_runs, tmp_path):
    code, out, err = run_script(script, "--preset", "ci", "--runs", tiny_runs, "--out", tmp_path,
                                "--allow-missing")
    assert code == 0, err
    stem = script
    assert_image_files(tmp_path, stem)
    assert str(tmp_path / "ci" / f"{stem}.png") in out
    assert "warning: skipping missing" in err  # the tiny tree lacks most cases, and says so


# ------------------------------------------------------------------------------------------ summary table
def test_summary_table_rows_columns_and_values(tiny_runs, tmp_path):
    code, _, err = run_script("summary_table", "--preset", "ci", "--runs", tiny_runs, "--out", tmp_path,
                              "--allow-missing")
    assert code == 0, err
    with open(tmp_path / "ci" / "summary.csv") as f:
        reader = csv.DictReader(f)
        assert list(reader.fieldnames) == list(summary_table.COLUMNS)
        rows = list(reader)
    figs = cases.figure_list()
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
        assert float(row["theta_D"]) == params_from_name(case)["theta_D"]
    assert by_case["theta0_s14.3_e5_cv0"]["status"] == "missing"
    assert float(by_case["theta0_s21.4_e10_cv0"]["paper_R_init_over_Gamma"]) == pytest.approx(4 / 3, rel=1e-5)
    assert by_case["theta0_s21.4_e10_cv0"]["paper_R_m_pooled_over_Gamma"] == "", "pooled values: Figs. 8/9 only"
    assert by_case["theta30_s21.4_e10_cv0"]["paper_R_ss_over_Gamma"] == "7;8"
    assert by_case["theta30_s28.5_e10_cv0.3_seed1"]["paper_R_m_pooled_over_Gamma"] == "5.95"
    md = (tmp_path / "ci" / "summary.md").read_text()
    assert "| theta30_s21.4_e10_cv0 |" in md and "Trends the paper states" in md
    # the tiny runs' --set overrides are named at the top (not the default model), threads is not
    head = md.split("\n| case |")[0]
    assert f"Runs: {tiny_runs}." in head and "not the default model" in head, head
    assert all(s in head for s in ("w_s_over_d=8", "stop_da_over_d=1.5", "frames_da_over_d=[0.5, 1.5]")), head
    assert "threads=" not in head and "rate_factor=" not in head, head


def test_summary_table_without_allow_missing_fails(tiny_runs, tmp_path):
    code, _, err = run_script("summary_table", "--preset", "ci", "--runs", tiny_runs, "--out", tmp_path)
    assert code == EXIT_MISSING
    assert "make runs PRESET=ci" in err


# ------------------------------------------------------------------------------------------ enamel_results
def test_loaded_result_matches_file_and_pooled_rm_matches_solver(tiny_runs):
    path = tiny_runs / "ci" / "theta30_s28.5_e10_cv0.3_seed1" / "result.h5"
    r = load_result(path, full=True)
    assert r.case == "theta30_s28.5_e10_cv0.3_seed1"
    assert (r.param("theta_D"), r.param("sigma_ru_over_sigma0"), r.param("cv"), r.param("seed")) == (30, 28.5, 0.3, 1)
    assert len(r.da) == len(r.R) > 0
    assert r.geometry.iface_midpoint.shape == (len(r.geometry.iface_tag), 3)
    assert all(f.iface_state.shape == r.geometry.iface_tag.shape for f in r.frames)
    # Python's pooled mean/std over one realisation = the solver's R_m, dR_m (same definition, output.cpp)
    m, s, n = pooled_rm([r])
    assert n == np.count_nonzero((r.da > 0) & (r.da < 30))
    assert m == pytest.approx(r.R_m, rel=1e-12) and s == pytest.approx(r.dR_m, rel=1e-9, abs=1e-12)
    # pooling two copies: same mean and std, twice the points
    assert pooled_rm([r, r])[:2] == pytest.approx((m, s), rel=1e-12)
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
    seal_result_file(runs / "ci" / case / "result.h5")  # an edit, not damage
    r = load_result(runs / "ci" / case / "result.h5")
    assert not r.completed and "NOT COMPLETED: interrupted" in plotting.status_flag(r)
    code, _, err = run_script("summary_table", "--preset", "ci", "--runs", runs, "--out", tmp_path / "out",
                              "--allow-missing")
    assert code == 0, err
    with open(tmp_path / "out" / "ci" / "summary.csv") as f:
        row = next(row for row in csv.DictReader(f) if row["case"] == case)
    assert row["status"] == "interrupted" and float(row["R_init_over_Gamma"]) == pytest.approx(r.R_init, rel=ATTR_RTOL)
    md = (tmp_path / "out" / "ci" / "summary.md").read_text()
    assert any(line.startswith(f"| {case} |") and "**interrupted**" in line for line in md.splitlines())
