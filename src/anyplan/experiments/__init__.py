"""anyplan.experiments."""
