#!/usr/bin/env python3
"""Write SLURM job scripts for the runs of the figure set: a job array with one task per run, and a figures job
that starts once every task has succeeded (standard library only; `make slurm` calls it).

    python3 -m pipeline.slurm_jobs --preset P [--cases RUN ...] [--partition X --time T --mem M ...]

writes OUT/runs.sbatch, OUT/figures.sbatch and OUT/submit.sh (OUT defaults to RUNS/P/slurm) and prints what
it wrote; run OUT/submit.sh on the cluster's login node to submit both (it prints the job ids).

Each array task builds its runs/P/<run>/result.h5 with `make` through the same Make rule as `make runs`, so a
task that starts again continues its run from the run's checkpoint. The runs are the figure set's cases and
their half-rate `<case>_slow` twins (the figure tables figures/figN_<name>.toml, as make_rules.py reads them); --cases keeps some.

Signals. Before the time limit SLURM sends the batch shell SIGUSR1 (--signal-seconds ahead); the shell passes
SIGTERM to the process group of make and the solver, the solver writes a checkpoint and exits, and the task
requeues itself (`scontrol requeue`): its next start continues the run. A SIGTERM from SLURM (scancel,
`scontrol requeue`, preemption) also reaches the solver, which writes its checkpoint before SLURM's KillWait
ends; a requeued task continues, a cancelled one continues when submitted again.

One run per directory. The solver holds a lock on its run directory for the run's life (DIR/.lock, released by
the kernel when the process ends, however it ends). A task that starts while another process still holds it (a
solver of the task's earlier start that outlived its job on a hung node, a run started by hand) waits up to
LOCK_WAIT_S for it (Make's LOCK_WAIT; --make-var LOCK_WAIT=... changes it), then is refused cleanly (exit
status 17, nothing of the other run changed) and the task fails without requeueing: submit again once that run
has ended.

Resources (every task of an array gets the same), both from the solver's own estimates (`enamel-dem info
--estimate`, which builds no model) over the runs: memory is the largest, x1.25 + 256 MB; time is the longest
run's `seconds`, one core's wall time of the whole run (the steps from the run's loading, stop criterion and
time step, the seconds per step from a measured DOF-update rate per integrator: docs/cluster.md), x2, between
10 min and 24 h (a common partition limit). A half-rate twin's estimate is made with its rate_factor = 0.5, so it
already takes twice the steps. A task that reaches its time limit is requeued and continues, so an estimate
that is too short costs a wait in the queue, not work. --mem and --time replace the estimates.
"""
import argparse
import concurrent.futures
import math
import os
import pathlib
import shlex
import subprocess
import sys

from enamel_results import paths  # the one place that defines paths
from enamel_results.constants import EXIT  # the solver's exit statuses
from pipeline.make_rules import figure_set  # the one place that lists the runs


PROG = "slurm_jobs.py"
MEM_FACTOR, MEM_EXTRA_MB = 1.25, 256     # memory request: solver estimate x1.25 + 256 MB (make, shell, HDF5)
TIME_FACTOR, TIME_MIN_S, TIME_MAX_S = 2.0, 600, 86400   # time: solver estimate x2, 10 min to 24 h
ESTIMATE_KEYS = ("dof", "memory_mb", "seconds")         # the lines of `info --estimate` read here
# s a task waits for another process's lock on its run directory: SLURM's KillWait (30 s by default) and an
# NFSv4 lease (90 s by default: the locks of a node that died), with a margin
LOCK_WAIT_S = 300


class EstimateError(Exception):
    pass


def fail(msg: str) -> None:
    print(f"{PROG}: {msg}", file=sys.stderr)
    sys.exit(2)


def select_runs(cases: list[str] | None) -> list[str]:
    """Run names (case, or case_slow for a half-rate twin) of the figure set, or the given subset of them."""
    _, all_cases, all_slow = figure_set()
    runs = all_cases + [f"{c}_slow" for c in all_slow]
    if not runs:
        fail("the figure tables (figures/figN_<name>.toml) list no runs")
    if cases is None:
        return runs
    unknown = [c for c in cases if c not in runs]
    if unknown:
        fail(f"'{unknown[0]}' is not a run of the figure set (the figure tables figures/figN_<name>.toml: a case, or <case>_slow for "
             "a half-rate twin)")
    if not cases:
        fail("--cases given without any run")
    return list(dict.fromkeys(cases))


