"""Command-line tools: analyze, simulate, replay, the demo, reports and plots."""
