"""Command line: --help on every command, and bad input answered by one clear line and a distinct exit
status before anything is allocated or written (docs/verification.md)."""
import os
import re
import subprocess

import h5py
import pytest

from conftest import CASES
from enamel_results.constants import EXIT

# Exit statuses, as the solver prints them (`enamel-dem constants`, read by enamel_results.constants).
USAGE, MISSING_FILE, MALFORMED, UNKNOWN_KEY, WRONG_TYPE, OUT_OF_RANGE, UNWRITABLE, EXISTS = (
    EXIT[k] for k in ("usage", "missing_file", "malformed_toml", "unknown_key", "wrong_type", "out_of_range",
                      "output_unwritable", "output_exists"))

GOOD = "theta_D = 0\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n"


@pytest.mark.parametrize("args", [["--help"], ["info", "--help"], ["run", "--help"], ["keys", "--help"]])
def test_help_explains_every_command(run, args):
    r = run(*args)
    assert r.returncode == 0
    assert "Usage" in r.stdout
    if args[0] == "run":
        for option in ("--preset", "--set", "--out", "--force"):
            assert option in r.stdout, option


def test_keys_lists_every_key_with_range(run):
    r = run("keys")
    assert r.returncode == 0
    for key in ("theta_D", "Er_over_kd", "sigma_ru_over_sigma0", "cv", "h_e_over_d", "v_app_over_cd"):
        assert f"`{key}`" in r.stdout, key


@pytest.mark.parametrize("text, status, words", [
    (GOOD + "foo = 1\n", UNKNOWN_KEY, ["'foo'", "unknown key"]),
    ("Er_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n", UNKNOWN_KEY, ["'theta_D'", "missing", "[0, 45]"]),
    (GOOD.replace("theta_D = 0", 'theta_D = "x"'), WRONG_TYPE, ["'theta_D'", '"x"', "wrong type", "[0, 45]"]),
    (GOOD.replace("theta_D = 0", "theta_D = 60"), OUT_OF_RANGE, ["'theta_D'", "60", "[0, 45]"]),
    (GOOD + "cv = -0.1\n", OUT_OF_RANGE, ["'cv'", "-0.1", "[0, 1)"]),
    (GOOD + "w_s_over_d = -5\n", OUT_OF_RANGE, ["'w_s_over_d'", "-5"]),
    (GOOD + "h_e_over_d = 1.5\n", OUT_OF_RANGE, ["'h_e_over_d'", "1.5", "(0, 1]"]),
    (GOOD + "v_app_over_cd = nan\n", OUT_OF_RANGE, ["'v_app_over_cd'", "nan"]),
    ("theta_D = = 0\n", MALFORMED, ["malformed TOML", ":1:"]),
])
def test_bad_case_file_one_clear_line(run, tmp_path, text, status, words):
    case = tmp_path / "case.toml"
    case.write_text(text)
    out = tmp_path / "out"
    r = run("run", case, "--out", out)
    assert r.returncode == status, r.stderr
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1, r.stderr
    for w in words:
        assert w in lines[0], (w, lines[0])
    assert not out.exists(), "nothing may be written before the case is valid"


@pytest.mark.parametrize("text, status, words", [
    (GOOD + "shear_strength_ratio = 0\n", OUT_OF_RANGE, ["'shear_strength_ratio'", "= 0", "(0, 10]"]),
    (GOOD + "shear_strength_ratio = 12\n", OUT_OF_RANGE, ["'shear_strength_ratio'", "= 12", "(0, 10]"]),
    (GOOD + 'shear_strength_ratio = "2"\n', WRONG_TYPE, ["'shear_strength_ratio'", '"2"', "wrong type", "(0, 10]"]),
    (GOOD + 'grip_constraint = "ux"\n', OUT_OF_RANGE, ["'grip_constraint'", '"ux"', '"uy", "uxuy"']),
    (GOOD + 'grip_profile = "centre"\n', OUT_OF_RANGE,
     ["'grip_profile'", '"centre"', '"to_right_edge", "about_centre"']),
])
def test_bad_model_reading_key_one_clear_line(run, tmp_path, text, status, words):
    """The keys of the paper's open readings (docs/model.md, Choices the paper leaves open): one line naming the
    key, the value and what is allowed, before anything is written."""
    test_bad_case_file_one_clear_line(run, tmp_path, text, status, words)


def test_missing_case_file(run, tmp_path):
    r = run("info", tmp_path / "nope.toml")
    assert r.returncode == MISSING_FILE
    assert "nope.toml" in r.stderr


def test_bad_set_override_names_key(run):
    r = run("info", CASES / "small_theta0.toml", "--set", "h_e_over_d=nan")
    assert r.returncode == OUT_OF_RANGE
    assert "h_e_over_d" in r.stderr and "nan" in r.stderr


def test_unknown_preset(run):
    r = run("info", CASES / "small_theta0.toml", "--preset", "huge")
    assert r.returncode == USAGE
    assert "huge" in r.stderr


