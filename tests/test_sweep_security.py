"""The sweep's cluster is not an open door: plain addresses only on loopback, TLS with client certificates."""

import subprocess
import sys

import pytest

from ladartui.errors import FieldError, OutputFileError
from ladartui.sweep.security import cluster_security, is_loopback, make_certificates


@pytest.mark.parametrize(
    "address", ["tcp://127.0.0.1:8786", "127.0.0.1:8786", "tcp://localhost:8786", "tcp://[::1]:8786"]
)
def test_plain_loopback_address_needs_no_tls(address):
    assert is_loopback(address)
    assert cluster_security(address) is None


@pytest.mark.parametrize(
    "address", ["tcp://0.0.0.0:8786", "tcp://192.0.2.1:8786", "head:8786", "tcp://127.example.com:8786"]
)
def test_plain_address_off_loopback_is_refused_unless_insecure(address):
    with pytest.raises(FieldError, match="can run code"):
        cluster_security(address)
    assert cluster_security(address, insecure=True) is None
    # In a subprocess, like a user's shell (the CLI in-process disturbs a later Dask loop).
    run = subprocess.run(
        [sys.executable, "-m", "ladartui", "sweep", "spec.toml", "--scheduler", address],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert run.returncode == 2
    err = run.stderr
    assert err.count("\n") == 1 and "--insecure" in err and "Traceback" not in err


def test_tls_flags_must_come_together_and_with_a_tls_address(tmp_path):
    paths = make_certificates(tmp_path)
    with pytest.raises(FieldError, match="--tls-key"):
        cluster_security("tls://10.0.0.1:8786", paths["ca"], paths["cert"])
    with pytest.raises(FieldError, match="tls://"):
        cluster_security("tcp://10.0.0.1:8786", paths["ca"], paths["cert"], paths["key"])
    with pytest.raises(FieldError, match="not found"):
        cluster_security("tls://10.0.0.1:8786", tmp_path / "no.pem", paths["cert"], paths["key"])
    assert (paths["key"].stat().st_mode & 0o077) == 0


def test_insecure_with_tls_is_refused_as_a_flag_that_does_not_apply(tmp_path):
    """--insecure beside a tls:// scheduler and its certificates was taken without a word,
    as if the connection were plain; a flag that does not apply is refused, as elsewhere."""
    paths = make_certificates(tmp_path)
    with pytest.raises(FieldError) as caught:
        cluster_security("tls://10.0.0.1:8786", paths["ca"], paths["cert"], paths["key"], insecure=True)
    assert str(caught.value).startswith(
        "--insecure = True: expected --insecure only with a plain tcp:// address"
    )


def test_tls_files_that_hold_no_certificate_or_key_are_named_by_their_flag(tmp_path):
    """A CA file holding no certificate was reported as '--scheduler = ...: connecting
    failed: [X509: NO_CERTIFICATE_OR_CRL_FOUND]'."""
    paths = make_certificates(tmp_path / "a")
    other = make_certificates(tmp_path / "b")
    text = tmp_path / "notes.pem"
    text.write_text("not a certificate\n")
    address = "tls://10.0.0.1:8786"
    with pytest.raises(
        FieldError, match=r"^--tls-ca-file = '.*notes.pem': expected a PEM certificate authority"
    ):
        cluster_security(address, text, paths["cert"], paths["key"])
    with pytest.raises(FieldError, match=r"^--tls-cert = '.*notes.pem': expected a PEM certificate"):
        cluster_security(address, paths["ca"], text, paths["key"])
    with pytest.raises(FieldError, match=r"^--tls-key = '.*key.pem': expected the private key of --tls-cert"):
        cluster_security(address, paths["ca"], paths["cert"], other["key"])
    assert cluster_security(address, paths["ca"], paths["cert"], paths["key"]) is not None


def test_an_encrypted_key_is_refused_without_asking_for_its_password(tmp_path):
    """The TLS library asks on the terminal for the password of an encrypted key: the
    check must refuse it instead (a sweep has no one to answer, a TUI no terminal)."""
    from cryptography.hazmat.primitives import serialization

    paths = make_certificates(tmp_path)
    key = serialization.load_pem_private_key(paths["key"].read_bytes(), password=None)
    locked = tmp_path / "locked-key.pem"
    locked.write_bytes(
        key.private_bytes(
            serialization.Encoding.PEM,
            serialization.PrivateFormat.PKCS8,
            serialization.BestAvailableEncryption(b"secret"),
        )
    )
    run = subprocess.run(
        [
            sys.executable,
            "-c",
            "from ladartui.sweep.security import cluster_security as c; import sys; "
            "c('tls://10.0.0.1:8786', *sys.argv[1:])",
            str(paths["ca"]),
            str(paths["cert"]),
            str(locked),
        ],
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert "--tls-key = " in run.stderr and "the private key of --tls-cert, unencrypted PEM" in run.stderr
    assert "pass phrase" not in (run.stdout + run.stderr).lower()


# The TLS scheduler runs in a process of its own, and each client check in another: several
# clients refused in one process sometimes left the next one's IO-loop thread unstarted
# past distributed's 10 s ("assert loop is not None"), failing the test at random.
TLS_SERVER = r"""
import sys

from distributed import LocalCluster
from distributed.security import Security

ca, cert, key = sys.argv[1:4]
server = Security(
    tls_ca_file=ca,
    tls_scheduler_cert=cert,
    tls_scheduler_key=key,
    tls_worker_cert=cert,
    tls_worker_key=key,
    tls_client_cert=cert,
    tls_client_key=key,
    require_encryption=True,
)
with LocalCluster(
    n_workers=1,
    threads_per_worker=1,
    processes=False,
    protocol="tls",
    host="127.0.0.1",
    dashboard_address=None,
    security=server,
) as cluster:
    print(cluster.scheduler_address, flush=True)
    sys.stdin.read()  # until the test closes it
"""

TLS_CLIENT = r"""
import os
import sys

from distributed import Client
from distributed.security import Security

from ladartui.errors import FieldError
from ladartui.sweep import connect
from ladartui.sweep.security import cluster_security

check, address, ca, cert, key, rogue_ca, rogue_cert, rogue_key = sys.argv[1:9]
port = address.rsplit(":", 1)[1]


def refused(make, kinds):
    try:
        make().close()
    except kinds:
        return True
    return False


if check == "plain tcp":  # a rogue client speaking plain TCP gets nothing
    assert refused(lambda: Client(f"tcp://127.0.0.1:{port}", timeout="2s"), (OSError, TimeoutError))
elif check == "no certificates":
    assert refused(lambda: Client(address, timeout="2s"), (OSError, TimeoutError, TypeError))
elif check == "foreign certificates":
    foreign = Security(
        tls_ca_file=rogue_ca, tls_client_cert=rogue_cert, tls_client_key=rogue_key, require_encryption=True
    )
    assert refused(lambda: Client(address, timeout="2s", security=foreign), (OSError, TimeoutError))
elif check == "connect without the files":  # the sweep's own connect
    try:
        connect(address, 2.0)
        raise AssertionError("connected without certificates")
    except FieldError as error:
        assert "--scheduler" in str(error), error
elif check == "connect over tcp":  # its port as plain tcp:// (the TLS flags forgotten): said in words
    try:
        connect(f"tcp://127.0.0.1:{port}", 2.0)
        raise AssertionError("connected over plain TCP")
    except FieldError as error:
        said = str(error)
        assert said == (
            f"--scheduler = 'tcp://127.0.0.1:{port}': expected the address of a running Dask "
            "scheduler (tcp://HOST:PORT); it reset the connection, as a TLS scheduler does to a "
            f"plain client: give tls://127.0.0.1:{port} with --tls-ca-file, --tls-cert and --tls-key"
        ), said
else:  # with the files: accepted, and a task runs
    client = connect(address, 10.0, cluster_security(address, ca, cert, key))
    assert client.submit(sum, [1, 2, 3]).result(timeout=10) == 6
    client.close()
print("checked", flush=True)
os._exit(0)
"""

TLS_CHECK_NAMES = (
    "plain tcp",
    "no certificates",
    "foreign certificates",
    "connect without the files",
    "connect over tcp",
    "connect with the files",
)


def test_tls_scheduler_on_loopback_refuses_clients_without_its_certificates(tmp_path):
    ours = make_certificates(tmp_path / "ours")
    rogue = make_certificates(tmp_path / "rogue")
    paths = [str(files[k]) for files in (ours, rogue) for k in ("ca", "cert", "key")]
    server = subprocess.Popen(
        [sys.executable, "-c", TLS_SERVER, *paths[:3]],
        stdin=subprocess.PIPE,
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        text=True,
    )
    try:
        address = server.stdout.readline().strip()
        assert address.startswith("tls://127.0.0.1:"), address
        for check in TLS_CHECK_NAMES:
            run = subprocess.run(
                [sys.executable, "-c", TLS_CLIENT, check, address, *paths],
                stdin=subprocess.DEVNULL,
                capture_output=True,
                text=True,
                timeout=120,
            )
            assert run.returncode == 0 and run.stdout.strip() == "checked", (check, run.stderr[-2000:])
    finally:
        server.stdin.close()
        try:
            server.wait(timeout=30)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait()


@pytest.mark.parametrize("address", ["foo", "tcp://head", "http://10.0.0.1:8786", "tcp://head:port"])
def test_a_scheduler_that_is_no_address_is_named_as_such(address):
    with pytest.raises(FieldError) as caught:
        cluster_security(address)
    assert str(caught.value) == (
        f"--scheduler = {address!r}: expected an address such as tcp://127.0.0.1:8786 or tls://HOST:PORT"
    )


def test_a_missing_tls_flag_is_said_to_be_missing(tmp_path):
    paths = make_certificates(tmp_path)
    with pytest.raises(FieldError) as caught:
        cluster_security("tls://10.0.0.1:8786", None, paths["cert"], paths["key"])
    assert str(caught.value) == (
        "--tls-ca-file is missing; expected a PEM file (TLS needs --tls-ca-file, --tls-cert "
        "and --tls-key together; ladartui certs DIR makes them)"
    )


def test_new_certificates_replace_the_old_three_together_or_not_at_all(tmp_path, monkeypatch):
    """--force rewrote the authority, the certificate and the key one after another: a
    failure between left an authority beside a certificate it did not sign."""
    from pathlib import Path

    paths = make_certificates(tmp_path)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    real = Path.write_bytes

    def full_on_the_key(self, data):
        if self.name.startswith(f".{paths['key'].name}"):
            raise OSError(28, "No space left on device")
        return real(self, data)

    monkeypatch.setattr(Path, "write_bytes", full_on_the_key)
    with pytest.raises(OutputFileError, match=r"no space left on device\); nothing was replaced"):
        make_certificates(tmp_path)
    monkeypatch.undo()
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    assert (paths["key"].stat().st_mode & 0o077) == 0


def test_a_handshake_that_fails_blames_the_tls_flags_not_the_address(tmp_path):
    """A scheduler made with other certificates was reported as '--scheduler = ...:
    expected the address of a running Dask scheduler; connecting failed: TLS certificate
    does not match'."""
    import ssl

    from ladartui.sweep.cluster import tls_refusal

    paths = make_certificates(tmp_path)
    security = cluster_security("tls://10.0.0.1:8786", paths["ca"], paths["cert"], paths["key"])
    blames_ca = f"--tls-ca-file = '{paths['ca']}': expected"
    # Found by the cause alone (a message that names nothing) ...
    try:
        try:
            raise ssl.SSLCertVerificationError("certificate verify failed")
        except ssl.SSLError as cause:
            raise OSError("closed") from cause
    except OSError as error:
        assert str(tls_refusal(error, security)).startswith(blames_ca)
    # ... and by Dask's wording alone, where the cause is not kept.
    said = OSError("TLS certificate does not match. Check your security settings.")
    assert str(tls_refusal(said, security)).startswith(blames_ca)
    rejected = OSError("closed")
    rejected.__context__ = ssl.SSLError("sslv3 alert bad certificate")
    assert str(tls_refusal(rejected, security)).startswith(f"--tls-cert = '{paths['cert']}'")
    assert tls_refusal(OSError("Timed out trying to connect"), security) is None


def test_the_sweep_screen_names_its_certificates_field_for_a_bad_tls_file(tmp_path):
    """The screen has one Certificates folder, not three flags: a CA file holding no
    certificate was told as '--tls-ca-file = ...'."""
    from ladartui.sweep.security import folder_security
    from ladartui.tui.sweep_jobs import in_form_words

    paths = make_certificates(tmp_path)
    paths["ca"].write_text("not a certificate\n")
    with pytest.raises(FieldError) as caught:
        folder_security("tls://10.0.0.1:8786", tmp_path)
    said = str(in_form_words(caught.value))
    assert said.startswith(
        f"Certificates: {paths['ca']} is not allowed; expected a PEM certificate authority"
    )
