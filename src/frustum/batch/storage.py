"""Output at an fsspec URL (``s3://``, ``gs://``, ``file://``, ``memory://`` ...): ``RemotePath``, ``is_url``.

A dataset or a ``RenderJob`` output may name a URL instead of a local path; the files are then written through
fsspec (``pip install 'frustum[remote]'``; S3 needs ``s3fs``, Google Cloud Storage ``gcsfs``). ``RemotePath``
is the handful of ``pathlib`` methods the dataset writer and the camera-file writers use (``/``, ``exists``,
``is_file``, ``read_bytes``, ``unlink``, ``glob`` ...), so the same code writes a folder and a bucket.

Writes are whole or nothing, as for local files: on an object store (S3, GCS, Azure, ``memory://``) one PUT
of the finished bytes is atomic by itself; on other file systems (``file://``, SFTP ...) the bytes go to a
temporary name beside the target first and are then renamed. Credentials and endpoints come from the
environment of each process that writes (``AWS_ACCESS_KEY_ID``, ``AWS_ENDPOINT_URL``, instance roles, or
fsspec's ``FSSPEC_S3_*`` variables), so on a cluster every node needs them.
"""

from __future__ import annotations

import contextlib
import io
import os
import posixpath
from pathlib import Path
from typing import Any

from frustum.errors import OutputError

__all__ = ["OBJECT_STORES", "RemotePath", "is_url", "to_location"]

OBJECT_STORES = frozenset({"s3", "s3a", "gs", "gcs", "az", "abfs", "abfss", "adl", "oci", "memory"})
"""fsspec protocols whose single PUT of a whole object is atomic (no temporary name needed)."""
TEMPORARY_MARK = ".partial-"
"""Infix of temporary file names (``.<name>.partial-<pid>``): a file with it is never a finished output."""


def is_url(value: Any) -> bool:
    """True for a ``RemotePath`` or a string with a ``scheme://`` prefix (a URL, not a local path)."""
    if isinstance(value, RemotePath):
        return True
    if not isinstance(value, str):
        return False
    scheme, found, _ = value.partition("://")
    return bool(found) and len(scheme) > 1 and scheme.replace("+", "").replace("-", "").isalnum()


def _fsspec() -> Any:
    try:
        import fsspec
    except ImportError:
        raise OutputError(
            "URL outputs need fsspec, which is not installed; pip install 'frustum[remote]' (and s3fs for s3://, "
            "gcsfs for gs://)"
        ) from None
    return fsspec


