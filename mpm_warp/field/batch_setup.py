"""What a field batch checks and opens around its runs: its inputs (read lazily), its folder, its scheduler, its
logs, its Dask client and its progress line.

:func:`iter_gather` yields the cases and refusals of the inputs one at a time, so a batch with ``--limit`` sets up
only the rows it runs and a large table starts at once; every input is checked first (a table that cannot be read
at all is one :class:`~.table_read.TableError` line before anything is set up). :func:`check_out_dir` and
:func:`check_scheduler` refuse an unwritable ``--out`` or a scheduler address that is not one, in one line.
:func:`dask_log` sends Dask's own logs (the local cluster's workers included) to ``dask.log`` in ``--out``;
:func:`dask_client` opens the cluster; :class:`Progress` is the batch's one line on the terminal.
"""

from __future__ import annotations

import contextlib
import os
import sys
import time

from ..errors import InvalidArgument
from .cases import FieldRefusal, field_case, field_cases
from .table import iter_table

__all__ = ["iter_gather", "check_out_dir", "check_scheduler", "dask_log", "dask_client", "Progress", "CAAML_SUFFIXES",
           "DASK_LOG"]

#: the file names a folder's CAAML pits end with (any case: ``.XML`` as some exports write it)
CAAML_SUFFIXES = (".xml", ".caaml")
#: the file in ``--out`` that Dask's logs go to unless the batch is verbose
DASK_LOG = "dask.log"


def _table_refusal(name: str, row) -> FieldRefusal:
    return FieldRefusal(f"{name}#{row.id}", f"row {row.line}", "table row", row.problem, row.observed)


def iter_gather(inputs, calibrate: bool = True):
    """Every :class:`~.cases.FieldCase` and :class:`~.cases.FieldRefusal` of ``inputs`` (folders of CAAML files,
    CAAML files, CSV tables), in input order, each set up only when asked for.

    Raises
    ------
    InvalidArgument
        An input that is none of these (before anything is set up).
    TableError
        A table that cannot be read at all (before anything is set up).
    """
    sources = []
    for path in inputs:
        path = os.fspath(path)
        if os.path.isdir(path):
            files = sorted(os.path.join(path, f) for f in os.listdir(path)
                           if f.lower().endswith(CAAML_SUFFIXES) and not f.startswith("."))   # as a glob "*" lists
            sources.append(("caaml", files))
        elif path.lower().endswith(".csv") and os.path.isfile(path):
            sources.append(("table", (os.path.basename(path), iter_table(path))))
        elif os.path.isfile(path):
            sources.append(("caaml", [path]))
        else:
            raise InvalidArgument("INPUT", path, "a folder of CAAML files, a CAAML file or a CSV table of PSTs")
    return _items(sources, calibrate)


def _items(sources, calibrate):
    for kind, what in sources:
        if kind == "table":
            name, rows = what
            for row in rows:
                if row.problem is not None:
                    yield _table_refusal(name, row)
                else:
                    yield field_case(row.profile, row.record, w_f=row.w_f, calibrate=calibrate)
            continue
        for f in what:
            yield from field_cases(f, calibrate=calibrate)


def check_out_dir(out_dir: str) -> None:
    """Create ``out_dir`` and check that a batch can write in it (its Dask log is opened there).

    Raises
    ------
    InvalidArgument
        One line naming the folder and why it cannot be written.
    """
    try:
        os.makedirs(out_dir, exist_ok=True)
        with open(os.path.join(out_dir, DASK_LOG), "a"):
            pass
    except OSError as e:
        raise InvalidArgument("out", os.fspath(out_dir), f"a folder this user can create and write in ({e.strerror})"
                              ) from None


def check_scheduler(address: str | None) -> None:
    """Refuse a ``--scheduler`` that is not a Dask address (``tcp://host:port``) in one line, before any setup."""
    if address is None:
        return
    from distributed.comm.addressing import parse_address, parse_host_port

    try:
        scheme, loc = parse_address(address)
        if scheme == "tcp":
            parse_host_port(loc)
    except (ValueError, TypeError) as e:
        raise InvalidArgument("scheduler", address, f"the address of a running Dask scheduler, e.g. tcp://host:8786 "
                              f"({e})") from None


@contextlib.contextmanager
def dask_log(out_dir: str, verbose: bool):
    """While the cluster runs, everything written to the process's stderr (file descriptor 2: Dask's loggers, its
    workers' output) goes to :data:`DASK_LOG` in ``out_dir``, unless ``verbose``; yields a text stream on the
    terminal's stderr for the batch's own progress line."""
    if verbose:
        yield sys.stderr
        return
    sys.stderr.flush()
    saved = os.dup(2)
    try:
        with open(os.path.join(out_dir, DASK_LOG), "a") as log:
            os.dup2(log.fileno(), 2)
            with open(os.dup(saved), "w", closefd=True) as terminal:
                try:
                    yield terminal
                finally:
                    terminal.flush()
                    with contextlib.suppress(ValueError, OSError):
                        sys.stderr.flush()
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def dask_client(stack, scheduler, workers, threads, verbose):
    """A client of the running scheduler ``scheduler``, else of a local cluster of ``workers`` processes (default:
    the cores over ``threads``), entered on the exit stack ``stack``; a scheduler that cannot be reached is one
    :class:`~mpm_warp.errors.InvalidArgument` line."""
    from distributed import Client, LocalCluster

    if not scheduler:
        cluster = stack.enter_context(LocalCluster(
            n_workers=workers or max(1, (os.cpu_count() or 1) // threads), threads_per_worker=1, processes=True,
            dashboard_address=None, silence_logs=False if verbose else 40, env={"MPM_WARP_THREADS": str(threads)}))
        return stack.enter_context(Client(cluster))
    try:
        return stack.enter_context(Client(scheduler, timeout=30))
    except (OSError, ValueError, TimeoutError) as e:
        raise InvalidArgument("scheduler", scheduler, f"the address of a running Dask scheduler ({e})") from None


class Progress:
    """The batch's one progress line: the records set up (and refused), the cases done of those to run so far."""

    def __init__(self, stream):
        self.stream, self.t0, self.shown = stream, time.perf_counter(), -1.0
        self.records = self.refused = self.tasks = self.done = 0
        self.setting_up = True

    def show(self, force: bool = False) -> None:
        """Write the line (at most twice a second unless ``force``)."""
        now = time.perf_counter()
        if self.stream is None or (not force and now - self.shown < 0.5):
            return
        self.shown, el = now, now - self.t0
        more = "+" if self.setting_up else ""
        eta = (f", ETA {el / self.done * (self.tasks - self.done):.0f} s" if self.done and not self.setting_up
               else "")
        self.stream.write(f"\rfield: {self.records}{more} records set up ({self.refused} refused), "
                          f"{self.done}/{self.tasks}{more} cases done, elapsed {el:.0f} s{eta} ")
        self.stream.flush()

    def end(self) -> None:
        """The last line, and a new line."""
        if self.stream is not None and (self.records or self.tasks):
            self.setting_up = False
            self.show(force=True)
            self.stream.write("\n")
