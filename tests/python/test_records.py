"""Run records (enamel_results/records.py, pipeline/records.py): a record loads as the Result of its run, exactly;
its maps draw as the run's, pixel for pixel; it is small; the summary table and Figs. 4 and 8 made from records are
the ones made from the runs (byte for byte, pixel for pixel); a malformed record is refused in one line naming it; the lookup prefers the run; `make records`
and `make figures-recorded` do what they say, running nothing.

The runs are the tiny ones of conftest.tiny_run (8 d x 4 d, stopped at Delta_a/d = 1.5, frames at 0.5 and 1.5)
and, for the size, one ci run (conftest.ci_run), all in temporary folders.
"""
import contextlib
import csv
import datetime
import hashlib
import io
import json
import math
import os
import pathlib
import shutil
import subprocess
import types

import numpy as np
import pytest

from conftest import ROOT, TINY_SETS, SharedRuns
from enamel_results import cli, paths, records, results
from enamel_results.results import EXIT_DAMAGED, TAG_INTER21, load_result
from figures import plotting
from pipeline import records as records_cli
from test_figures import TINY_CASES, run_script

FIG4 = ["theta0_s21.4_e10_cv0", "theta15_s21.4_e10_cv0", "theta30_s21.4_e10_cv0"]
BROKEN = "theta30_s28.5_e10_cv0.3_seed1"   # breaks rods in the tiny run
ENV = {k: v for k, v in os.environ.items() if k not in ("MAKEFLAGS", "MFLAGS", "MAKELEVEL")}


