"""`python -m freefloat.cli ...` is the same as `python -m freefloat ...` and the `freefloat` command."""

from . import main

main(prog_name="freefloat")
