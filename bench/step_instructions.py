"""`make bench-step`: what one time step costs in instructions and cache misses, per kernel, per interface and per
node, counted by valgrind's callgrind (with its cache simulation) on a fixed model. Counts do not depend on how
busy the machine is, so two binaries can be compared on any machine; the wall-clock profile (`enamel-dem
profile`, interleaved rounds) is printed next to them.

    python3 -m bench.step_instructions [--binary build/enamel-dem] [--against OTHER_BINARY] [--out DIR]

The model: theta30 (21.4, 10) at 40 x 20 d, h_e 0.3 d, the lumped scheme (dt_factor 0.22, damping_cap 0.5), one
thread; `enamel-dem profile --steps 10` under callgrind, collecting only inside profileKernels (the model's
set-up is left out). Per call of each kernel (from callgrind's inclusive counts and call counts):

- step: Simulation::step; advance: the integrator's advance (the slice pass and the position update);
- interfaces: the interface pass alone (the profile's "interfaces" kernel, with a copy of the step's schedule:
  computeInterfaceCorrectionsScheduled, the law where it is due, in solvers that apply the elastic interfaces
  as K_I q in the node rows; computeForcesForInterfacesScheduled, every interface's force, in solvers before
  them; computeForcesForInterfaces in solvers before the schedule), per interface;
- node rows and positions: advance - interfaces, per node (the profile's "nodes"; the step computes q_{n+1} in
  its node pass, solvers before it in a pass of their own: both counted here, so the row compares; since the
  elastic interfaces are K_I q, their forces are counted here, not under interfaces: compare the whole step);
- positions: advancePositions alone, per DOF (the profile's "(positions)").

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
# kernel: (the function's names as callgrind_annotate prints them, the first found counts; the count it is
# divided by). The interfaces kernel is the scheduled pass the step runs (solvers before it: the pass of every
# interface by the law).
KERNELS = {
    "step": (("enamel::Simulation::step()",), "DOF"),
    "advance": (("LumpedIntegrator::advance(",), "DOF"),
    "interfaces": (("enamel::computeInterfaceCorrectionsScheduled(", "enamel::computeForcesForInterfacesScheduled(",
                    "enamel::computeForcesForInterfaces("), "interfaces"),
    "positions": (("enamel::advancePositions(",), "DOF"),
}


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
                        "--toggle-collect=enamel::profileKernels*"] + solver_args(binary),
                       capture_output=True, text=True)
    if r.returncode != 0:
        raise SystemExit(f"bench-step: valgrind failed ({r.returncode}): {r.stderr.strip().splitlines()[-1:]}")
    return out, r.stdout


def _counts(line: str) -> list[int]:
    """The event columns of one callgrind_annotate line ('.' is a zero), before its '<' / '*' marker."""
    left = re.split(r"\s[<*]\s", line, maxsplit=1)[0]
    tokens = re.sub(r"\(\s*[\d.]+%\)", " ", left).split()
    return [0 if t == "." else int(t.replace(",", "")) for t in tokens][:len(EVENTS)]


def inclusive_per_call(out: pathlib.Path) -> dict:
    """{kernel: {event: inclusive count per call}} from callgrind_annotate's caller tree: the line marked '*' of
    the function carries its inclusive counts, the lines above it ('<') its callers with their call counts."""
    text = subprocess.run(["callgrind_annotate", "--inclusive=yes", "--tree=caller", "--threshold=100", f"--show={','.join(EVENTS)}",
                           str(out)], capture_output=True, text=True, check=True).stdout
    blocks = text.split("\n\n")
    got = {}
    for kernel, (names, _) in KERNELS.items():
        for name, b in ((n, b) for n in names for b in blocks):
            if kernel in got:
                break
            lines = b.strip().splitlines()
            star = [ln for ln in lines if re.search(r"\*\s+.*" + re.escape(name), ln) and "_omp_fn" not in ln]
            if not star:
                continue
            counts = _counts(star[0])
            calls = sum(int(c) for ln in lines if ln.lstrip().startswith(tuple("0123456789")) and " < " in ln
                        for c in re.findall(r"\((\d+)x\)", ln))
            if calls:
                got[kernel] = {e: c / calls for e, c in zip(EVENTS, counts)} | {"calls": calls}
                break
    missing = set(KERNELS) - set(got) - {"positions"}  # the position update alone: shown where found
    if missing:
        raise SystemExit(f"bench-step: callgrind_annotate shows no {sorted(missing)} (inlined or renamed?)")
    return got


def per_item(got: dict, sizes: dict) -> dict:
    """Counts per interface, per node and per DOF; the node rows with the position update."""
    nodes = {e: got["advance"][e] - got["interfaces"][e] for e in EVENTS}
    return {"step per DOF": {e: got["step"][e] / sizes["DOF"] for e in EVENTS},
            "interfaces per interface": {e: got["interfaces"][e] / sizes["interfaces"] for e in EVENTS},
            "node rows and positions per node": {e: nodes[e] / sizes["nodes"] for e in EVENTS},
            **({"positions per DOF": {e: got["positions"][e] / sizes["DOF"] for e in EVENTS}}
               if "positions" in got else {})}


def measure(binary) -> tuple[dict, dict, str]:
    with tempfile.TemporaryDirectory() as d:
        out, profile = callgrind(binary, pathlib.Path(d))
        got = inclusive_per_call(out)
    sizes = model_counts(binary)
    return per_item(got, sizes), sizes, profile


def git(binary) -> str:
    r = subprocess.run([str(binary), "--version"], capture_output=True, text=True)
    return r.stdout.strip() or "?"


def markdown(runs: list[tuple[str, dict]], sizes: dict, wall: str) -> str:
    L = ["# Instructions and cache misses per time step, per kernel (`make bench-step`)", "",
         f"{datetime.date.today()}, {records.cpu_model()}. Model: theta30 (21.4, 10), 40 x 20 d, h_e 0.3 d, lumped, one thread: "
         f"{sizes['DOF']} DOF, {sizes['nodes']} nodes, {sizes['interfaces']} interfaces; valgrind callgrind with "
         f"its cache simulation, {STEPS} steps per kernel in the profile's interleaved rounds. Counts per call, "
         "divided by what each kernel loops over; D1/LL = first/last-level data-cache misses (reads + writes).", "",
         "| binary | kernel | instructions | D1 misses | LL misses |", "|---|---|---|---|---|"]
    for label, items in runs:
        for what, c in items.items():
            L.append(f"| {label} | {what} | {c['Ir']:.1f} | {c['D1mr'] + c['D1mw']:.2f} | {c['DLmr'] + c['DLmw']:.3f} |")
    if len(runs) == 2:
        L += ["", "| kernel | instructions, second / first |", "|---|---|"]
        for what in (w for w in runs[0][1] if w in runs[1][1]):
            L.append(f"| {what} | {runs[1][1][what]['Ir'] / runs[0][1][what]['Ir']:.3f} |")
    L += ["", "Wall-clock profile of the first binary under valgrind (times are valgrind's, for the shares only):", "",
          wall.strip(), ""]
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
