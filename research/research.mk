# The notebook's targets (research/README.md), included by the Makefile when research/ is there. The product's
# targets never depend on these.

# The notebook's own tests (make test-research): the studies' reports regenerate from their committed records.
test-research: build
	ENAMEL_BINARY=$(abspath $(ENAMEL)) $(PYTHON) -m pytest -q research/tests

# The interface-ductility identification study (research/identify/README.md); resumable, niced runs in
# runs/identify/, report in research/identify/. IDENTIFY_ARGS: e.g. --stages ab --stop-starting 02:15.
identify: $(ENAMEL)
	ENAMEL_BINARY=$(abspath $(ENAMEL)) $(PYTHON) -m research.identify.identify $(IDENTIFY_ARGS)

# Full and reduced far field of the same cases, one run each, JOBS at a time (research/far_field/README.md).
FF_RUNS ?=
bench-far-field: $(ENAMEL)
	$(PYTHON) -m research.far_field.compare --run-all $(ENAMEL) --jobs $(JOBS) $(if $(FF_RUNS),--only $(FF_RUNS))

.PHONY: test-research identify bench-far-field