def run_sets(run: str, run_set: list[str]) -> list[str]:
    """The --set arguments of one run, as the Make rule passes them: the twin's rate_factor, then RUN_SET's."""
    sets = ["--set", "rate_factor=0.5"] if run.endswith("_slow") else []
    for kv in run_set:
        sets += ["--set", kv]
    return sets


def case_of(run: str) -> str:
    return run[:-len("_slow")] if run.endswith("_slow") else run


def estimate(solver: pathlib.Path, preset: str, run: str, run_set: list[str]) -> dict:
    """The solver's estimate of one run without building it: {'dof': int, 'memory_mb': int, 'seconds': int}
    (seconds: one core's wall time of the whole run, the twin's rate_factor included)."""
    cmd = [str(solver), "info", str(paths.case_file(case_of(run))), "--preset", preset,
           *run_sets(run, run_set), "--estimate"]
    try:
        r = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    except OSError as e:
        raise EstimateError(f"cannot run the solver {solver} ({e}): run `make build`")
    out = {}
    for line in r.stdout.splitlines():
        parts = line.split()
        if len(parts) == 2 and parts[0] in ESTIMATE_KEYS:
            out[parts[0]] = int(float(parts[1]))
    if r.returncode != 0 or len(out) != len(ESTIMATE_KEYS):
        why = (r.stderr.strip().splitlines() or [f"not every line of {', '.join(ESTIMATE_KEYS)}"])[0]
        raise EstimateError(f"`{' '.join(cmd[1:])}`: {why}")
    return out


def slurm_time(seconds: float) -> str:
    """SLURM's days-hours:minutes:seconds, rounded up to whole minutes."""
    m = math.ceil(seconds / 60)
    return f"{m // 1440}-{m // 60 % 24:02d}:{m % 60:02d}:00"


def quote_vars(make_vars: list[str]) -> str:
    return " ".join(shlex.quote(v) for v in make_vars)


def sbatch_lines(opts: dict) -> str:
    return "".join(f"#SBATCH --{k}={v}\n" if v is not None else f"#SBATCH --{k}\n" for k, v in opts.items())


ARRAY_BODY = r"""
targets=(
{targets})
target=${{targets[$SLURM_ARRAY_TASK_ID]}}
export OMP_THREAD_LIMIT=${{SLURM_CPUS_PER_TASK:-1}}   # the solver's automatic thread count stays in the allocation
unset MAKEFLAGS MFLAGS MAKELEVEL   # a make of its own, whatever the submitting shell was
say() {{ echo "$(date '+%F %T') task $SLURM_ARRAY_TASK_ID (job $SLURM_JOB_ID): $*"; }}
say "start $((${{SLURM_RESTART_COUNT:-0}} + 1)) on $(hostname): make $target"

# make runs as a job of its own (set -m: its own process group), so that a signal reaches the solver: make
# passes SIGTERM only to its recipe's shell, which dies without passing it on.
set -m
{make} "$target" &
group=$!
requeue=no
trap 'say "time limit in {signal_s} s or less: stopping the run at a checkpoint, then requeueing"; requeue=yes
      kill -TERM -- -$group 2>/dev/null' USR1
trap 'say "SIGTERM (cancelled, requeued or preempted): stopping the run at a checkpoint"
      kill -TERM -- -$group 2>/dev/null' TERM
wait $group; rc=$?
while kill -0 $group 2>/dev/null; do wait $group; rc=$?; done   # a trap ended the wait early: wait again
while kill -0 -- -$group 2>/dev/null; do sleep 1; done          # the solver may still be writing its checkpoint
if [ $requeue = yes ] && [ $rc != 0 ]; then
  say "requeueing: the next start continues from the checkpoint"
  trap '' TERM   # SLURM ends this start at once: let scontrol (which inherits this) finish
  # the task's own id: $SLURM_JOB_ID of the array's last task is the array's id (it would requeue every task)
  scontrol requeue "${{SLURM_ARRAY_JOB_ID}}_${{SLURM_ARRAY_TASK_ID}}" && exit 0
  say "scontrol requeue failed: submit again to continue from the checkpoint"
fi
[ $rc = {locked} ] && say "another live run holds the run directory (exit {locked}): nothing was changed and the" \
                         "task is not requeued; submit again once that run has ended"
say "make exited with status $rc"
exit $rc
"""

