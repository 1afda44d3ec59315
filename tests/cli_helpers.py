"""Running the command line inside a test."""

from __future__ import annotations

from gcodekit import cli


def run(args, capsys) -> tuple[int, str, str]:
    """``gcodekit ARGS`` in this process: exit status, standard output, standard error."""
    status = cli.main([str(a) for a in args])
    out = capsys.readouterr()
    return status, out.out, out.err
