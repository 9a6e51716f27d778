"""Learned policies: single-agent wrappers, SB3 training, self-play and the model zoo."""