SUBMIT = r"""#!/bin/bash
# Submit the runs of preset {preset} (written by pipeline/slurm_jobs.py): the job array, then the figures job.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
array=$(sbatch --parsable "$here/runs.sbatch"); array=${{array%%;*}}
echo "array $array: {n} runs of preset {preset}; logs $here/logs/run-${{array}}_<task>.out"
{figures}"""

SUBMIT_FIGURES = r"""figures=$(sbatch --parsable --dependency=afterok:$array "$here/figures.sbatch")
figures=${{figures%%;*}}
echo "figures $figures:" {then} "once every task of $array has succeeded; log $here/logs/figures-$figures.out"
"""


def parse_args(argv):
    ap = argparse.ArgumentParser(prog=PROG, description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--preset", required=True, help="preset of the runs (ci, reduced, converged, paper)")
    ap.add_argument("--cases", nargs="*", metavar="RUN", default=None,
                    help="only these runs of the figure set (<case> or <case>_slow); with --cases there is no "
                         "figures job unless --then gives one")
    ap.add_argument("--runs", default="runs", help="root of the runs, as Make's RUNS (default: runs)")
    ap.add_argument("--out", type=pathlib.Path, default=None, help="where the scripts go (default RUNS/PRESET/slurm)")
    ap.add_argument("--solver", type=pathlib.Path, default=paths.SOLVER,
                    help=f"the solver binary, as Make's ENAMEL (default {paths.SOLVER}); the jobs never rebuild it")
    ap.add_argument("--make-var", action="append", default=[], metavar="NAME=VALUE",
                    help="a Make variable for every make command of the jobs (repeatable), e.g. CHECKPOINT_EVERY=60")
    ap.add_argument("--run-set", default="", help="Make's RUN_SET: 'key=value ...' --set overrides of every run "
                    "(they also go into the estimates)")
    ap.add_argument("--then", default=None,
                    help="command of the figures job (default: make figures PRESET=P with the same variables; "
                         "'none': no figures job)")
    ap.add_argument("--cpus", type=int, default=1, help="CPUs per task (default 1); the solver uses at most these")
    ap.add_argument("--mem", default=None, help="memory per task, SLURM syntax (default: the solver's estimate)")
    ap.add_argument("--time", default=None, help="time limit per task start, SLURM syntax (default: the estimate)")
    ap.add_argument("--figures-time", default="1:00:00", help="time limit of the figures job (default 1:00:00)")
    ap.add_argument("--figures-mem", default="4G", help="memory of the figures job (default 4G)")
    ap.add_argument("--partition", default=None, help="SLURM partition (default: the cluster's default)")
    ap.add_argument("--account", default=None, help="SLURM account (default: none given)")
    ap.add_argument("--sbatch", action="append", default=[], metavar="OPTION",
                    help="another #SBATCH option for both jobs (repeatable), e.g. --sbatch=--qos=long")
    ap.add_argument("--signal-seconds", type=int, default=300,
                    help="SIGUSR1 this many seconds before the time limit: checkpoint and requeue (default 300)")
    return ap.parse_args(argv)


def request_resources(a, runs: list, run_set: list) -> list:
    """Fills a.mem and a.time from the solver's estimates where they were not given; returns what it chose, one
    note each. With both given, one estimate is still made: it checks the solver, the preset and RUN_SET."""
    note = []
    try:
        with concurrent.futures.ThreadPoolExecutor(os.cpu_count() or 2) as pool:
            todo = runs if a.mem is None or a.time is None else runs[:1]
            est = dict(zip(todo, pool.map(lambda r: estimate(a.solver, a.preset, r, run_set), todo)))
    except EstimateError as e:
        fail(str(e))    # one line, whichever run failed first
    if a.mem is None:
        mb = max(e["memory_mb"] for e in est.values())
        a.mem = f"{math.ceil((mb * MEM_FACTOR + MEM_EXTRA_MB) / 100) * 100}M"
        note.append(f"--mem {a.mem} (solver estimate {mb} MB, largest run)")
    if a.time is None:
        s = max(e["seconds"] for e in est.values())
        a.time = slurm_time(min(TIME_MAX_S, max(TIME_MIN_S, TIME_FACTOR * s)))
        note.append(f"--time {a.time} (solver estimate {s / 3600:.2g} h on one core, longest run)")
    return note


def write_runs_job(a, runs: list, out: pathlib.Path, make: str, common: dict, extra: str, header: str) -> None:
    """OUT/runs.sbatch: the job array, one task per run."""
    logs = out / "logs"
    targets = [str(paths.result_file(a.preset, case_of(r), r.endswith("_slow"), runs=pathlib.Path(a.runs)))
               for r in runs]
    array = {"job-name": f"enamel-{a.preset}-runs", "array": f"0-{len(runs) - 1}", "chdir": str(paths.ROOT),
             "output": str(logs / "run-%A_%a.out"), "open-mode": "append", "requeue": None,
             "signal": f"B:USR1@{a.signal_seconds}", "cpus-per-task": a.cpus, "mem": a.mem, "time": a.time,
             **common}
    body = ARRAY_BODY.format(targets="".join(f"  {shlex.quote(t)}   # task {i}\n" for i, t in enumerate(targets)),
                             make=make, signal_s=a.signal_seconds, locked=EXIT["output_locked"])
    out.mkdir(parents=True, exist_ok=True)
    logs.mkdir(exist_ok=True)
    (out / "runs.sbatch").write_text(header + sbatch_lines(array) + extra + body)


def write_figures_job(a, out: pathlib.Path, make: str, common: dict, extra: str, header: str) -> str:
    """OUT/figures.sbatch, the job after the array (none with --then none, or with --cases and no --then; an
    older one is removed); returns its part of submit.sh ("" without it)."""
    then = a.then if a.then is not None else ("none" if a.cases is not None else f"{make} figures-all")
    if then == "none":
        (out / "figures.sbatch").unlink(missing_ok=True)
        return ""
    fig = {"job-name": f"enamel-{a.preset}-figures", "chdir": str(paths.ROOT),
           "output": str(out / "logs" / "figures-%j.out"), "kill-on-invalid-dep": "yes", "cpus-per-task": 1,
           "mem": a.figures_mem, "time": a.figures_time, **common}
    (out / "figures.sbatch").write_text(
        header + sbatch_lines(fig) + extra +
        f'\necho "$(date \'+%F %T\') figures (job $SLURM_JOB_ID) on $(hostname):" {shlex.quote(then)}\n{then}\n'
        'rc=$?\necho "$(date \'+%F %T\') figures: exit status $rc"\nexit $rc\n')
    return SUBMIT_FIGURES.format(then=shlex.quote(then))


def main(argv=None) -> int:
    a = parse_args(argv)
    runs = select_runs(a.cases)
    out = (a.out or pathlib.Path(a.runs) / a.preset / "slurm").resolve()
    run_set = a.run_set.split()
    make_vars = [f"PRESET={a.preset}", f"RUNS={a.runs}", *([f"RUN_SET={a.run_set}"] if run_set else []),
                 f"LOCK_WAIT={LOCK_WAIT_S}", *a.make_var]   # a later --make-var LOCK_WAIT=... wins
    make = f"make --no-print-directory -o {shlex.quote(str(a.solver))} {quote_vars(make_vars)}"
    note = request_resources(a, runs, run_set)

    common = {k: v for k, v in {"partition": a.partition, "account": a.account}.items() if v}
    extra = "".join(f"#SBATCH {o}\n" for o in a.sbatch)
    header = (f"#!/bin/bash\n# Written by pipeline/slurm_jobs.py: preset {a.preset}, {len(runs)} runs; "
              f"submit with {out / 'submit.sh'}\n")
    write_runs_job(a, runs, out, make, common, extra, header)
    figures_part = write_figures_job(a, out, make, common, extra, header)
    submit = out / "submit.sh"
    submit.write_text(SUBMIT.format(preset=a.preset, n=len(runs), figures=figures_part))
    submit.chmod(0o755)
    print(f"{PROG}: {out}/: runs.sbatch ({len(runs)} array tasks, {', '.join(note) or 'resources as given'})"
          + (", figures.sbatch" if figures_part else ", no figures job") + f"; submit with {submit}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
