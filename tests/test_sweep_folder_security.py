"""Cluster security from one certificates folder (the terminal UI's sweep screen)."""

from __future__ import annotations

import pytest

from ladartui.errors import FieldError
from ladartui.sweep.security import folder_security, make_certificates


def test_a_folder_made_by_certs_gives_mutual_tls_for_a_tls_scheduler(tmp_path):
    make_certificates(tmp_path / "certs")
    security = folder_security("tls://10.0.0.5:8786", tmp_path / "certs")
    assert security.require_encryption and security.tls_client_cert.endswith("cluster.pem")


@pytest.mark.parametrize(
    "address, folder, words",
    [
        ("tcp://10.0.0.5:8786", None, "run code on it"),  # plain, off this machine
        ("tls://10.0.0.5:8786", None, "the folder of the certificates"),
        ("tcp://10.0.0.5:8786", "certs", "tls://HOST:PORT"),  # certificates need tls://
        ("tls://10.0.0.5:8786", "empty", "missing: ca.pem, cluster.pem, cluster-key.pem"),
    ],
)
def test_what_is_refused_says_why(tmp_path, address, folder, words):
    make_certificates(tmp_path / "certs")
    (tmp_path / "empty").mkdir()
    with pytest.raises(FieldError, match=words):
        folder_security(address, tmp_path / folder if folder else None)


def test_loopback_and_insecure_plain_schedulers_are_allowed():
    assert folder_security("tcp://127.0.0.1:8786") is None
    assert folder_security("tcp://10.0.0.5:8786", insecure=True) is None
