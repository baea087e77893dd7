"""springc.ir."""
