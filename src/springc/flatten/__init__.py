"""springc.flatten."""
