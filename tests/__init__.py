"""tests/ as a package: tests.reference.make_reference is importable from the repository root."""
