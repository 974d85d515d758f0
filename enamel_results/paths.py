"""The one place that defines the pipeline's paths: paper_cases/ -> runs/<preset>/<case>/result.h5 -> figures/out/<preset>/.
records/<preset>/<case>.json is the small committed record of a finished run (enamel_results/records.py), which
stands for the run when its result file is gone (find_result: the one lookup of a run's result)."""
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[1]
PAPER_CASES = ROOT / "paper_cases"
PAPER_VALUES = ROOT / "figures" / "paper_values.toml"
RUNS = ROOT / "runs"
RECORDS = ROOT / "records"  # committed: records/<preset>/<run>.json (git keeps them when runs/ is gone)
RECORD_SUFFIX = ".json"
FIGURES_OUT = ROOT / "figures" / "out"
SOLVER = ROOT / "build" / "enamel-dem"  # the solver binary (ENAMEL_BINARY overrides it)

# The result files of a run directory, by status (solver/lib/io/output.cpp resultFileFor): result.h5 exists only for a
# completed run; a run in progress or interrupted has result.partial.h5, a failed one result.failed.h5.
RESULT_NAMES = {"completed": "result.h5", "partial": "result.partial.h5", "failed": "result.failed.h5"}


def case_file(case: str) -> pathlib.Path:
    """The TOML file of a paper case, by name (e.g. 'theta30_s21.4_e10_cv0')."""
    return PAPER_CASES / f"{case}.toml"


def run_name(case: str, slow: bool = False) -> str:
    """The name of one run of a case: the case, or <case>_slow for its half-rate twin."""
    return f"{case}_slow" if slow else case


def result_file(preset: str, case: str, slow: bool = False, runs: pathlib.Path = None) -> pathlib.Path:
    """The HDF5 result of one run; `slow` runs are the half-rate twins. `runs` replaces the runs/ root (tests)."""
    return pathlib.Path(runs or RUNS) / preset / run_name(case, slow) / RESULT_NAMES["completed"]


def record_file(preset: str, case: str, slow: bool = False, records: pathlib.Path = None) -> pathlib.Path:
    """The record of one run, records/<preset>/<run>.json; `records` replaces the records/ root."""
    return pathlib.Path(records or RECORDS) / preset / (run_name(case, slow) + RECORD_SUFFIX)


def is_record(path) -> bool:
    """Whether a path found by find_result is a record (else it is a result file)."""
    return pathlib.Path(path).suffix == RECORD_SUFFIX


def find_result(preset: str, case: str, slow: bool = False, runs: pathlib.Path = None,
                records: pathlib.Path | None = None) -> pathlib.Path:
    """Where the figures read one run from: its result.h5 when that exists (the run is preferred: a record is made
    from it), else its record in `records` (None: records are not looked up) when that exists, else the result.h5
    path (missing: the caller says so and names the command that runs it)."""
    run = result_file(preset, case, slow=slow, runs=runs)
    if run.is_file() or records is None:
        return run
    record = record_file(preset, case, slow=slow, records=records)
    return record if record.is_file() else run


def source_root(path) -> pathlib.Path:
    """The root a result file (ROOT/<preset>/<run>/result.h5) or a record (ROOT/<preset>/<run>.json) lies under."""
    path = pathlib.Path(path)
    return path.parent.parent if is_record(path) else path.parent.parent.parent


def run_result(run_dir, kinds=("completed", "partial", "failed")) -> pathlib.Path | None:
    """The result file of a run directory: the first of `kinds` (RESULT_NAMES) that exists, None when none does.
    The default order gives the completed result, else the partial one (running or interrupted), else the failed
    one; kinds=("completed", "failed") gives a finished run's only."""
    for kind in kinds:
        p = pathlib.Path(run_dir) / RESULT_NAMES[kind]
        if p.is_file():
            return p
    return None


def figure_dir(preset: str, out: pathlib.Path = None) -> pathlib.Path:
    """Where the figures of one preset go; `out` replaces the figures/out/ root (tests)."""
    return pathlib.Path(out or FIGURES_OUT) / preset


def make_command(preset: str) -> str:
    """The command that produces the result files of one preset."""
    return f"make runs PRESET={preset}"
