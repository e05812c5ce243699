"""run_sweep's arguments of the wrong kind: refused, naming the argument, before any work."""

import pytest

from ladartui.errors import FieldError
from ladartui.sweep import run_sweep
from tiny_sweep import tiny_folder, write_spec


@pytest.fixture(scope="module")
def tiny(tmp_path_factory):
    return tiny_folder(tmp_path_factory)


@pytest.mark.parametrize(
    "arguments, message",
    [
        (
            dict(client="tcp://127.0.0.1:8786"),
            "client = 'tcp://127.0.0.1:8786': expected a distributed.Client (or None)",
        ),
        (dict(client=3), "client = 3: expected a distributed.Client (or None)"),
        (dict(out=3, serial=True), "out = 3: expected a results folder's path (str or pathlib.Path)"),
        (dict(serial="no"), "serial = 'no': expected True or False"),
        (dict(serial=1), "serial = 1: expected True or False"),
    ],
)
def test_run_sweep_refuses_a_client_folder_or_serial_of_the_wrong_kind_first(
    tiny, tmp_path, arguments, message
):
    """A scheduler's address given as the client failed with AttributeError once the
    variants were due to run, out=3 with TypeError, and serial="no" ran serially."""
    spec = write_spec(tiny, "[grid]\nradius = [20.0]\n", name="kinds.toml")
    arguments = {"out": tmp_path / "o", **arguments}
    with pytest.raises(FieldError) as caught:
        run_sweep(spec, **arguments)
    assert str(caught.value) == message
    assert not (tmp_path / "o").exists()
