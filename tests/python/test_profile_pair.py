"""bench/profile_pair.py, the interleaved profile of two solver binaries, without the `paper` preset: its parse of
`enamel-dem profile`'s Markdown (captured outputs of the present form and an older binary's, and the binary's own
at the ci preset), an old profile against a new one, the medians and new / old ratios on made-up numbers with a
known answer, the page it writes, and a failing binary. Correctness only: no timing is asserted here."""
import math

import pytest

from bench import profile_pair as pp

# `enamel-dem profile paper_cases/theta30_s21.4_e10_cv0.toml --preset ci --warmup 5 --steps 3` with
# bench.run_bench.PROFILE_SETS and threads=1: the phases of the real step, in ms/step (an AMD EPYC).
CAPTURED = """\
4488 DOF, 1 thread(s), scheme lumped, 3 steps timed after 5 warm-up steps: 0.03673 ms/step, 122.2 M DOF-updates/s per core; triad 13.2 GB/s; timers: 174 laps per step, a clock read 26 ns

| phase | ms/step | share of step | laps/step | MB/step | GB/s | % of triad | what |
|---|---|---|---|---|---|---|---|
| step | 0.03673 | 100% | - | 0.3 | 8.1 | 62% | Simulation::step, timed around each call; the phases below are its parts, each timed around the calls the step makes for it |
|   advance | 0.03446 | 94% | 1 | - | - | - | the scheme's step (Integrator::advance) |
|     interface schedule | 4.667e-05 | 0% | 1 | - | - | - | advanceInterfaceSchedule: the drift of the displacements, which interfaces may be due |
|     slice pass | 0.0333 | 91% | 1 | 0.3 | 8.7 | 66% | computeForcesAndAdvanceVelocities: the parallel pass over the slices, forces then velocities and positions |
|       interfaces | 0.001732 | 5% | 54 | 0.0 | 8.8 | 67% | per slice, mean over the threads: addInterfaceCorrectionsOfSliceScheduled, the law where the schedule makes an interface due and, off the elastic branch, its force beyond the elastic one (the step: the law saw 0% of the interfaces per step) |
|       nodes | 0.02433 | 66% | 54 | 0.3 | 11.3 | 86% | per slice, mean over the threads: advanceNodesOfSlice, per node K_I q, K q, K v, v_{n+1/2}, grip residuals, damping sums, q_{n+1} = q_n + dt v_{n+1/2} |
|       slice writes | 0.002452 | 7% | 55 | - | - | - | per slice, mean over the threads: SliceOutputs, v_{n+1/2} and q_{n+1} written over the old values (the waiting slices after the barrier) |
|       barrier | 0.001476 | 4% | 1 | - | - | - | mean over the threads: waiting for the other threads at the pass's barrier |
|     grips and work | 0.0007477 | 2% | 2 | - | - | - | computeReactions, addWorkOfGrips, addDampingWork: the grips' reactions and work, the damping work |
|     clock and grips | 0.0002707 | 1% | 1 | - | - | - | moveOfStep, advanceClock, prescribeDisplacements, boundOfMove: t_{n+1}, q of the grips, the step's move |
|   interface dissipation | 4.033e-05 | 0% | 1 | - | - | - | bookInterfaceDissipation (mixed-mode law only; nothing to book otherwise) |
|   deletion check | 0.002044 | 6% | 1 | 0.0 | 3.1 | 24% | checkRodStresses: the rod stress check as scheduled (0% of the rod elements computed per step) |
|   deletions | 3.7e-05 | 0% | 1 | - | - | - | deleteOverloadedBeams: the overloaded rod elements found and, where there are any, deleted |
|   crack measure | 2.967e-05 | 0% | 1 | - | - | - | measureCrackAdvance, when something failed or broke |
"""
# The same of an older binary (the older format: kernels in s/step, some of them timed alone), as
# `--against` may be given one.
CAPTURED_OLD = """\
4488 DOF, 1 thread(s), 5 steps per kernel in 5 interleaved rounds (median round): 5.107e-05 s/step, 87.9 M DOF-updates/s per core; triad 32.8 GB/s

| kernel | s/step | share of step | MB/step | GB/s | % of triad | what |
|---|---|---|---|---|---|---|
| step | 5.107e-05 | 100% | 0.4 | 7.4 | 23% | the whole time step (integrator's advance, rod stress check, crack measure when something failed) |
| advance | 4.77e-05 | 93% | 0.4 | 7.8 | 24% | the integrator's step: the slice pass (interfaces, then per node its velocity and position) |
|   interfaces | 2.155e-05 | 42% | 0.2 | 9.7 | 29% | per interface: its elastic force, or the law's where the schedule makes it due (the step: 0% of the interfaces per step), its wrench added to both nodes (alone, with f written) |
|   nodes | 2.615e-05 | 51% | 0.2 | 9.0 | 28% | advance - interfaces: per node K rows, v_{n+1/2}, grip residuals, damping sums, q_{n+1} = q_n + dt v_{n+1/2} |
|   (positions) | 5.981e-06 | 12% | 0.1 | 18.0 | 55% | alone, for comparison: q += dt v over all DOF as a pass of its own (the step does it in the node pass) |
| check and rest | 3.368e-06 | 7% | 0.0 | 1.9 | 6% | step - advance: the rod stress check as the step runs it (scheduled: 0% of the rod elements computed per step), crack measure when something failed, bookkeeping |
| (stress check, every element) | 1.456e-05 | 29% | 0.1 | 3.8 | 11% | alone, for comparison: per rod element 5 rows of K_local T u_e, sigma / sigma_ru (what the check cost before the schedule) |
"""


