"""Runs functions of an FMU on a Dask cluster: the machinery shared by
:class:`membrane_contact.study.Study` and :func:`membrane_contact.inverse.fit` (its own module, so
that neither imports the other for it).

The FMU travels as bytes (or a path every worker can read): a worker needs this package and
fmpy, no cargo and no repository.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable, Iterator


@dataclass(frozen=True)
class FmuRef:
    """Which FMU a worker runs: its content hash, its file name and, for a shared filesystem, a
    path every worker reads (else the bytes travel with the tasks, sent once per worker)."""

    sha256: str
    name: str
    shared_path: str | None = None

    @classmethod
    def of(cls, path: str | os.PathLike, shared: bool = False) -> tuple["FmuRef", bytes]:
        data = Path(path).read_bytes()
        ref = cls(hashlib.sha256(data).hexdigest(), Path(path).name, str(Path(path).resolve()) if shared else None)
        return ref, data


_LOCAL_FMUS: dict[str, Path] = {}


def local_fmu(ref: FmuRef, data: bytes | None) -> Path:
    """The FMU on this machine: the shared path, or the bytes written once per process into the
    temporary directory (``membrane-contact-fmus/<sha256>/``, checked against the hash)."""
    if ref.shared_path is not None:
        return Path(ref.shared_path)
    path = _LOCAL_FMUS.get(ref.sha256)
    if path is not None and path.is_file():
        return path
    if data is None:
        raise RuntimeError(f"no bytes of the FMU {ref.name} reached this worker")
    if hashlib.sha256(data).hexdigest() != ref.sha256:
        raise RuntimeError(f"the bytes of the FMU {ref.name} reached this worker damaged (hash differs)")
    folder = Path(tempfile.gettempdir()) / "membrane-contact-fmus" / ref.sha256
    folder.mkdir(parents=True, exist_ok=True)
    path = folder / ref.name
    if not path.is_file():
        fd, tmp = tempfile.mkstemp(dir=folder, suffix=".part")
        with os.fdopen(fd, "wb") as f:
            f.write(data)
        os.replace(tmp, path)
    _LOCAL_FMUS[ref.sha256] = path
    return path


def call_with_fmu(ref: FmuRef, data: Any, function: Callable[..., Any], *args: Any) -> Any:
    """Runs ``function(fmu_path, *args)`` on a worker with the FMU at a local path."""
    return function(local_fmu(ref, data), *args)


class Runner:
    """Runs functions of an FMU path on a Dask cluster: the machinery shared by :class:`Study`
    and :func:`membrane_contact.inverse.fit`. The FMU's bytes are scattered once to every
    worker (or, with ``shared=True``, its path is given to them)."""

    def __init__(self, client: Any, fmu: str | os.PathLike, shared: bool = False) -> None:
        self.client = client
        self.fmu = Path(fmu)
        self.ref, data = FmuRef.of(fmu, shared)
        self._data = None if shared else client.scatter(data, broadcast=True, hash=False)

    def submit(self, function: Callable[..., Any], *args: Any, key: str | None = None) -> Any:
        """A future of ``function(fmu_path, *args)`` on a worker."""
        kwargs = {"pure": False}
        if key is not None:
            kwargs["key"] = key
        return self.client.submit(call_with_fmu, self.ref, self._data, function, *args, **kwargs)

    def map(self, function: Callable[..., Any], arguments: list[tuple]) -> list:
        """``[function(fmu_path, *a) for a in arguments]``, run in parallel, in order."""
        futures = [self.submit(function, *a) for a in arguments]
        return self.client.gather(futures)


@contextlib.contextmanager
def cluster(scheduler: str | None = None, workers: int | None = None) -> Iterator[Any]:
    """A ``dask.distributed.Client``: to ``scheduler`` (an address ``tcp://host:8786`` or the
    path of a scheduler file), else to a new ``LocalCluster`` with ``workers`` worker processes
    (default: one per core), one thread each. The local cluster ends with the block."""
    from dask.distributed import Client, LocalCluster

    if scheduler:
        client = Client(scheduler_file=scheduler) if Path(scheduler).is_file() else Client(scheduler)
        try:
            yield client
        finally:
            client.close()
        return
    import logging

    cores = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count()
    n = workers or cores or 1
    with LocalCluster(n_workers=n, threads_per_worker=1, processes=True, dashboard_address=None,
                      silence_logs=logging.CRITICAL) as local, Client(local) as client:
        yield client
