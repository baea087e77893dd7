"""springc.parse."""
