"""The runs of a sweep on an existing Dask distributed cluster.

:func:`run_dask` sends each run (:func:`polind.sweeps.runs.run_one`) as a
task to the cluster's workers and hands the rows back as they finish.  An
address is checked before a client connects to it (:func:`check_scheduler`):
only ``tcp://`` is taken (a ``tls://`` or ``ucx://`` address is refused,
naming the schemes it takes), and a Dask scheduler must answer with its
handshake within :data:`CONNECT_TIMEOUT` seconds, so that an address where
something else listens (a web server, a port that never answers) is refused
in bounded time instead of hanging, and no stray bytes of another protocol
are taken for a message.  A scheduler that goes away during the sweep ends it
with an :class:`~polind.errors.InputError` (the rows finished by then are
kept), and the cluster's own log lines stay off standard error.
"""

from __future__ import annotations

import contextlib
import logging
import socket
import time

from polind.errors import InputError, describe
from polind.sweeps.runs import RunPlan, one_line, run_one

__all__ = ["CONNECT_TIMEOUT", "check_scheduler", "run_dask"]

#: How long a Dask scheduler may take to answer a connection [s].
CONNECT_TIMEOUT = 10.0

# The largest handshake a scheduler sends on connecting [bytes] (about 60 in practice).
_HANDSHAKE_BYTES = 1 << 16


def _host_and_port(address: str):
    """``(host, port)`` of a ``tcp://HOST:PORT`` (or ``HOST:PORT``) address; InputError else."""
    scheme, separator, rest = address.partition("://")
    if not separator:
        scheme, rest = "tcp", address
    if scheme != "tcp":
        raise InputError(f"--scheduler {address}: a sweep reaches its Dask scheduler over "
                         f"plain TCP; expected an address tcp://HOST:PORT, not {scheme}://")
    host, _, port = rest.rstrip("/").rpartition(":")
    host = host.strip("[]")
    if not host or not port.isdigit() or not 0 < int(port) < 65536:
        raise InputError(f"--scheduler {address}: expected an address tcp://HOST:PORT with a "
                         f"port number from 1 to 65535")
    return host, int(port)


def _receive(connection, count, deadline):
    """Exactly ``count`` bytes, or fewer if the peer closes; socket.timeout at the deadline."""
    data = b""
    while len(data) < count:
        left = deadline - time.monotonic()
        if left <= 0.0:
            raise socket.timeout
        connection.settimeout(left)
        chunk = connection.recv(count - len(data))
        if not chunk:
            break
        data += chunk
    return data


def check_scheduler(address: str, timeout: float = None) -> None:
    """Refuse (InputError) an address where no Dask scheduler answers within ``timeout`` [s].

    A Dask scheduler greets every connection with a handshake (a framed
    message naming its Python and pickle versions); this connects, reads it
    and closes.  Default ``timeout``: :data:`CONNECT_TIMEOUT`.
    """
    timeout = CONNECT_TIMEOUT if timeout is None else float(timeout)
    host, port = _host_and_port(address)
    deadline = time.monotonic() + timeout
    not_dask = (f"--scheduler {address}: something answers there, but not a Dask scheduler; "
                f"expected the address of a running cluster's scheduler (tcp://HOST:8786)")
    try:
        with socket.create_connection((host, port), timeout=timeout) as connection:
            header = _receive(connection, 8, deadline)
            size = int.from_bytes(header, "little") if len(header) == 8 else 0
            if not 16 <= size <= _HANDSHAKE_BYTES:
                raise InputError(not_dask)
            if b"python" not in _receive(connection, size, deadline):
                raise InputError(not_dask)
    except socket.timeout:
        raise InputError(f"--scheduler {address}: no Dask scheduler answered within "
                         f"{timeout:g} s; expected the address of a running cluster, such as "
                         f"tcp://HOST:8786") from None
    except OSError as error:
        raise InputError(f"cannot reach the Dask scheduler at {address!r} "
                         f"({error.strerror or error}); expected the address of a running "
                         f"cluster, such as tcp://HOST:8786") from None


