# enamel-dem — the front door. `make help` lists the targets.
#
#   make deps     install the Debian packages the project needs (idempotent; needs root to install)
#   make build    configure and build the solver and the C++ tests (Release)
#   make test     all C++ and Python tests (runs deps and build first when needed)
#
#   make figures  [PRESET=ci|reduced|converged|paper] [JOBS=N]  every run of Figs. 4-9, then the figures and the summary
#                 table under figures/out/<preset>/ (default PRESET=reduced; JOBS runs at once, default: the
#                 number of cores). A run that was stopped continues from its checkpoint.
#   make runs     [PRESET=...] [JOBS=N]  only the runs: runs/<preset>/<case>/result.h5 (re-runs only what changed)
#                 Both take RUN_SET="key=value ..." (e.g. "Gamma_k_over_sigma0sq=3"): --set on every run, in a runs
#                 folder and a figures folder of their own (runs/set_<keys>/, figures/out/set_<keys>/)
#                 A run with a record (records/<preset>/<case>.json, committed) and no result.h5 is not run again:
#                 `make figures` draws it from its record. A run of PRESET in RECORD_PRESETS (default: converged
#                 paper) writes its record as it completes.
#   make records  [PRESET=...]  a record of every completed run of the figure set that has none or an older one,
#                 in records/<preset>/ (commit them: they keep the figures when runs/ is gone; README)
#   make figures-recorded  [PRESET=...]  every figure (and the summary) whose runs all have a result.h5 or a
#                 record, from those, running nothing; lists the missing runs of the others
#   make publish  [PRESET=...]  as figures-recorded, then the figures made and the summary copied into
#                 docs/figures/<preset>/ (256-colour PNGs, each <= 400 kB) with an index.md of what each was drawn from
#   make slurm    [PRESET=...] [CASES="run ..."] [SLURM_PARTITION= SLURM_ACCOUNT= SLURM_TIME= SLURM_MEM=
#                 SLURM_CPUS= SLURM_SIGNAL=300 SLURM_SBATCH="--qos=..." SLURM_THEN="command"]  SLURM job scripts in
#                 runs/<preset>/slurm/: a job array of the runs (one task each, checkpointed and requeued at the
#                 time limit) and a figures job after it; submit with runs/<preset>/slurm/submit.sh (README:
#                 Cluster runs)
#   make vtk      [PRESET=...]  ParaView files (.pvd + .vtu series) of every finished run, in runs/<preset>/<case>/vtk/
#   make reference      regenerate tests/reference/ (ci-preset R-curves the tests compare with)
#   make clean-runs     [PRESET=...]  delete runs/<preset>/ and figures/out/<preset>/
#
#   make bench          [BENCH_G=3] [BENCH_FRESH=1]  speed against error of every integrator and knob, and cost growth
#                       (98 min on 2 cores at G = 3, 141 min at G = 9; at the solver's default G, which the report's
#                       header names); resumable: Ctrl-C stops the runs at a checkpoint, the same command continues
#                       (BENCH_FRESH=1: all again): bench/results.csv, bench/cost_growth.csv, bench/results.md, bench/out/*.png
#   make bench-converged  [BASELINE=commit] [CONVERGED_SET="key=value ..."] [CONVERGED_ARGS="--preset ci --nice 10
#                       ..."]  three cases at the `converged` preset to Delta_a = 30 d, each by the build of commit
#                       BASELINE (default in the Makefile; built once in build/baseline-<commit>/: the baseline),
#                       by build/enamel-dem with CONVERGED_SET (new) and without it (the R-curve's reference;
#                       --reference-set in CONVERGED_ARGS), one thread a run, JOBS at once, resumable (6-9 runs of
#                       23-37 min at the default baseline's speed): bench/converged_cost.md
#   make bench-step     instructions and cache misses per phase of the step, per DOF and per node (valgrind; ~3 min):
#                       bench/step_instructions.md
#   make bench-paper    [PAPER_SET="key=value ..."]  one `paper`-preset case (200 x 200 d, 1.39 M DOF) to Delta_a =
#                       30 d at the preset's rate from the static start (~1.2 h on 2 cores; the report says how long;
#                       Ctrl-C writes a checkpoint, the same command continues), judged against the 15 min goal and
#                       against the committed record bench/paper_preset_record.json (the same R-curve):
#                       bench/paper_preset.md, bench/out/paper_preset.png
#   A full clone also holds the lab notebook, whose research.mk adds: make test-research (the notebook's own
#   tests), make identify, make bench-far-field.
#   make test-asan      C++ tests built with AddressSanitizer + UBSan (build-asan/)
#   make fuzz           [FUZZ_SECONDS=120]  libFuzzer on the case parser (needs clang and libclang-rt-dev)

