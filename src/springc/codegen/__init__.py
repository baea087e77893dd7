"""springc.codegen."""