def same(a, b) -> bool:
    """Equal, NaN equal to NaN (also inside dicts and lists)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        return np.array_equal(np.asarray(a), np.asarray(b), equal_nan=True)
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return type(a) is type(b) and a == b


@pytest.fixture(scope="module")
def tiny(run, tiny_run, tmp_path_factory):
    """A runs/ root of its own with the tiny runs of Fig. 4's cases and the rod-breaking case, and a half-rate twin
    (a copy): the two that test_figures uses too are copied from the shared tiny runs, the other two run here (in
    the shared root they would change what test_figures finds missing)."""
    own = SharedRuns(run, tmp_path_factory.mktemp("record_runs"), TINY_SETS)
    for case in FIG4 + [BROKEN]:
        if case in TINY_CASES:
            (own.root / "ci" / case).mkdir(parents=True)
            shutil.copy(tiny_run(case), own.root / "ci" / case / "result.h5")
        else:
            own(case)
    slow = own.root / "ci" / f"{FIG4[2]}_slow"
    slow.mkdir()
    shutil.copy(own.root / "ci" / FIG4[2] / "result.h5", slow / "result.h5")
    return own.root


def rewrite(path: pathlib.Path, change) -> None:
    """Edit a record's content with change(dict) and give it a matching content_sha256 (a well-sealed record
    whose fields are wrong)."""
    rec = json.loads(path.read_text())
    change(rec)
    rec["content_sha256"] = hashlib.sha256(records.canonical(rec)).hexdigest()
    path.write_text(json.dumps(rec))


# ------------------------------------------------------------------------------------------ round trip
@pytest.mark.parametrize("case", [FIG4[2], BROKEN])
def test_record_loads_as_the_runs_result_exactly(case, tiny, tmp_path):
    h5 = tiny / "ci" / case / "result.h5"
    records.write_record(h5, tmp_path / "r.json")
    run, rec = load_result(h5, case=case, full=True), records.load_record(tmp_path / "r.json", case=case, full=True)
    assert rec.da.dtype == run.da.dtype == np.float64 and np.array_equal(rec.da, run.da)
    assert np.array_equal(rec.R, run.R) and rec.R.size > 3
    for name in ("case", "R_init", "R_ss", "R_m", "dR_m", "da_max", "broken_rods", "da_first_rod_fracture",
                 "status", "completed", "wall_time_s", "params", "meta"):
        assert same(getattr(rec, name), getattr(run, name)), name
    if case == BROKEN:
        assert run.broken_rods > 0 and math.isfinite(run.da_first_rod_fracture)
    assert rec.geometry.attrs == run.geometry.attrs
    # the map of the figures' frame: in each panel, as many interfaces of each state, at the same midpoints (x
    # exactly, y within records.BACKGROUND_TOL), and the same deleted rod elements
    f_run, f_rec = run.frame_near(15), rec.frame_near(15)
    assert (f_rec.index, f_rec.da, f_rec.target_da, f_rec.step) == (f_run.index, f_run.da, f_run.target_da, f_run.step)
    for _, tag, ply in plotting.MAP_PANELS:
        for state in (0, 1, 2):
            pick = lambda r, f: np.array(sorted(map(tuple, r.geometry.iface_midpoint[
                (r.geometry.iface_tag == tag) & (f.iface_state == state), :2]))).reshape(-1, 2)
            a, b = pick(run, f_run), pick(rec, f_rec)
            assert a.shape == b.shape and (state == 0 or a.size), (tag, state, a.shape, b.shape)
            assert np.array_equal(a[:, 0], b[:, 0]) and np.all(np.abs(a[:, 1] - b[:, 1]) <= records.BACKGROUND_TOL)
    rods = lambda r, f: sorted(tuple(r.geometry.node_position[n, :2].tolist() for n in e) + (r.geometry.node_ply[e[0]],)
                               for e in r.geometry.beam_nodes[f.beam_broken > 0])
    assert rods(rec, f_rec) == rods(run, f_run)
    assert not np.any(rec.geometry.iface_tag == TAG_INTER21), "interlayer 2-1 is drawn nowhere: left out"
    assert {tag for _, tag, _ in plotting.MAP_PANELS} == set(records.MAP_TAGS), "the record holds what the maps draw"


def map_pixels(r, da: float = 15) -> np.ndarray:
    """The RGBA pixels of one row of the three process-zone maps of r at the frame nearest da."""
    import matplotlib.pyplot as plt
    fig, axes = plotting.map_row_layout(1, r.geometry.attrs)
    plotting.draw_map_row(axes[0], r, da, "row")
    fig.canvas.draw()
    pixels = np.asarray(fig.canvas.buffer_rgba()).copy()
    plt.close(fig)
    return pixels


def test_record_draws_the_runs_maps_pixel_for_pixel(tiny, tmp_path):
    h5 = tiny / "ci" / BROKEN / "result.h5"
    records.write_record(h5, tmp_path / "r.json")
    a, b = map_pixels(load_result(h5, full=True)), map_pixels(records.load_record(tmp_path / "r.json", full=True))
    assert a.shape == b.shape and np.array_equal(a, b)
    assert np.count_nonzero(np.any(a[..., :3] != 255, axis=2)) > 10000, "the maps are drawn"


def test_record_holds_the_figures_frames_and_says_when_asked_for_another(tiny, tmp_path):
    h5 = tiny / "ci" / BROKEN / "result.h5"
    records.write_record(h5, tmp_path / "r.json")
    rec = records.load_record(tmp_path / "r.json", full=True)
    assert [f.target_da for f in rec.frames] == [1.5], "only the frame nearest the figures' 15 d"
    with pytest.raises(records.MissingFrame) as e:
        rec.frame_near(0.4)
    assert str(tmp_path / "r.json") in str(e.value) and "0.5" in str(e.value) and len(str(e.value).splitlines()) == 1
    assert records_cli.main(["write", str(h5), str(tmp_path / "both.json"), "--da", "0.5", "--da", "15"]) == 0
    both, run = records.load_record(tmp_path / "both.json", full=True), load_result(h5, full=True)
    for da in (0.4, 15):
        assert both.frame_near(da).index == run.frame_near(da).index
        assert np.array_equal(map_pixels(both, da), map_pixels(run, da)), da


def test_record_is_small_against_its_result_file(ci_run, tmp_path):
    """A ci run's record is under 5% of its result.h5 (22 kB of 887 kB measured; an 80 x 80 d run's 83 kB
    of 6.2 MB) and is text that git can diff: JSON, one line per field or list, no gzip."""
    h5 = ci_run(FIG4[2])
    record = tmp_path / "r.json"
    records.write_record(h5, record)
    size, whole = record.stat().st_size, h5.stat().st_size
    assert size < 0.05 * whole, (size, whole)
    text = record.read_text(encoding="utf-8")
    assert json.loads(text)["record"] == records.RECORD_KIND
    assert max(map(len, text.splitlines())) < 0.5 * size, "laid out in lines, not one blob"


# ------------------------------------------------------------------------------------------ figures from records
def test_summary_from_records_is_the_summary_from_runs(tiny, tmp_path):
    recs = tmp_path / "records"
    with contextlib.redirect_stdout(io.StringIO()) as out:
        assert records_cli.main(["update", "--preset", "ci", "--runs", str(tiny), "--records", str(recs)]) == 0
    assert "5 written, 0 up to date" in out.getvalue(), out.getvalue()
    assert sorted(p.name for p in (recs / "ci").iterdir()) == sorted(
        [f"{c}.json" for c in FIG4 + [BROKEN]] + [f"{FIG4[2]}_slow.json"])
    code, _, err = run_script("summary_table", "--preset", "ci", "--runs", tiny, "--out", tmp_path / "a",
                              "--allow-missing")
    assert code == 0, err
    code, _, err = run_script("summary_table", "--preset", "ci", "--runs", tmp_path / "no_runs", "--records", recs,
                              "--out", tmp_path / "b", "--allow-missing")
    assert code == 0, err
    a, b = (tmp_path / "a" / "ci" / "summary.csv").read_text(), (tmp_path / "b" / "ci" / "summary.csv").read_text()
    assert a == b
    assert sum(row["status"] == "completed" for row in csv.DictReader(io.StringIO(b))) == 5
    ma, mb = ((tmp_path / d / "ci" / "summary.md").read_text().splitlines() for d in ("a", "b"))
    differ = [(x, y) for x, y in zip(ma, mb) if x != y]
    assert len(ma) == len(mb) and len(differ) == 1, differ   # only where the numbers come from
    assert differ[0][0].startswith(f"Runs: {tiny}.") and differ[0][1].startswith(f"Records: {recs}.")
    # the map figures from records alone are the ones from the runs, pixel for pixel
    import matplotlib.image as mpimg
    for fig in ("fig4_decussation", "fig8_statistics_rcurves"):
        for where, source in (("a", ["--runs", tiny]), ("b", ["--runs", tmp_path / "no_runs", "--records", recs])):
            code, _, err = run_script(fig, "--preset", "ci", *source, "--out", tmp_path / where, "--allow-missing")
            assert code == 0, err
        a, b = (mpimg.imread(tmp_path / d / "ci" / f"{fig}.png") for d in ("a", "b"))
        assert a.shape == b.shape and np.array_equal(a, b), fig


# ------------------------------------------------------------------------------------------ malformed records
def malformations():
    yield "truncated", lambda p: p.write_text(p.read_text()[: len(p.read_text()) // 2])
    yield "a merge conflict", lambda p: p.write_text("<<<<<<< HEAD\n" + p.read_text())
    yield "not text", lambda p: p.write_bytes(b"\xff\xfe\x00garbage")
    yield "edited", lambda p: p.write_text(p.read_text().replace('"R_init_over_Gamma":', '"R_init_over_Gamma":1', 1))
    yield "another kind", lambda p: rewrite(p, lambda r: r.update(record="something else"))
    yield "a newer format", lambda p: rewrite(p, lambda r: r.update(format=records.RECORD_FORMAT + 1))
    yield "no R-curve", lambda p: rewrite(p, lambda r: r["rcurve"].pop("R_over_Gamma"))
    yield "R as text", lambda p: rewrite(p, lambda r: r["rcurve"].update(R_over_Gamma="1 2 3"))
    yield "lengths", lambda p: rewrite(p, lambda r: r["rcurve"]["da_over_d"].pop())
    yield "a map's states", lambda p: rewrite(p, lambda r: r["maps"]["frames"][0]["states"]["0"].__setitem__(
        0, [1, 10 ** 6]))
    yield "a map's tags", lambda p: rewrite(p, lambda r: r["maps"]["background"].pop("2"))
    yield "a map's slices", lambda p: rewrite(p, lambda r: r["maps"]["slice_x"].pop())
    yield "no sha", lambda p: rewrite(p, lambda r: None) or p.write_text(p.read_text().replace("content_sha256", "x"))


@pytest.mark.parametrize("what,damage", list(malformations()), ids=[w for w, _ in malformations()])
def test_malformed_record_is_refused_in_one_line_naming_it(what, damage, tiny, tmp_path, capsys):
    recs = tmp_path / "records"
    target = paths.record_file("ci", BROKEN, records=recs)
    records.write_record(tiny / "ci" / BROKEN / "result.h5", target)
    records.load_record(target, full=True)
    damage(target)
    with pytest.raises(records.MalformedRecord) as e:
        records.load_record(target, full=True)
    message = str(e.value)
    assert len(message.splitlines()) == 1 and str(target) in message and "malformed record" in message, message
    # the figures' loader: one line, the damaged status, no traceback
    args = types.SimpleNamespace(preset="ci", runs=tmp_path / "no_runs", records=recs, allow_missing=False)
    with pytest.raises(SystemExit) as e:
        cli.load_cases("fig_test.py", args, [BROKEN])
    assert e.value.code == EXIT_DAMAGED
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "malformed record" in err[0] and str(target) in err[0], err
    assert records_cli.main(["check", str(target)]) == EXIT_DAMAGED
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(target) in err[0], err


def test_bad_input_to_write_writes_nothing(tiny, tmp_path, capsys):
    h5 = tiny / "ci" / BROKEN / "result.h5"
    assert records_cli.main(["write", str(h5), str(tmp_path / "r.txt")]) == 2
    damaged = tmp_path / "run" / "result.h5"
    damaged.parent.mkdir()
    damaged.write_bytes(h5.read_bytes()[:-100])
    assert records_cli.main(["write", str(damaged), str(tmp_path / "out" / "r.json")]) == EXIT_DAMAGED
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 2 and "r.txt" in err[0] and str(damaged) in err[1], err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"], "nothing written"


# ------------------------------------------------------------------------------------------ the lookup
def test_lookup_prefers_the_run_and_falls_back_to_the_record(tmp_path):
    runs, recs = tmp_path / "runs", tmp_path / "records"
    run, record = paths.result_file("ci", "c", runs=runs), paths.record_file("ci", "c", records=recs)
    assert paths.find_result("ci", "c", runs=runs, records=recs) == run, "neither: the run's path (missing)"
    record.parent.mkdir(parents=True)
    record.write_text("{}")
    assert paths.find_result("ci", "c", runs=runs, records=recs) == record
    assert paths.find_result("ci", "c", runs=runs, records=None) == run, "records=None: not looked up"
    run.parent.mkdir(parents=True)
    run.write_bytes(b"")
    assert paths.find_result("ci", "c", runs=runs, records=recs) == run, "both: the run"
    slow = paths.record_file("ci", "c", slow=True, records=recs)
    assert slow.name == "c_slow.json" and paths.is_record(slow) and not paths.is_record(run)
    assert paths.source_root(record) == recs and paths.source_root(run) == runs
    # the figure scripts' default: records/ unless --runs names other runs
    ns = types.SimpleNamespace
    assert cli.records_root(ns(runs=None, records=None)) == paths.RECORDS
    assert cli.records_root(ns(runs=runs, records=None)) is None
    assert cli.records_root(ns(runs=runs, records=recs)) == recs


# ------------------------------------------------------------------------------------------ make
def make(enamel, *args, timeout=600):
    cmd = ["make", "--no-print-directory", "-o", str(enamel), f"ENAMEL={enamel}", "PRESET=ci", *map(str, args)]
    return subprocess.run(cmd, cwd=ROOT, env=ENV, capture_output=True, text=True, timeout=timeout)


def test_make_records_and_figures_recorded(enamel, tiny, tmp_path):
    """make records writes what is missing once; make figures-all with every case of Fig. 4 recorded and no run
    runs none of them; make figures-recorded makes Fig. 4 from the records, runs nothing and lists the missing
    cases of the other figures."""
    recs, runs, out = tmp_path / "records", tmp_path / "runs", tmp_path / "out"
    shutil.copytree(tiny / "ci", runs / "ci", ignore=shutil.ignore_patterns(f"{BROKEN}"))
    r = make(enamel, "records", f"RUNS={runs}", f"RECORDS={recs}")
    assert r.returncode == 0, r.stdout + r.stderr
    assert "4 written, 0 up to date" in r.stdout, r.stdout
    r = make(enamel, "records", f"RUNS={runs}", f"RECORDS={recs}")
    assert r.returncode == 0 and "0 written, 4 up to date" in r.stdout, r.stdout + r.stderr
    shutil.rmtree(runs)
    fig4 = f"{out}/ci/fig4_decussation.png"
    r = make(enamel, "-n", fig4, f"RUNS={runs}", f"RECORDS={recs}", f"FIG_ROOT={out}")
    assert r.returncode == 0, r.stdout + r.stderr
    assert " run " not in r.stdout and "figures.fig4_decussation" in r.stdout, r.stdout
    r = make(enamel, "-n", "figures-all", f"RUNS={runs}", f"RECORDS={recs}", f"FIG_ROOT={out}")
    assert r.returncode == 0, r.stdout + r.stderr
    assert all(f"--out {runs}/ci/{c} " not in r.stdout for c in FIG4 + [f"{FIG4[2]}_slow"]), "recorded: not run"
    assert f"--out {runs}/ci/theta0_s7.1_e5_cv0 " in r.stdout, "a run without a record is run"
    r = make(enamel, "figures-recorded", f"RUNS={runs}", f"RECORDS={recs}", f"FIG_ROOT={out}")
    assert r.returncode == 0, r.stdout + r.stderr
    assert (out / "ci" / "fig4_decussation.png").is_file() and not (out / "ci" / "fig7_summary.png").exists()
    assert not runs.exists(), "nothing was run"
    lines = r.stdout.splitlines()
    assert any(line.startswith("figures-recorded: fig4: from 3 runs and records") for line in lines), r.stdout
    fig5 = next(line for line in lines if line.startswith("figures-recorded: fig5: not made"))
    assert "theta30_s7.1_e10_cv0" in fig5 and "theta30_s21.4_e10_cv0 " not in fig5 + " ", fig5
    assert "figures-recorded: 1 of 7 made" in r.stdout, r.stdout


def test_publish_copies_the_figures_made_small_with_an_index(tiny, tmp_path, monkeypatch, capsys):
    """publish (make publish): the figures whose runs are all there go to DOCS/PRESET/ as 256-colour PNGs under the
    size limit, an earlier copy of a figure not made now is removed, and index.md says what each was drawn from
    and what is missing; a figure over the limit after the palette is refused (exit 1) and not left there."""
    from PIL import Image
    docs, out = tmp_path / "docs", tmp_path / "out"
    (docs / "ci").mkdir(parents=True)
    (docs / "ci" / "fig5_rod_strength.png").write_bytes(b"stale")
    args = ["publish", "--preset", "ci", "--runs", str(tiny), "--records", str(tmp_path / "none"),
            "--out", str(out), "--docs", str(docs)]
    assert records_cli.main(args) == 0, capsys.readouterr()
    png = docs / "ci" / "fig4_decussation.png"
    with Image.open(png) as im:
        assert im.mode == "P" and im.size == Image.open(out / "ci" / "fig4_decussation.png").size
    assert 0 < png.stat().st_size <= records_cli.PUBLISHED_PNG_BYTES
    assert not (docs / "ci" / "fig5_rod_strength.png").exists(), "a stale copy disagrees with the index"
    index = (docs / "ci" / "index.md").read_text()
    assert "| fig4 | [fig4_decussation.png](fig4_decussation.png) | 3 runs and records |" in index, index
    fig5 = next(line for line in index.splitlines() if line.startswith("| fig5 |"))
    assert "not drawn" in fig5 and "theta30_s7.1_e10_cv0" in fig5, fig5
    monkeypatch.setattr(records_cli, "PUBLISHED_PNG_BYTES", 1000)
    assert records_cli.main(args) == 1
    assert not png.exists() and "refused above 1 kB after the palette: fig4_decussation.png" in capsys.readouterr().err


def test_update_rewrites_a_record_of_an_older_run_and_keeps_one_of_a_newer_run(tiny, tmp_path, capsys):
    runs, recs = tmp_path / "runs", tmp_path / "records"
    (runs / "ci" / BROKEN).mkdir(parents=True)
    h5 = runs / "ci" / BROKEN / "result.h5"
    shutil.copy(tiny / "ci" / BROKEN / "result.h5", h5)
    update = ["update", "--preset", "ci", "--runs", str(runs), "--records", str(recs)]
    assert records_cli.main(update) == 0
    record = paths.record_file("ci", BROKEN, records=recs)
    first = record.read_bytes()
    assert records_cli.main(update) == 0 and record.read_bytes() == first
    assert "0 written, 1 up to date" in capsys.readouterr().out
    import h5py   # the run again, later: another file, a later written_utc
    with h5py.File(h5, "r+") as f:
        f["meta"].attrs["written_utc"] = "2999-01-01T00:00:00Z"
    results.seal_result_file(h5)
    assert records_cli.main(update) == 0
    assert "an older run" in capsys.readouterr().out
    assert records.record_is_of(records.read_record(record), h5)
    with h5py.File(h5, "r+") as f:   # the run there is older than the record's
        f["meta"].attrs["written_utc"] = datetime.datetime(2000, 1, 1).strftime("%Y-%m-%dT%H:%M:%SZ")
    results.seal_result_file(h5)
    before = record.read_bytes()
    assert records_cli.main(update) == 0
    err = capsys.readouterr().err
    assert f"kept {record}" in err and "newer run" in err and record.read_bytes() == before
    record.write_text("{")   # malformed: refused, nothing written
    assert records_cli.main(update) == EXIT_DAMAGED
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(record) in err[0] and record.read_text() == "{"


def test_a_run_of_a_recorded_preset_leaves_its_record(enamel, tmp_path):
    """The run rule writes the record of a run of a preset in RECORD_PRESETS (converged and paper by default; here
    ci, for a tiny run) as it completes, and none for the others (the default make figures is as before)."""
    runs, recs = tmp_path / "runs", tmp_path / "records"
    case = "theta30_s21.4_e10_cv0"
    target = runs / "ci" / case / "result.h5"
    sets = "w_s_over_d=8 h_s_over_d=4 stop_da_over_d=1.5 frames_da_over_d=[1.5] threads=1"  # no spaces in a value
    common = [f"RUNS={runs}", f"RECORDS={recs}", f"RUN_SET={sets}", str(target)]
    r = make(enamel, *common)
    assert r.returncode == 0 and target.is_file(), r.stdout + r.stderr
    assert not recs.exists(), "ci is not a recorded preset by default"
    target.unlink()
    r = make(enamel, "RECORD_PRESETS=ci", *common)
    assert r.returncode == 0, r.stdout + r.stderr
    record = paths.record_file("ci", case, records=recs)
    assert records.record_is_of(records.read_record(record), target)


def test_update_with_a_damaged_result_file_writes_nothing(tiny, tmp_path, capsys):
    runs, recs = tmp_path / "runs", tmp_path / "records"
    for case in (FIG4[0], BROKEN):
        (runs / "ci" / case).mkdir(parents=True)
        shutil.copy(tiny / "ci" / case / "result.h5", runs / "ci" / case / "result.h5")
    damaged = runs / "ci" / BROKEN / "result.h5"
    damaged.write_bytes(damaged.read_bytes()[:-10])
    assert records_cli.main(["update", "--preset", "ci", "--runs", str(runs), "--records", str(recs)]) == EXIT_DAMAGED
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(damaged) in err[0] and "damaged result" in err[0], err
    assert not recs.exists(), "nothing written, not even the undamaged run's record"
