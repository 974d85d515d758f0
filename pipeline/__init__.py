"""pipeline/ as a package, so its scripts run as `python3 -m pipeline.<script>` from the repository root."""
