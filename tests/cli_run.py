"""Running the command line in-process for the tests: exit code, stdout and stderr."""

from stewart.cli import main


def run(argv, capsys):
    """Exit code, stdout and stderr of one command; a traceback in either stream fails."""
    try:
        main(argv)
        code = 0
    except SystemExit as exc:
        code = exc.code or 0
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err