SHELL := /bin/bash
BUILD_DIR ?= build
JOBS ?= $(shell nproc 2>/dev/null || echo 2)
CHECKPOINT_EVERY ?= 60
LOCK_WAIT ?= 0
RUN_SET ?=

# Debian packages: the complete set needed to build, test and draw figures.
# libopenblas0-pthread: CHOLMOD's supernodal factorisation calls BLAS; OpenBLAS replaces the reference BLAS
# through Debian's alternatives (the static elastic start of a paper-size case: minutes instead of ~8 min).
DEB_PACKAGES := g++ make cmake pkg-config git \
  libeigen3-dev libsuitesparse-dev libopenblas0-pthread libhdf5-dev zlib1g-dev libtomlplusplus-dev libcli11-dev \
  libgtest-dev \
  python3 python3-numpy python3-h5py python3-matplotlib python3-meshio python3-pytest python3-vtk9 \
  slurm-wlm munge valgrind

# An interpreter that can import the pipeline's modules. The `python3` first on PATH may be a
# pyenv one without them, so probe the Debian interpreter first; fall back to it (after
# `make deps` it has everything). The Python scripts run as modules from the repository root
# (`$(PYTHON) -m figures.fig4_decussation`), so they import the package enamel_results (paths,
# results, metrics) and each other normally; pytest gets the root from pytest.ini.
PY_MODULES := numpy,h5py,matplotlib,meshio
PYTHON ?= $(shell for p in /usr/bin/python3 python3; do \
    if $$p -c 'import $(PY_MODULES)' >/dev/null 2>&1; then command -v $$p; exit 0; fi; done; \
    echo /usr/bin/python3)