def prof(s, m, advance, interfaces, nodes, rest):
    """One made-up parse, as pp.parse returns it."""
    return {"dof": 1000, "threads": 2, "s_per_step": s, "mdofs_per_core": m, "step": s, "advance": advance,
            "interfaces": interfaces, "nodes": nodes, "check and rest": rest}


# Three rounds, out of order so that a median is neither the middle round's value nor the mean; the old binary's
# third round lacks "check and rest" (its median is that of the two others: their mean).
ROUNDS = [
    (prof(3.5, 12.0, 2.8, 1.6, 1.2, 0.2), prof(1.0, 40.0, 0.9, 0.5, 0.4, 0.1)),
    (prof(1.0, 30.0, 0.9, 0.4, 0.5, 0.1), prof(0.5, 50.0, 0.4, 0.2, 0.2, 0.05)),
    (prof(2.0, 20.0, 1.8, 1.0, 0.8, 0.2), prof(3.0, 45.0, 2.9, 1.9, 1.0, 0.3)),
]
del ROUNDS[2][0]["check and rest"]
OLD = {"s_per_step": 2.0, "mdofs_per_core": 20.0, "advance": 1.8, "interfaces": 1.0, "nodes": 0.8,
       "check and rest": 0.15}
NEW = {"s_per_step": 1.0, "mdofs_per_core": 45.0, "advance": 0.9, "interfaces": 0.5, "nodes": 0.4,
       "check and rest": 0.1}


PHASES = ("advance", "interface schedule", "slice pass", "interfaces", "nodes", "slice writes", "barrier",
          "grips and work", "clock and grips", "interface dissipation", "deletion check", "deletions", "crack measure")


def test_parse_reads_the_header_and_the_phases_in_seconds():
    p = pp.parse(CAPTURED)
    assert p.keys() == {"dof", "threads", "s_per_step", "mdofs_per_core", "step", *PHASES}
    assert (p["dof"], p["threads"], p["mdofs_per_core"]) == (4488, 1, 122.2)
    ms = {"step": 0.03673, "advance": 0.03446, "interfaces": 0.001732, "nodes": 0.02433, "crack measure": 2.967e-05}
    for k, v in ms.items():
        assert p[k] == pytest.approx(1e-3 * v, rel=1e-12), k
    assert p["s_per_step"] == p["step"]
    with pytest.raises(ValueError, match="no profile header"):
        pp.parse(CAPTURED.split("\n", 1)[1])
    with pytest.raises(ValueError, match="no profile table"):
        pp.parse(CAPTURED.split("\n\n", 1)[0])


def test_parse_reads_an_older_binarys_kernels():
    p = pp.parse(CAPTURED_OLD)
    assert p == {"dof": 4488, "threads": 1, "s_per_step": 5.107e-05, "mdofs_per_core": 87.9, "step": 5.107e-05,
                 "advance": 4.77e-05, "interfaces": 2.155e-05, "nodes": 2.615e-05, "check and rest": 3.368e-06}
    # the kernels timed alone for comparison, "(positions)" and "(stress check, every element)", are not parts
    # of the step and are not read


def test_an_old_and_a_new_profile_compare_where_they_share_a_phase():
    old, new = pp.parse(CAPTURED_OLD), pp.parse(CAPTURED)
    rounds = [(old, new), (old, new)]
    assert pp.phases(rounds)[:4] == ["advance", "interfaces", "nodes", "check and rest"]
    med = pp.medians(rounds)
    assert "check and rest" in med["old"] and "check and rest" not in med["new"] and "slice pass" not in med["old"]
    ratio = pp.ratios(med)
    assert ratio["advance"] == pytest.approx(3.446e-05 / 4.77e-05)
    assert math.isnan(ratio["check and rest"]) and math.isnan(ratio["slice pass"])


