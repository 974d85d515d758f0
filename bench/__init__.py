"""bench/ as a package, so its scripts run as `python3 -m bench.<script>` from the repository root; its paths."""
import pathlib

from enamel_results import paths as _paths

HERE = pathlib.Path(__file__).resolve().parent   # make bench: results.csv, cost_growth.csv, results.md (committed), out/
RUNS = _paths.RUNS / "bench"                     # ... and its runs
PAPER_PRESET_RUNS = RUNS / "paper_preset"        # make bench-paper: the one paper-preset case
# make bench-converged: runs/bench/converged_cost/ (bench.converged_cost.RUNS)