ENAMEL := $(BUILD_DIR)/enamel-dem
PRESET ?= reduced
PRESETS := ci reduced converged paper
# Where the runs and the figures go. RUN_SET (below) changes the runs' physics or numerics, which Make does not
# track, so a RUN_SET without RUNS on the command line gets a folder of its own, named after it:
#   make figures RUN_SET="Gamma_k_over_sigma0sq=8"  ->  runs/set_Gamma_k_over_sigma0sq-8/<preset>/<case>/result.h5,
#                                                       figures/out/set_Gamma_k_over_sigma0sq-8/<preset>/
# and never mixes with (or counts as done because of) the default runs in runs/<preset>/.
empty :=
space := $(empty) $(empty)
set_tag = $(subst /,-,$(subst ',,$(subst ",,$(subst =,-,$(subst $(space),_,$(strip $(1)))))))
ifneq ($(filter command line environment,$(origin RUNS)),)
else ifneq ($(strip $(RUN_SET)),)
RUNS := runs/set_$(call set_tag,$(RUN_SET))
else
RUNS := runs
endif
FIG_ROOT := $(if $(filter runs,$(RUNS)),figures/out,figures/out/$(notdir $(RUNS)))
# Run records (enamel_results/records.py), committed: records/<preset>/<run>.json, beside each runs folder's
# figures folder (runs/set_<keys>/ -> records/set_<keys>/); RECORDS= on the command line replaces it.
ifeq ($(filter command line environment,$(origin RECORDS)),)
RECORDS := $(if $(filter runs,$(RUNS)),records,records/$(notdir $(RUNS)))
endif
RECORD_PRESETS ?= converged paper
FIG_OUT := $(FIG_ROOT)/$(PRESET)

.PHONY: bench bench-converged bench-step bench-paper help deps build test test-cpp test-python clean figures runs figures-all runs-all \
  vtk reference clean-runs check-preset slurm records figures-recorded publish

help:
	@sed -n '1,/^$$/p' $(firstword $(MAKEFILE_LIST)) | sed 's/^# \{0,1\}//'

deps:
	@missing=$$(for p in $(DEB_PACKAGES); do \
	    dpkg-query -W -f='$${Status}\n' $$p 2>/dev/null | grep -q '^install ok installed' || echo $$p; done); \
	if [ -z "$$missing" ]; then echo "deps: all Debian packages present"; exit 0; fi; \
	echo "deps: missing Debian packages:" $$missing; \
	if [ "$$(id -u)" != 0 ]; then \
	  if command -v sudo >/dev/null && sudo -n true 2>/dev/null; then SUDO=sudo; else \
	    echo "deps: ERROR: installing packages needs root. Run 'sudo make deps' (or as root:" >&2; \
	    echo "      apt-get install $$missing), then re-run this command." >&2; exit 1; fi; \
	fi; \
	$$SUDO apt-get update -qq && \
	DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq --no-install-recommends $$missing

# cmake leaves an unchanged cache's time alone: touch it, or every make (and two at once, racing) configures again
$(BUILD_DIR)/CMakeCache.txt: CMakeLists.txt | deps
	cmake -S . -B $(BUILD_DIR) -DCMAKE_BUILD_TYPE=Release
	touch $@

build: deps $(BUILD_DIR)/CMakeCache.txt
	cmake --build $(BUILD_DIR) -j $(JOBS)

test: build
	$(MAKE) --no-print-directory test-cpp test-python

test-cpp:
	cd $(BUILD_DIR) && ctest --output-on-failure -j $(JOBS)

test-python:
	ENAMEL_BINARY=$(abspath $(ENAMEL)) $(PYTHON) -m pytest -q tests/python

clean:
	rm -rf $(BUILD_DIR)

bench: $(ENAMEL)
	ENAMEL_BINARY=$(abspath $(ENAMEL)) PYTHONUNBUFFERED=1 $(PYTHON) -m bench.run_bench --jobs $(JOBS) \
	  $(if $(BENCH_G),--G $(BENCH_G)) $(if $(BENCH_FRESH),--fresh)

# A converged run's cost: BASELINE's build against this one (or CONVERGED_SET on it), the same R-curve decided by
# enamel_results.metrics.same_rcurve. CONVERGED_ARGS passes more options (bench/converged_cost.py --help).
BASELINE ?= c09beab
bench-converged: $(ENAMEL)
	ENAMEL_BINARY=$(abspath $(ENAMEL)) PYTHONUNBUFFERED=1 $(PYTHON) -m bench.converged_cost --jobs $(JOBS) \
	  --baseline $(BASELINE) $(foreach s,$(CONVERGED_SET),--set '$(s)') $(CONVERGED_ARGS)

# Instructions and cache misses per phase of the step, per DOF and per node (valgrind callgrind; independent of how
# busy the machine is). BENCH_STEP_AGAINST=path/to/older/enamel-dem counts a second binary beside it.
bench-step: $(ENAMEL)
	$(PYTHON) -m bench.step_instructions --binary $(ENAMEL) $(if $(BENCH_STEP_AGAINST),--against $(BENCH_STEP_AGAINST))

bench-paper: $(ENAMEL)
	ENAMEL_BINARY=$(abspath $(ENAMEL)) $(PYTHON) -m bench.paper_preset --threads $(JOBS) \
	  $(foreach s,$(PAPER_SET),--set '$(s)')

# --- the pipeline: paper_cases/ -> runs/<preset>/<case>/result.h5 -> figures/out/<preset>/ ---------------
# The solver binary is a file target, so runs depend on it: a rebuilt solver re-runs the cases.
SOLVER_SOURCES := $(wildcard solver/lib/*/*.cpp solver/lib/*/*.hpp solver/app/*.cpp) CMakeLists.txt
$(ENAMEL): $(SOLVER_SOURCES) | deps $(BUILD_DIR)/CMakeCache.txt
	cmake --build $(BUILD_DIR) -j $(JOBS) --target enamel-dem

# Which figure uses which case: generated from the table next to each figure script, figures/figN_<name>.toml
# (FIG4_CASES, ..., FIGURES, ALL_CASES, ALL_SLOW); a new figures/figN_<name>.py with its .toml joins by itself.
$(BUILD_DIR)/figures.mk: $(wildcard figures/fig*_*.toml figures/fig*_*.py) pipeline/make_rules.py enamel_results/paths.py \
    enamel_results/cases.py
	$(PYTHON) -m pipeline.make_rules $@
-include $(BUILD_DIR)/figures.mk

# What a figure reads of one run (enamel_results.paths.find_result, the same rule): its result.h5 when that is there
# or when it has no record (then Make runs it), else its record, a file no rule makes: a recorded run is not run
# again (delete its record to run it again).
run_file = $(RUNS)/$(PRESET)/$(1)/result.h5
record_file = $(RECORDS)/$(PRESET)/$(1)$(RECORD_SUFFIX)
source_of = $(if $(or $(wildcard $(call run_file,$(1))),$(if $(wildcard $(call record_file,$(1))),,none)),$\
  $(call run_file,$(1)),$(call record_file,$(1)))
run_targets = $(foreach c,$(1),$(call source_of,$(c))) $(foreach c,$(2),$(call source_of,$(c)_slow))
ALL_RUNS := $(call run_targets,$(ALL_CASES),$(ALL_SLOW))

check-preset:
	@case " $(PRESETS) " in *" $(PRESET) "*) ;; *) \
	  echo "make: PRESET=$(PRESET) is not a preset (allowed: $(PRESETS))" >&2; exit 2;; esac

# One run. The solver writes result.h5 only when the run completes (result.partial.h5 while it runs or after it
# was stopped, result.failed.h5 when it failed), so whatever stops the pipeline (Ctrl-C, SIGTERM, SIGKILL of
# make), the next `make` re-runs exactly the unfinished cases; --resume continues each from its checkpoint
# (written every CHECKPOINT_EVERY s) when the case and the solver binary are unchanged, and from step 0
# otherwise, saying which in the log (appended to, one piece after another). The solver locks the run directory
# (DIR/.lock) for the run's life: a second run into it is refused with exit 17, changing nothing, after waiting
# up to LOCK_WAIT s for the holder to end (default 0; the SLURM jobs wait, docs/cluster.md).
# RUN_SET="key=value ..." adds --set overrides to every run (sweeps, experiments, tests). Make does not track them,
# so without RUNS= on the command line they get a runs folder of their own (RUNS above).
RUN_SETS := $(foreach s,$(RUN_SET),--set $(s))
define run_case
	@mkdir -p $(@D)
	@echo "run: $(@D)"
	@echo "== $$(date '+%F %T') make: $(ENAMEL) run $< --preset $(PRESET) $(1) $(RUN_SETS)" >> $(@D)/log.txt
	@$(ENAMEL) run $< --preset $(PRESET) --out $(@D) --force --resume --checkpoint-every $(CHECKPOINT_EVERY) \
	  --lock-wait $(LOCK_WAIT) \
	  $(1) $(RUN_SETS) 2>> $(@D)/log.txt \
	  || { rc=$$?; tail -n 3 $(@D)/log.txt >&2; \
	       echo "run: $(@D) stopped (exit $$rc); partial result in $(@D)/result.failed.h5 or result.partial.h5," \
	            "log in $(@D)/log.txt" >&2; exit $$rc; }
	@tail -n 2 $(@D)/log.txt
	$(if $(filter $(PRESET),$(RECORD_PRESETS)),@ENAMEL_BINARY=$(abspath $(ENAMEL)) $(PYTHON) -m pipeline.records write $@ \
	  $(call record_file,$(notdir $(@D))))
endef

$(RUNS)/$(PRESET)/%_slow/result.h5: paper_cases/%.toml $(ENAMEL) | check-preset
	$(call run_case,--set rate_factor=0.5)

$(RUNS)/$(PRESET)/%/result.h5: paper_cases/%.toml $(ENAMEL) | check-preset
	$(call run_case,)

# `make figures` and `make runs` run JOBS cases at once (default: all cores); an outer `make -jN` is passed on.
define parallel
	@echo "$(1): up to $(JOBS) runs at once (JOBS=$(JOBS); set JOBS=1 for one at a time)"
	@$(MAKE) --no-print-directory -j$(JOBS) $(1)-all
endef
runs: check-preset
	$(call parallel,runs)

runs-all: check-preset $(ALL_RUNS)

# Figures: one script per figure (figures/figN_*.py, run as the module figures.figN_*), reading only the HDF5
# results of its runs; every figure depends on the plotting code, the results package and the paper's values.
fig_script = $(wildcard figures/$(1)_*.py)
fig_module = figures.$(basename $(notdir $(call fig_script,$(1))))
FIG_COMMON := figures/plotting.py $(wildcard enamel_results/*.py) figures/paper_values.toml
define figure_rule
$(FIG_OUT)/$(basename $(notdir $(call fig_script,$(1)))).png: $(call fig_script,$(1)) $(FIG_COMMON) \
    $(call run_targets,$($(shell echo $(1) | tr a-z A-Z)_CASES),$($(shell echo $(1) | tr a-z A-Z)_SLOW))
	ENAMEL_BINARY=$(abspath $(ENAMEL)) $(PYTHON) -m $(call fig_module,$(1)) --preset $(PRESET) --runs $(RUNS) --out $(FIG_ROOT) \
	  --records $(RECORDS)
endef
$(foreach f,$(FIGURES),$(eval $(call figure_rule,$(f))))
FIGURE_PNGS := $(foreach f,$(FIGURES),$(FIG_OUT)/$(basename $(notdir $(call fig_script,$(f)))).png)

$(FIG_OUT)/summary.csv: figures/summary_table.py $(FIG_COMMON) $(ALL_RUNS)
	ENAMEL_BINARY=$(abspath $(ENAMEL)) $(PYTHON) -m figures.summary_table --preset $(PRESET) --runs $(RUNS) --out $(FIG_ROOT) \
	  --records $(RECORDS)

figures: check-preset
	$(call parallel,figures)

figures-all: check-preset $(ENAMEL) $(FIGURE_PNGS) $(FIG_OUT)/summary.csv
	@test -n "$(FIGURES)" || { echo "figures: no figure list ($(BUILD_DIR)/figures.mk could not be made with PYTHON=$(PYTHON)); run 'make deps' first" >&2; exit 1; }
	@echo "figures: $(FIG_OUT)/ ($(words $(FIGURE_PNGS)) figures + summary.csv/.md)"

# Records: `make records` records the completed runs; `make figures-recorded` draws what is there, running nothing.
records: check-preset $(ENAMEL) $(BUILD_DIR)/figures.mk
	ENAMEL_BINARY=$(abspath $(ENAMEL)) $(PYTHON) -m pipeline.records update --preset $(PRESET) --runs $(RUNS) --records $(RECORDS)

figures-recorded: check-preset $(ENAMEL) $(BUILD_DIR)/figures.mk
	ENAMEL_BINARY=$(abspath $(ENAMEL)) $(PYTHON) -m pipeline.records figures --preset $(PRESET) --runs $(RUNS) \
	  --records $(RECORDS) --out $(FIG_ROOT)

# The figures drawn as by figures-recorded, copied small into docs/figures/PRESET/ (PNG <= 400 kB) with an index.
publish: check-preset $(ENAMEL) $(BUILD_DIR)/figures.mk
	ENAMEL_BINARY=$(abspath $(ENAMEL)) $(PYTHON) -m pipeline.records publish --preset $(PRESET) --runs $(RUNS) \
	  --records $(RECORDS) --out $(FIG_ROOT)

# SLURM: job scripts for the runs of the figure set (pipeline/slurm_jobs.py --help). Every task and the figures
# job run make with the variables below, never rebuilding the solver (-o): it is built here first.
# CASES: only these runs (<case> or <case>_slow); then there is no figures job unless SLURM_THEN gives one.
SLURM_DIR = $(RUNS)/$(PRESET)/slurm
SLURM_CPUS ?= 1
# passed on to the jobs' make when given on the command line
SLURM_PASS := BUILD_DIR ENAMEL CHECKPOINT_EVERY LOCK_WAIT PYTHON
slurm_opt = $(if $(2),'--$(1)=$(subst ','\'',$(2))')
slurm: check-preset $(ENAMEL) $(BUILD_DIR)/figures.mk
	ENAMEL_BINARY=$(abspath $(ENAMEL)) $(PYTHON) -m pipeline.slurm_jobs --preset $(PRESET) --runs $(RUNS) --out $(SLURM_DIR) --solver $(ENAMEL) \
	  --cpus $(SLURM_CPUS) $(call slurm_opt,partition,$(SLURM_PARTITION)) $(call slurm_opt,account,$(SLURM_ACCOUNT)) \
	  $(call slurm_opt,time,$(SLURM_TIME)) $(call slurm_opt,mem,$(SLURM_MEM)) $(call slurm_opt,then,$(SLURM_THEN)) \
	  $(call slurm_opt,signal-seconds,$(SLURM_SIGNAL)) \
	  $(call slurm_opt,run-set,$(RUN_SET)) $(foreach o,$(SLURM_SBATCH),$(call slurm_opt,sbatch,$(o))) \
	  $(foreach v,$(SLURM_PASS),$(if $(filter command line,$(origin $(v))),$(call slurm_opt,make-var,$(v)=$($(v))))) \
	  $(if $(CASES),--cases $(CASES)) $(if $(filter command line,$(origin CASES)),$(if $(CASES),,--cases))

# ParaView: one .pvd + .vtu time series per finished run (rods and interfaces), in runs/<preset>/<case>/vtk/.
vtk: check-preset
	@found=0; for h in $(RUNS)/$(PRESET)/*/result.h5; do [ -f "$$h" ] || continue; found=1; \
	  d=$$(dirname $$h)/vtk; if [ ! -d "$$d" ] || [ "$$h" -nt "$$d" ]; then \
	    ENAMEL_BINARY=$(abspath $(ENAMEL)) $(PYTHON) -m pipeline.export_vtk $$h $$d || exit 1; touch $$d; fi; done; \
	if [ $$found = 0 ]; then echo "vtk: no finished runs under $(RUNS)/$(PRESET)/: run 'make runs PRESET=$(PRESET)' first" >&2; exit 1; fi

reference: build
	ENAMEL_BINARY=$(abspath $(ENAMEL)) $(PYTHON) -m tests.reference.make_reference

clean-runs: check-preset
	rm -rf $(RUNS)/$(PRESET) $(FIG_OUT)

# Sanitizer and fuzz targets.
include tests/fuzz/quality.mk

# The lab notebook's targets (identify, bench-far-field, test-research), where the notebook is present.
-include research/research.mk
