"""The bench script itself, in its --quick mode (tiny specimens at the ci preset):
it runs, writes results.csv, cost_growth.csv, results.md and both figures, measures the reference against
itself as zero error, and computes the errors of the other variants against it. Correctness only: no
timing is asserted here (`make bench` measures). Also `make bench-paper`'s script (bench/paper_preset.py):
interrupted and continued."""
import csv
import datetime
import math
import os
import signal
import subprocess
import sys
import time

import h5py

from conftest import ROOT
from enamel_results.constants import EXIT



def test_quick_bench_writes_its_report(enamel, tmp_path):
    """Stopped by Ctrl-C while its reference runs, then continued by the same command: the report, with each run's
    time summed over its pieces; a third time it runs nothing again."""
    from bench import jobs
    env = dict(os.environ, ENAMEL_BINARY=str(enamel))
    command = [sys.executable, "-m", "bench.run_bench", "--quick", "--out", str(tmp_path), "--runs",
               str(tmp_path / "runs")]
    reference = tmp_path / "runs" / "theta30_s21.4_e10_cv0" / "paper"
    first = subprocess.Popen(command, env=env, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    t0 = time.monotonic()
    while not (reference / "result.partial.h5").exists() and time.monotonic() - t0 < 120:
        time.sleep(0.2)   # once it exists the solver handles SIGINT (a checkpoint, then exit)
    time.sleep(1.0)
    first.send_signal(signal.SIGINT)
    out, err = first.communicate(timeout=120)
    assert first.returncode == 130 and "the same command continues" in err, (out, err)
    assert (reference / "checkpoint.bin").exists() and not (reference / "result.h5").exists()
    assert [p["exit"] for p in jobs.read_record(reference)["pieces"]] == [EXIT["interrupted"]]
    assert not (tmp_path / "results.csv").exists()

    r = subprocess.run(command, capture_output=True, text=True, env=env, timeout=600, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    pieces = jobs.read_record(reference)["pieces"]
    assert [p["exit"] for p in pieces] == [EXIT["interrupted"], 0]
    rows = list(csv.DictReader(open(tmp_path / "results.csv")))
    assert [row["variant"] for row in rows] == ["paper", "lumped", "lumped rate2"]
    ref = rows[0]
    assert ref["integrator"] == "paper" and float(ref["rcurve_rel_l2"]) == 0.0 and float(ref["speedup_wall"]) == 1.0
    for row in rows:
        assert row["status"] == "completed" and row["exit_code"] == "0"
        for key in ("wall_s", "cpu_s", "steps", "dof", "dof_updates_per_s_per_core", "peak_memory_mb",
                    "rcurve_rel_l2", "R_mean_rel_diff", "R_init_rel_diff", "R_ss_rel_diff", "broken_rods_diff"):
            assert math.isfinite(float(row[key])), (row["variant"], key, row[key])
    lumped = rows[1]
    assert lumped["integrator"] == "lumped" and float(lumped["dt"]) > float(ref["dt"])
    assert float(rows[2]["rate_factor"]) == 2.0
    # the lumped scheme at the same rate is close to the reference on this tiny case (a loose check of the
    # comparison itself: a broken comparison gives nan, zero for everything, or a large number)
    assert 0 < float(lumped["rcurve_rel_l2"]) < 0.05
    cost = list(csv.DictReader(open(tmp_path / "cost_growth.csv")))
    assert {c["integrator"] for c in cost} == {"lumped", "paper"} and len(cost) == 4
    assert all(float(c["s_per_step"]) > 0 and float(c["est_run_s"]) > 0 for c in cost)
    for name in ("pareto.png", "pareto.pdf", "cost_growth.png", "cost_growth.pdf"):
        assert (tmp_path / "out" / name).stat().st_size > 1000
    md = (tmp_path / "results.md").read_text()
    assert "Fastest within the bound" in md or "No fast variant within the bound" in md
    # at the solver's default G (no --G), named in the report's first line, and the G the runs ran at
    from bench.run_bench import G_KEY, bench_physics
    from enamel_results import results
    G = bench_physics(binary=enamel)[G_KEY]
    assert md.splitlines()[0].endswith(f", G = {G:g})")
    ref_run = results.load_result(tmp_path / "runs" / ref["case"] / "paper" / "result.h5")
    assert ref_run.param(G_KEY) == G
    # the reference's time is its two pieces' (the set-up counted in each), and the report says so
    assert math.isclose(float(ref["wall_s"]), sum(p["wall_s"] for p in pieces), rel_tol=1e-5)
    assert math.isclose(float(ref["cpu_s"]), sum(p["cpu_s"] for p in pieces), rel_tol=1e-5)
    resumed = [d for d in (tmp_path / "runs").glob("*/*") if len(jobs.read_record(d)["pieces"]) > 1]
    assert reference in resumed and f"; {len(resumed)} of them in more than one piece" in md

    again = subprocess.run(command, capture_output=True, text=True, env=env, timeout=600, cwd=ROOT)
    assert again.returncode == 0, again.stderr
    assert again.stdout.count("complete, not run again") == len(rows) + len(cost)
    assert list(csv.DictReader(open(tmp_path / "results.csv"))) == rows   # the same times, from the records
    assert len(jobs.read_record(reference)["pieces"]) == 2
    # another binary at the same path (a rebuilt solver) or another command starts the run over
    rec = jobs.read_record(reference)
    assert not jobs.prepare(reference, rec["command"], rec["solver_sha256"])
    assert rec["solver_sha256"] == jobs.binary_digest(enamel)
    assert jobs.prepare(reference, rec["command"], "0" * 64)
    assert not (reference / "result.h5").exists() and not (reference / jobs.RECORD).exists()


def test_within_the_bound_needs_no_quasi_static_warning():
    """The bench's headline variant: completed, the same R-curve as `paper` by metrics.same_rcurve, and kinetic /
    strain energy at most the solver's warning threshold while the crack grows; the L2 does not decide."""
    from bench.run_bench import KINETIC_WARN, within_bound
    ok = dict(status="completed", same_rcurve=True, rcurve_rel_l2=0.113, max_kinetic_over_strain=0.037)
    assert within_bound(ok)
    assert not within_bound(dict(ok, max_kinetic_over_strain=0.078))  # warned (rate 2 on the reduced case)
    assert within_bound(dict(ok, max_kinetic_over_strain=KINETIC_WARN))
    assert not within_bound(dict(ok, max_kinetic_over_strain=math.nan))  # never grew: nothing to compare
    assert not within_bound(dict(ok, same_rcurve=False))
    assert within_bound(dict(ok, same_rcurve="True")) and not within_bound(dict(ok, same_rcurve="False"))  # from csv
    assert not within_bound(dict(ok, status="failed"))


def profile_rows(stdout: str) -> dict:
    """{phase: (depth, ms/step, laps/step)} of one `enamel-dem profile` table (depth 0: the step)."""
    rows = {}
    for line in stdout.splitlines():
        cells = line.split("|")
        if line.startswith("| ") and not line.startswith("| phase"):
            name = cells[1].rstrip()
            laps = cells[4].strip()
            rows[name.strip()] = ((len(name) - len(name.lstrip()) - 1) // 2, float(cells[2]),
                                  float(laps) if laps != "-" else None)
    return rows


def test_profile_times_each_phase_of_either_scheme(enamel):
    """`enamel-dem profile` (what `make bench` writes into bench/profile.md): the real step run with its phase
    timers, one row per phase of the scheme's step and of Simulation::step under the step, each timed once per
    step (the lumped slice pass's parts per slice), the parts of a phase no longer than it; the `paper` scheme's
    own phases. Correctness of the report only: no speed is asserted."""
    case = str(ROOT / "paper_cases" / "theta30_s21.4_e10_cv0.toml")
    args = [str(enamel), "profile", case, "--preset", "ci", "--set", "w_s_over_d=8", "--set", "h_s_over_d=4",
            "--set", "threads=1", "--steps", "10", "--warmup", "20"]
    common = {"step", "advance", "interface dissipation", "deletion check", "deletions", "crack measure"}
    schemes = {"lumped": {"interface schedule", "slice pass", "interfaces", "nodes", "slice writes", "barrier",
                          "rod damping", "grips and work", "clock and grips"},
               "paper": {"positions", "boundary conditions", "interface forces", "rod forces", "accelerations",
                         "velocities", "reactions and work"}}
    for scheme, own in schemes.items():
        r = subprocess.run(args + ["--set", f'integrator="{scheme}"'], capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
        assert f"1 thread(s), scheme {scheme}, 10 steps timed after 20 warm-up steps" in r.stdout
        rows = profile_rows(r.stdout)
        assert set(rows) == common | own, scheme
        assert all(t >= 0 for _, t, _ in rows.values()) and rows["step"][1] > 0 and rows["advance"][1] > 0
        names = list(rows)
        parent = {name: next(p for p in reversed(names[:i]) if rows[p][0] == rows[name][0] - 1)
                  for i, name in enumerate(names) if rows[name][0] > 0}
        for name in parent:
            assert rows[name][2] >= 1 and rows[name][2] == int(rows[name][2]), (name, rows[name][2])
        for p in set(parent.values()):
            parts = sum(rows[c][1] for c in parent if parent[c] == p)
            assert parts <= rows[p][1] * (1 + 1e-3), (p, parts)  # printed to 4 digits
        assert parent["deletion check"] == "step" and rows["advance"][2] == 1 and rows["deletion check"][2] == 1
        if scheme == "lumped":
            assert parent["nodes"] == "slice pass" and parent["slice pass"] == "advance"
    assert rows["rod forces"][2] == 1


def test_profile_holds_or_ramps_the_loading_rate(enamel):
    """`enamel-dem profile --rate-multiplier PHI [--rate-target PHI2]` profiles the step with the loading clock at
    phi (as a run of the adaptive rate does between its rows): the grips move further over the same timed steps
    at phi = 4 than at 1, a ramp ends at its target, and a phi above rate_adapt_max is refused before any model
    is built (exit 2, naming the option, the value and the key)."""
    import re
    case = str(ROOT / "paper_cases" / "theta30_s21.4_e10_cv0.toml")
    args = [str(enamel), "profile", case, "--preset", "ci", "--set", "w_s_over_d=8", "--set", "h_s_over_d=4",
            "--set", "threads=1", "--steps", "10", "--warmup", "20", "--set", "rate_adapt_max=4"]

    def loading(extra):
        r = subprocess.run(args + extra, capture_output=True, text=True, timeout=300)
        assert r.returncode == 0, r.stderr
        m = re.search(r"loading over the timed steps: U/d (\S+) -> (\S+), phi (\S+) -> (\S+)", r.stdout)
        assert m, r.stdout
        return [float(x) for x in m.groups()]
    u0, u1, p0, p1 = loading([])
    assert (p0, p1) == (1.0, 1.0) and u1 > u0 > 0
    v0, v1, q0, q1 = loading(["--rate-multiplier", "4"])
    assert (q0, q1) == (4.0, 4.0) and v1 - v0 > 2 * (u1 - u0)
    _, _, r0, r1 = loading(["--rate-multiplier", "4", "--rate-target", "2"])
    assert 2.0 < r0 < 4.0 and r1 == 2.0   # linear from 4 over the 30 steps: 4 - 2 x 20/30 after the warm-up
    r = subprocess.run(args[:-2] + ["--rate-multiplier", "4"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "rate_adapt_max" in r.stderr and "4" in r.stderr, r.stderr
    assert "|" not in r.stdout


def start_paper_preset(enamel, tmp_path):
    """bench/paper_preset.py --quick on a run long enough to interrupt, started in a process group of its own (as a
    terminal's process group); returns once the solver has written its first partial result."""
    env = dict(os.environ, ENAMEL_BINARY=str(enamel))
    cmd = [sys.executable, "-m", "bench.paper_preset", "--quick", "--threads", "1", "--runs", str(tmp_path / "runs"),
           "--out", str(tmp_path), "--set", "stop_da_over_d=1e3", "--set", "max_steps=120000"]
    run = tmp_path / "runs" / "theta30_s21.4_e10_cv0__stop_da_over_d-1e3_max_steps-120000"   # its --set's folder
    p = subprocess.Popen(cmd, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         start_new_session=True, cwd=ROOT)
    deadline = time.time() + 120
    while time.time() < deadline and not (run / "result.partial.h5").exists():   # first progress write
        time.sleep(0.2)
    return p, cmd, env, run


def test_paper_preset_run_stops_on_ctrl_c_and_continues(enamel, tmp_path):
    """`make bench-paper` in --quick mode: Ctrl-C (SIGINT to the process group, as a terminal sends it)
    leaves a checkpoint and an 'interrupted' report and exits non-zero; the same command continues the run
    to its end, and a third call only reports."""
    p, cmd, env, run = start_paper_preset(enamel, tmp_path)
    os.killpg(p.pid, signal.SIGINT)
    out, err = p.communicate(timeout=120)
    assert p.returncode == EXIT["interrupted"], (p.returncode, err)   # the solver's "interrupted"
    assert (run / "checkpoint.bin").exists()
    md = (tmp_path / "paper_preset.md").read_text()
    assert "status: **interrupted**" in md and "not finished" in md
    assert not (run / "result.h5").exists()   # only a completed run has one
    steps_before = int(h5py.File(run / "result.partial.h5")["meta"].attrs["steps"])
    assert 0 < steps_before < 120000

    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    assert "continuing from the checkpoint" in r.stdout
    md = (tmp_path / "paper_preset.md").read_text()
    assert "status: **completed**" in md
    assert "interrupted after" in (run / "log.txt").read_text()   # the first part's last lines were logged
    assert "2 pieces" in md
    assert "against the goal (Delta_a = 30 d in at most 15 min of stepping on 2 cores): **not met**" in md
    assert "`paper_preset_record.json`" in md and "not comparable" in md   # an 8 d specimen against 200 d's 30 d
    assert sum(line.startswith("# ") for line in open(run / "log.txt")) == 2
    for name in ("paper_preset.png", "paper_preset.pdf"):
        assert (tmp_path / "out" / name).stat().st_size > 1000

    r = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert r.returncode == 0 and "is complete; reporting it" in r.stdout
    # another command into the same folder (here another thread count) is refused, naming both; the run is kept
    before = (run / "result.h5").read_bytes()
    other = [("2" if prev == "--threads" else w) for prev, w in zip([None] + cmd, cmd)]
    r = subprocess.run(other, env=env, capture_output=True, text=True, timeout=300, cwd=ROOT)
    assert r.returncode == 2 and "holds a run of another command" in r.stderr and "threads=2" in r.stderr, r.stderr
    assert (run / "result.h5").read_bytes() == before


def test_paper_preset_judges_its_run_by_the_goal_and_the_committed_record():
    """`make bench-paper`'s report: the goal (30 d in 15 min of stepping on 2 cores) met or not, and the run's
    R-curve against the committed paper-size record by metrics.same_rcurve: the record against itself is the
    same, R 5% higher is not, a missing record is said."""
    import copy
    import pathlib
    from bench import paper_preset as pp
    from enamel_results import records
    r = records.load(pp.AGAINST, case=pp.CASE)
    assert r.param("w_s_over_d") == 200 and r.completed
    line = pp.against_line(r, pp.AGAINST)
    assert "the same R-curve: **True**" in line and "+0.00%" in line and f"broken rods {r.broken_rods} / " in line
    higher = copy.copy(r)
    higher.R = r.R * 1.05
    assert "the same R-curve: **False**" in pp.against_line(higher, pp.AGAINST) and "+5.00%" in pp.against_line(
        higher, pp.AGAINST)
    assert "none to compare with" in pp.against_line(r, pathlib.Path("/nonexistent/record.json"))
    assert "**not met**, 74 min (4.91x the goal)" in pp.goal_line(r, 324298, 4422.0, 2)
    assert "66,004 of its 324,298 steps" in pp.goal_line(r, 324298, 4422.0, 2)
    assert "**met**, 14 min" in pp.goal_line(r, 100000, 840.0, 2)
    assert "**not met**" in pp.goal_line(r, 100000, 840.0, 4)   # more than 2 cores


def test_paper_preset_passes_sigterm_on_to_the_solver(enamel, tmp_path):
    """A SIGTERM to the script alone (a batch system stopping it) reaches the solver, which checkpoints."""
    p, _, _, run = start_paper_preset(enamel, tmp_path)
    p.send_signal(signal.SIGTERM)
    out, err = p.communicate(timeout=120)
    assert p.returncode == EXIT["interrupted"], (p.returncode, err)
    assert (run / "checkpoint.bin").exists() and "interrupted by signal 15" in (run / "log.txt").read_text()


def test_bench_step_reads_callgrind_annotate_columns():
    """`make bench-step` reads callgrind_annotate's event columns, '.' and a bare 0 being zeros, and divides each
    phase's inclusive counts per step by what it loops over (the law: per call)."""
    from bench.step_instructions import _counts, per_item
    line = ("   28,224,987 ( 1.60%)    201,687 ( 0.64%)     35,680 ( 0.24%)  .                  0           "
            "< ???:enamel::profileStep(enamel::Simulation&, long, long) (10x) [/x/enamel-dem]")
    assert _counts(line) == [28224987, 201687, 35680, 0, 0]
    star = line.replace("< ???", "*  ???")
    assert _counts(star) == [28224987, 201687, 35680, 0, 0]
    ev = lambda ir, calls: dict(Ir=ir, D1mr=0, D1mw=0, DLmr=0, DLmw=0, calls=calls)  # noqa: E731
    # 5 steps of a model of 10 DOF and 2 nodes, 4 slices (node rows called per slice), the law called 3 times
    got = {"step": ev(1100, 5), "advance": ev(1000, 5), "slice pass": ev(900, 5), "node rows": ev(600, 20),
           "law": ev(90, 3)}
    items = per_item(got, {"DOF": 10, "nodes": 2, "interfaces": 3})
    assert items["step per DOF"]["Ir"] == 22 and items["advance per DOF"]["Ir"] == 20
    assert items["slice pass per node"]["Ir"] == 90 and items["node rows per node"]["Ir"] == 60  # per step, not per call
    assert items["law per call"]["Ir"] == 30
    del got["law"]  # no interface due: no row
    assert "law per call" not in per_item(got, {"DOF": 10, "nodes": 2, "interfaces": 3})


def test_bench_G_is_the_solver_default_unless_given(enamel):
    """`make bench` measures at the solver's default G (read from `enamel-dem keys`, not written in the bench) unless
    --G names one, and its report's first line and header name the G it ran at."""
    from bench import run_bench
    table = "| key | kind | default |\n|---|---|---|\n| `Gamma_k_over_sigma0sq` | physics | 7.5 | [1, 1e4] |\n" \
            "| `integrator` | numerics | \"paper\" | ... |\n"
    assert run_bench.key_defaults(table) == {"Gamma_k_over_sigma0sq": "7.5", "integrator": '"paper"'}
    keys = subprocess.run([str(enamel), "keys"], capture_output=True, text=True, check=True).stdout
    row = next(line for line in keys.splitlines() if line.startswith("| `Gamma_k_over_sigma0sq`"))
    listed = float(row.split("|")[3])
    assert run_bench.bench_physics(binary=enamel) == {"Gamma_k_over_sigma0sq": listed}
    assert run_bench.bench_physics(3.0, binary=enamel) == {"Gamma_k_over_sigma0sq": 3.0}
    when = datetime.datetime(2026, 12, 6, 9, 0).strftime("%Y-%m-%d %H:%M")   # as the bench stamps its report
    header = dict(date=when, machine="AMD EPYC", git="abc", preset="reduced", jobs=2, total_min=98.0,
                  G=listed, G_source="the solver's default, `enamel-dem keys`")
    md = run_bench.summary_markdown([], [], header)
    assert md.splitlines()[0] == f"# Bench results ({when}, G = {listed:g})"
    assert f"G = Gamma_k_over_sigma0sq = {listed:g} (the solver's default" in md
    assert run_bench.parser().parse_args(["--G", "3"]).G == 3.0 and run_bench.parser().parse_args([]).G is None