class RemotePath:
    """A file or folder at an fsspec URL, with the pathlib methods the batch writers use.

    Plain data (the URL string): it pickles to Ray workers and worker processes, each of which opens its own
    fsspec file system (cached by fsspec) on first use.
    """

    __slots__ = ("_fs", "_path", "url")

    def __init__(self, url: str) -> None:
        if not is_url(url):
            raise OutputError(f"RemotePath: url = {url!r} is not a URL (scheme://...)")
        scheme, _, rest = str(url).partition("://")
        rest = rest.rstrip("/")
        self.url = f"{scheme}://{rest}"
        self._fs: Any = None
        self._path = ""

    def __getstate__(self) -> str:
        return self.url

    def __setstate__(self, url: str) -> None:
        self.url, self._fs, self._path = url, None, ""

    @property
    def fs(self) -> Any:
        """The fsspec file system (opened once per process)."""
        if self._fs is None:
            try:
                self._fs, self._path = _fsspec().core.url_to_fs(self.url)
            except (ImportError, ValueError) as error:
                raise OutputError(f"{self.url}: cannot open this URL with fsspec ({error})") from None
        return self._fs

    @property
    def path(self) -> str:
        """The path inside the file system (the URL without its scheme, as fsspec writes it)."""
        self.fs  # noqa: B018 - opens the file system, which sets _path
        return self._path

    @property
    def protocol(self) -> str:
        return self.url.partition("://")[0]

    @property
    def atomic_put(self) -> bool:
        """True where one PUT of the finished bytes is atomic (object stores)."""
        protocols = self.fs.protocol if isinstance(self.fs.protocol, tuple | list) else (self.fs.protocol,)
        return any(p in OBJECT_STORES for p in protocols)

    def __truediv__(self, other: str | os.PathLike) -> RemotePath:
        part = os.fspath(other).replace(os.sep, "/").strip("/")
        return RemotePath(f"{self.url}/{part}" if part else self.url)

    def __str__(self) -> str:
        return self.url

    def __repr__(self) -> str:
        return f"RemotePath({self.url!r})"

    def __eq__(self, other: object) -> bool:
        return isinstance(other, RemotePath) and other.url == self.url

    def __hash__(self) -> int:
        return hash(self.url)

    @property
    def name(self) -> str:
        return posixpath.basename(self.url.partition("://")[2])

    @property
    def suffix(self) -> str:
        return posixpath.splitext(self.name)[1]

    @property
    def parent(self) -> RemotePath:
        scheme, _, rest = self.url.partition("://")
        return RemotePath(f"{scheme}://{posixpath.dirname(rest)}")

    def with_name(self, name: str) -> RemotePath:
        return self.parent / name

    def relative_to(self, other: RemotePath) -> str:
        """The part of this URL below `other` (a POSIX relative path)."""
        prefix = str(other).rstrip("/") + "/"
        if not self.url.startswith(prefix):
            raise ValueError(f"{self.url!r} is not under {str(other)!r}")
        return self.url[len(prefix) :]

    def as_posix(self) -> str:
        return self.url

    # --- reading --------------------------------------------------------------------------------------------

    def exists(self) -> bool:
        return bool(self.fs.exists(self.path))

    def is_file(self) -> bool:
        return bool(self.fs.isfile(self.path))

    def is_dir(self) -> bool:
        return bool(self.fs.isdir(self.path))

    def read_bytes(self) -> bytes:
        return bytes(self.fs.cat_file(self.path))

    def read_text(self, encoding: str = "utf-8", errors: str = "strict") -> str:
        return self.read_bytes().decode(encoding, errors)

    def files(self) -> set[str]:
        """Every file below this folder, as paths relative to it (one listing, not one request per file)."""
        if not self.exists():
            return set()
        base = self.path.rstrip("/") + "/"
        return {p[len(base) :] for p in self.fs.find(self.path) if p.startswith(base)}

    def iterdir(self) -> list[RemotePath]:
        base = self.path.rstrip("/") + "/"
        return [self / p[len(base) :] for p in self.fs.ls(self.path, detail=False) if p.startswith(base)]

    def glob(self, pattern: str) -> list[RemotePath]:
        base = self.path.rstrip("/") + "/"
        return [self / p[len(base) :] for p in sorted(self.fs.glob(base + pattern)) if p.startswith(base)]

    # --- writing --------------------------------------------------------------------------------------------

    def mkdir(self, parents: bool = True, exist_ok: bool = True) -> None:
        if not self.atomic_put:  # object stores have no folders; a file system needs its parents
            self.fs.makedirs(self.path, exist_ok=True)

    def write_bytes(self, data: bytes) -> None:
        """Write `data` whole or not at all: one PUT on an object store, else a temporary name renamed."""
        fs = self.fs
        if self.atomic_put:
            fs.pipe_file(self.path, bytes(data))
            return
        parent = posixpath.dirname(self.path)
        fs.makedirs(parent, exist_ok=True)
        temporary = f"{parent}/.{self.name}{TEMPORARY_MARK}{os.getpid()}"
        try:
            fs.pipe_file(temporary, bytes(data))
            fs.mv(temporary, self.path)
        except BaseException:
            with contextlib.suppress(Exception):  # best effort: the temporary file may not exist
                fs.rm_file(temporary)
            raise

    def rmdir(self) -> None:
        """Remove this folder if it is empty (object stores have none to remove)."""
        if not self.atomic_put:
            with contextlib.suppress(OSError):
                self.fs.rmdir(self.path)

    def unlink(self, missing_ok: bool = False) -> None:
        try:
            self.fs.rm_file(self.path)
        except FileNotFoundError:
            if not missing_ok:
                raise


def to_location(value: Any) -> Any:
    """A ``RemotePath`` for a URL, else a local ``pathlib.Path``."""
    from pathlib import Path

    if isinstance(value, RemotePath):
        return value
    if is_url(value):
        return RemotePath(value)
    return Path(value)


def write_atomically(path: str | os.PathLike, write: Any) -> None:
    """Call ``write(file)`` on a temporary file beside `path`, then rename it to `path`.

    Readers never see a partly written `path`: it appears whole or not at all (``os.replace`` is atomic on
    one file system). On any exception, Ctrl-C included, the temporary file is removed. A URL (a string with
    ``scheme://`` or a ``RemotePath``) is written through fsspec, whole or not at all (``RemotePath.write_bytes``).
    """
    if is_url(path):
        buffer = io.BytesIO()
        write(buffer)
        (path if isinstance(path, RemotePath) else RemotePath(path)).write_bytes(buffer.getbuffer())
        return
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    temporary = target.with_name(f".{target.name}{TEMPORARY_MARK}{os.getpid()}")
    try:
        with open(temporary, "wb") as file:
            write(file)
        os.replace(temporary, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.remove(temporary)
        raise