def test_parse_reads_the_binarys_own_profile(run):
    """The format parse expects is the one the solver prints (ci preset, one thread, a few steps)."""
    args = pp.profile_args("x", threads=1, steps=3, preset="ci")[1:] + ["--warmup", "5"]
    r = run(*args, timeout=120)
    assert r.returncode == 0, r.stderr
    p = pp.parse(r.stdout)
    assert p["threads"] == 1 and p["dof"] > 0
    assert set(p) == {"dof", "threads", "s_per_step", "mdofs_per_core", "step", *PHASES, "rod damping"}
    assert p["step"] == p["s_per_step"] and all(p[k] >= 0 for k in (*PHASES, "rod damping"))


def test_profile_args_are_the_bench_profiles():
    args = pp.profile_args("old/enamel-dem", threads=2, steps=20)
    assert args[:2] == ["old/enamel-dem", "profile"] and args[2].endswith(f"{pp.PROFILE_CASE}.toml")
    assert args[args.index("--preset") + 1] == "paper" and args[args.index("--steps") + 1] == "20"
    sets = [args[i + 1] for i, a in enumerate(args) if a == "--set"]
    assert sets == [f"{k}={v}" for k, v in pp.PROFILE_SETS.items()] + ["threads=2"]


def test_medians_and_ratios_on_known_numbers():
    med = pp.medians(ROUNDS)
    assert med.keys() == {"old", "new"}
    for name, want in (("old", OLD), ("new", NEW)):
        assert med[name].keys() == want.keys()
        for k, v in want.items():
            assert med[name][k] == pytest.approx(v), (name, k)
    ratio = pp.ratios(med)
    assert ratio == pytest.approx({"s_per_step": 0.5, "mdofs_per_core": 2.25, "advance": 0.5,
                                   "interfaces": 0.5, "nodes": 0.5, "check and rest": 0.1 / 0.15})


def test_a_zero_old_median_gives_no_ratio_and_no_error():
    med = pp.medians(ROUNDS)
    med["old"]["check and rest"] = 0.0
    ratio = pp.ratios(med)
    assert math.isnan(ratio["check and rest"]) and ratio["nodes"] == pytest.approx(0.5)


def test_report_states_the_rounds_medians_and_speedup(monkeypatch):
    monkeypatch.setattr(pp, "version", lambda binary: f"0.1.0 ({binary})")
    md = pp.report("old/enamel-dem", "new/enamel-dem", ROUNDS, threads=2)
    assert "1000 DOF, 2 thread(s)" in md and "old = 0.1.0 (old/enamel-dem), new = 0.1.0 (new/enamel-dem)" in md
    assert "3 rounds, old then new in each" in md
    rows = [line for line in md.splitlines() if line.startswith("| ") and line.split("|")[1].strip().isdigit()]
    assert [tuple(c.strip() for c in r.split("|")[1:3]) for r in rows] == [
        (str(i), name) for i in (1, 2, 3) for name in ("old", "new")]
    assert "| 3 | old | 2 | 20.0 | 1.8 | 1 | 0.8 | nan |" in md  # the missing kernel shows as nan
    assert "| s_per_step | 2 | 1 | 0.500 |" in md
    assert "| check and rest | 0.15 | 0.1 | 0.667 |" in md
    assert "**DOF-updates/s per core: 20.0 M (old) -> 45.0 M (new), 2.25x**" in md


def test_main_interleaves_two_binaries(enamel, tmp_path, monkeypatch):
    """The whole script on the ci preset (instead of `paper`), the build's binary against itself: 2 rounds, old
    then new in each, one thread."""
    calls, paper_args = [], pp.profile_args

    def ci_args(binary, threads, steps):
        calls.append(binary)
        return paper_args(binary, threads, steps, preset="ci") + ["--warmup", "5"]

    monkeypatch.setattr(pp, "profile_args", ci_args)
    out = tmp_path / "pair.md"
    old = tmp_path / "old-enamel-dem"
    old.symlink_to(enamel)
    assert pp.main(["--against", str(old), "--binary", str(enamel), "--rounds", "2", "--threads", "1",
                    "--steps", "3", "--out", str(out)]) == 0
    assert calls == [str(old), str(enamel)] * 2
    md = out.read_text()
    assert "1 thread(s)" in md and "2 rounds, old then new in each" in md
    med_rows = {line.split("|")[1].strip(): line for line in md.splitlines() if line.startswith("| ")}
    for k in ("s_per_step", *PHASES):
        ratio = float(med_rows[k].split("|")[4])
        assert math.isfinite(ratio) and ratio > 0, med_rows[k]
    assert "x** (medians of the rounds)" in md


def test_main_stops_at_a_failing_binary(enamel, tmp_path, capsys):
    out = tmp_path / "pair.md"
    rc = pp.main(["--against", "/bin/false", "--binary", str(enamel), "--rounds", "1", "--out", str(out)])
    assert rc != 0 and not out.exists()
    assert "profile_pair: /bin/false failed" in capsys.readouterr().err