def test_unwritable_output_directory(run, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("I am a file")
    r = run("run", CASES / "small_theta0.toml", "--out", blocker / "sub")
    assert r.returncode == UNWRITABLE, r.stderr
    assert blocker.read_text() == "I am a file"


def test_existing_output_needs_force(run, tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "result.h5").write_bytes(b"precious")
    r = run("run", CASES / "small_theta0.toml", "--out", out)
    assert r.returncode == EXISTS, r.stderr
    assert "--force" in r.stderr
    assert (out / "result.h5").read_bytes() == b"precious"


def info_line(stdout, label):
    """The rest of the one `enamel-dem info` line that starts with `label` (after leading spaces)."""
    found = [m[1] for m in re.finditer(rf"^ *{re.escape(label)} +(\S.*)$", stdout, re.M)]
    assert len(found) == 1, (label, stdout)
    return found[0]


def info_count(stdout, label):
    """The number that follows `label` on its line."""
    m = re.match(r"(\d+)\b", info_line(stdout, label))
    assert m, (label, stdout)
    return int(m[1])


def test_info_prints_counts(run):
    r = run("info", CASES / "small_theta0.toml")
    assert r.returncode == 0, r.stderr
    out = r.stdout
    # hand count of the 6 d x 4 d specimen at h_e = 0.3 d (tests/cpp/test_geometry.cpp): 21 slices, 8 rods each
    # in every slice, 20 interfaces per slice of which the pre-crack cuts 4 in each of slices 0..K, K = 10
    # (a0 = 3 d = 10 h_e: the tip at a0_eff = 10.25 h_e, docs/model.md Geometry)
    assert info_count(out, "slices") == 21
    assert info_count(out, "rods") == 8
    assert info_count(out, "nodes") == 8 * 21
    assert info_count(out, "DOF") == 6 * 8 * 21
    assert info_count(out, "beam elements") == 8 * 20
    assert "(+0 cut by the pre-crack)" in info_line(out, "beam elements")
    assert info_count(out, "interfaces") == 20 * 21 - 44
    assert "(+44 cut by the pre-crack)" in info_line(out, "interfaces")
    assert info_line(out, "pre-crack tip").startswith("a0_eff 3.075 d") and "K = 10" in info_line(out, "pre-crack tip")
    assert info_count(out, "ply 1") + info_count(out, "ply 2") == 6 * 21 - 2 * 11
    assert info_count(out, "interlayer 1-2") == info_count(out, "interlayer 2-1 (periodic wrap)") == 7 * 21 - 11
    assert "bending governs" in info_line(out, "element frequency")


def test_time_step_above_stable_limit_is_refused(run, tmp_path):
    """dt_factor 0.5 with the paper scheme is above 0.95 x 2/omega_max: refused with the limit, nothing written."""
    out = tmp_path / "out"
    r = run("run", CASES / "small_theta0.toml", "--out", out, "--set", "dt_factor=0.5", "--set", 'integrator="paper"')
    assert r.returncode == OUT_OF_RANGE, r.stderr
    line = r.stderr.strip()
    assert len(line.splitlines()) == 1 and "stable limit" in line and "dt_factor <=" in line, line
    assert not (out / "result.h5").exists()


def test_diverging_run_stops_with_readable_failed_result(enamel, tmp_path):
    """A NaN in the state (injected after step 200, as a diverging run would produce) stops the run at the next
    check with a message naming the quantity and the step; the partial result is readable as result.failed.h5 and
    marked failed, and there is no result.h5 (which only a completed run writes)."""
    out = tmp_path / "out"
    env = dict(os.environ, ENAMEL_INJECT_NAN_AT_STEP="200")
    r = subprocess.run([str(enamel), "run", str(CASES / "small_theta0.toml"), "--out", str(out), "--quiet"],
                       capture_output=True, text=True, env=env, timeout=600)
    assert r.returncode == EXIT["run_unstable"], r.stderr
    assert "non-finite" in r.stderr and "step" in r.stderr
    assert not (out / "result.h5").exists() and not (out / "result.partial.h5").exists()
    with h5py.File(out / "result.failed.h5", "r") as f:
        assert f["meta"].attrs["status"] == "failed"
        assert "non-finite" in f["meta"].attrs["stop_reason"]
        assert f["history/step"][-1] >= 200


@pytest.mark.parametrize("sets", [["w_s_over_d=2000", "h_s_over_d=2000"], ["h_e_over_d=1e-9"]])
def test_case_too_large_for_memory_is_refused_before_anything_is_written(run, tmp_path, sets):
    """A case that cannot fit is refused in one line with the memory it needs and the memory available (exit 7),
    before the model is allocated (no bad_alloc) and before the output directory is created; `info` too."""
    out = tmp_path / "out"
    args = [CASES / "small_theta0.toml"] + [a for s in sets for a in ("--set", s)]
    for cmd in (["run", *args, "--out", out], ["info", *args]):
        r = run(*cmd, timeout=60)
        assert r.returncode == OUT_OF_RANGE, r.stderr
        line = r.stderr.strip()
        assert len(line.splitlines()) == 1, line
        assert re.search(r"needs about [0-9.e+]+ GB of memory .* and [0-9.]+ GB are available", line), line
        assert sets[0].split("=")[0] in line
    assert not out.exists()


def test_info_estimate_matches_the_built_model(run):
    """`info --estimate` (no model built) gives counts within 5% of the model `info` builds, and a memory figure."""
    est = dict(l.split() for l in run("info", CASES / "small_theta30.toml", "--estimate").stdout.splitlines())
    built = run("info", CASES / "small_theta30.toml").stdout
    nodes = int(re.search(r"^nodes\s+(\d+)", built, re.M).group(1))
    dof = int(re.search(r"^DOF\s+(\d+)", built, re.M).group(1))
    assert abs(float(est["nodes"]) / nodes - 1) < 0.05, (est, nodes)
    assert abs(float(est["dof"]) / dof - 1) < 0.05, (est, dof)
    assert 10 < float(est["memory_mb"]) < 1000
