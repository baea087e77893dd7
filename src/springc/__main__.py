"""``python -m springc``: the command-line interface (a warm run replayed without the
command line's imports where it can: :mod:`springc.launcher`)."""

from .launcher import main

main()
