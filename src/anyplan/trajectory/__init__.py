"""anyplan.trajectory."""
