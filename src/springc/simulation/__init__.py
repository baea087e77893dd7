"""springc.simulation."""
