"""Every policy (analytic, baseline, learned-policy loader) and the theory they stand on."""
