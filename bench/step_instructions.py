"""`make bench-step`: what one time step costs in instructions and cache misses, per phase of the step, per node
and per DOF, counted by valgrind's callgrind (with its cache simulation) on a fixed model. Counts do not depend on
how busy the machine is, so two binaries can be compared on any machine; the wall-clock profile (`enamel-dem
profile`: the step's phase timers) is printed next to them.

    python3 -m bench.step_instructions [--binary build/enamel-dem] [--against OTHER_BINARY] [--out DIR]

The model: theta30 (21.4, 10) at 40 x 20 d, h_e 0.3 d, the lumped scheme (dt_factor 0.22, damping_cap 0.5), one
thread; `enamel-dem profile --steps 10` under callgrind, collecting only inside Simulation::step (the model's set-up
and the profile's own measurements are left out; its 200 warm-up steps are counted with the 10 timed ones, whose
timers' laps add about 0.05% to the counts). Each phase is a function of the real step, found by
its name (PHASES below), and counted inclusively (with what it calls) over all its calls, per step (per call of
Simulation::step):

- step: enamel::Simulation::step(), per DOF;
- advance: LumpedIntegrator::advance, the scheme's step, per DOF;
- slice pass: LumpedIntegrator::computeForcesAndAdvanceVelocities, the pass over the slices (the interface pass
  where due, the node rows, the slices' writes), per node;
- node rows: enamel::advanceNodesOfSlice (the copy the loader picked: valgrind has no AVX-512, so the x86-64-v3
  one), per node: K_I q, K q, K v, v_{n+1/2}, the damping sums, q_{n+1};
- law: evaluateDueInterface, per call: one due interface seen by the law (shown where the counted steps have one).

What it cannot count by name: the interface pass's scan of its schedule (addInterfaceCorrectionsOfSliceScheduled
is inlined into the slice pass, and counted in it) and, since the step moves q in its node pass, a position update
of its own (the counts of solvers that had one, as advancePositions, are in earlier pages). A binary whose step
lacks one of the required functions (an older solver's) is refused with the names it lacks.

Writes DIR/step_instructions.md (default bench/) and prints it.
"""
from __future__ import annotations

import argparse
import datetime
import pathlib
import re
import subprocess
import sys
import tempfile

from enamel_results import paths
import bench
from bench import records

CASE = paths.case_file("theta30_s21.4_e10_cv0")
SETS = {"w_s_over_d": "40", "h_s_over_d": "20", "integrator": '"lumped"', "dt_factor": "0.22",
        "damping_cap": "0.5", "threads": "1"}
STEPS = 10
EVENTS = ("Ir", "D1mr", "D1mw", "DLmr", "DLmw")   # instructions; first-level and last-level data misses
# phase: (what callgrind_annotate prints of the function's name, every piece of it (the slice pass: the body of its
# parallel region, which OpenMP makes a function of its own; the pass itself is inlined into advance); what its count
# per step is divided by: DOF, nodes, or "call" for a count per call of the function).
PHASES = {
    "step": (("enamel::Simulation::step()",), "DOF"),
    "advance": (("LumpedIntegrator::advance(",), "DOF"),
    "slice pass": (("LumpedIntegrator::computeForcesAndAdvanceVelocities(", "[clone ._omp_fn.0]"), "nodes"),
    "node rows": (("enamel::advanceNodesOfSlice(",), "nodes"),
    "law": (("evaluateDueInterface(",), "call"),
}
OPTIONAL = {"law"}  # no interface due in the counted steps: no call


def solver_args(binary) -> list[str]:
    args = [str(binary), "profile", str(CASE), "--preset", "ci", "--steps", str(STEPS)]
    for k, v in SETS.items():
        args += ["--set", f"{k}={v}"]
    return args


def model_counts(binary) -> dict:
    """DOF, nodes and interfaces of the model, from `enamel-dem info`."""
    args = solver_args(binary)
    args[1] = "info"
    args = [a for a in args if a not in ("--steps", str(STEPS))]
    out = subprocess.run(args, capture_output=True, text=True, check=True).stdout
    num = lambda key: int(re.search(rf"^{key}\s+(\d+)", out, re.M).group(1))  # noqa: E731
    return {"DOF": num("DOF"), "nodes": num("nodes"), "interfaces": num("interfaces")}


def callgrind(binary, workdir: pathlib.Path) -> tuple[pathlib.Path, str]:
    out = workdir / "callgrind.out"
    r = subprocess.run(["valgrind", "--tool=callgrind", "--cache-sim=yes", f"--callgrind-out-file={out}",
                        "--toggle-collect=enamel::Simulation::step()"] + solver_args(binary),
                       capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"bench-step: valgrind failed ({r.returncode}): {r.stderr.strip().splitlines()[-1:]}")
    return out, r.stdout


