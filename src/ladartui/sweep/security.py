"""Who may talk to the sweep's Dask cluster: mutual TLS, or a plain address on loopback only.

A peer that reaches a Dask scheduler without TLS can run any code on the
scheduler and every worker, and a rogue worker can hand this client an object
that runs code when unpickled. So a plain ``tcp://`` address is accepted only
on loopback (or with ``--insecure``); other clusters use TLS with certificates
signed by one certificate authority (``ladartui certs DIR`` makes them).
"""

from __future__ import annotations

import datetime
import ipaddress
from pathlib import Path
from urllib.parse import urlsplit

from ladartui.errors import FieldError
from ladartui.fileprobe import file_problem, user_path

CA_FILE = "ca.pem"
CERT_FILE = "cluster.pem"
KEY_FILE = "cluster-key.pem"


def is_loopback(address: str) -> bool:
    """Whether the host of ``address`` (``tcp://HOST:PORT`` or ``HOST:PORT``) is this machine only."""
    host = urlsplit(address if "://" in address else f"tcp://{address}").hostname or ""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


class MissingFlagError(FieldError):
    """A flag that must come with others and was left out."""

    def __init__(self, flag: str, expected: str):
        super().__init__(flag, None, expected)
        self.args = (f"{flag} is missing; expected {expected}",)


def _is_address(address: str) -> bool:
    """``[tcp|tls://]HOST:PORT`` with a host and a port number."""
    parts = urlsplit(address if "://" in address else f"tcp://{address}")
    try:
        port = parts.port
    except ValueError:  # not a number
        return False
    return parts.scheme in ("tcp", "tls") and bool(parts.hostname) and port is not None


def cluster_security(address: str, ca_file=None, cert_file=None, key_file=None, insecure: bool = False):
    """The ``distributed.Security`` for ``address``, or None for a permitted plain address.

    Raises FieldError naming the flag: a TLS file missing or unreadable, TLS files with
    a plain address, or a plain address off loopback without ``insecure``.
    """
    files = {"--tls-ca-file": ca_file, "--tls-cert": cert_file, "--tls-key": key_file}
    scheme = address.split("://", 1)[0] if "://" in address else "tcp"
    if not _is_address(address):
        raise FieldError("--scheduler", address, "an address such as tcp://127.0.0.1:8786 or tls://HOST:PORT")
    if insecure and (scheme == "tls" or any(files.values())):
        raise FieldError(
            "--insecure",
            True,
            "--insecure only with a plain tcp:// address (a tls:// scheduler with its "
            "certificates needs none)",
        )
    if any(files.values()):
        for flag, path in files.items():
            if not path:
                raise MissingFlagError(
                    flag,
                    "a PEM file (TLS needs --tls-ca-file, --tls-cert "
                    "and --tls-key together; ladartui certs DIR makes them)",
                )
            if problem := file_problem(Path(path)):
                raise FieldError(flag, str(path), f"a readable PEM file: {problem}")
        if scheme != "tls":
            raise FieldError(
                "--scheduler",
                address,
                "a tls://HOST:PORT address with the TLS "
                "files (the scheduler must be started with the same certificates)",
            )
        _check_tls_files(ca_file, cert_file, key_file)
        from distributed.security import Security

        return Security(
            tls_ca_file=str(ca_file),
            tls_client_cert=str(cert_file),
            tls_client_key=str(key_file),
            require_encryption=True,
        )
    if scheme == "tls":
        raise FieldError(
            "--scheduler", address, "--tls-ca-file, --tls-cert and --tls-key with a tls:// address"
        )
    if not insecure and not is_loopback(address):
        raise FieldError(
            "--scheduler",
            address,
            "a tls:// address with --tls-ca-file, "
            "--tls-cert and --tls-key, or a loopback address: any peer that "
            "reaches a plain tcp:// scheduler can run code on it, its workers "
            "and this machine (see docs/sweeps.md; --insecure to use it anyway)",
        )
    return None


def _check_tls_files(ca_file, cert_file, key_file) -> None:
    """FieldError naming the flag whose file holds no certificate authority, no
    certificate, or no key of that certificate: said before connecting, where the
    TLS library's words would be blamed on the address."""
    import ssl

    try:
        ssl.create_default_context(cafile=str(ca_file))
    except (ssl.SSLError, ValueError):
        raise FieldError("--tls-ca-file", str(ca_file), "a PEM certificate authority (ca.pem)") from None
    try:  # read as a list of certificates: a chain, or text around them, is taken
        ssl.SSLContext(ssl.PROTOCOL_TLS_CLIENT).load_verify_locations(cafile=str(cert_file))
    except (ssl.SSLError, ValueError):
        raise FieldError("--tls-cert", str(cert_file), "a PEM certificate") from None
    try:  # (an empty password: an encrypted key is refused, never asked for on the terminal)
        ssl.SSLContext(ssl.PROTOCOL_TLS_CLIENT).load_cert_chain(str(cert_file), str(key_file), password=b"")
    except (ssl.SSLError, ValueError):
        raise FieldError(
            "--tls-key", str(key_file), "the private key of --tls-cert, unencrypted PEM"
        ) from None


