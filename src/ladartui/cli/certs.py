"""``ladartui certs DIR``: make the TLS certificates of a multi-machine sweep cluster."""

from __future__ import annotations

from ladartui.textsafe import single_line


def add_parser(subparsers):
    parser = subparsers.add_parser(
        "certs",
        help="make TLS certificates for a Dask cluster of several machines",
        description="Write a new certificate authority (ca.pem) and one cluster certificate "
        "and key (cluster.pem, cluster-key.pem, owner-readable only) into DIR. Copy DIR to the "
        "scheduler, every worker and the machine that runs 'ladartui sweep'; each accepts "
        "only peers holding a certificate from this authority. See docs/sweeps.md.",
    )
    parser.add_argument("folder", metavar="DIR", help="folder for the three PEM files")
    parser.add_argument(
        "--days", type=int, default=365, help="validity of the certificates in days (default 365)"
    )
    parser.add_argument("--force", action="store_true", help="replace existing files in DIR")
    parser.set_defaults(handler=run)
    return parser


def run(args) -> int:
    from pathlib import Path

    from ladartui.cli.flags import check_file_names
    from ladartui.errors import FieldError
    from ladartui.sweep.security import CA_FILE, CERT_FILE, KEY_FILE, make_certificates

    check_file_names({"DIR": args.folder}, "a folder name, such as certs")  # "" is the current folder
    if not 1 <= args.days <= 36500:
        raise FieldError("--days", args.days, "an integer from 1 to 36500")
    folder = Path(args.folder)
    if folder.exists() and not folder.is_dir():
        raise FieldError("DIR", str(folder), "a folder (this is an existing file)")
    existing = [name for name in (CA_FILE, CERT_FILE, KEY_FILE) if (folder / name).exists()]
    if existing and not args.force:
        raise FieldError(
            "DIR",
            str(folder),
            f"a folder without {', '.join(existing)} "
            "(--force replaces them; every cluster machine then needs the new ones)",
        )
    try:
        paths = make_certificates(folder, args.days)
    except OSError as error:
        raise FieldError("DIR", str(folder), f"a writable folder ({error.strerror})") from None
    for path in paths.values():
        print(single_line(path))
    return 0
