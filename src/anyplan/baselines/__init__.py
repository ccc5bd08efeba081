"""anyplan.baselines."""
