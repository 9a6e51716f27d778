"""Tests of strategies.control (Secs. 5-7 of the paper)."""
