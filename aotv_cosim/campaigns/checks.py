"""Checks made before a Monte Carlo campaign starts: a folder to resume holds a readable
campaign, and a Dask scheduler address answers. Each failure is one InputError line."""

import csv
import socket
from pathlib import Path
from urllib.parse import urlsplit

from aotv_cosim.errors import InputError

CONNECT_TIMEOUT_S = 5.0
"""How long a scheduler may take to accept a TCP connection, s."""


def check_resumable(out_dir) -> None:
    """Refuse `--resume` on a folder whose campaign.json is not a JSON object or whose rows.csv
    cannot be read back (not UTF-8 text, not CSV, a complete row with a cell that is no number
    where the store writes numbers). A missing file is fine: the campaign starts afresh."""
    from aotv_cosim.model.documents import strict_json
    from aotv_cosim.campaigns.store import INTEGER, TEXT

    out_dir = Path(out_dir)
    manifest = out_dir / "campaign.json"
    fix = "remove the damaged file to start the campaign again, or give a new --out"
    if manifest.is_file():
        try:
            doc = strict_json(manifest.read_text(encoding="utf-8"))
        except (OSError, ValueError, RecursionError) as exc:
            raise InputError(f"cannot resume: corrupt campaign file ({type(exc).__name__}: {exc})",
                             file=manifest, entry="--resume", fix=fix) from None
        if not isinstance(doc, dict):
            raise InputError("cannot resume: the campaign file is not a JSON object", file=manifest,
                             entry="--resume", fix=fix)
    rows = out_dir / "rows.csv"
    if not rows.is_file():
        return
    try:
        text = rows.read_text(encoding="utf-8")
        lines = list(csv.reader(text.splitlines(keepends=True)))
    except (OSError, ValueError, csv.Error) as exc:
        raise InputError(f"cannot resume: unreadable rows ({type(exc).__name__}: {exc})", file=rows,
                         entry="--resume", fix=fix) from None
    if not lines:
        return
    header = lines[0]
    complete = lines[1:] if text.endswith("\n") else lines[1:-1]  # as the store reads them
    for number, cells in enumerate(complete, start=2):
        if len(cells) != len(header):
            continue  # the store drops a row cut short
        for name, cell in zip(header, cells):
            if name in TEXT or (name in INTEGER and cell == ""):
                continue
            try:
                int(cell) if name in INTEGER else float(cell)
            except ValueError:
                raise InputError(f"cannot resume: line {number} column {name!r} holds {cell[:40]!r}, "
                                 "not a number", file=rows, entry="--resume", fix=fix) from None


def check_reachable(address: str) -> None:
    """Refuse a `--scheduler` address (tcp:// or tls:// or host:port) that accepts no TCP
    connection within `CONNECT_TIMEOUT_S`. Other transports (inproc, ucx) are left to Dask."""
    text = address if "://" in address else f"tcp://{address}"
    parts = urlsplit(text)
    if parts.scheme not in ("tcp", "tls"):
        return
    try:
        host, port = parts.hostname, parts.port
    except ValueError:  # a port that is no number or out of range
        host, port = None, None
    if not host or not isinstance(port, int):
        raise InputError("cannot read the scheduler address", file=address, entry="--scheduler",
                         fix="give tcp://HOST:PORT (e.g. tcp://127.0.0.1:8786)")
    try:
        connection = socket.create_connection((host, port), timeout=CONNECT_TIMEOUT_S)
    except OSError as exc:
        raise InputError(f"cannot reach the Dask scheduler: {exc.strerror or exc}", file=address,
                         entry="--scheduler", fix="start the scheduler there, or correct --scheduler") from None
    with connection:
        if parts.scheme == "tcp" and not _greets_as_dask(connection):
            raise InputError("the server there does not answer as a Dask scheduler (its dashboard, a web server?)",
                             file=address, entry="--scheduler",
                             fix="give the scheduler's address (tcp://HOST:8786 by default; the dashboard is :8787)")


def _greets_as_dask(connection) -> bool:
    """True if the peer of the open TCP `connection` begins as a Dask scheduler does: its
    handshake, sent at once, a message whose first 8 bytes are its small length (little-endian).
    A web server (a scheduler's dashboard) says nothing until asked, an SSH server says text: Dask's
    client then waits forever for the handshake, or allocates a 'length' read from the text."""
    connection.settimeout(CONNECT_TIMEOUT_S)
    data = b""
    try:
        while len(data) < 8:
            chunk = connection.recv(8 - len(data))
            if not chunk:
                break
            data += chunk
    except OSError:  # socket.timeout among them: no greeting
        return False
    return len(data) == 8 and 0 < int.from_bytes(data, "little") < 2**20
