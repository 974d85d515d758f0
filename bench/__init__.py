"""bench/ as a package, so its scripts run as `python3 -m bench.<script>` from the repository root."""
