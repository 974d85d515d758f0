"""The reference outputs and their generator (python3 -m tests.reference.make_reference)."""
