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


class Completed:
    """What :func:`call` returns, named as :class:`subprocess.CompletedProcess`."""

    def __init__(self, returncode: int, stdout: str, stderr: str):
        self.returncode, self.stdout, self.stderr = returncode, stdout, stderr


def call(*args) -> Completed:
    """``stewart ARGS`` in this process, its streams captured: as ``subprocess.run`` of the
    command, without the start-up of a new interpreter."""
    import contextlib
    import io

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        try:
            main([str(a) for a in args])
            code = 0
        except SystemExit as exc:
            code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    return Completed(code, out.getvalue(), err.getvalue())