def make_certificates(folder, days: int = 365) -> dict[str, Path]:
    """Write a new certificate authority and one cluster certificate and key into ``folder``.

    Scheduler, workers and client all present the cluster certificate; each accepts only
    peers whose certificate the authority signed. The keys are readable by the owner only.
    """
    from cryptography import x509
    from cryptography.hazmat.primitives import hashes, serialization
    from cryptography.hazmat.primitives.asymmetric import ec
    from cryptography.x509.oid import ExtendedKeyUsageOID, NameOID

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    now = datetime.datetime.now(datetime.UTC)
    start, end = now - datetime.timedelta(minutes=5), now + datetime.timedelta(days=days)

    def name(text):
        return x509.Name([x509.NameAttribute(NameOID.COMMON_NAME, text)])

    ca_key = ec.generate_private_key(ec.SECP256R1())
    ca_cert = (
        x509.CertificateBuilder()
        .subject_name(name("ladartui cluster CA"))
        .issuer_name(name("ladartui cluster CA"))
        .public_key(ca_key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(start)
        .not_valid_after(end)
        .add_extension(x509.BasicConstraints(ca=True, path_length=0), critical=True)
        .sign(ca_key, hashes.SHA256())
    )
    key = ec.generate_private_key(ec.SECP256R1())
    cert = (
        x509.CertificateBuilder()
        .subject_name(name("ladartui cluster"))
        .issuer_name(ca_cert.subject)
        .public_key(key.public_key())
        .serial_number(x509.random_serial_number())
        .not_valid_before(start)
        .not_valid_after(end)
        .add_extension(x509.BasicConstraints(ca=False, path_length=None), critical=True)
        .add_extension(
            x509.ExtendedKeyUsage([ExtendedKeyUsageOID.SERVER_AUTH, ExtendedKeyUsageOID.CLIENT_AUTH]),
            critical=False,
        )
        .sign(ca_key, hashes.SHA256())
    )
    from ladartui.outputset import OutputSet

    pem = serialization.Encoding.PEM
    paths = {"ca": folder / CA_FILE, "cert": folder / CERT_FILE, "key": folder / KEY_FILE}
    contents = {
        "ca": ca_cert.public_bytes(pem),
        "cert": cert.public_bytes(pem),
        "key": key.private_bytes(pem, serialization.PrivateFormat.PKCS8, serialization.NoEncryption()),
    }

    # one set: an authority and a certificate it did not sign must never sit together; the
    # key owner-only before it is in its file
    with OutputSet(paths, folder / ".certs.lock") as output_set:
        output_set.write_contents(contents, modes={"key": 0o600})
    return paths


def folder_security(address: str, folder=None, insecure: bool = False):
    """``cluster_security`` for the three files in ``folder`` (as ``ladartui certs`` writes
    them), with messages naming the folder rather than flags; None for a permitted plain
    address. For the terminal UI, where one folder is simpler than three files."""
    scheme = address.split("://", 1)[0] if "://" in address else "tcp"
    if folder:
        folder = user_path(folder)
        missing = [name for name in (CA_FILE, CERT_FILE, KEY_FILE) if not (folder / name).is_file()]
        if missing:
            raise FieldError(
                "certificates",
                str(folder),
                f"a folder made by 'ladartui certs' (missing: {', '.join(missing)})",
            )
        if scheme != "tls":
            raise FieldError("scheduler", address, "a tls://HOST:PORT address to use the certificates with")
        return cluster_security(address, folder / CA_FILE, folder / CERT_FILE, folder / KEY_FILE)
    if scheme == "tls":
        raise FieldError(
            "certificates",
            "",
            f"the folder of the certificates for {address} (ladartui certs DIR makes them)",
        )
    if not insecure and not is_loopback(address):
        raise FieldError(
            "scheduler",
            address,
            "a tls:// address with its certificates, or a "
            "loopback address: any peer that reaches a plain tcp:// scheduler can "
            "run code on it, its workers and this machine (see docs/sweeps.md)",
        )
    return None
