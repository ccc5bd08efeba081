"""anyplan.planning."""