@contextlib.contextmanager
def _quiet_cluster_logs():
    """Keep distributed's log lines (reconnection attempts, tracebacks) off standard error.

    distributed sets the levels of its own loggers (``distributed.client``...),
    so each is silenced, and given its level back afterwards.
    """
    names = ["distributed", *(name for name in logging.root.manager.loggerDict
                              if name.startswith("distributed."))]
    loggers = [logging.getLogger(name) for name in names]
    levels = [logger.level for logger in loggers]
    for logger in loggers:
        logger.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        for logger, level in zip(loggers, levels):
            logger.setLevel(level)


def _dask_task(plan, index, values):
    return run_one(plan, index, values)


def _client(scheduler):
    """``(client, own)``: a client of the cluster at ``scheduler`` (an address or a Client)."""
    from distributed import Client

    if isinstance(scheduler, Client):
        return scheduler, False
    address = str(scheduler)
    check_scheduler(address)
    try:
        return Client(address, timeout=CONNECT_TIMEOUT), True
    except Exception as error:  # noqa: BLE001 - whatever the client meets, the address is at fault
        raise InputError(f"cannot reach the Dask scheduler at {address!r} "
                         f"({one_line(error)}); expected the address of a running cluster, "
                         f"such as tcp://HOST:8786") from None


def run_dask(plan: RunPlan, todo, scheduler, record, keep, lost) -> None:
    """Every run of ``todo`` as a task of an existing Dask cluster; rows to ``record``.

    ``scheduler`` is an address or a ``distributed.Client``.  A task that
    fails outside its run (its worker died) is ``lost``: it is not recorded,
    and running the sweep again computes it.  A scheduler that goes away is
    an InputError once the rows finished by then are recorded.  On any
    exception here (Ctrl-C) the unfinished tasks are cancelled, the rows of
    finished ones not yet recorded go to ``keep``, and the exception goes on.
    """
    import uuid

    try:
        from distributed import as_completed
    except ImportError:  # pragma: no cover - a dependency of polind
        raise InputError("--scheduler needs the 'distributed' package (pip install "
                         "'dask[distributed]')") from None
    with _quiet_cluster_logs():
        client, own = _client(scheduler)
        tag = uuid.uuid4().hex[:8]
        unrecorded = set()
        failure = None
        try:
            shared = client.scatter(plan, broadcast=True, hash=False)
            unrecorded = {client.submit(_dask_task, shared, index, values, pure=False,
                                        key=f"polind-sweep-{tag}-{index}")
                          for index, values in todo}
            for future in as_completed(list(unrecorded)):
                unrecorded.discard(future)
                if future.status == "finished":
                    record(future.result())
                elif client.status == "running":
                    lost(future)
                else:
                    unrecorded.add(future)      # the scheduler is gone, not the task
                    break
            if client.status != "running":
                failure = "gone"
        except (OSError, TimeoutError) as error:
            failure = error
        finally:
            _keep_finished(client, unrecorded, keep)
            if own:
                with contextlib.suppress(Exception):
                    client.close(timeout=CONNECT_TIMEOUT)
        if failure is not None:
            _gone(client, scheduler, None if failure == "gone" else failure)


def _keep_finished(client, unrecorded, keep):
    """The rows of finished tasks not yet recorded go to ``keep``; the others are cancelled."""
    finished = [future for future in unrecorded if future.status == "finished"]
    with contextlib.suppress(Exception):
        client.cancel([future for future in unrecorded if future.status == "pending"])
    for future in sorted(finished, key=lambda f: f.key):
        with contextlib.suppress(Exception):
            keep(future.result(timeout=CONNECT_TIMEOUT))


def _gone(client, scheduler, error):
    """Raise the InputError of a scheduler that went away during the sweep."""
    reason = f" ({one_line(error)})" if error is not None else ""
    address = scheduler if isinstance(scheduler, str) else getattr(
        getattr(client, "scheduler", None), "address", describe(scheduler))
    raise InputError(f"the Dask scheduler at {address} went away during the sweep{reason}; the "
                     f"rows of the runs finished by then are kept: run the same command again "
                     f"(with a running cluster) to compute the rest")
