"""Tournaments, benchmarks, reports and plots, and the ``surveil`` command line."""
