"""``python -m springc``: the command-line interface."""

from .cli import main

main()
