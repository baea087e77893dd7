"""springc.pipeline."""
