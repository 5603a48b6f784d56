"""Landlock: the Linux kernel's unprivileged sandbox, through its three system calls.

:func:`restrict_self` confines the calling process (and every process it starts) for
good: afterwards it may read only below the folders it was given, write nowhere, and
(ABI 4 and later) neither bind nor connect a TCP socket; ABI 6 and later also keep it
from signalling processes outside the sandbox and from abstract Unix sockets.

The calls are made with :mod:`ctypes` (``syscall(2)``): the numbers 444-446 are the same
on every Linux architecture, the structures are a handful of 64-bit fields. No Python
package is needed, and a kernel without Landlock (older than 5.13, or with the module
off) or another system is reported by :func:`abi_version` as 0.

Landlock restricts the calling *thread* and the threads and processes it creates later.
:func:`restrict_self` is therefore meant for a freshly forked, single-threaded child
(see :mod:`robotwright._confine`).
"""

from __future__ import annotations

import ctypes
import os
import sys
from collections.abc import Iterable
from pathlib import Path

__all__ = ["LandlockError", "abi_version", "restrict_self"]

_SYS_CREATE_RULESET = 444
_SYS_ADD_RULE = 445
_SYS_RESTRICT_SELF = 446
_CREATE_RULESET_VERSION = 1 << 0
_RULE_PATH_BENEATH = 1
_PR_SET_NO_NEW_PRIVS = 38

# Filesystem rights (include/uapi/linux/landlock.h), by the ABI that introduced them.
_FS_EXECUTE = 1 << 0
_FS_READ_FILE = 1 << 2
_FS_READ_DIR = 1 << 3
_FS_RIGHTS_BY_ABI = {1: (1 << 13) - 1, 2: (1 << 14) - 1, 3: (1 << 15) - 1, 5: (1 << 16) - 1}
_NET_BIND_TCP = 1 << 0
_NET_CONNECT_TCP = 1 << 1
_SCOPE_ABSTRACT_UNIX_SOCKET = 1 << 0
_SCOPE_SIGNAL = 1 << 1

#: Rights granted below a folder that may be read: open and list files, map libraries.
READ_RIGHTS = _FS_EXECUTE | _FS_READ_FILE | _FS_READ_DIR
# Rights a rule on a single file may carry (directory rights are refused there).
_FILE_RIGHTS = _FS_EXECUTE | (1 << 1) | _FS_READ_FILE | (1 << 14) | (1 << 15)


class LandlockError(OSError):
    """The kernel refused to set up the sandbox (message names the step)."""


class _RulesetAttr(ctypes.Structure):
    _fields_ = [
        ("handled_access_fs", ctypes.c_uint64),
        ("handled_access_net", ctypes.c_uint64),
        ("scoped", ctypes.c_uint64),
    ]


class _PathBeneathAttr(ctypes.Structure):
    _pack_ = 1  # __attribute__((packed)) in the kernel's header
    _fields_ = [("allowed_access", ctypes.c_uint64), ("parent_fd", ctypes.c_int32)]


def _libc() -> ctypes.CDLL | None:
    if not sys.platform.startswith("linux"):
        return None
    try:
        return ctypes.CDLL(None, use_errno=True)
    except OSError:
        return None


def abi_version() -> int:
    """The Landlock ABI version the running kernel offers; 0 where there is none
    (another system, an old kernel, Landlock disabled at boot)."""
    libc = _libc()
    if libc is None:
        return 0
    version = libc.syscall(
        ctypes.c_long(_SYS_CREATE_RULESET), None, ctypes.c_size_t(0), _CREATE_RULESET_VERSION
    )
    return max(0, int(version))


def _fs_rights(abi: int) -> int:
    return _FS_RIGHTS_BY_ABI[max(k for k in _FS_RIGHTS_BY_ABI if k <= abi)]


def _fail(step: str) -> LandlockError:
    err = ctypes.get_errno()
    return LandlockError(err, f"landlock {step}: {os.strerror(err)}")


def restrict_self(
    readable: Iterable[str | os.PathLike[str]], writable: Iterable[str | os.PathLike[str]] = ()
) -> int:
    """Confine the calling process: from now on it may read (and execute, and list)
    only below the existing paths in ``readable``, may create, write, rename or delete
    only below the existing folders in ``writable`` (which it may read too), and
    (ABI >= 4) may not bind or connect TCP sockets. Irreversible.

    Returns:
        The ABI version used.

    Raises:
        LandlockError: the kernel has no Landlock or refused a step.
    """
    libc = _libc()
    abi = abi_version()
    if libc is None or abi < 1:
        raise LandlockError(0, "landlock: not offered by this system")
    fs = _fs_rights(abi)
    attr = _RulesetAttr(handled_access_fs=fs)
    size = 8
    if abi >= 4:
        attr.handled_access_net = _NET_BIND_TCP | _NET_CONNECT_TCP
        size = 16
    if abi >= 6:
        attr.scoped = _SCOPE_ABSTRACT_UNIX_SOCKET | _SCOPE_SIGNAL
        size = 24
    ruleset = libc.syscall(
        ctypes.c_long(_SYS_CREATE_RULESET), ctypes.byref(attr), ctypes.c_size_t(size), 0
    )
    if ruleset < 0:
        raise _fail("create_ruleset")
    try:
        rules = [(p, READ_RIGHTS) for p in _existing(readable)]
        rules += [(p, fs) for p in _existing(writable) if os.path.isdir(p)]
        for path, granted in rules:
            flags = os.O_PATH | os.O_CLOEXEC
            try:
                fd = os.open(path, flags)
            except OSError:
                continue
            try:
                rights = granted if os.path.isdir(path) else granted & _FILE_RIGHTS
                rule = _PathBeneathAttr(allowed_access=rights & fs, parent_fd=fd)
                done = libc.syscall(
                    ctypes.c_long(_SYS_ADD_RULE), ruleset, _RULE_PATH_BENEATH, ctypes.byref(rule), 0
                )
                if done < 0:
                    raise _fail(f"add_rule {path}")
            finally:
                os.close(fd)
        if libc.prctl(_PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0:
            raise _fail("no_new_privs")
        if libc.syscall(ctypes.c_long(_SYS_RESTRICT_SELF), ruleset, 0) < 0:
            raise _fail("restrict_self")
    finally:
        os.close(ruleset)
    return abi


def _existing(paths: Iterable[str | os.PathLike[str]]) -> list[str]:
    """Each existing path once, resolved (a rule on a link would follow it anyway)."""
    seen: dict[str, None] = {}
    for p in paths:
        try:
            resolved = Path(p).resolve(strict=True)
        except (OSError, RuntimeError):
            continue
        seen.setdefault(str(resolved), None)
    return list(seen)