def _counts(line: str) -> list[int]:
    """The event columns of one callgrind_annotate line ('.' is a zero), before its '<' / '*' marker."""
    left = re.split(r"\s[<*]\s", line, maxsplit=1)[0]
    tokens = re.sub(r"\(\s*[\d.]+%\)", " ", left).split()
    return [0 if t == "." else int(t.replace(",", "")) for t in tokens][:len(EVENTS)]


def inclusive_counts(out: pathlib.Path) -> dict:
    """{phase: {event: inclusive count over all calls, 'calls': calls}} from callgrind_annotate's caller tree: the
    line marked '*' of the function carries its inclusive counts, the lines above it ('<') its callers with their
    call counts."""
    text = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--tree=caller", "--threshold=100", f"--show={','.join(EVENTS)}",
                           str(out)], capture_output=True, text=True, check=True).stdout
    blocks = text.split("\n\n")
    got = {}
    for phase, (names, _) in PHASES.items():
        for b in blocks:
            if phase in got:
                break
            lines = b.strip().splitlines()
            star = [ln for ln in lines if re.search(r"\*\s+", ln) and all(n in ln for n in names)
                    and ("_omp_fn" in names[-1] or "_omp_fn" not in ln)]
            if not star:
                continue
            calls = sum(int(c.replace(",", "")) for ln in lines if ln.lstrip().startswith(tuple("0123456789"))
                        and " < " in ln for c in re.findall(r"\(([\d,]+)x\)", ln))
            if calls:
                got[phase] = dict(zip(EVENTS, _counts(star[0]))) | {"calls": calls}
                break
    missing = set(PHASES) - set(got) - OPTIONAL
    if missing:
        raise SystemExit(f"bench-step: callgrind_annotate shows no {sorted(missing)} (inlined, renamed, or a solver "
                         f"before the step's phase functions?)")
    return got


def per_item(got: dict, sizes: dict) -> dict:
    """Counts per step (per call of Simulation::step), divided by what each phase loops over (PHASES)."""
    steps = got["step"]["calls"]
    items = {}
    for phase, (_, unit) in PHASES.items():
        if phase not in got:
            continue
        label, divisor = (f"{phase} per call", got[phase]["calls"]) if unit == "call" else \
            (f"{phase} per {'DOF' if unit == 'DOF' else 'node'}", steps * sizes[unit])
        items[label] = {e: got[phase][e] / divisor for e in EVENTS}
    return items


def measure(binary) -> tuple[dict, dict, str]:
    with tempfile.TemporaryDirectory() as d:
        out, profile = callgrind(binary, pathlib.Path(d))
        got = inclusive_counts(out)
    sizes = model_counts(binary)
    return per_item(got, sizes), sizes, profile


def git(binary) -> str:
    r = subprocess.run([str(binary), "--version"], capture_output=True, text=True)
    return r.stdout.strip() or "?"


def markdown(runs: list[tuple[str, dict]], sizes: dict, wall: str) -> str:
    L = ["# Instructions and cache misses per time step, per phase (`make bench-step`)", "",
         f"{datetime.date.today()}, {records.cpu_model()}. Model: theta30 (21.4, 10), 40 x 20 d, h_e 0.3 d, lumped, one thread: "
         f"{sizes['DOF']} DOF, {sizes['nodes']} nodes, {sizes['interfaces']} interfaces; valgrind callgrind with "
         f"its cache simulation, `enamel-dem profile --steps {STEPS}` with its warm-up. Inclusive counts per step "
         "divided by what each phase loops over (the law: per call); D1/LL = first/last-level data-cache misses "
         "(reads + writes).", "",
         "| binary | phase | instructions | D1 misses | LL misses |", "|---|---|---|---|---|"]
    for label, items in runs:
        for what, c in items.items():
            L.append(f"| {label} | {what} | {c['Ir']:.1f} | {c['D1mr'] + c['D1mw']:.2f} | {c['DLmr'] + c['DLmw']:.3f} |")
    if len(runs) == 2:
        L += ["", "| phase | instructions, second / first |", "|---|---|"]
        for what in (w for w in runs[0][1] if w in runs[1][1]):
            L.append(f"| {what} | {runs[1][1][what]['Ir'] / runs[0][1][what]['Ir']:.3f} |")
    L += ["", "Wall-clock profile of the first binary under valgrind (times are valgrind's, for the shares only):", "",
          wall.strip(), "", "<!-- generated by: make bench-step (bench/step_instructions.py) -->", ""]
    return "\n".join(L)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--binary", default=str(paths.SOLVER))
    ap.add_argument("--against", help="a second binary (e.g. an older commit's), counted the same way")
    ap.add_argument("--out", type=pathlib.Path, default=bench.HERE)
    a = ap.parse_args(argv)
    first, sizes, wall = measure(a.binary)
    runs = [(git(a.binary), first)]
    if a.against:
        runs.insert(0, (git(a.against), measure(a.against)[0]))
    md = markdown(runs, sizes, wall)
    a.out.mkdir(parents=True, exist_ok=True)
    (a.out / "step_instructions.md").write_text(md)
    print(md)
    return 0


if __name__ == "__main__":
    sys.exit(main())
