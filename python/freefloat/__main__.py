"""`python -m freefloat ...` is the same as the `freefloat` command (for when pip's script folder is not on PATH)."""

from .cli import main

main(prog_name="freefloat")
