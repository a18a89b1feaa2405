"""The bytes of a CAAML file, read so that no file can hang or flood the reader, and its CAAML version.

A profile is read only from a regular file of at most :data:`MAX_BYTES` (a FIFO, a device or a
folder is refused before it is opened; the file is opened non-blocking and read with a bound). The
bytes must be an XML document whose root element is a CAAML ``SnowProfile``, of at most
:data:`MAX_ELEMENTS` elements nested at most :data:`MAX_DEPTH` deep (checked in one streaming pass,
so that a crafted file is refused in a fraction of a second); a document type or an entity
declaration (which CAAML never uses, and which could expand without bound) is refused.
"""

from __future__ import annotations

import os
import re
import stat
import xml.etree.ElementTree as ET

from .records import ProfileError

__all__ = ["MAX_BYTES", "MAX_ELEMENTS", "MAX_DEPTH", "read_capped", "caaml_version"]

#: largest profile file read (bytes): a field profile is 5-100 kB, one with hundreds of layers < 1 MB
MAX_BYTES = 8 * 1024 * 1024
#: most XML elements and deepest nesting of a profile (a layer is about 15 elements, CAAML nests about 8 deep)
MAX_ELEMENTS = 250_000
MAX_DEPTH = 64

_FIELD = "profile"
_KINDS = ((stat.S_ISDIR, "a directory"), (stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
          (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"))


def _not_regular(mode: int) -> str:
    return next((what for test, what in _KINDS if test(mode)), "not a regular file")


def read_capped(path, limit: int = MAX_BYTES) -> bytes:
    """The bytes of the regular file ``path`` (at most ``limit``); :class:`ProfileError` otherwise."""
    try:
        path = os.fspath(path)
    except TypeError:
        raise ProfileError(_FIELD, path, "a path to a CAAML file (str or os.PathLike)") from None
    try:
        st = os.stat(path)
    except FileNotFoundError:
        raise ProfileError(_FIELD, path, "an existing CAAML file (there is no such file)") from None
    except (OSError, ValueError) as e:
        raise ProfileError(_FIELD, path, f"a readable CAAML file ({getattr(e, 'strerror', None) or e})") from None
    if not stat.S_ISREG(st.st_mode):
        raise ProfileError(_FIELD, path, f"a regular CAAML file (this is {_not_regular(st.st_mode)})")
    if st.st_size > limit:
        raise ProfileError(_FIELD, path, f"a CAAML file of at most {limit / 2**20:g} MiB (this one has "
                                         f"{st.st_size / 2**20:.3g} MiB)")
    try:
        # non-blocking: were the file swapped for a FIFO since the stat, the open must not wait for a writer
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    except OSError as e:
        raise ProfileError(_FIELD, path, f"a readable CAAML file ({e.strerror})") from None
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise ProfileError(_FIELD, path, f"a regular CAAML file (this is {_not_regular(os.fstat(fd).st_mode)})")
        chunks, size = [], 0
        while size <= limit:
            chunk = os.read(fd, min(1 << 20, limit + 1 - size))
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    except OSError as e:
        raise ProfileError(_FIELD, path, f"a readable CAAML file ({e.strerror})") from None
    finally:
        os.close(fd)
    if size > limit:
        raise ProfileError(_FIELD, path, f"a CAAML file of at most {limit / 2**20:g} MiB (it grew while read)")
    return b"".join(chunks)


def _scan(data: bytes, path: str) -> str:
    """The root element's tag, after one streaming pass that checks the XML and bounds its size and nesting."""
    parser, depth, count, root = ET.XMLPullParser(events=("start", "end")), 0, 0, None
    try:
        for at in range(0, len(data), 1 << 16):
            parser.feed(data[at:at + (1 << 16)])
            for event, elem in parser.read_events():
                if event == "end":
                    depth -= 1
                    elem.clear()
                    continue
                depth, count = depth + 1, count + 1
                root = elem.tag if root is None else root
                if depth > MAX_DEPTH or count > MAX_ELEMENTS:
                    what = f"nesting deeper than {MAX_DEPTH}" if depth > MAX_DEPTH else f"over {MAX_ELEMENTS} elements"
                    raise ProfileError(_FIELD, path, f"a CAAML XML document of a snow profile (this one has {what})")
        parser.close()
    except ProfileError:
        raise
    except ET.ParseError as e:
        raise ProfileError(_FIELD, path, f"a CAAML XML document (it is not well-formed XML: {e})") from None
    except (ValueError, LookupError, RecursionError) as e:   # e.g. encoding="utf-9", bytes no codec decodes
        raise ProfileError(_FIELD, path, f"a CAAML XML document (it is not readable XML: {e})") from None
    return root


def caaml_version(data: bytes, path: str) -> str:
    """"5" or "6": the CAAML version of the XML document ``data``; :class:`ProfileError` if it is not one."""
    head = data.lstrip()[:1]
    if not head:
        raise ProfileError(_FIELD, path, "a CAAML XML document (the file is empty)")
    if head in (b"{", b"["):
        raise ProfileError(_FIELD, path, "a CAAML XML document (this looks like JSON: export the profile as "
                                         "CAAML XML)")
    if re.search(rb"<!(DOCTYPE|ENTITY)", data):
        raise ProfileError(_FIELD, path, "a CAAML XML document without a document type or entity declarations "
                                         "(CAAML uses none)")
    tag = _scan(data, path)
    m = re.fullmatch(r"(?:\{(.*)\})?(.*)", tag)
    ns, name = m.group(1) or "", m.group(2)
    if name != "SnowProfile":
        raise ProfileError(_FIELD, path, f"a CAAML SnowProfile document (its root element is {name!r})")
    if not ns:
        return "6"
    if "caaml" not in ns.lower():
        raise ProfileError(_FIELD, path, f"a CAAML 5 or 6 SnowProfile (its namespace {ns!r} is not CAAML's)")
    return "5" if re.search(r"[vV]5", ns) else "6"
