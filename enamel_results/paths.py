"""The one place that defines the pipeline's paths: paper_cases/ -> runs/<preset>/<case>/result.h5 -> figures/out/<preset>/."""
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[1]
PAPER_CASES = ROOT / "paper_cases"
PAPER_VALUES = ROOT / "figures" / "paper_values.toml"
RUNS = ROOT / "runs"
FIGURES_OUT = ROOT / "figures" / "out"
SOLVER = ROOT / "build" / "enamel-dem"  # the solver binary (ENAMEL_BINARY overrides it)

# The result files of a run directory, by status (solver/lib/output.cpp resultFileFor): result.h5 exists only for a
# completed run; a run in progress or interrupted has result.partial.h5, a failed one result.failed.h5.
RESULT_NAMES = {"completed": "result.h5", "partial": "result.partial.h5", "failed": "result.failed.h5"}


def case_file(case: str) -> pathlib.Path:
    """The TOML file of a paper case, by name (e.g. 'theta30_s21.4_e10_cv0')."""
    return PAPER_CASES / f"{case}.toml"


def result_file(preset: str, case: str, slow: bool = False, runs: pathlib.Path = None) -> pathlib.Path:
    """The HDF5 result of one run; `slow` runs are the half-rate twins. `runs` replaces the runs/ root (tests)."""
    return pathlib.Path(runs or RUNS) / preset / (f"{case}_slow" if slow else case) / "result.h5"


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
