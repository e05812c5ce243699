"""Helpers shared by the CLI tests."""


def one_error_line(capsys) -> str:
    """The one line a CLI run wrote to stderr: ``ladartui: error: ...``, no traceback."""
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and err.startswith("ladartui: error:") and "Traceback" not in err, err
    return err
