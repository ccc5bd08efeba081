"""anyplan.control."""
