"""The file rules of the Python side, as the CLI's (src/impact1d_files.f90): only regular
files are read; files are written whole, under a temporary name of this process's own
beside the target, then renamed, so a full disk, an interrupt or another process writing
the same file leaves the previous file (or none, or the other's whole file), never a
truncated or mixed one."""

from __future__ import annotations

import contextlib
import errno
import os
import secrets
import signal
import stat
import sys
import threading

from ._scene import InputError

_KINDS = ((stat.S_ISDIR, "a folder"), (stat.S_ISFIFO, "a FIFO (named pipe)"),
          (stat.S_ISCHR, "a character device"), (stat.S_ISBLK, "a block device"),
          (stat.S_ISSOCK, "a socket"))


# Names of standard output, as impact1d's -o takes them (it streams the samples there);
# impact1d-plot and impact1d-sweep write files only, and say so for these.
STANDARD_OUTPUT = ("-", "/dev/stdout", "/dev/fd/1", "/proc/self/fd/1")


def _kind(mode) -> str:
    for test, name in _KINDS:
        if test(mode):
            return name
    return "not a regular file"


def check_input(path, what="file") -> None:
    """Refuse, before anything opens it, a path that is not a regular file (or a link to
    one): a FIFO or a device would block or never end. InputError names the path and what
    it is, or says that there is no such file."""
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        missing = "it is a symbolic link to a missing file" if os.path.islink(path) else "no such file"
        raise InputError(f"cannot open {what} '{os.fsdecode(path)}': {missing}") from None
    except OSError as error:
        raise InputError(f"cannot open {what} '{os.fsdecode(path)}': {error.strerror}") from None
    if not stat.S_ISREG(mode):
        raise InputError(f"cannot open {what} '{os.fsdecode(path)}': it is {_kind(mode)}, "
                         "not a regular file (only regular files are read)")


def output_target(path) -> str:
    """The file writing `path` replaces: `path` when it is missing or a regular file, the
    file a symbolic link there leads to when it is one to a regular file (written through:
    the link stays). InputError for anything else: a folder, FIFO, device or socket, or a
    link to nothing."""
    path = os.fspath(path)
    try:
        mode = os.stat(path).st_mode
    except FileNotFoundError:
        if os.path.islink(path):
            raise InputError(f"cannot write {path}: it is a symbolic link to a missing file") from None
        return path
    if not stat.S_ISREG(mode):
        raise InputError(f"cannot write {path}: it is {_kind(mode)}, not a regular file")
    return os.path.realpath(path) if os.path.islink(path) else path


def _create_temporary(target) -> str:
    """A new empty file beside target, TARGET_STEM.PID-N.part.EXT (the extension still
    tells writers the format), created exclusively: never another process's."""
    root, ext = os.path.splitext(target)
    while True:
        temporary = f"{root}.{os.getpid()}-{secrets.token_hex(3)}.part{ext}"
        try:
            os.close(os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
            return temporary
        except FileExistsError:
            continue


def write_whole(path, write) -> None:
    """Call write(temporary_path), then put that file in place as `path` (through a
    symbolic link at `path`: output_target). An OSError about the temporary file is
    raised as the same error about `path`: the temporary is ours, the user named `path`."""
    target = output_target(path)
    temporary = None
    try:
        temporary = _create_temporary(target)
        write(temporary)
        os.replace(temporary, target)
    except BaseException as error:
        if temporary is not None and os.path.lexists(temporary):
            os.remove(temporary)
        if isinstance(error, OSError) and _is_temporary(error.filename, target):
            # OSError(errno, ...) is the matching subclass again (FileNotFoundError, ...).
            raise OSError(error.errno, error.strerror, os.fspath(path)) from None
        raise


def _is_temporary(name, target) -> bool:
    """Whether `name` is one of _create_temporary's names for target."""
    if not isinstance(name, str):
        return False
    root, ext = os.path.splitext(target)
    return name.startswith(f"{root}.{os.getpid()}-") and name.endswith(f".part{ext}")


def print_line(text) -> None:
    """Print a line on stdout now; OSError when it cannot be written (a full disk, a closed
    stdout): a command's report that nobody can read is a failure, not a success. After a
    failure stdout goes to /dev/null, so that Python's own flush at exit does not fail
    again with a traceback."""
    if sys.stdout is None:         # Python found file descriptor 1 closed
        raise OSError(errno.EBADF, os.strerror(errno.EBADF))
    try:
        print(text, file=sys.stdout, flush=True)
    except OSError:
        null = os.open(os.devnull, os.O_WRONLY)
        os.dup2(null, sys.stdout.fileno())
        os.close(null)
        raise


class Ended(BaseException):
    """A signal that ends a command (SIGTERM, SIGHUP), raised in Python: on its way out
    write_whole removes its temporary file (it catches BaseException), which the signal's
    default action, ending the process at once, left behind."""

    def __init__(self, signum):
        super().__init__(signum)
        self.signum = signum


@contextlib.contextmanager
def ending_signals_raise():
    """Within: SIGTERM and SIGHUP raise Ended (a signal the caller ignores, nohup, stays
    ignored; only the main thread can set handlers). The previous handlers come back."""
    def handler(signum, frame):
        raise Ended(signum)

    previous = {}
    if threading.current_thread() is threading.main_thread():
        for sig in (signal.SIGTERM, signal.SIGHUP):
            if signal.getsignal(sig) == signal.SIG_DFL:
                previous[sig] = signal.signal(sig, handler)
    try:
        yield
    finally:
        for sig, handler_before in previous.items():
            signal.signal(sig, handler_before)


def die_of(signum, line) -> None:
    """Say line on stderr, then end by the signal as without a handler (a shell sees
    128 + signal, a parent the signal)."""
    print(line, file=sys.stderr, flush=True)
    signal.signal(signum, signal.SIG_DFL)
    os.kill(os.getpid(), signum)
