"""enamel_results: the Python side's library for enamel-dem's HDF5 results (no plotting).

    paths          the one place that defines the pipeline's paths (paper_cases/, runs/, records/, figures/out/,
                   bench/) and find_result, the one lookup of a run's result file or record
    cases          the figure tables figures/figN_<name>.toml (which figure uses which case), case-name parameters
    constants      the numbers shared with the solver, read from `enamel-dem constants --json` (exit codes, warning
                   bounds, the result seal, result file names)
    paper_values   figures/paper_values.toml: the numbers the paper states, with their sentences
    results        load one result.h5 (Result, Geometry, Frame), interface tags, EXIT_MISSING
    records        a run's record (records/<preset>/<run>.json): write one from a result.h5, load one as a Result
    metrics        R-curve comparison and the pooled R_m of Fig. 9
    mechanism      measures of the mechanism: the rise length of an R-curve, and of one frame the inelastic
                   zone, the kinks at the tip, the crack's offset from its plane, the kinks' period, far rod breaks
    cli            the figure scripts' shared command line and loading of a figure's runs

figures/, bench/, pipeline/ and tests/ import it as `from enamel_results import results`; they find it because
they run with the repository root on sys.path: `python3 -m figures.fig4_decussation` from the root (what the
Makefile does), and pytest through the root's pytest.ini (`pythonpath = .`). Nothing here imports matplotlib.
"""
