"""springc.tradeoff."""
