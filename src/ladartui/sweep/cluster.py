"""A sweep's Dask cluster: a local one started here, or a scheduler to connect to.

A local cluster's workers never see a Ctrl-C (the key reaches the terminal's whole
process group): they start with SIGINT blocked and ignore it once running, and this
process stops them after keeping the finished rows.
"""

from __future__ import annotations

import contextlib
import importlib.metadata
import logging
import os
import signal

from ladartui.errors import FieldError, LadarError


def check_local_workers(workers: int | None, name: str = "workers") -> None:
    """FieldError naming ``name`` for more local worker processes than 4 per core: a
    mistyped count started workers until the machine gave out."""
    cores = os.cpu_count() or 1
    if workers is not None and workers > 4 * cores:
        raise FieldError(
            name,
            workers,
            f"at most {4 * cores} local worker processes (4 per core of this machine's {cores})",
        )


def local_client(workers: int | None = None):
    """A client of a new LocalCluster: ``workers`` processes (default one per core), 1 thread each.

    The tracing kernels are parallel themselves, so each worker's numba pool
    gets an even share of the cores instead of every worker using them all.
    """
    from distributed import Client, LocalCluster

    cores = os.cpu_count() or 1
    count = workers or cores
    try:
        with _ctrl_c_blocked():
            cluster = LocalCluster(
                n_workers=count,
                threads_per_worker=1,
                processes=True,
                # The scheduler serves HTTP even without a dashboard, by default on port
                # 8787 of every interface: a second sweep at once warned that the port
                # was taken. A free port of the loopback alone.
                dashboard_address="127.0.0.1:0",
                silence_logs=logging.ERROR,
                env={"NUMBA_NUM_THREADS": str(max(1, cores // count))},
            )
    except RuntimeError as error:  # "Nanny failed to start": the worker said why above
        raise LadarError(
            f"the local cluster's worker processes failed to start ({error}); their messages above say "
            "why. From a script, call run_sweep under 'if __name__ == \"__main__\":'"
        ) from error
    client = Client(cluster)
    _set_up_local_workers(client)
    _quiet_lost_scattered_data()
    return client


# distributed's scheduler's message for a worker gone with data scattered to it.
LOST_SCATTERED = "lose scattered data, which can't be recovered"


class _DropLostScattered(logging.Filter):
    def filter(self, record):
        return LOST_SCATTERED not in record.getMessage()


def _quiet_lost_scattered_data() -> None:
    """The scheduler of a local cluster (in this process) does not log a worker lost with
    the scene scattered to it. SIGTERM to the terminal's process group reaches the workers
    too, and every stop printed that ERROR line; a worker lost mid-sweep is told by the
    sweep itself (its rows are 'failed', run again on resume)."""
    scheduler_log = logging.getLogger("distributed.scheduler")
    if not any(isinstance(f, _DropLostScattered) for f in scheduler_log.filters):
        scheduler_log.addFilter(_DropLostScattered())


@contextlib.contextmanager
def _ctrl_c_blocked():
    """SIGINT blocked in this thread while a local cluster starts. Threads started here
    (the cluster's) and the worker processes they spawn inherit the block, so a Ctrl-C
    while they start up reaches this process's main thread alone: each worker printed
    a KeyboardInterrupt traceback from its start-up before. (The plugin below makes the
    workers ignore the key once running.)"""
    if not hasattr(signal, "pthread_sigmask"):
        yield
        return
    # The first process spawned through multiprocessing starts its resource tracker,
    # which unblocks SIGINT in the calling thread afterwards, so every worker spawned
    # from that thread later started with the key unblocked: started here, before.
    from multiprocessing import resource_tracker

    resource_tracker.ensure_running()
    before = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, before)


def _ignore_ctrl_c() -> None:
    """In a worker process (on its main thread, where its event loop runs): SIGINT ignored."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)


# distributed's message for a heartbeat that failed (logged with its tracebacks).
HEARTBEAT_FAILED = "Failed to communicate with scheduler during heartbeat"


class _DropFailedHeartbeat(logging.Filter):
    def filter(self, record):
        return not record.getMessage().startswith(HEARTBEAT_FAILED)


def _quiet_failed_heartbeats() -> None:
    """In a local worker: a failed heartbeat is not logged. Its scheduler lives in the
    sweep's own process, so a heartbeat fails only as that process closes the cluster
    or is gone: a sweep stopped right after its cluster started printed one, with three
    tracebacks, in a third of the tries (the worker closed its connections while a
    heartbeat was under way), and a sweep killed (kill -9, the out-of-memory killer) in
    two of three, under the command's last line. The sweep tells what it kept itself;
    a killed one's rows are in its table. Other errors are logged as before."""
    log = logging.getLogger("distributed.worker")
    if not any(isinstance(f, _DropFailedHeartbeat) for f in log.filters):
        log.addFilter(_DropFailedHeartbeat())


def _set_up_local_workers(client) -> None:
    """A local cluster's workers, now and when restarted, ignore Ctrl-C (the key reaches
    the terminal's whole process group, and each worker printed a traceback as it
    died; this process stops them instead, after keeping the finished rows) and do
    not log a failed heartbeat (their scheduler is this process, closing or gone)."""
    from distributed.diagnostics.plugin import WorkerPlugin

    class LocalWorker(WorkerPlugin):
        name = "ladartui-local-worker"

        def setup(self, worker):
            _ignore_ctrl_c()
            _quiet_failed_heartbeats()

    client.register_plugin(LocalWorker())


def connect(address: str, timeout: float = 30.0, security=None):
    """A client of the Dask scheduler at ``address`` that has ladartui on every worker.

    ``security``: a ``distributed.Security`` for a TLS scheduler (see ``sweep.security``).
    """
    from distributed import Client

    try:
        client = Client(address, timeout=f"{timeout}s", security=security)
    except (OSError, TimeoutError, ValueError, TypeError) as error:  # TypeError: tls:// sans TLS
        if security is not None and (refusal := tls_refusal(error, security)) is not None:
            raise refusal from None
        if security is None and address.startswith("tcp://") and _was_reset(error):
            raise FieldError(
                "--scheduler",
                address,
                "the address of a running Dask scheduler (tcp://HOST:PORT); it reset the connection, "
                f"as a TLS scheduler does to a plain client: give tls://{address[len('tcp://') :]} "
                "with --tls-ca-file, --tls-cert and --tls-key",
            ) from None
        raise FieldError(
            "--scheduler",
            address,
            f"the address of a running Dask scheduler (tcp://HOST:PORT); connecting failed: {error}",
        ) from None
    try:
        client.wait_for_workers(1, timeout=timeout)
    except (TimeoutError, OSError):
        close_client(client)
        raise FieldError(
            "--scheduler", address, f"a scheduler with workers; none joined within {timeout:g} s"
        ) from None
    check_workers(client)
    return client


def _was_reset(error: BaseException) -> bool:
    """Whether the peer reset the connection (``error`` or what caused it)."""
    seen: BaseException | None = error
    while seen is not None:
        if isinstance(seen, ConnectionResetError):
            return True
        seen = seen.__cause__ or seen.__context__
    return False


def tls_refusal(error: BaseException, security) -> FieldError | None:
    """The TLS flag to blame when connecting failed in the TLS handshake (the address
    was right, the certificates not), or None: a certificate of the scheduler that does
    not verify against --tls-ca-file, else this client's certificate refused."""
    import ssl

    seen: BaseException | None = error
    while seen is not None:
        verify = isinstance(seen, ssl.SSLCertVerificationError) or "TLS certificate does not match" in str(
            seen
        )
        if verify:
            return FieldError(
                "--tls-ca-file",
                str(security.tls_ca_file),
                "the certificate authority the scheduler's certificate was made with; the "
                "scheduler's certificate does not verify against this one",
            )
        if isinstance(seen, ssl.SSLError):
            return FieldError(
                "--tls-cert",
                str(security.tls_client_cert),
                "a certificate the scheduler trusts (made with its ca.pem); the TLS handshake "
                f"failed ({seen})",
            )
        seen = seen.__cause__ or seen.__context__
    return None


def check_workers(client) -> None:
    """Raise LadarError when a worker lacks ladartui or runs another version of it."""
    mine = importlib.metadata.version("ladartui")
    answers = client.run(importlib.metadata.version, "ladartui", on_error="return")
    for worker, answer in answers.items():
        if isinstance(answer, BaseException):
            raise LadarError(
                f"worker {worker} cannot import ladartui ({answer}); install this "
                f"version ({mine}) in the workers' environment"
            )
        if answer != mine:
            raise LadarError(
                f"worker {worker} runs ladartui {answer}, this client {mine}; "
                "install the same version everywhere"
            )


def close_client(client):
    """Close ``client`` and, for a local cluster, the cluster with its workers."""
    cluster = getattr(client, "cluster", None)
    with _reconnect_cut_short_unlogged():
        client.close()
    if cluster is not None:
        cluster.close()


# distributed's message when a client stops trying to reconnect, closed or timed out.
RECONNECT_FAILED = "Failed to reconnect to scheduler"


@contextlib.contextmanager
def _reconnect_cut_short_unlogged():
    """A client that lost its scheduler keeps trying to reconnect (30 s by default):
    closing it ends the attempt, which distributed logged as an ERROR under the sweep's
    one-line message: the attempt cancelled (three tracebacks), or 'Failed to reconnect
    to scheduler after 30.00 seconds' at once. Other errors are logged as before."""
    import asyncio

    class DropReconnect(logging.Filter):
        def filter(self, record):
            cancelled = record.exc_info and isinstance(record.exc_info[1], asyncio.CancelledError)
            return not (cancelled or record.getMessage().startswith(RECONNECT_FAILED))

    log = logging.getLogger("distributed.client")
    drop = DropReconnect()
    log.addFilter(drop)
    try:
        yield
    finally:
        log.removeFilter(drop)
