"""springc.simplify."""
