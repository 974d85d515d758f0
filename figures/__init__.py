"""figures/ as a package, so its scripts run as `python3 -m figures.<script>` from the repository root."""
